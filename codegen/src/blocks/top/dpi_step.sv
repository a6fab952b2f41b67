            bw_sel = (k % 97 == 0) ? $urandom_range(P_ROM_DEPTH - 1, 0) : bw_sel;
            y_a = random_code(P_IN_W, k);
            y_b = random_code(P_IN_W, k + 1);
            check_call(gyrofx_chain_step(chain, longint'(y_a), longint'(y_b), int'(bw_sel),
                model_mode_a, model_mode_b, valid, stream_model, bias_a_model, bias_b_model, estimated_model));
            #1;
            compare(longint'(mode_a), longint'(model_mode_a), "mode_a");
            compare(longint'(mode_b), longint'(model_mode_b), "mode_b");
            if (valid == 1) expect_stream(stream_model, 0);
            // The estimates show @settle@ clocks after the edge that takes the sample.
            @(posedge clk);
            @(negedge clk);
            ce = 1'b0;
            repeat (@settle@) @(posedge clk);
            #1;
            compare(longint'(bias_a), flip_next(bias_a_model), "bias_a");
            compare(longint'(bias_b), bias_b_model, "bias_b");
            compare(longint'(estimated), longint'(estimated_model), "estimated");
