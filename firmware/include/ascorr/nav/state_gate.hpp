// ascorr/nav/state_gate.hpp: the verdict on each incoming spacecraft state.
//
// Conventions: a state is the spacecraft's position (km) and velocity (km/s)
// relative to the Earth's centre, in ITRF or GCRS (the check is the same in
// both: it uses only |r| and |v|), with a TtTime (tt_time.hpp). Verdicts, in
// the order they are tested:
//   a non-finite component                               → kNotFinite;
//   |r| outside [kMinOrbitRadiusKm, kMaxOrbitRadiusKm] or
//   |v| > kMaxOrbitSpeedKmS (plausible_orbit)            → kImplausible;
//   the same time as the latest accepted state's         → kDuplicateTime
//                                                          (the first is kept);
//   a time earlier than the latest accepted state's      → kTimeBackwards;
//   otherwise                                            → kAccepted.
// The gate counts every verdict (StateCounts) and remembers the latest
// accepted time; a refused state changes nothing else. Double, outside the
// per-solution path; no loop.
#pragma once

#include <cstdint>

#include "../core/scalar_traits.hpp"
#include "../core/vector3.hpp"
#include "orbit_propagation.hpp"
#include "tt_time.hpp"

namespace ascorr {

// Plausible Earth orbit: above 100 km altitude, below 50,000 km (beyond GEO),
// slower than 12 km/s (escape speed at 100 km altitude is 11.1 km/s).
inline constexpr double kMinOrbitRadiusKm = kEarthEquatorialRadiusKm + 100.0;
inline constexpr double kMaxOrbitRadiusKm = 50000.0;
inline constexpr double kMaxOrbitSpeedKmS = 12.0;

// |r| and |v| within the plausible orbit, compared as squares (no sqrt);
// false for NaN. The one test for a received state and a propagated one.
constexpr bool plausible_orbit(const Vector3<double>& r_km, const Vector3<double>& v_kms) noexcept {
    const double rr = squared_norm(r_km);
    return rr >= kMinOrbitRadiusKm * kMinOrbitRadiusKm && rr <= kMaxOrbitRadiusKm * kMaxOrbitRadiusKm &&
           squared_norm(v_kms) <= kMaxOrbitSpeedKmS * kMaxOrbitSpeedKmS;
}
constexpr bool plausible_orbit(const OrbitState& s) noexcept {
    return plausible_orbit(s.r_km, s.v_kms);
}

enum class StateFrame : std::uint8_t { kItrf, kGcrs };

enum class StateVerdict : std::uint8_t { kAccepted, kNotFinite, kImplausible, kTimeBackwards, kDuplicateTime };

struct StateCounts {
    std::uint32_t accepted;
    std::uint32_t not_finite;
    std::uint32_t implausible;
    std::uint32_t time_backwards;
    std::uint32_t duplicate_time;
};

class StateGate {
public:
    // The verdict on a state without changing anything.
    StateVerdict check(TtTime t, const Vector3<double>& r_km, const Vector3<double>& v_kms) const noexcept {
        if (!(is_finite(r_km.x) && is_finite(r_km.y) && is_finite(r_km.z) && is_finite(v_kms.x) && is_finite(v_kms.y) &&
              is_finite(v_kms.z))) {
            return StateVerdict::kNotFinite;
        }
        if (!plausible_orbit(r_km, v_kms)) {
            return StateVerdict::kImplausible;
        }
        if (has_state_ && t == latest_) {
            return StateVerdict::kDuplicateTime;
        }
        if (has_state_ && t < latest_) {
            return StateVerdict::kTimeBackwards;
        }
        return StateVerdict::kAccepted;
    }

    // The verdict, counted; an accepted state's time becomes the latest.
    StateVerdict admit(TtTime t, const Vector3<double>& r_km, const Vector3<double>& v_kms) noexcept {
        const StateVerdict verdict = check(t, r_km, v_kms);
        switch (verdict) {
            case StateVerdict::kAccepted:
                ++counts_.accepted;
                latest_ = t;
                has_state_ = true;
                break;
            case StateVerdict::kNotFinite:
                ++counts_.not_finite;
                break;
            case StateVerdict::kImplausible:
                ++counts_.implausible;
                break;
            case StateVerdict::kTimeBackwards:
                ++counts_.time_backwards;
                break;
            case StateVerdict::kDuplicateTime:
                ++counts_.duplicate_time;
                break;
        }
        return verdict;
    }

    constexpr const StateCounts& counts() const noexcept { return counts_; }
    constexpr bool has_state() const noexcept { return has_state_; }
    // The latest accepted state's time (TtTime{0} before the first).
    constexpr TtTime latest() const noexcept { return latest_; }

private:
    StateCounts counts_{};
    bool has_state_ = false;
    TtTime latest_{0};
};

}  // namespace ascorr
