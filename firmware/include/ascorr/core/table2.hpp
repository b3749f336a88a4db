// ascorr/core/table2.hpp: Table 2 of Herceg, Jørgensen & Jørgensen 2017 (Swarm
// Alpha), the thermal model the project is built around, as numbers.
//
// Conventions: model_coefficients.hpp's layout; arcsec and arcsec/°C exactly
// as printed in the paper (heads A, B, C; linear; head D has none); convert
// with thermal_model<T>(kTable2, kArcsecToRad). This is the one source of
// Table 2 in code: the flight application's model (firmware/app/flight_data.hpp)
// and `ascorr simulate`'s default truth (host_sim's embedded_model.hpp) are
// derived from it, and Table2.* (tests/test_facts.cpp) checks it bit for bit
// against the data contract's copy, tests/data/model_table2.csv (itself
// checked against the specification by tests/data/SHA256SUMS).
#pragma once

#include "model_coefficients.hpp"

namespace ascorr {

inline constexpr ModelCoefficients kTable2 = {
    {true, true, true},
    {
        // A: alpha, beta, gamma × c0, c1, c2, c3
        {{-4.67067e-01, 3.58190e-03, -9.04363e-03, -1.04154e-01},
         {4.59718e-01, -3.52161e-03, 8.89788e-03, 1.02497e-01},
         {2.36543e-01, -7.31744e-01, 4.50041e-01, -1.12265e+00}},
        // B
        {{-1.19000e+00, 3.27044e-01, -2.10603e-01, 2.40148e-01},
         {2.03750e+00, -4.03134e-01, 4.04762e-02, 6.57657e-02},
         {5.51564e+00, -3.12725e-02, -7.31304e-01, 2.07894e+00}},
        // C
        {{4.08584e-02, 1.36145e-02, 1.57687e-02, 8.06663e-03},
         {2.99157e-02, 9.95873e-03, 1.15304e-02, 5.89875e-03},
         {1.17996e+01, -2.01007e-01, 4.97267e-01, 2.25162e+00}},
    },
};

}  // namespace ascorr
