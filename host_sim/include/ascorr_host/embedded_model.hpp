// ascorr_host/embedded_model.hpp: the paper's Table 2 (Swarm Alpha), built in.
//
// The default truth of `ascorr simulate`, so that the main job needs no file.
// Identical to host_sim/data/model_table2.csv (a test checks it).
#pragma once

#include <string_view>

#include "ascorr_host/model_csv.hpp"

namespace ascorr::host {

inline constexpr std::string_view kTable2ModelCsv =
    "chu,axis,c0,c1,c2,c3\n"
    "A,alpha,-4.67067e-01,3.58190e-03,-9.04363e-03,-1.04154e-01\n"
    "A,beta,4.59718e-01,-3.52161e-03,8.89788e-03,1.02497e-01\n"
    "A,gamma,2.36543e-01,-7.31744e-01,4.50041e-01,-1.12265e+00\n"
    "B,alpha,-1.19000e+00,3.27044e-01,-2.10603e-01,2.40148e-01\n"
    "B,beta,2.03750e+00,-4.03134e-01,4.04762e-02,6.57657e-02\n"
    "B,gamma,5.51564e+00,-3.12725e-02,-7.31304e-01,2.07894e+00\n"
    "C,alpha,4.08584e-02,1.36145e-02,1.57687e-02,8.06663e-03\n"
    "C,beta,2.99157e-02,9.95873e-03,1.15304e-02,5.89875e-03\n"
    "C,gamma,1.17996e+01,-2.01007e-01,4.97267e-01,2.25162e+00\n";

inline ModelFile table2_model() {
    return parse_model("<embedded Table 2>", kTable2ModelCsv);
}

}  // namespace ascorr::host
