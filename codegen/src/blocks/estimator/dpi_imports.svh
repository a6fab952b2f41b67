import "DPI-C" function chandle gyrofx_estimator_new(input chandle plan);
import "DPI-C" function int gyrofx_estimator_reset(input chandle estimator);
import "DPI-C" function int gyrofx_estimator_step(input chandle estimator, input longint y_a, input longint y_b,
    input int blank_a, input int blank_b, input int done_a, input int done_b,
    input int interval_a, input int interval_b, input int window_done,
    output longint bias_a, output longint bias_b, output int estimated);
import "DPI-C" function int gyrofx_estimator_pipeline(input chandle handle, output int latency_clocks, output int min_clocks_per_sample);
