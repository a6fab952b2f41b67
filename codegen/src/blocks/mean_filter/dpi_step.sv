            x = random_code(P_IN_W, k);
            check_call(gyrofx_mean_filter_step(filter, longint'(x), valid, stream_model, model_kept));
            if (valid == 1) expect_stream(stream_model, model_kept);
            @(posedge clk);
