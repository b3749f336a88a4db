#include "ascorr_host/analysis/iba.hpp"

#include <cmath>

#include "ascorr/core/constants.hpp"

namespace ascorr::host {

double angle_arcsec(const Vector3<double>& a, const Vector3<double>& b) noexcept {
    // atan2 of |a×b| and a·b keeps full precision near 0 and 90°, unlike acos.
    const Vector3<double> c = cross(a, b);
    return std::atan2(std::sqrt(squared_norm(c)), dot(a, b)) * kRadToArcsec;
}

std::int64_t epoch_key(double t) noexcept {
    return static_cast<std::int64_t>(std::llround(t * 1000.0));
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
