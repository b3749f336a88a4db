// libFuzzer: the model-file reader on arbitrary text. It either returns a
// model whose every coefficient is finite, or throws InputError.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "ascorr_host/formats/model_csv.hpp"
#include "ascorr_text/input_error.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string_view text(reinterpret_cast<const char*>(data), size);
    try {
        const ascorr::host::ModelFile m = ascorr::host::parse_model("fuzz.csv", text);
        for (const auto& head : m.coefficients) {
            for (const auto& axis : head) {
                for (double c : axis) {
                    if (!std::isfinite(c)) {
                        std::abort();
                    }
                }
            }
        }
        // What the writer makes of it must read back identically.
        if (ascorr::host::parse_model("again", ascorr::host::format_model(m)).coefficients != m.coefficients) {
            std::abort();
        }
    } catch (const ascorr::text::InputError&) {
    }
    return 0;
}
