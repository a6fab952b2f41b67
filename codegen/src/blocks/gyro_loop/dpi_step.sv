            // A mode switch every 701 samples: the loop's presets and re-acquisition.
            if (k == 0) mode = 1'b1;
            else if (k % 701 == 0) mode = ~mode;
            adc_x = random_code(P_DEMOD_ADC_W, k);
            adc_y = random_code(P_DEMOD_ADC_W, k + 1);
            check_call(gyrofx_gyro_loop_step(gyro_loop, longint'(adc_x), longint'(adc_y), int'(mode),
                dac_x_model, dac_y_model, locked_model, valid, stream_model, quadrature_model));
            if (valid == 1) expect_stream(stream_model, quadrature_model);
            // The outputs show @settle@ clocks after the edge that takes the sample; the next
            // sample may come then.
            @(posedge clk);
            @(negedge clk);
            ce = 1'b0;
            repeat (@settle@) @(posedge clk);
            #1;
            compare(longint'(dac_x), flip_next(dac_x_model), "dac_x");
            compare(longint'(dac_y), dac_y_model, "dac_y");
            compare(longint'(locked), longint'(locked_model), "locked");
