#include "ascorr_host/analysis/iba.hpp"

#include <cmath>

#include "ascorr/calib/frame.hpp"

namespace ascorr::host {

double angle_arcsec(const Vector3<double>& a, const Vector3<double>& b) noexcept {
    return calib::angle_arcsec(a, b);
}

std::string pair_name(const HeadPair& p) {
    return std::string(1, kHeadLetters[p.first]) + '-' + kHeadLetters[p.second];
}

std::string head_letters(HeadMask s) {
    std::string out;
    const HeadList l = heads_of(s);
    for (std::size_t i = 0; i < l.count; ++i) {
        out += kHeadLetters[l.head[i]];
    }
    return out;
}

std::string head_words(HeadMask s, const char* last) {
    const std::string letters = head_letters(s);
    std::string out;
    for (std::size_t i = 0; i < letters.size(); ++i) {
        out += i == 0 ? "" : i + 1 == letters.size() ? last : ", ";
        out += letters[i];
    }
    return out;
}

std::optional<HeadMask> parse_head_letters(const std::string& letters) {
    HeadMask s = 0;
    int last = -1;
    for (const char c : letters) {
        const std::uint8_t h = head_index(c);
        if (h == kUnknownHead || static_cast<int>(h) <= last) {
            return std::nullopt;
        }
        last = h;
        s |= head_bit(h);
    }
    if (letters.empty()) {
        return std::nullopt;
    }
    return s;
}

namespace {

// Mean and RMS about it, in two passes (the values sit on a large offset, the
// IBA itself, so a one-pass sum of squares would cancel catastrophically).
double rms_of(const std::vector<double>& v) {
    if (v.empty()) {
        return 0.0;
    }
    double mean = 0.0;
    for (double x : v) {
        mean += x;
    }
    mean /= static_cast<double>(v.size());
    double ss = 0.0;
    for (double x : v) {
        ss += (x - mean) * (x - mean);
    }
    return std::sqrt(ss / static_cast<double>(v.size()));
}

}  // namespace

Rms rms_about_mean(const std::vector<double>& t, const std::vector<double>& v, double window_s) {
    Rms r;
    r.n = v.size();
    if (v.empty()) {
        return r;
    }
    r.rms = rms_of(v);
    // Running mean by a sliding window [lo, hi) around each sample; sums are
    // taken relative to v[0] to keep the offset out of them.
    const double ref = v[0];
    const double half = 0.5 * window_s;
    std::vector<double> smooth(v.size());
    std::size_t lo = 0;
    std::size_t hi = 0;
    double sum = 0.0;
    for (std::size_t i = 0; i < v.size(); ++i) {
        while (hi < v.size() && t[hi] <= t[i] + half) {
            sum += v[hi] - ref;
            ++hi;
        }
        while (t[lo] < t[i] - half) {
            sum -= v[lo] - ref;
            ++lo;
        }
        smooth[i] = sum / static_cast<double>(hi - lo);
    }
    r.rms_smoothed = rms_of(smooth);
    return r;
}

}  // namespace ascorr::host
