// tests/target/accuracy_main.cpp: runs the core on a target under QEMU over the
// inputs in vectors.bin (written by the host, tests/target_vectors.cpp) and
// writes results.bin for the host to compare with the double reference.
//
// One image per scalar (ASCORR_TARGET_FIXED: Q30, else float). The conversion
// of inputs from double happens here, at run time, so this image (unlike the
// flight application) links floating-point routines; the core itself is the
// same object the application uses (firmware/app/core_entry_*.cpp).
// Exit status: 0 after writing every result, 1 on an I/O or format error.
#include <cstdint>
#include <cstdio>

#include "ascorr/core/fixed_point.hpp"
#include "core_entry.hpp"
#include "vector_convert.hpp"

namespace {

using namespace ascorr;
using namespace ascorr::target;

#if defined(ASCORR_TARGET_FIXED)
using T = Q30;
#else
using T = float;
#endif
using Tr = ScalarTraits<T>;

ThermalModel<T> g_models[kModels];

}  // namespace

int main() {
    std::FILE* in = std::fopen("vectors.bin", "rb");
    std::FILE* out = std::fopen("results.bin", "wb");
    if (in == nullptr || out == nullptr) {
        std::fputs("target: cannot open vectors.bin or results.bin\n", stderr);
        return 1;
    }
    static VectorHeader header;
    if (std::fread(&header, sizeof header, 1, in) != 1 || header.magic != kVectorMagic) {
        std::fputs("target: bad vectors.bin header\n", stderr);
        return 1;
    }
    for (std::uint32_t m = 0; m < kModels; ++m) {
        g_models[m] = to_core_model<T>(header.model[m]);
    }
    for (std::uint32_t i = 0; i < header.count; ++i) {  // count is bounded by the file
        VectorRecord r{};
        if (std::fread(&r, sizeof r, 1, in) != 1 || r.model >= kModels) {
            std::fputs("target: short or bad vectors.bin\n", stderr);
            return 1;
        }
        const SolutionInput<T> s = to_core_input<T>(r);
        const ThermalModel<T>* model = &g_models[r.model];
        const CorrectionConfig<T> cfgs[kConfigs] = {{true, nullptr}, {false, model}, {true, model}};
        ResultRecord res{};
        for (int c = 0; c < kConfigs; ++c) {
            const CorrectedSolution<T> o = app::correct(s, cfgs[c]);
            res.q[c][0] = Tr::to_double(o.q_chu_icrf.w);
            res.q[c][1] = Tr::to_double(o.q_chu_icrf.x);
            res.q[c][2] = Tr::to_double(o.q_chu_icrf.y);
            res.q[c][3] = Tr::to_double(o.q_chu_icrf.z);
            res.status[c] = o.status;
        }
        if (std::fwrite(&res, sizeof res, 1, out) != 1) {
            std::fputs("target: cannot write results.bin\n", stderr);
            return 1;
        }
    }
    std::fclose(in);
    if (std::fclose(out) != 0) {
        return 1;
    }
    std::printf("target: %u solutions corrected in 3 configurations\n", static_cast<unsigned>(header.count));
    return 0;
}
