// tests/target/vector_convert.hpp: records of vector_format.hpp → the core's
// types in scalar T, rounded the way a DPU would be given them
// (ScalarTraits<T>::from_double, celsius; the model through the core's
// thermal_model(), ascorr/core/model_coefficients.hpp).
// Shared by the target accuracy image and the benchmarks.
#pragma once

#include <cstdint>

#include "ascorr/core/correct.hpp"
#include "ascorr/core/model_coefficients.hpp"
#include "vector_format.hpp"

namespace ascorr::target {

// Radians already: the core's conversion with unit 1 (exact).
template <typename T>
ThermalModel<T> to_core_model(const ModelRecord& m) {
    ModelCoefficients c{};
    for (std::uint32_t h = 0; h < kMaxHeads; ++h) {
        c.present[h] = m.present[h] != 0U;
        for (std::uint32_t a = 0; a < kModelAxes; ++a) {
            for (std::uint32_t i = 0; i < kModelTerms; ++i) {
                c.coefficient[h][a][i] = m.coefficient[h][a][i];
            }
        }
    }
    return thermal_model<T>(c, 1.0);
}

template <typename T>
SolutionInput<T> to_core_input(const VectorRecord& r) {
    using Tr = ScalarTraits<T>;
    SolutionInput<T> in{};
    in.q_chu_icrf = {Tr::from_double(r.q[0]), Tr::from_double(r.q[1]), Tr::from_double(r.q[2]),
                     Tr::from_double(r.q[3])};
    in.head = static_cast<std::uint8_t>(r.head < 255U ? r.head : 255U);
    in.temperatures.t_chu = {Tr::celsius(r.temperature[0]), (r.temperature_valid & 1U) != 0U};
    in.temperatures.t_029 = {Tr::celsius(r.temperature[1]), (r.temperature_valid & 2U) != 0U};
    in.temperatures.t_032 = {Tr::celsius(r.temperature[2]), (r.temperature_valid & 4U) != 0U};
    in.velocity = {{Tr::from_double(r.beta[0]), Tr::from_double(r.beta[1]), Tr::from_double(r.beta[2])},
                   Tr::from_double(r.inv_sun_distance_au),
                   r.velocity_valid != 0U};
    return in;
}

}  // namespace ascorr::target
