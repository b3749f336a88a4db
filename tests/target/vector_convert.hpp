// tests/target/vector_convert.hpp: records of vector_format.hpp → the core's
// types in scalar T, rounded the way a DPU would be given them
// (ScalarTraits<T>::from_double, celsius, coefficient, quadratic_coefficient).
// Shared by the target accuracy image and the benchmarks.
#pragma once

#include <cstdint>

#include "ascorr/correct.hpp"
#include "vector_format.hpp"

namespace ascorr::target {

template <typename T>
ThermalModel<T> to_core_model(const ModelRecord& m) {
    using Tr = ScalarTraits<T>;
    ThermalModel<T> out{};
    for (std::uint32_t h = 0; h < kMaxHeads; ++h) {
        out.head[h].present = m.present[h] != 0U;
        AxisPolynomial<T>* axes[3] = {&out.head[h].alpha, &out.head[h].beta, &out.head[h].gamma};
        for (std::uint32_t a = 0; a < 3; ++a) {
            const double* c = m.coefficient[h][a];
            *axes[a] = {Tr::coefficient(c[0]),           Tr::coefficient(c[1]),
                        Tr::coefficient(c[2]),           Tr::coefficient(c[3]),
                        Tr::quadratic_coefficient(c[4]), Tr::quadratic_coefficient(c[5]),
                        Tr::quadratic_coefficient(c[6])};
        }
    }
    return out;
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
