    @fd@ = $fopen(@file@, "r");
    if (@fd@ == 0) begin
        $sformat(message, "cannot open %0s", @file@);
        fail_setup;
    end
    fields = $fgets(line, @fd@);
    fields = $fscanf(@fd@, "// @pattern@\n", @targets@);
    if (fields != @count@ || @compare@) begin
        $sformat(message, "%0s declares @declared_pattern@; the testbench expects @wanted_text@", @file@, @targets@);
        fail_setup;
    end
