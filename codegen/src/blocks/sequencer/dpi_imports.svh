import "DPI-C" function chandle gyrofx_sequencer_new(input chandle plan);
import "DPI-C" function int gyrofx_sequencer_reset(input chandle sequencer);
import "DPI-C" function int gyrofx_sequencer_step(input chandle sequencer, output int mode_a, output int mode_b,
    output int blank_a, output int blank_b, output int interval_a, output int interval_b,
    output int done_a, output int done_b, output int window_done);
import "DPI-C" function int gyrofx_sequencer_pipeline(input chandle handle, output int latency_clocks, output int min_clocks_per_sample);
