/* A C program against gyrofx.h (the test in tests/dpi.rs builds and runs it): a plan from
 * TOML text, a refused config and a refused input with their messages, a KF run, and gyro B's
 * loop and the system on a few samples, whose outputs the test compares with the Rust model.
 * Prints one line per result. */
#include <stdint.h>
#include <stdio.h>

#include "gyrofx.h"

int main(void) {
    int latency, spacing;
    printf("version %s\n", gyrofx_version());
    GyrofxPlan *bad = gyrofx_plan_from_toml("[kf]\nbandwidths_hz = [10.0, 500.0]\n");
    printf("bad plan %s: %s\n", bad == NULL ? "NULL" : "made", gyrofx_last_error());
    GyrofxPlan *plan = gyrofx_plan_from_toml("[kf]\nbandwidths_hz = [5.0, 10.0]\n");
    if (plan == NULL) {
        printf("plan failed: %s\n", gyrofx_last_error());
        return 1;
    }
    GyrofxKf *kf = gyrofx_kf_new(plan);
    GyrofxGyroLoop *no_loop = gyrofx_gyro_loop_new(plan, 2);
    printf("bad gyro %s: %s\n", no_loop == NULL ? "NULL" : "made", gyrofx_last_error());
    GyrofxGyroLoop *loop = gyrofx_gyro_loop_new(plan, 1);
    GyrofxSystem *system = gyrofx_system_new(plan);
    gyrofx_plan_free(plan); /* the blocks keep their own copies */
    int64_t dac_x, dac_y, loop_rate, quadrature;
    int locked, valid;
    printf("refused mode: %d ", gyrofx_gyro_loop_step(loop, 0, 0, 2, &dac_x, &dac_y, &locked, &valid,
                                                       &loop_rate, &quadrature));
    printf("%s\n", gyrofx_last_error());
    for (int64_t k = 0; k < 20; ++k) {
        if (gyrofx_gyro_loop_step(loop, k * 40009 % 1000003, -k * 7, (int)(k < 10), &dac_x, &dac_y,
                                  &locked, &valid, &loop_rate, &quadrature) != 0)
            return 1;
        printf("loop %lld %lld %d %d\n", (long long)dac_x, (long long)dac_y, locked, valid);
    }
    int64_t dac[4], rate_out, bias_a, bias_b;
    int flags[2], modes[2], estimated;
    for (int64_t k = 0; k < 20; ++k) {
        int next[2];
        if (gyrofx_system_next_modes(system, &next[0], &next[1]) != 0) return 1;
        if (gyrofx_system_step(system, (int)(k >= 5), 0, k * 1000, -k * 1000, k * 77, 3 - k, &dac[0],
                               &dac[1], &dac[2], &dac[3], &flags[0], &flags[1], &modes[0], &modes[1],
                               &valid, &rate_out, &bias_a, &bias_b, &estimated) != 0)
            return 1;
        printf("system %d %d %lld %lld %lld %lld %d %d\n", next[0], next[1], (long long)dac[0],
               (long long)dac[1], (long long)dac[2], (long long)dac[3], modes[0], modes[1]);
    }
    if (gyrofx_gyro_loop_pipeline(loop, &latency, &spacing) != 0) return 1;
    printf("pipeline gyro_loop %d %d\n", latency, spacing);
    if (gyrofx_system_pipeline(system, &latency, &spacing) != 0) return 1;
    printf("pipeline system %d %d\n", latency, spacing);
    gyrofx_gyro_loop_free(loop);
    gyrofx_system_free(system);
    GyrofxPlan *serial = gyrofx_plan_from_toml("architecture = \"serial\"\n");
    GyrofxChain *chain = gyrofx_chain_new(serial);
    GyrofxMeanFilter *filter = gyrofx_mean_filter_new(serial);
    GyrofxEstimator *estimator = gyrofx_estimator_new(serial);
    GyrofxSequencer *sequencer = gyrofx_sequencer_new(serial);
    if (gyrofx_chain_pipeline(chain, &latency, &spacing) != 0) return 1;
    printf("pipeline serial chain %d %d\n", latency, spacing);
    if (gyrofx_mean_filter_pipeline(filter, &latency, &spacing) != 0) return 1;
    printf("pipeline serial mean_filter %d %d\n", latency, spacing);
    if (gyrofx_estimator_pipeline(estimator, &latency, &spacing) != 0) return 1;
    printf("pipeline estimator %d %d\n", latency, spacing);
    if (gyrofx_sequencer_pipeline(sequencer, &latency, &spacing) != 0) return 1;
    printf("pipeline sequencer %d %d\n", latency, spacing);
    gyrofx_chain_free(chain);
    gyrofx_mean_filter_free(filter);
    gyrofx_estimator_free(estimator);
    gyrofx_sequencer_free(sequencer);
    gyrofx_plan_free(serial);
    GyrofxPlan *rate_plant = gyrofx_plan_from_toml("[plant]\nmodel = \"rate\"\n");
    GyrofxSystem *no_system = gyrofx_system_new(rate_plant);
    printf("no system for the rate plant, %s: %s\n", no_system == NULL ? "NULL" : "made", gyrofx_last_error());
    gyrofx_plan_free(rate_plant);
    int64_t rate = 0;
    int status = gyrofx_kf_step(kf, INT64_C(1) << 40, 0, &rate);
    printf("refused z: %d %s\n", status, gyrofx_last_error());
    char saved[256];
    int length = gyrofx_last_error_copy(saved, (int)sizeof saved);
    status = gyrofx_kf_step(kf, 5, 2, &rate);
    printf("refused bw_sel: %d %s\n", status, gyrofx_last_error());
    /* The copy is the caller's: the next failure replaced the library's text, not this. */
    printf("copied %d: %s\n", length, saved);
    char cut[8];
    length = gyrofx_last_error_copy(cut, (int)sizeof cut);
    printf("cut %d: %s\n", length, cut);
    printf("copy refused: %d %d\n", gyrofx_last_error_copy(NULL, 8), gyrofx_last_error_copy(cut, -1));
    for (int64_t k = 0; k < 50; ++k) {
        int64_t z = (k * 7919 % 20001) - 10000;
        if (gyrofx_kf_step(kf, z, (int)(k / 25), &rate) != 0) return 1;
        printf("rate %lld\n", (long long)rate);
    }
    int ports = gyrofx_kf_port_count(kf);
    for (int index = 0; index < ports; ++index) {
        const char *name;
        int width, fraction, is_signed, is_output;
        if (gyrofx_kf_port(kf, index, &name, &width, &fraction, &is_signed, &is_output) != 0) return 1;
        printf("port kf %s %s %c%d.%d\n", name, is_output ? "out" : "in", is_signed ? 's' : 'u', width,
               fraction);
    }
    status = gyrofx_kf_port(kf, ports, NULL, NULL, NULL, NULL, NULL);
    printf("no port: %d %s\n", status, gyrofx_last_error());
    if (gyrofx_kf_pipeline(kf, &latency, &spacing) != 0) return 1;
    printf("pipeline kf %d %d\n", latency, spacing);
    gyrofx_kf_free(kf);
    gyrofx_kf_free(NULL);
    printf("null pipeline: %d\n", gyrofx_kf_pipeline(NULL, &latency, &spacing));
    status = gyrofx_kf_step(NULL, 0, 0, &rate); /* before reading the error: C leaves the
                                                  * order of a call's arguments open */
    printf("null step: %d %s\n", status, gyrofx_last_error());
    return 0;
}
