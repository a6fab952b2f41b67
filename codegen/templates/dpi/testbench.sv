@provenance@
// Language: SystemVerilog (Verilator --binary --timing), with DPI-C imports from libgyrofx_capi.
`timescale 1ns / 1ps
`default_nettype none

/*
 * @tb@: @module@ (@title@) against gyrofx's golden model through DPI-C (see the package
 * README): random codes over the input range (every other stretch of 64 samples at 1/256 of
 * it), the model of this package's manifest stepped beside the DUT. PASS n=<N> or
 * FAIL mismatches=<M> n=<N>; plusargs +samples=<n> (default @samples@), +seed=<n>, +flip=<k>.
 */
module @tb@;

`include "@params_file@"
localparam integer TB_INTERVAL_W = @interval_width@;

import gyrofx_dpi_pkg::*;

logic clk = 1'b0;
always #5 clk = ~clk;
logic rst = 1'b1;
logic ce = 1'b0;
@declarations@

@instance@
chandle plan, kf, filter, chain, sequencer, estimator, gyro_loop, system;
longint stream_model, model_kept, bias_a_model, bias_b_model, quadrature_model;
longint dac_x_model, dac_y_model, dac_a_x_model, dac_a_y_model, dac_b_x_model, dac_b_y_model;
int valid, model_mode_a, model_mode_b, estimated_model, locked_model, locked_a_model, locked_b_model;
int model_blank_a, model_blank_b, model_interval_a, model_interval_b;
int model_done_a, model_done_b, model_window_done;
longint expected_first[$];
longint expected_second[$];
int compared = 0;
int mismatches = 0;
int expected_count = 0;
int flip = -1;
int samples = @samples@;
int seed = 1;
int k;

// A random code of a `width`-bit signed port: the whole range, or 1/256 of it in every
// other stretch of 64 samples (small signals, where rounding rather than saturation rules).
function automatic longint random_code(input int width, input int sample);
    longint wide;
    wide = {$urandom(), $urandom()};
    wide = wide >>> (64 - width);
    if ((sample / 64) % 2 == 1) wide = wide >>> 8;
    return wide;
endfunction

// The next expected value, bit 0 flipped when it is the +flip=<k>-th.
function automatic longint flip_next(input longint value);
    flip_next = (expected_count == flip) ? (value ^ 64'sd1) : value;
    expected_count = expected_count + 1;
endfunction

function automatic void expect_stream(input longint first, input longint second);
    expected_first.push_back(flip_next(first));
    expected_second.push_back(second);
endfunction

function automatic void compare(input longint actual, input longint expected, input string name);
    compared = compared + 1;
    if (actual != expected) begin
        mismatches = mismatches + 1;
        if (mismatches <= 10)
            $display("MISMATCH sample %0d signal %s expected %0d actual %0d", k, name, expected, actual);
    end
endfunction

function automatic void check_call(input int status);
    if (status != 0) $fatal(1, "the model refused an input: %s", gyrofx_last_error());
endfunction

@monitor@
initial begin
    void'($value$plusargs("samples=%d", samples));
    void'($value$plusargs("seed=%d", seed));
    void'($value$plusargs("flip=%d", flip));
    void'($urandom(seed));
    plan = gyrofx_plan_from_package("..");
    if (plan == null) $fatal(1, "gyrofx_plan_from_package: %s", gyrofx_last_error());
    @handles@
    repeat (4) @(posedge clk);
    @(negedge clk);
    rst = 1'b0;
    for (k = 0; k < samples; k = k + 1) begin
        @(negedge clk);
        ce = 1'b1;
@step@
        if ($urandom_range(3, 0) == 0) begin
            @(negedge clk);
            ce = 1'b0;
            @(posedge clk);
        end
    end
    @(negedge clk);
    ce = 1'b0;
    repeat (16) @(posedge clk);
    @(negedge clk);
    if (expected_first.size() != 0) begin
        mismatches = mismatches + 1;
        $display("MISMATCH %0d expected outputs never came", expected_first.size());
    end
    gyrofx_plan_free(plan);
    if (mismatches == 0 && compared > 0) begin
        $display("PASS n=%0d", compared);
        $finish;
    end else begin
        $display("FAIL mismatches=%0d n=%0d", mismatches, compared);
        $fatal(1, "@tb@ failed");
    end
end

endmodule
