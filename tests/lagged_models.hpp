// tests/lagged_models.hpp: a simulated mission's truth as models, for the
// tests of the lag and the Sun term on board.
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

// Writes dir/`out`, dir/`in` (a model file) with a Sun term (docs/contract.md,
// "The Sun term") of `scale` arcsec: on its k-th row sun_x, sun_y, sun_z =
// scale·(1 − 0.2k, ±0.6, 0.3 + 0.05k), every head and axis its own term.
inline void write_sun_model(const std::filesystem::path& dir, const std::string& in, const std::string& out,
                            double scale = 1.0) {
    const std::vector<std::string> model = lines_of_file(dir / in);
    std::vector<std::string> sun{model[0] + ",sun_x,sun_y,sun_z"};
    for (std::size_t k = 1; k < model.size(); ++k) {
        const double x = static_cast<double>(k - 1);
        sun.push_back(model[k] + "," + std::to_string(scale * (1.0 - 0.2 * x)) + "," +
                      std::to_string(scale * (k % 2 == 0 ? 0.6 : -0.6)) + "," +
                      std::to_string(scale * (0.3 + 0.05 * x)));
    }
    write_lines(dir / out, sun);
}

}  // namespace ascorr::test
