// libFuzzer: the solutions-file reader and the core behind it, on arbitrary
// text. Malformed input must end in InputError, never in a crash or UB; rows
// that parse go through the double and float cores like in `ascorr correct`.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "ascorr/core/correct.hpp"
#include "ascorr_host/correct/solution_input.hpp"
#include "ascorr_host/formats/solutions_csv.hpp"
#include "ascorr_text/input_error.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    ascorr::ThermalModel<double> model_d{};
    ascorr::ThermalModel<float> model_f{};
    for (auto& h : model_d.head) {
        h.present = true;
        h.gamma.c3 = 1e-5;
    }
    for (auto& h : model_f.head) {
        h.present = true;
        h.gamma.c3 = 1e-5F;
    }
    try {
        ascorr::host::SolutionsReader reader("fuzz.csv", text);
        ascorr::host::SolutionRecord rec;
        for (;;) {
            try {
                if (!reader.next(rec)) {
                    break;
                }
            } catch (const ascorr::text::InputError&) {
                continue;  // --skip-bad behaviour: the reader has moved on
            }
            (void)ascorr::correct_solution(ascorr::host::to_core_input<double>(rec, nullptr),
                                           ascorr::CorrectionConfig<double>{true, &model_d});
            (void)ascorr::correct_solution(ascorr::host::to_core_input<float>(rec, nullptr),
                                           ascorr::CorrectionConfig<float>{true, &model_f});
        }
    } catch (const ascorr::text::InputError&) {
        // a bad header: reported, not a crash
    }
    return 0;
}
