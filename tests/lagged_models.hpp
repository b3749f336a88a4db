// tests/lagged_models.hpp: a simulated mission's truth as two models, for the
// tests of the lag on board.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "cli_run.hpp"

namespace ascorr::test {

// Writes dir/m.csv, the truth simulate wrote beside dir/`solutions`, and
// dir/m_lag.csv, the same with every head lagging by lag_s (docs/contract.md,
// "The bench's lag").
inline void write_truth_models(const std::filesystem::path& dir, const std::string& lag_s,
                               const std::string& solutions = "s.csv") {
    const std::vector<std::string> truth = lines_of_file(dir / (solutions + ".truth.csv"));
    std::vector<std::string> lagged{truth[0] + ",lag_s"};
    for (std::size_t i = 1; i < truth.size(); ++i) {
        lagged.push_back(truth[i] + "," + lag_s);
    }
    write_lines(dir / "m.csv", truth);
    write_lines(dir / "m_lag.csv", lagged);
}

}  // namespace ascorr::test
