// Language: Verilog 2001 (+ $fatal, supported by Icarus and Verilator)

`resetall
`timescale 1ns / 1ps
`default_nettype none

/*
 * gyrofx_spacing_check — simulation only: stops the simulation when a sample (a clock with
 * ce high) comes sooner than MIN_CLOCKS_PER_SAMPLE clocks after the previous one.
 *
 * Purpose: a pipelined block (gyrofx_kf, gyrofx_bias_estimator, gyrofx_top,
 *   gyrofx_gyro_loop, gyrofx_system) takes a sample at most every MIN_CLOCKS_PER_SAMPLE
 *   clocks; a sooner ce would be lost in its pipeline without a trace. Each instantiates this
 *   checker inside `ifndef SYNTHESIS (yosys defines SYNTHESIS), so it never reaches a
 *   netlist. gyrofx_job::pipeline holds the same figures for the testbenches and models.
 *
 * Behaviour: counts the clocks since the last ce (rst clears the count's history); on a ce
 *   sooner than the minimum prints "FAIL <instance>: a sample <n> clocks after the previous
 *   one; <BLOCK_NAME> takes one at most every <m> clocks" and calls $fatal.
 *
 * The whole module is left out under SYNTHESIS too: a synthesis flow that reads every file
 *   of hdl/ never sees the simulation-only tasks.
 */
`ifndef SYNTHESIS
module gyrofx_spacing_check #(
    // the fewest clocks from one sample's ce to the next one's
    parameter integer MIN_CLOCKS_PER_SAMPLE = 2,
    // the checked block's module name, for the message
    parameter BLOCK_NAME = "block"
) (
    input  wire clk,
    input  wire rst,
    input  wire ce
);

integer clocks_since_sample = MIN_CLOCKS_PER_SAMPLE;

always @(posedge clk) begin
    if (rst) begin
        clocks_since_sample <= MIN_CLOCKS_PER_SAMPLE;
    end else if (ce) begin
        if (clocks_since_sample < MIN_CLOCKS_PER_SAMPLE) begin
            $display("FAIL %m: a sample %0d clocks after the previous one; %0s takes one at most every %0d clocks",
                clocks_since_sample, BLOCK_NAME, MIN_CLOCKS_PER_SAMPLE);
            $fatal(1, "%m: samples closer than MIN_CLOCKS_PER_SAMPLE");
        end
        clocks_since_sample <= 1;
    end else if (clocks_since_sample < MIN_CLOCKS_PER_SAMPLE) begin
        clocks_since_sample <= clocks_since_sample + 1;
    end
end

endmodule
`endif

`resetall
