// The stream: each valid-qualified output against the oldest expected one, whatever
// the latency (sampled mid-cycle, after the registers settled).
always @(negedge clk) begin
    if (!rst && @valid@ == 1'b1) begin
        if (expected_first.size() == 0) begin
            mismatches = mismatches + 1;
            $display("MISMATCH @value@ = %0d with none expected", longint'(@value@));
        end else begin
            compare(longint'(@value@), expected_first.pop_front(), "@value@");
            @second@
        end
    end
end
