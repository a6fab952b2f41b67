`default_nettype none
// @name@: the whole system on one part, as a sensor board carries it. The folded system
// (@system@) and, on its published rate, one sample at each out_valid, the serial mean filter
// (@mean_filter@). Place and route only: each of the two is proven bit-exact against its
// model by its own vectors; this wiring measures what they take together.
module @top@ (
@ports@
);
@system_top@ system (
@system_ports@
);
@mean_filter_top@ mean_filter (
    .clk(clk),
    .rst(rst),
    .ce(out_valid),
    .x(@x@),
@mean_filter_ports@
);
endmodule
`default_nettype wire
