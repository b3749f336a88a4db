// firmware/app/sun_entry.hpp: the thermal model's Sun term (core/sun_term.hpp)
// compiled once per scalar for the DPU, as out-of-line entry points.
//
// Conventions: as lag_entry.hpp, in its own translation units
// (sun_entry_fixed.cpp, sun_entry_float.cpp) with the core's options, so that
// its instructions per solution (bench/target_bench.cpp) are those a head
// with a Sun term would add to the core's. Not in the flight image: the
// flight loop does not evaluate the term yet (docs/ground.md, "What each of
// those needs").
#pragma once

#include <cstdint>

#include "ascorr/core/fixed_point.hpp"
#include "ascorr/core/sun_term.hpp"

namespace ascorr::app {

// q ← the Sun term of `head` applied to q (with_sun_term), s_icrf the Sun's
// direction (formed at the velocity service's rate, not per solution).
void sun_fixed(const SunTermModel<Q30>& m, std::uint8_t head, const Vector3<Q30>& s_icrf, Quaternion<Q30>& q) noexcept;
void sun_float(const SunTermModel<float>& m, std::uint8_t head, const Vector3<float>& s_icrf,
               Quaternion<float>& q) noexcept;

// The entry for scalar T, for code templated on it.
inline void sun(const SunTermModel<Q30>& m, std::uint8_t head, const Vector3<Q30>& s_icrf,
                Quaternion<Q30>& q) noexcept {
    sun_fixed(m, head, s_icrf, q);
}
inline void sun(const SunTermModel<float>& m, std::uint8_t head, const Vector3<float>& s_icrf,
                Quaternion<float>& q) noexcept {
    sun_float(m, head, s_icrf, q);
}

}  // namespace ascorr::app
