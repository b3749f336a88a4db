// `ascorr fit --terms linear|quadratic` and its model-selection report, on
// data the simulator did not make (tests/analysis_generator.hpp) with a known
// quadratic or linear truth: the quadratic fit reaches the noise floor inside
// and outside the modelling period where the linear one does not, the report
// prefers the model the truth has, and the refusals name their reason.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "analysis_generator.hpp"
#include "ascorr_host/analysis/fit.hpp"
#include "ascorr_host/analysis/stats.hpp"
#include "cli_run.hpp"
#include "test_support.hpp"

namespace ascorr::test {
namespace {

namespace fs = std::filesystem;

constexpr double kQuadraticTruth = 0.04;  // arcsec/°C²: ±2.6" over the ±8 °C seasons

using DataSet = GeneratedSet;

DataSet make(const std::string& name, const GeneratorOptions& o) {
    return generate_set(scratch_dir(name), "data.csv", o);
}

const DataSet& quadratic_truth() {
    static const DataSet d = [] {
        GeneratorOptions o;
        o.quadratic_truth = kQuadraticTruth;
        return make("quadratic-truth", o);
    }();
    return d;
}

const DataSet& linear_truth() {
    static const DataSet d = make("linear-truth", GeneratorOptions{});
    return d;
}

host::FitReport fit(const DataSet& d, const fs::path& model, host::Terms terms) {
    host::FitOptions o;
    o.in = d.data.string();
    o.out = model.string();
    o.from = d.t_from;
    o.to = d.t_split;
    o.terms = terms;
    o.lag_s.emplace();  // the generator's bench does not lag: these tests are the terms' (test_bench_lag.cpp the lag's)
    return host::fit_model(o);
}

// `correct` with the model, then the IBA RMS of the corrected file against
// the generator's noise floor, per pair, inside [0] and outside [1] the
// modelling period: the relative excess got/floor − 1.
std::array<std::array<double, 3>, 2> excess_over_floor(const DataSet& d, const fs::path& model, const char* label) {
    const fs::path corrected = d.dir / (model.stem().string() + ".corrected.csv");
    EXPECT_EQ(run_cli("correct --in " + d.data.string() + " --model " + model.string() + " --out " + corrected.string(),
                      d.dir / "out.txt", d.dir / "err.txt"),
              0)
        << slurp(d.dir / "err.txt");
    std::array<std::array<double, 3>, 2> out{};
    for (int period = 0; period < 2; ++period) {
        host::StatsOptions so;
        so.in = corrected.string();  // read as raw: its "original" stage is the corrected one
        so.from = period == 0 ? d.t_from : d.t_split + 1.0;
        so.to = period == 0 ? d.t_split : d.t_end;
        const host::StatsResult r = host::compute_stats(so, std::cerr);
        for (std::size_t p = 0; p < 3; ++p) {
            const double fl = floor_rms(d.gen.floor[p], *so.from, *so.to);
            out[static_cast<std::size_t>(period)][p] = r.rms[p][0].rms / fl - 1.0;
            std::printf("%-9s %s %s: floor %.3f\", fit+correct %.3f\" (%+.2f %%)\n", label,
                        period == 0 ? "inside " : "outside", host::pair_name(host::kPaperPairs.pair[p]).c_str(), fl,
                        r.rms[p][0].rms, 100.0 * (r.rms[p][0].rms / fl - 1.0));
        }
    }
    return out;
}

// One test per data set: each test runs in its own process under CTest, and
// generating and fitting a data set is most of the cost.
TEST(FitTerms, QuadraticTruth) {
    const DataSet& d = quadratic_truth();
    // --terms quadratic: the noise floor inside and outside the period, and
    // the report prefers it.
    const fs::path model = d.dir / "quadratic.csv";
    const host::FitReport rep = fit(d, model, host::Terms::kQuadratic);
    std::printf("%s", host::describe(rep).c_str());
    const host::ModelFile m = host::read_model_file(model.string());
    EXPECT_TRUE(m.quadratic);
    EXPECT_EQ(rep.fit.unknowns, 63);
    // The 9 unobservable directions (a common rotation linear in T029 and
    // T032) are exactly that; the 54 others are not.
    EXPECT_LT(rep.singular_values[54], 1e-9 * rep.singular_values[0]);
    EXPECT_GT(rep.singular_values[53], 1e-3 * rep.singular_values[0]);
    const auto ex = excess_over_floor(d, model, "quadratic");
    for (std::size_t p = 0; p < 3; ++p) {
        EXPECT_LT(std::fabs(ex[0][p]), 0.03) << host::pair_name(host::kPaperPairs.pair[p]) << " inside";
        EXPECT_LT(std::fabs(ex[1][p]), 0.03) << host::pair_name(host::kPaperPairs.pair[p]) << " outside";
    }
    // The quadratic coefficients are observable (the gauge is linear): the
    // fit recovers the truth's to a fraction of their size.
    double worst = 0.0;
    for (std::size_t h = 0; h < 3; ++h) {
        for (std::size_t a = 0; a < 2; ++a) {  // about the boresight (gamma) the noise is 6x larger
            for (std::size_t j = 4; j < 7; ++j) {
                worst = std::max(worst, std::fabs(m.coefficients[h][a][j] - d.gen.truth.coefficients[h][a][j]));
            }
        }
    }
    std::printf("largest error of a cross-boresight quadratic coefficient: %.4f\"/degC^2 (truth up to %.2f)\n", worst,
                kQuadraticTruth);
    EXPECT_LT(worst, 0.25 * kQuadraticTruth);
    ASSERT_TRUE(rep.selection.decided);
    EXPECT_EQ(rep.selection.preferred, host::Terms::kQuadratic) << rep.selection.verdict;
    EXPECT_NE(host::describe(rep).find("supported by the data: quadratic: its held-out IBA RMS"), std::string::npos);

    // --terms linear on the same data: it misses the floor (the test can
    // fail), and its report says that the data support quadratic terms.
    const fs::path lin_model = d.dir / "linear.csv";
    const host::FitReport lin = fit(d, lin_model, host::Terms::kLinear);
    EXPECT_FALSE(host::read_model_file(lin_model.string()).quadratic);
    const auto lin_ex = excess_over_floor(d, lin_model, "linear");
    double worst_inside = 0.0;
    double worst_outside = 0.0;
    for (std::size_t p = 0; p < 3; ++p) {
        worst_inside = std::max(worst_inside, lin_ex[0][p]);
        worst_outside = std::max(worst_outside, lin_ex[1][p]);
    }
    EXPECT_GT(worst_inside, 0.03);
    EXPECT_GT(worst_outside, 0.03);
    const std::string report = host::describe(lin);
    EXPECT_NE(report.find("supported by the data: quadratic"), std::string::npos) << report;
    EXPECT_NE(report.find("note: the model written has linear terms; the data support quadratic terms"),
              std::string::npos)
        << report;

    // A condition-number limit between the linear and the quadratic design's
    // refuses the quadratic model only, naming the number and the weakest term.
    ASSERT_LT(lin.condition, rep.condition);
    const fs::path refused = d.dir / "refused.csv";
    host::FitOptions o;
    o.in = d.data.string();
    o.out = refused.string();
    o.from = d.t_from;
    o.to = d.t_split;
    o.terms = host::Terms::kQuadratic;
    o.max_condition = 0.5 * (lin.condition + rep.condition);
    const std::string what =
        thrown_by<host::FitRefused>([&] { host::fit_model(o); }, "accepted a condition number above the limit");
    EXPECT_NE(what.find("quadratic terms not supported by the data"), std::string::npos) << what;
    EXPECT_NE(what.find("rank-deficient design: condition number"), std::string::npos) << what;
    EXPECT_NE(what.find("the weakest direction is mostly CHU "), std::string::npos) << what;
    EXPECT_FALSE(fs::exists(refused));
}

TEST(FitTerms, LinearTruth) {
    const DataSet& d = linear_truth();
    // The report prefers the linear model: quadratic terms fit noise.
    const fs::path model = d.dir / "quadratic.csv";
    const host::FitReport rep = fit(d, model, host::Terms::kQuadratic);
    std::printf("%s", host::describe_selection(rep.selection).c_str());
    ASSERT_TRUE(rep.selection.decided);
    EXPECT_EQ(rep.selection.preferred, host::Terms::kLinear) << rep.selection.verdict;
    EXPECT_NE(rep.selection.verdict.find("they fit noise"), std::string::npos) << rep.selection.verdict;
    ASSERT_EQ(rep.selection.models.size(), 2U);
    for (std::size_t p = 0; p < 3; ++p) {
        EXPECT_GT(rep.selection.models[1].out[p].n, 1000U);
        EXPECT_GT(rep.selection.models[1].out[p].rms,
                  (1.0 - host::kSelectionMargin) * rep.selection.models[0].out[p].rms);
    }
    // Fitting noise costs little: the quadratic model of a linear truth is
    // still at the floor.
    const auto ex = excess_over_floor(d, model, "quadratic");
    for (std::size_t p = 0; p < 3; ++p) {
        EXPECT_LT(std::fabs(ex[0][p]), 0.03) << host::pair_name(host::kPaperPairs.pair[p]) << " inside";
        EXPECT_LT(std::fabs(ex[1][p]), 0.03) << host::pair_name(host::kPaperPairs.pair[p]) << " outside";
    }
    // The holdout changes the report, never the model written (with the lag given:
    // --lag auto chooses on the held-out part).
    host::FitOptions o;
    o.lag_s.emplace();
    o.in = d.data.string();
    o.from = d.t_from;
    o.to = d.t_split;
    o.out = (d.dir / "h0.csv").string();
    o.holdout = 0.0;
    const host::FitReport r0 = host::fit_model(o);
    o.out = (d.dir / "h25.csv").string();
    o.holdout = 0.25;
    const host::FitReport r25 = host::fit_model(o);
    EXPECT_EQ(slurp(d.dir / "h0.csv"), slurp(d.dir / "h25.csv"));
    EXPECT_FALSE(r0.selection.decided);
    EXPECT_NE(r0.selection.verdict.find("nothing held out"), std::string::npos);
    EXPECT_TRUE(r25.selection.decided);
}

TEST(FitTerms, RefusesQuadraticTermsOnASmallTemperatureRange) {
    GeneratorOptions o;
    o.temperature_swing = 0.1;
    const DataSet d = make("small-range", o);
    const fs::path model = d.dir / "m.csv";
    const std::string what = thrown_by<host::FitRefused>([&] { fit(d, model, host::Terms::kQuadratic); },
                                                         "accepted quadratic terms on a small temperature range");
    EXPECT_NE(what.find("quadratic terms not supported by the data"), std::string::npos) << what;
    EXPECT_NE(what.find("temperature range too small for quadratic terms: CHU "), std::string::npos) << what;
    EXPECT_NE(what.find("at least 2.000 degC"), std::string::npos) << what;
    EXPECT_NE(what.find("use --terms linear"), std::string::npos) << what;
    EXPECT_FALSE(fs::exists(model));
    // The linear model is still fitted, and the report says why quadratic is not.
    const host::FitReport rep = fit(d, model, host::Terms::kLinear);
    EXPECT_TRUE(fs::exists(model));
    EXPECT_EQ(rep.selection.preferred, host::Terms::kLinear);
    EXPECT_NE(
        rep.selection.verdict.find("linear: the data do not support quadratic terms (temperature range too small"),
        std::string::npos)
        << rep.selection.verdict;
}

TEST(FitTerms, BadOptionsAreRefusedAndWriteNothing) {
    const fs::path dir = scratch_dir("fit-terms-bad");
    const fs::path data = ASCORR_TEST_DATA "/solutions.csv";  // refused before it is read
    const fs::path model = dir / "m.csv";
    EXPECT_EQ(
        run_cli("fit --in " + data.string() + " --out " + model.string() + " --terms cubic", dir / "out", dir / "err"),
        2);  // a command-line error: a value outside the set
    EXPECT_NE(slurp(dir / "err").find("--terms"), std::string::npos) << slurp(dir / "err");
    for (const char* h : {"-0.1", "0.6"}) {
        EXPECT_EQ(run_cli("fit --in " + data.string() + " --out " + model.string() + " --holdout " + h, dir / "out",
                          dir / "err"),
                  2)  // a usage error, found before the input is read
            << h;
        EXPECT_NE(slurp(dir / "err").find("--holdout: " + std::string(h) + " is out of range: the range is [0, 0.5]"),
                  std::string::npos)
            << slurp(dir / "err");
    }
    EXPECT_EQ(run_cli("fit --in " + data.string() + " --out " + model.string() + " --min-temperature-range -1",
                      dir / "out", dir / "err"),
              2);
    EXPECT_NE(slurp(dir / "err").find("--min-temperature-range: -1 is out of range: the range is [0, inf)"),
              std::string::npos)
        << slurp(dir / "err");
    host::FitOptions o;
    o.in = data.string();
    o.out = model.string();
    o.holdout = std::nan("");
    EXPECT_THROW(host::fit_model(o), host::FitRefused);
    o.holdout = 0.25;
    o.min_temperature_range_c = std::numeric_limits<double>::infinity();
    EXPECT_THROW(host::fit_model(o), host::FitRefused);
    EXPECT_FALSE(fs::exists(model));
}

}  // namespace
}  // namespace ascorr::test
