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
    return model_file_of(kTable2);  // linear, as Table 2
}

}  // namespace ascorr::host
