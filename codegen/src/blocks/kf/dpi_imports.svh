import "DPI-C" function chandle gyrofx_kf_new(input chandle plan);
import "DPI-C" function int gyrofx_kf_reset(input chandle kf);
import "DPI-C" function int gyrofx_kf_step(input chandle kf, input longint z, input int bw_sel, output longint rate_out);
import "DPI-C" function int gyrofx_kf_pipeline(input chandle handle, output int latency_clocks, output int min_clocks_per_sample);
