// ascorr_text/numbers.hpp: what a piece of text is as a real number, and the
// words for a number beyond double's range ("1e999", "1e-999"), shared by the
// host's readers (host_sim/src/formats/csv.cpp), the HAL's text readers
// (hal/linux/src/text_lines.hpp) and the command line's options
// (host_sim/cli/number_options.hpp), so that all three say it alike.
//
// Conventions: std::from_chars's syntax (no spaces, no hexadecimal, "nan" and
// "inf" spelt out); a leading '+' only where the caller accepts one.
#pragma once

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <string>
#include <string_view>
#include <system_error>

namespace ascorr::text {

enum class RealText { kNumber, kNotANumber, kOverflow, kUnderflow };
enum class LeadingPlus { kRefused, kAccepted };

// kNumber with value set; kOverflow and kUnderflow for a number whose
// magnitude is beyond double's range (value unset); kNotANumber otherwise.
inline RealText classify_real(std::string_view s, double& value, LeadingPlus plus) {
    const char* first = s.data();
    const char* const last = s.data() + s.size();
    if (plus == LeadingPlus::kAccepted && first != last && *first == '+') {
        ++first;
    }
    if (first == last || *first == '+') {
        return RealText::kNotANumber;
    }
    const auto [ptr, ec] = std::from_chars(first, last, value);
    if (ptr != last || (ec != std::errc() && ec != std::errc::result_out_of_range)) {
        return RealText::kNotANumber;
    }
    if (ec == std::errc::result_out_of_range) {
        // from_chars leaves value unset: strtod tells overflow (±HUGE_VAL) from underflow.
        const std::string text(s);
        errno = 0;
        return std::isinf(std::strtod(text.c_str(), nullptr)) ? RealText::kOverflow : RealText::kUnderflow;
    }
    return RealText::kNumber;
}

// Why an out-of-range number is refused (after "... is out of range: ");
// empty for the other kinds.
inline std::string out_of_range_words(RealText kind) {
    switch (kind) {
        case RealText::kOverflow:
            return "a number's magnitude is at most 1.797693e+308";
        case RealText::kUnderflow:
            return "a nonzero number's magnitude is at least 4.940656e-324 (write 0)";
        case RealText::kNumber:
        case RealText::kNotANumber:
            break;
    }
    return {};
}

}  // namespace ascorr::text
