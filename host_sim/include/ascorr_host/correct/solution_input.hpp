// ascorr_host/correct/solution_input.hpp: from a recorded row to the core's input.
//
// The observer velocity is v = v_earth(t) + v_sc (km/s, ICRF axes), passed to
// the core as β = v/c together with 1/s, the inverse Sun distance, for the
// solar-potential term. Conversion to a narrower scalar happens here, once,
// so that the core sees exactly what a DPU would be given.
#pragma once

#include <string>

#include "ascorr/core/correct.hpp"
#include "ascorr_host/correct/earth_velocity.hpp"
#include "ascorr_host/formats/solutions_csv.hpp"

namespace ascorr::host {

template <typename T>
SolutionInput<T> to_core_input(const SolutionRecord& rec, EarthVelocity* earth) {
    const auto s = [](double x) { return ScalarTraits<T>::from_double(x); };
    const auto c = [](double x) { return ScalarTraits<T>::celsius(x); };
    SolutionInput<T> in{};
    in.q_chu_icrf = {s(rec.q_chu_icrf.w), s(rec.q_chu_icrf.x), s(rec.q_chu_icrf.y), s(rec.q_chu_icrf.z)};
    in.head = rec.head;
    in.temperatures.t_chu = {c(rec.temperature[0]), rec.temperature_present[0]};
    in.temperatures.t_029 = {c(rec.temperature[1]), rec.temperature_present[1]};
    in.temperatures.t_032 = {c(rec.temperature[2]), rec.temperature_present[2]};
    in.velocity.valid = rec.velocity_components == 3 && earth != nullptr;
    in.velocity.beta_icrf = {s(0.0), s(0.0), s(0.0)};
    in.velocity.inv_sun_distance_au = s(1.0);
    const EarthState e = in.velocity.valid ? earth->at(rec.t) : EarthState{};
    in.velocity.valid = in.velocity.valid && e.valid;  // outside the ephemeris: see velocity_problem()
    if (in.velocity.valid) {
        const double inv_c = 1.0 / kSpeedOfLightKmS;
        in.velocity.beta_icrf = {s((e.v_bary_kms.x + rec.v_sc_kms.x) * inv_c),
                                 s((e.v_bary_kms.y + rec.v_sc_kms.y) * inv_c),
                                 s((e.v_bary_kms.z + rec.v_sc_kms.z) * inv_c)};
        in.velocity.inv_sun_distance_au = s(1.0 / e.sun_distance_au);
    }
    return in;
}

// Why a row's velocity, although given, could not reach the core: 1 or 2 of
// vx,vy,vz only, or a time outside the span of the Earth ephemeris (1900–2100,
// e.g. a time in ms). Empty when it could. Such a row gets status 32 on top of
// the core's 4 (velocity given but unusable), in `correct` and `replay` alike.
std::string velocity_problem(const SolutionRecord& rec);
inline StatusBits host_status(const SolutionRecord& rec, bool aberration, StatusBits core_status) {
    return aberration && (core_status & status::kNoVelocity) != 0U && !velocity_problem(rec).empty()
               ? static_cast<StatusBits>(core_status | status::kVelocityInvalid)
               : core_status;
}

}  // namespace ascorr::host
