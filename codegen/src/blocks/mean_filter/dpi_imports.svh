import "DPI-C" function chandle gyrofx_mean_filter_new(input chandle plan);
import "DPI-C" function int gyrofx_mean_filter_reset(input chandle filter);
import "DPI-C" function int gyrofx_mean_filter_step(input chandle filter, input longint x, output int y_valid, output longint y, output longint kept);
import "DPI-C" function int gyrofx_mean_filter_pipeline(input chandle handle, output int latency_clocks, output int min_clocks_per_sample);
