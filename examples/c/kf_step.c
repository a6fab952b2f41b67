/* The C model in a few lines: the default plan's KF, one sample, the error text copied into a
 * buffer of yours. Build against an installed libgyrofx_capi (scripts/install-capi.sh):
 *
 *     cc -std=c99 kf_step.c $(pkg-config --cflags --libs gyrofx_capi) -o kf_step
 *
 * The test suite builds and runs it (tests/dpi.rs) and checks its code against the Rust model.
 */
#include <gyrofx.h>
#include <stdio.h>

int main(void) {
    struct GyrofxPlan *plan = gyrofx_plan_default();
    struct GyrofxKf *kf = gyrofx_kf_new(plan);
    int64_t rate_out;
    if (plan == NULL || kf == NULL || gyrofx_kf_step(kf, 1000, 0, &rate_out) != 0) {
        char message[256];
        gyrofx_last_error_copy(message, sizeof message);
        fprintf(stderr, "%s\n", message);
        return 1;
    }
    printf("rate_out = %lld\n", (long long)rate_out);
    /* A code outside the input format is refused, naming the port. */
    if (gyrofx_kf_step(kf, (int64_t)1 << 40, 0, &rate_out) == 0) {
        return 1;
    }
    char message[256];
    gyrofx_last_error_copy(message, sizeof message);
    printf("refused: %s\n", message);
    gyrofx_kf_free(kf);
    gyrofx_plan_free(plan);
    return 0;
}
