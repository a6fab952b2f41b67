/* A C program against gyrofx.h (the test in tests/dpi.rs builds and runs it): a plan from
 * TOML text, a refused config and a refused input with their messages, and a KF run whose
 * outputs the test compares with the Rust model. Prints one line per result. */
#include <stdint.h>
#include <stdio.h>

#include "gyrofx.h"

int main(void) {
    printf("version %s\n", gyrofx_version());
    GyrofxPlan *bad = gyrofx_plan_from_toml("[kf]\nbandwidths_hz = [10.0, 500.0]\n");
    printf("bad plan %s: %s\n", bad == NULL ? "NULL" : "made", gyrofx_last_error());
    GyrofxPlan *plan = gyrofx_plan_from_toml("[kf]\nbandwidths_hz = [5.0, 10.0]\n");
    if (plan == NULL) {
        printf("plan failed: %s\n", gyrofx_last_error());
        return 1;
    }
    GyrofxKf *kf = gyrofx_kf_new(plan);
    gyrofx_plan_free(plan); /* the KF keeps its own copy */
    int64_t rate = 0;
    int status = gyrofx_kf_step(kf, INT64_C(1) << 40, 0, &rate);
    printf("refused z: %d %s\n", status, gyrofx_last_error());
    status = gyrofx_kf_step(kf, 5, 2, &rate);
    printf("refused bw_sel: %d %s\n", status, gyrofx_last_error());
    for (int64_t k = 0; k < 50; ++k) {
        int64_t z = (k * 7919 % 20001) - 10000;
        if (gyrofx_kf_step(kf, z, (int)(k / 25), &rate) != 0) return 1;
        printf("rate %lld\n", (long long)rate);
    }
    gyrofx_kf_free(kf);
    gyrofx_kf_free(NULL);
    status = gyrofx_kf_step(NULL, 0, 0, &rate); /* before reading the error: C leaves the
                                                  * order of a call's arguments open */
    printf("null step: %d %s\n", status, gyrofx_last_error());
    return 0;
}
