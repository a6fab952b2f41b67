import "DPI-C" function chandle gyrofx_system_new(input chandle plan);
import "DPI-C" function int gyrofx_system_reset(input chandle system);
import "DPI-C" function int gyrofx_system_step(input chandle system, input int enable, input int bw_sel,
    input longint adc_a_x, input longint adc_a_y, input longint adc_b_x, input longint adc_b_y,
    output longint dac_a_x, output longint dac_a_y, output longint dac_b_x, output longint dac_b_y,
    output int locked_a, output int locked_b, output int mode_a, output int mode_b, output int out_valid,
    output longint rate_out, output longint bias_a, output longint bias_b, output int estimated);
import "DPI-C" function int gyrofx_system_pipeline(input chandle handle, output int latency_clocks, output int min_clocks_per_sample);
