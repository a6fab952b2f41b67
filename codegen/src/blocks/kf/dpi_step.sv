            bw_sel = (k % 97 == 0) ? $urandom_range(P_ROM_DEPTH - 1, 0) : bw_sel;
            z = random_code(P_IN_W, k);
            check_call(gyrofx_kf_step(kf, longint'(z), int'(bw_sel), stream_model));
            expect_stream(stream_model, 0);
            // The next sample after the pipeline's @idle@ clocks more (ce every @every@th clock).
            @(posedge clk);
            @(negedge clk);
            ce = 1'b0;
            repeat (@idle@) @(posedge clk);
