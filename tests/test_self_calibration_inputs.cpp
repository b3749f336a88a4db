// Self-calibration's inputs and outputs as a user meets them (issue 30, the
// third hostile probe): the initial model's form, the orbit period, the model
// history's times and heads, the memory of rows out of order. Each through
// `ascorr correct --self-calibrate` (and host::self_calibrate, which Python
// and replay run), on a short simulated mission.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "ascorr_host/correct/self_calibration.hpp"
#include "ascorr_host/formats/embedded_model.hpp"
#include "ascorr_host/formats/model_csv.hpp"
#include "cli_run.hpp"
#include "test_support.hpp"

namespace ascorr::test {
namespace {

namespace fs = std::filesystem;

// Four simulated days at 300 s (3 heads, 2751 rows): the estimator adopts a
// model on day 3.
fs::path simulated(const std::string& name, const std::string& extra = "") {
    const fs::path dir = scratch_dir(name);
    const CliRun r = run_in("simulate --out sim.csv --days 4 --step 300 --seed 3" + extra, dir);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return dir;
}

// Class 5: a quadratic --model is refused for self-calibration, as replay
// refuses it (one rule, refuse_quadratic_initial_model): the history could
// only list c0..c3 beside the quadratic model's CRC, and the target could not
// start from it. A quadratic file whose quadratic terms are zero is linear.
TEST(SelfCalibrationInputs, AQuadraticInitialModelIsRefusedAsReplayRefusesIt) {
    const fs::path dir = simulated("sc_in_quadratic");
    host::ModelFile m = host::table2_model();
    m.quadratic = true;
    host::write_model_file((dir / "zero_quadratic.csv").string(), m);
    m.coefficients[1][2][5] = 1e-3;  // B gamma c2_2
    host::write_model_file((dir / "quadratic.csv").string(), m);
    const CliRun r =
        run_in("correct --in sim.csv --out c.csv --self-calibrate --model quadratic.csv --model-history h.csv", dir);
    EXPECT_EQ(r.exit_code, 1);
    EXPECT_NE(r.err.find("quadratic.csv: head B gamma has a quadratic term (c2_2): self-calibration starts from a "
                         "linear model"),
              std::string::npos)
        << r.err;
    EXPECT_FALSE(fs::exists(dir / "c.csv"));
    EXPECT_FALSE(fs::exists(dir / "h.csv"));
    // The library refuses it too, whoever calls it.
    EXPECT_THROW(host::self_calibrate<double>(
                     "sim.csv", [](const std::function<void(const host::SolutionRecord&)>&) {}, m,
                     calib::EstimatorConfig{}, std::nullopt),
                 std::runtime_error);
    // Control: the same model with zero quadratic terms is taken.
    const CliRun z = run_in(
        "correct --in sim.csv --out c.csv --self-calibrate --model zero_quadratic.csv --model-history h.csv", dir);
    EXPECT_EQ(z.exit_code, 0) << z.err;
    EXPECT_NE(slurp(dir / "h.csv").find(",0,A,alpha,"), std::string::npos);
}

}  // namespace
}  // namespace ascorr::test
