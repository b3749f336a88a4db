// ascorr/nav/earth_grid.hpp: the Earth's barycentric velocity at any time, linear
// between evaluations of its series on a 60 s grid.
//
// Conventions: times are TtTime (tt_time.hpp); the grid is t_k = k·60 s TT
// from J2000 (kEarthNodeUs), so the value at t is one function of t, whatever
// the path that reached it. Out: EarthBarycentric (earth_series.hpp) at t,
// v(t) = v_k + f·(v_k+1 − v_k) with f = (t − t_k)/60 s, the same for the Sun
// distance, and the chord's rate (km/s²). |v''| ≤ 1.4e-9 m/s³
// (earth_series.hpp), so the interpolation error is ≤ 60²/8 · 1.4e-9
// = 6.3e-7 m/s. The series runs once per minute of flight (the grid keeps its
// last two samples), not per state: double, outside the per-solution path.
#pragma once

#include <cstdint>

#include "../core/vector3.hpp"
#include "earth_series.hpp"
#include "tt_time.hpp"

namespace ascorr {

inline constexpr std::int64_t kEarthNodeUs = 60000000;  // the Earth series' grid (60 s TT)

// The Earth's part: earth_series.hpp on board and on the host; any callable
// bool(double t_tt_j2000_s, EarthBarycentric&) in its place (tests).
struct OnBoardEarth {
    bool operator()(double t_tt_j2000_s, EarthBarycentric& out) const noexcept {
        return earth_series(t_tt_j2000_s, out);
    }
};

class EarthGrid {
public:
    // The Earth at t (out) and its rate (rate_kms2); false when either grid
    // sample is outside the series' span (earth returned false).
    template <typename EarthFn>
    bool at(TtTime t, EarthFn& earth, EarthBarycentric& out, Vector3<double>& rate_kms2) noexcept {
        std::int64_t k = t.us / kEarthNodeUs;
        if (k * kEarthNodeUs > t.us) {
            --k;  // floor for negative times
        }
        if (!valid_ || k != k_) {
            if (valid_ && k == k_ + 1) {
                a_ = b_;
                a_ok_ = b_ok_;
            } else {
                a_ok_ = earth(tt_seconds(TtTime{k * kEarthNodeUs}), a_);
            }
            b_ok_ = earth(tt_seconds(TtTime{(k + 1) * kEarthNodeUs}), b_);
            k_ = k;
            valid_ = true;
        }
        const double f = static_cast<double>(t.us - k * kEarthNodeUs) * (1.0 / static_cast<double>(kEarthNodeUs));
        const Vector3<double> chord = b_.v_earth_icrf_kms - a_.v_earth_icrf_kms;
        rate_kms2 = (static_cast<double>(kMicrosecondsPerSecond) / static_cast<double>(kEarthNodeUs)) * chord;
        out.v_earth_icrf_kms = a_.v_earth_icrf_kms + f * chord;
        out.sun_distance_au = a_.sun_distance_au + f * (b_.sun_distance_au - a_.sun_distance_au);
        return a_ok_ && b_ok_;
    }

private:
    // The samples at t_k and t_k+1.
    bool valid_ = false;
    std::int64_t k_ = 0;
    EarthBarycentric a_{};
    EarthBarycentric b_{};
    bool a_ok_ = false;
    bool b_ok_ = false;
};

}  // namespace ascorr
