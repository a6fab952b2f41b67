import "DPI-C" function chandle gyrofx_chain_new(input chandle plan);
import "DPI-C" function int gyrofx_chain_reset(input chandle chain);
import "DPI-C" function int gyrofx_chain_step(input chandle chain, input longint y_a, input longint y_b, input int bw_sel,
    output int mode_a, output int mode_b, output int out_valid, output longint rate_out,
    output longint bias_a, output longint bias_b, output int estimated);
import "DPI-C" function int gyrofx_chain_pipeline(input chandle handle, output int latency_clocks, output int min_clocks_per_sample);
