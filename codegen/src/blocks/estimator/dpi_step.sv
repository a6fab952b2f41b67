            // The slot comes from the sequencer's own model: the estimator's protocol.
            check_call(gyrofx_sequencer_step(sequencer, model_mode_a, model_mode_b, model_blank_a,
                model_blank_b, model_interval_a, model_interval_b, model_done_a, model_done_b,
                model_window_done));
            y_a = random_code(P_IN_W, k);
            y_b = random_code(P_IN_W, k + 1);
            blank_a = model_blank_a[0];
            blank_b = model_blank_b[0];
            done_a = model_done_a[0];
            done_b = model_done_b[0];
            interval_a = model_interval_a[TB_INTERVAL_W - 1:0];
            interval_b = model_interval_b[TB_INTERVAL_W - 1:0];
            window_done = model_window_done[0];
            check_call(gyrofx_estimator_step(estimator, longint'(y_a), longint'(y_b), model_blank_a,
                model_blank_b, model_done_a, model_done_b, model_interval_a, model_interval_b,
                model_window_done, bias_a_model, bias_b_model, estimated_model));
            // The estimates show @settle@ clocks after the edge that takes the sample.
            @(posedge clk);
            @(negedge clk);
            ce = 1'b0;
            repeat (@settle@) @(posedge clk);
            #1;
            compare(longint'(bias_a), flip_next(bias_a_model), "bias_a");
            compare(longint'(bias_b), bias_b_model, "bias_b");
            compare(longint'(estimated), longint'(estimated_model), "estimated");
