            // enable low for the first 500 samples (the start-up), then high.
            enable = (k >= 500) ? 1'b1 : 1'b0;
            bw_sel = (k % 997 == 0) ? $urandom_range(P_ROM_DEPTH - 1, 0) : bw_sel;
            adc_a_x = random_code(P_DEMOD_ADC_W, k);
            adc_a_y = random_code(P_DEMOD_ADC_W, k + 1);
            adc_b_x = random_code(P_DEMOD_ADC_W, k + 2);
            adc_b_y = random_code(P_DEMOD_ADC_W, k + 3);
            check_call(gyrofx_system_step(system, int'(enable), int'(bw_sel), longint'(adc_a_x),
                longint'(adc_a_y), longint'(adc_b_x), longint'(adc_b_y), dac_a_x_model, dac_a_y_model,
                dac_b_x_model, dac_b_y_model, locked_a_model, locked_b_model, model_mode_a, model_mode_b,
                valid, stream_model, bias_a_model, bias_b_model, estimated_model));
            if (valid == 1) expect_stream(stream_model, 0);
            // Every output shows @settle@ clocks after the edge that takes the sample.
            @(posedge clk);
            @(negedge clk);
            ce = 1'b0;
            repeat (@settle@) @(posedge clk);
            #1;
            compare(longint'(dac_a_x), flip_next(dac_a_x_model), "dac_a_x");
            compare(longint'(dac_a_y), dac_a_y_model, "dac_a_y");
            compare(longint'(dac_b_x), dac_b_x_model, "dac_b_x");
            compare(longint'(dac_b_y), dac_b_y_model, "dac_b_y");
            compare(longint'(locked_a), longint'(locked_a_model), "locked_a");
            compare(longint'(locked_b), longint'(locked_b_model), "locked_b");
            compare(longint'(mode_a), longint'(model_mode_a), "mode_a");
            compare(longint'(mode_b), longint'(model_mode_b), "mode_b");
            compare(longint'(bias_a), bias_a_model, "bias_a");
            compare(longint'(bias_b), bias_b_model, "bias_b");
            compare(longint'(estimated), longint'(estimated_model), "estimated");
