// ascorr_text/numbers.hpp: what a piece of text is as a real number, and the
// words for a number beyond double's range ("1e999", "1e-999"), shared by the
// host's readers (number_fields.hpp), the HAL's text readers
// (text_file.hpp) and the command line's options
// (host_sim/cli/number_options.hpp), so that all three say it alike.
//
// Conventions: std::from_chars's syntax (no spaces, no hexadecimal, "nan" and
// "inf" spelt out); a leading '+' only where the caller accepts one.
#pragma once

#include <charconv>
#include <cmath>
#include <string>
#include <string_view>
#include <system_error>

namespace ascorr::text {

enum class RealText { kNumber, kNotANumber, kOverflow, kUnderflow };
enum class LeadingPlus { kRefused, kAccepted };

namespace detail {

// For a text from_chars read whole but found out of range: true when its
// magnitude is too large (overflow), false when too small (underflow). The
// text is [-]digits[.digits][(e|E)[+|-]digits] with a nonzero digit (a zero
// is never out of range); its value is 0.d₁d₂… × 10^k with d₁ the first
// nonzero digit, and it is too large exactly when k > 0 (double's range,
// 4.9e-324 to 1.8e308, holds every magnitude with k from −322 to 308).
// Digits only, no strtod: the C locale's decimal point plays no part.
constexpr bool is_digit(char c) noexcept {
    return c >= '0' && c <= '9';
}

// The decimal exponent k of the first nonzero digit of [-]digits[.digits]
// read from s[i]; i left at the first character after them.
constexpr long long mantissa_exponent(std::string_view s, std::size_t& i) noexcept {
    long long k = 0;  // saturated far beyond any digit count
    bool seen_nonzero = false;
    for (; i < s.size() && is_digit(s[i]); ++i) {
        seen_nonzero = seen_nonzero || s[i] != '0';
        k += seen_nonzero && k < (1LL << 40) ? 1 : 0;
    }
    if (i < s.size() && s[i] == '.') {
        for (++i; i < s.size() && is_digit(s[i]); ++i) {
            if (!seen_nonzero && s[i] == '0') {
                k -= k > -(1LL << 40) ? 1 : 0;
            }
            seen_nonzero = seen_nonzero || s[i] != '0';
        }
    }
    return k;
}

// The exponent part [(e|E)[+|-]digits] read from s[i] (0 without one),
// saturated far beyond any digit count.
constexpr long long exponent_part(std::string_view s, std::size_t i) noexcept {
    long long e = 0;
    if (i < s.size() && (s[i] == 'e' || s[i] == 'E')) {
        ++i;
        bool negative = false;
        if (i < s.size() && (s[i] == '-' || s[i] == '+')) {
            negative = s[i] == '-';
            ++i;
        }
        for (; i < s.size() && is_digit(s[i]); ++i) {
            e = e < (1LL << 50) ? e * 10 + (s[i] - '0') : e;
        }
        e = negative ? -e : e;
    }
    return e;
}

constexpr bool magnitude_above_one(std::string_view s) noexcept {
    std::size_t i = s.empty() || s[0] != '-' ? 0 : 1;
    const long long k = mantissa_exponent(s, i);
    return k + exponent_part(s, i) > 0;
}

}  // namespace detail

// kNumber with value set; kOverflow and kUnderflow for a number whose
// magnitude is beyond double's range (value unset); kNotANumber otherwise.
// Independent of the C and C++ locales (std::from_chars).
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
    if (ec == std::errc::result_out_of_range) {  // from_chars leaves value unset
        return detail::magnitude_above_one(std::string_view(first, static_cast<std::size_t>(last - first)))
                   ? RealText::kOverflow
                   : RealText::kUnderflow;
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
