// ascorr_text/number_fields.hpp: a field of the host's CSV files as a number,
// and the words for one refused (docs/contract.md, section 3: a number as
// std::from_chars reads it, a leading '+' accepted, as CSV writers emit it).
// The host's readers of solutions, model, mountings, states and combined
// files and the Python module take every number through these; the HAL's
// text files refuse a '+' (text_file.hpp, LeadingPlus::kRefused).
#pragma once

#include <charconv>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>

#include "ascorr_text/csv_fields.hpp"
#include "ascorr_text/numbers.hpp"

namespace ascorr::text {

// The shortest decimal text that reads back as x ("0.50000001", "1e-05",
// "nan", "inf"), for messages that repeat a refused value: never rounded.
inline std::string number_text(double x) {
    char buf[64];
    const auto r = std::to_chars(buf, buf + sizeof buf, x);
    return std::string(buf, r.ptr);
}

namespace detail {
// Clinger's fast path: a plain decimal [-]ddd.ddd with at most 15 significant
// digits is m / 10^k with m < 2^53 and k ≤ 22, both exact doubles, so one
// IEEE division gives the correctly rounded value, the same bits as
// from_chars. Anything else (exponents, long mantissas, nan) takes from_chars.
// This halves the cost of reading a recorded file.
// Eight ASCII digits at p, if they are all digits (little-endian SWAR, as in
// fast_float): 8 digits in a few word operations instead of a loop of 8.
inline bool eight_digits(const char* p, std::uint64_t& value) noexcept {
    std::uint64_t v = 0;
    std::memcpy(&v, p, 8);
    if ((((v + 0x4646464646464646ULL) | (v - 0x3030303030303030ULL)) & 0x8080808080808080ULL) != 0) {
        return false;
    }
    v -= 0x3030303030303030ULL;
    v = (v * 10U) + (v >> 8);
    v = (((v & 0x000000FF000000FFULL) * 0x000F424000000064ULL) +
         (((v >> 16) & 0x000000FF000000FFULL) * 0x0000271000000001ULL)) >>
        32;
    value = v;
    return true;
}

// The decimal digits at p appended to m; p left after them.
inline void append_digits(const char*& p, const char* last, std::uint64_t& m) noexcept {
    while (p != last && static_cast<unsigned>(*p - '0') < 10U) {
        m = m * 10U + static_cast<unsigned>(*p - '0');
        ++p;
    }
}

// The first character at or after q that is not '0' (there is one).
inline const char* past_zeros(const char* q) noexcept {
    while (*q == '0') {
        ++q;
    }
    return q;
}

inline bool parse_plain_decimal(const char* first, const char* last, double& out) noexcept {
    static constexpr double kPow10[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
                                        1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
    const bool negative = first != last && *first == '-';
    const char* p = negative ? first + 1 : first;
    while (p != last && *p == '0') {  // leading zeros are not significant
        ++p;
    }
    const char* int_begin = p;
    std::uint64_t m = 0;
    append_digits(p, last, m);
    auto significant = static_cast<std::ptrdiff_t>(p - int_begin);
    const bool had_int = significant > 0 || int_begin != (negative ? first + 1 : first);
    std::ptrdiff_t decimals = 0;
    if (p != last && *p == '.') {
        ++p;
        const char* frac_begin = p;
        std::uint64_t eight = 0;
        while (last - p >= 8 && p - frac_begin < 16 && eight_digits(p, eight)) {
            m = m * 100000000U + eight;
            p += 8;
        }
        append_digits(p, last, m);
        decimals = p - frac_begin;
        if (m != 0 && significant == 0) {
            // 0.000123: the zeros after the point are not significant either.
            significant = p - past_zeros(frac_begin);
        } else {
            significant += decimals;
        }
        if (!had_int && decimals == 0) {
            return false;  // "." or "-."
        }
    } else if (!had_int) {
        return false;
    }
    if (p != last || significant > 15 || decimals > 22) {
        return false;
    }
    const double v = static_cast<double>(m) / kPow10[decimals];
    out = negative ? -v : v;
    return true;
}
}  // namespace detail

// A field as a double: a decimal or scientific number, "nan", "inf".
// Leading/trailing spaces are not accepted (they are not in the format).
inline std::optional<double> parse_double(std::string_view field) noexcept {
    if (field.empty()) {
        return std::nullopt;
    }
    const char* first = field.data();
    const char* last = first + field.size();
    if (*first == '+') {  // from_chars rejects a leading '+', CSV writers emit it
        ++first;
    }
    if (double fast = 0.0; detail::parse_plain_decimal(first, last, fast)) {
        return fast;
    }
    double x = 0.0;
    const auto [ptr, ec] = std::from_chars(first, last, x);
    if (ec == std::errc::result_out_of_range) {
        return std::nullopt;
    }
    if (ec != std::errc() || ptr != last) {
        return std::nullopt;
    }
    return x;
}

// A field as a decimal integer with an optional sign ('+' as in parse_double);
// nullopt for other text and beyond long long (why_not_an_integer says which).
inline std::optional<long long> parse_integer(std::string_view field) noexcept {
    if (!field.empty() && field[0] == '+') {  // as parse_double: CSV writers emit it
        field.remove_prefix(1);
        if (!field.empty() && (field[0] == '+' || field[0] == '-')) {
            return std::nullopt;
        }
    }
    if (field.empty()) {
        return std::nullopt;
    }
    long long x = 0;
    const auto [ptr, ec] = std::from_chars(field.data(), field.data() + field.size(), x);
    if (ec != std::errc() || ptr != field.data() + field.size()) {
        return std::nullopt;
    }
    return x;
}

// Why parse_double refused a field, for the message: "out of range ..." (with
// a double's range) for a number beyond it (1e999, 1e-999), otherwise
// "expected a number, got 'FIELD'".
inline std::string why_not_a_number(std::string_view field) {
    const std::string text(field);
    if (!text.empty() && text[0] == '"') {
        return csv::quoted_field_refusal(text);
    }
    double x = 0.0;
    const std::string words = out_of_range_words(classify_real(text, x, LeadingPlus::kAccepted));
    if (!words.empty()) {
        return "'" + text + "' is out of range: " + words;
    }
    return "expected a number, got '" + text + "'";
}

// Why an integer field is refused: "out of range ..." (with [lo, hi]) for
// decimal digits beyond it (-1 for flags, 99999999999999999999), otherwise
// "expected an integer in [lo, hi], got 'FIELD'".
inline std::string why_not_an_integer(std::string_view field, long long lo, long long hi) {
    const std::string range = "an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
    const std::string text(field);
    if (!text.empty() && text[0] == '"') {
        return csv::quoted_field_refusal(text);
    }
    std::size_t i = !text.empty() && (text[0] == '-' || text[0] == '+') ? 1 : 0;
    const bool digits = i < text.size() && text.find_first_not_of("0123456789", i) == std::string::npos;
    if (digits) {  // decimal digits the caller refused: beyond long long or beyond [lo, hi]
        return "'" + text + "' is out of range: expected " + range;
    }
    return "expected " + range + ", got '" + text + "'";
}

}  // namespace ascorr::text
