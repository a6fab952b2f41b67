import "DPI-C" function chandle gyrofx_gyro_loop_new(input chandle plan, input int gyro);
import "DPI-C" function int gyrofx_gyro_loop_reset(input chandle gyro_loop);
import "DPI-C" function int gyrofx_gyro_loop_step(input chandle gyro_loop, input longint adc_x, input longint adc_y,
    input int mode, output longint dac_x, output longint dac_y, output int locked, output int out_valid,
    output longint rate, output longint quadrature);
import "DPI-C" function int gyrofx_gyro_loop_pipeline(input chandle handle, output int latency_clocks, output int min_clocks_per_sample);
