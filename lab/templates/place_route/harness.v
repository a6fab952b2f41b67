`default_nettype none
// Place-and-route harness of @module@: @in_bits@ input bits from one shift register,
// @out_bits@ output bits captured and shifted out, 4 pins.
module @harness@ (
    input wire clk,
    input wire serial_in,
    input wire capture,
    output wire serial_out
);
@input_regs@@output_wires@reg [@out_top@:0] captured = {@out_bits@{1'b0}};
always @(posedge clk) begin
    {@input_names@} <= {@shifted_inputs@serial_in};
    captured <= capture ? {@output_names@} : {1'b0, captured[@out_top@:1]};
end
assign serial_out = captured[0];
@configured@ dut (
@ports@
);
endmodule
`default_nettype wire
