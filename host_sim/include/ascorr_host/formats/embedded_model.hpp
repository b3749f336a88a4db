// ascorr_host/formats/embedded_model.hpp: the paper's Table 2 (Swarm Alpha), built in.
//
// The default truth of `ascorr simulate`, so that the main job needs no file:
// the core's ascorr/core/table2.hpp (the one copy in code) as a model file's
// contents. Table2.* (tests/test_facts.cpp) checks that against the contract's
// tests/data/model_table2.csv and host_sim/data/model_table2.csv.
#pragma once

#include "ascorr/core/table2.hpp"
#include "ascorr_host/formats/model_csv.hpp"

namespace ascorr::host {

inline ModelFile table2_model() {
    ModelFile m;
    for (std::size_t h = 0; h < kMaxHeads; ++h) {
        m.present[h] = kTable2.present[h];
        for (std::size_t a = 0; a < kModelAxes; ++a) {
            for (std::size_t i = 0; i < kModelTerms; ++i) {
                m.coefficients[h][a][i] = kTable2.coefficient[h][a][i];
            }
        }
    }
    m.quadratic = false;  // Table 2 is linear
    return m;
}

}  // namespace ascorr::host
