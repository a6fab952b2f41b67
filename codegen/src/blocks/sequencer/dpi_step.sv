            check_call(gyrofx_sequencer_step(sequencer, model_mode_a, model_mode_b, model_blank_a,
                model_blank_b, model_interval_a, model_interval_b, model_done_a, model_done_b,
                model_window_done));
            #1;
            compare(longint'(mode_a), flip_next(longint'(model_mode_a)), "mode_a");
            compare(longint'(mode_b), longint'(model_mode_b), "mode_b");
            compare(longint'(blank_a), longint'(model_blank_a), "blank_a");
            compare(longint'(blank_b), longint'(model_blank_b), "blank_b");
            compare(longint'(interval_a), longint'(model_interval_a), "interval_a");
            compare(longint'(interval_b), longint'(model_interval_b), "interval_b");
            compare(longint'(done_a), longint'(model_done_a), "done_a");
            compare(longint'(done_b), longint'(model_done_b), "done_b");
            compare(longint'(window_done), longint'(model_window_done), "window_done");
            @(posedge clk);
