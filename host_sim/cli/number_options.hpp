// host_sim/cli/number_options.hpp: the text of every numeric option is checked
// before CLI11 converts it, so that no value is wrapped, truncated or turned
// into infinity on the way in.
//
// CLI11 2.1 converts integers with strtoull/strtoll in base 0 and reals with
// strtold: `--seed -1` became 18446744073709551615, `--seed 010` became 8,
// `--seed 99999999999999999999` became 2^64 − 1, `--days 1e999` became inf.
// These validators refuse such text with a message that names the option (CLI11
// prefixes it), says which kind of problem it is and gives the allowed range:
//
//   not a number   the text is no number at all ("abc", "1,5", " 5", "0x10")
//   not an integer a number, but not decimal digits ("1.5", "1e3", "nan")
//   out of range   a number beyond the option's range ("-1" for a seed, "1e999")
//
// A refused option is a usage error: exit status 2, before anything is read.
#pragma once

#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <string>

#include "ascorr_text/c_format.hpp"
#include "ascorr_text/numbers.hpp"

namespace ascorr::cli {

namespace detail {

// What a piece of text is, as a real number (ascorr_text/numbers.hpp), with an
// optional leading '+'.
using text::RealText;
inline RealText classify_real(const std::string& s, double& value) {
    return text::classify_real(s, value, text::LeadingPlus::kAccepted);
}

// Decimal digits with an optional sign, as sign and magnitude; false for any
// other text or a magnitude beyond 2^64 − 1 (overflow set).
inline bool parse_decimal(const std::string& s, bool& negative, std::uint64_t& magnitude, bool& overflow) {
    std::size_t i = 0;
    negative = false;
    overflow = false;
    magnitude = 0;
    if (i < s.size() && (s[i] == '+' || s[i] == '-')) {
        negative = s[i] == '-';
        ++i;
    }
    if (i == s.size()) {
        return false;
    }
    for (; i < s.size(); ++i) {
        if (s[i] < '0' || s[i] > '9') {
            return false;
        }
        const auto d = static_cast<std::uint64_t>(s[i] - '0');
        if (magnitude > (std::numeric_limits<std::uint64_t>::max() - d) / 10U) {
            overflow = true;
        } else {
            magnitude = magnitude * 10U + d;
        }
    }
    return true;
}

// |v| of a negative v, exactly (also for the type's minimum).
template <typename T>
std::uint64_t negative_magnitude(T v) {
    return static_cast<std::uint64_t>(-(static_cast<std::int64_t>(v) + 1)) + 1U;
}

// lo <= ±m <= hi, without converting ±m to T (it may not fit).
template <typename T>
bool within(bool negative, std::uint64_t m, T lo, T hi) {
    if constexpr (!std::numeric_limits<T>::is_signed) {
        return !negative && m >= static_cast<std::uint64_t>(lo) && m <= static_cast<std::uint64_t>(hi);
    } else {
        if (!negative) {
            return (lo <= 0 || m >= static_cast<std::uint64_t>(lo)) && hi >= 0 && m <= static_cast<std::uint64_t>(hi);
        }
        return lo < 0 && m <= negative_magnitude(lo) && (hi >= 0 || m >= negative_magnitude(hi));
    }
}

}  // namespace detail

// An integer option of type T in [lo, hi] (by default T's whole range), in
// decimal: `->transform(integer_in<T>())` (a transform, as it hands CLI11 the
// digits without leading zeros or '+').
template <typename T>
CLI::Validator integer_in(T lo = std::numeric_limits<T>::min(), T hi = std::numeric_limits<T>::max()) {
    static_assert(std::numeric_limits<T>::is_integer, "integer_in is for integer options");
    const std::string range = "an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
    return CLI::Validator(
        [lo, hi, range](std::string& s) {
            bool negative = false;
            bool overflow = false;
            std::uint64_t m = 0;
            if (detail::parse_decimal(s, negative, m, overflow)) {
                if (!overflow && detail::within(negative && m != 0, m, lo, hi)) {
                    // Plain decimal for CLI11, which reads base 0: 010 would be 8.
                    s = (negative && m != 0 ? "-" : "") + std::to_string(m);
                    return std::string();
                }
                return s + " is out of range: expected " + range;
            }
            double x = 0.0;
            switch (detail::classify_real(s, x)) {
                case detail::RealText::kOverflow:
                    return s + " is out of range: expected " + range;
                case detail::RealText::kNumber:
                    if (std::isnan(x)) {
                        return s + " is not an integer: expected " + range;
                    }
                    if (!(x >= static_cast<double>(lo) && x <= static_cast<double>(hi))) {
                        return s + " is out of range: expected " + range;
                    }
                    return s + " is not an integer (decimal digits only): expected " + range;
                case detail::RealText::kUnderflow:
                    return s + " is not an integer: expected " + range;
                case detail::RealText::kNotANumber:
                    break;
            }
            return s + " is not a number: expected " + range;
        },
        "INT");
}

// A real option: any double, NaN and infinity spelt out included (the commands
// judge those with their own, more specific messages); refused are text that is
// no number and a number beyond a double's range (1e999 would become inf,
// 1e-999 would become 0).
inline CLI::Validator real_number() {
    return CLI::Validator(
        [](std::string& s) {
            double x = 0.0;
            const detail::RealText kind = detail::classify_real(s, x);
            switch (kind) {
                case detail::RealText::kNumber:
                    return std::string();
                case detail::RealText::kOverflow:
                case detail::RealText::kUnderflow:
                    return s + " is out of range: " + text::out_of_range_words(kind);
                case detail::RealText::kNotANumber:
                    break;
            }
            return s + " is not a number";
        },
        "NUMBER");
}

// Whether an end of a real option's range belongs to it.
enum class End { kClosed, kOpen };

// A real option in [lo, hi] (or with an open end: (0, 36600], (0, inf)):
// real_number()'s checks, and then NaN, the infinities and finite values
// outside the range are "out of range" with the range, the value as given
// (CLI::Range lets NaN through: every comparison with it is false). A refused
// value is a usage error (exit status 2) found before any input is read.
inline CLI::Validator real_in(double lo, double hi, End lo_end = End::kClosed, End hi_end = End::kClosed) {
    return CLI::Validator(
        [lo, hi, lo_end, hi_end](std::string& s) {
            std::string why = real_number()(s);
            if (!why.empty()) {
                return why;
            }
            double x = 0.0;
            detail::classify_real(s, x);
            const bool above = lo_end == End::kOpen ? x > lo : x >= lo;
            const bool below = hi_end == End::kOpen ? x < hi : x <= hi;
            if (above && below) {
                return std::string();
            }
            char range[80];
            text::c_snprintf(range, sizeof range, "%c%g, %g%c", lo_end == End::kOpen ? '(' : '[', lo, hi,
                             hi_end == End::kOpen ? ')' : ']');
            return s + " is out of range: the range is " + range;
        },
        "NUMBER");
}

// A real option that is 0 (an option's "none") or within [lo, hi], lo > 0:
// as real_in(), the range written "0 or [lo, hi]".
inline CLI::Validator zero_or_in(double lo, double hi) {
    return CLI::Validator(
        [lo, hi](std::string& s) {
            std::string why = real_number()(s);
            if (!why.empty()) {
                return why;
            }
            double x = 0.0;
            detail::classify_real(s, x);
            if (x == 0.0 || (x >= lo && x <= hi)) {  // NaN is neither
                return std::string();
            }
            char range[80];
            text::c_snprintf(range, sizeof range, "0 or [%g, %g]", lo, hi);
            return s + " is out of range: the range is " + range;
        },
        "NUMBER");
}

}  // namespace ascorr::cli
