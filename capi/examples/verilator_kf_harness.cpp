// A C++ Verilator harness that checks gyrofx_kf against gyrofx's C API directly (no DPI):
// the model is stepped beside the DUT and every out_valid-qualified rate_out is compared.
// A sample every 3rd clock: the KF's pipeline takes one sample at a time (docs/blocks/kf.md).
//
// Build and run it from a generated package's kf/ folder (ROM paths are relative to it), with
// the package's parameter wrapper as the top level:
//
//   verilator --cc --exe --build -j 2 -I. --top-module cocotb_gyrofx_kf \
//       ../hdl/gyrofx_quantize.v ../hdl/gyrofx_kf.v ../cocotb/cocotb_gyrofx_kf.v \
//       <gyrofx>/capi/examples/verilator_kf_harness.cpp \
//       -CFLAGS -I<gyrofx>/capi/include \
//       -LDFLAGS "<gyrofx>/target/release/libgyrofx_capi.a -lpthread -ldl -lm"
//   ./obj_dir/Vcocotb_gyrofx_kf [samples]
//
// Prints PASS n=<N> or FAIL mismatches=<M> n=<N> (exit 1).

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <memory>

#include "Vcocotb_gyrofx_kf.h"
#include "gyrofx.h"
#include "verilated.h"

namespace {

// A code of a `width`-bit signed port from a 64-bit random word.
int64_t random_code(uint64_t &state, int width) {
    state ^= state << 13;
    state ^= state >> 7;
    state ^= state << 17;
    return static_cast<int64_t>(state) >> (64 - width);
}

// The DUT's `width`-bit signed output as int64_t.
int64_t sign_extend(uint64_t bits, int width) {
    return static_cast<int64_t>(bits << (64 - width)) >> (64 - width);
}

}  // namespace

int main(int argc, char **argv) {
    const long samples = argc > 1 ? std::atol(argv[1]) : 5000;
    GyrofxPlan *plan = gyrofx_plan_from_package("..");
    if (plan == nullptr) {
        std::fprintf(stderr, "gyrofx_plan_from_package: %s\n", gyrofx_last_error());
        return 2;
    }
    GyrofxKf *kf = gyrofx_kf_new(plan);
    auto context = std::make_unique<VerilatedContext>();
    auto dut = std::make_unique<Vcocotb_gyrofx_kf>(context.get());
    const int in_width = 24;   // the default config's kf.input (s24.14)
    const int out_width = 24;  // kf.output (s24.14)

    auto tick = [&]() {
        dut->clk = 0;
        dut->eval();
        dut->clk = 1;
        dut->eval();
    };
    dut->rst = 1;
    dut->ce = 0;
    for (int i = 0; i < 4; ++i) tick();
    dut->rst = 0;

    std::deque<int64_t> expected;
    uint64_t state = 0x9e3779b97f4a7c15ULL;
    long compared = 0, mismatches = 0;
    const long clocks_per_sample = 3;
    for (long t = 0; t < clocks_per_sample * samples + 8; ++t) {
        const long k = t / clocks_per_sample;
        const bool sample = t % clocks_per_sample == 0 && k < samples;
        int64_t z = random_code(state, in_width);
        if ((k / 64) % 2 == 1) z >>= 8;
        const int bw_sel = static_cast<int>((k / 500) % 3);
        dut->ce = sample;
        dut->z = static_cast<uint32_t>(z) & ((1u << in_width) - 1);
        dut->bw_sel = bw_sel;
        if (sample) {
            int64_t rate = 0;
            if (gyrofx_kf_step(kf, z, bw_sel, &rate) != 0) {
                std::fprintf(stderr, "gyrofx_kf_step: %s\n", gyrofx_last_error());
                return 2;
            }
            expected.push_back(rate);
        }
        tick();
        if (dut->out_valid) {
            const int64_t actual = sign_extend(dut->rate_out, out_width);
            ++compared;
            if (expected.empty() || expected.front() != actual) {
                if (++mismatches <= 10)
                    std::printf("MISMATCH sample %ld expected %lld actual %lld\n", compared - 1,
                                expected.empty() ? 0LL : static_cast<long long>(expected.front()),
                                static_cast<long long>(actual));
            }
            if (!expected.empty()) expected.pop_front();
        }
    }
    dut->final();
    gyrofx_kf_free(kf);
    gyrofx_plan_free(plan);
    if (mismatches == 0 && expected.empty() && compared == samples) {
        std::printf("PASS n=%ld\n", compared);
        return 0;
    }
    std::printf("FAIL mismatches=%ld n=%ld\n", mismatches, compared);
    return 1;
}
