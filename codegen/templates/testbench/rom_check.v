    // $readmemh in the DUT only warns about a missing file (Icarus): check it here.
    rom_fd = $fopen("@rom@", "r");
    if (rom_fd == 0) begin
        $sformat(message, "cannot open @rom@");
        fail_setup;
    end
    $fclose(rom_fd);
