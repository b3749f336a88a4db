// ascorr_host/solution_input.hpp: from a recorded row to the core's input.
//
// The observer velocity is v = v_earth(t) + v_sc (km/s, ICRF axes), passed to
// the core as β = v/c together with 1/s, the inverse Sun distance, for the
// solar-potential term. Conversion to a narrower scalar happens here, once,
// so that the core sees exactly what a DPU would be given.
#pragma once

#include "ascorr/correct.hpp"
#include "ascorr_host/earth_velocity.hpp"
#include "ascorr_host/solutions_csv.hpp"

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
    if (in.velocity.valid) {
        const EarthState e = earth->at(rec.t);
        const double inv_c = 1.0 / kSpeedOfLightKmS;
        in.velocity.beta_icrf = {s((e.v_bary_kms.x + rec.v_sc_kms.x) * inv_c),
                                 s((e.v_bary_kms.y + rec.v_sc_kms.y) * inv_c),
                                 s((e.v_bary_kms.z + rec.v_sc_kms.z) * inv_c)};
        in.velocity.inv_sun_distance_au = s(1.0 / e.sun_distance_au);
    }
    return in;
}

}  // namespace ascorr::host
