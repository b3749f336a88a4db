// tests/test_facts.cpp: one place for each fact. The heads
// (ascorr/core/heads.hpp) are defined once; what can include them derives from them,
// and what cannot (documentation, the HAL's role names) is checked here against
// them, so a copy that drifts fails this test.
#include <gtest/gtest.h>

#include <cctype>
#include <cmath>
#include <fstream>
#include <random>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <type_traits>
#include <vector>

#include "ascorr/core/fixed_point.hpp"
#include "ascorr/core/heads.hpp"
#include "ascorr/core/model_coefficients.hpp"
#include "ascorr/core/table2.hpp"
#include "ascorr_hal/channel_config.hpp"
#include "ascorr_host/formats/embedded_model.hpp"
#include "ascorr_host/formats/model_csv.hpp"
#include "ascorr_host/formats/solutions_csv.hpp"
#include "flight_data.hpp"  // firmware/app: the flight model, in float (app_scalar.hpp) on the host
#include "target/model_record.hpp"
#include "target/vector_convert.hpp"

namespace ascorr {
namespace {

std::string source_file(const std::string& rel) {
    std::ifstream f(std::string(ASCORR_SOURCE_DIR) + "/" + rel, std::ios::binary);
    EXPECT_TRUE(f.good()) << rel;
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
}

char first_letter() {
    return kHeadLetters[0];
}
char last_letter() {
    return kHeadLetters[kMaxHeads - 1];
}

// ---- Heads

TEST(Heads, LettersAndIndicesMapBothWays) {
    std::set<char> seen;
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        const char c = head_letter(h);
        EXPECT_TRUE(std::isupper(static_cast<unsigned char>(c)) != 0) << int(h);
        EXPECT_TRUE(seen.insert(c).second) << "letter " << c << " twice";
        EXPECT_EQ(head_index(c), h);
        EXPECT_EQ(host::head_from_name(std::string(1, c)), h);
        EXPECT_EQ(host::head_name(h), c);
    }
    EXPECT_EQ(head_letter(kMaxHeads), '?');
    EXPECT_EQ(head_letter(kUnknownHead), '?');
    for (int c = 0; c < 256; ++c) {  // everything else is no head
        if (seen.count(static_cast<char>(c)) == 0) {
            EXPECT_EQ(head_index(static_cast<char>(c)), kUnknownHead) << c;
        }
    }
    EXPECT_EQ(host::head_from_name(std::string(1, first_letter()) + first_letter()), kUnknownHead);
    EXPECT_EQ(host::head_from_name(""), kUnknownHead);
    EXPECT_EQ(host::head_from_name(std::string(1, static_cast<char>(std::tolower(first_letter())))), kUnknownHead);
}

TEST(Heads, ChoicesTextListsEveryLetter) {
    std::string want;  // built here by joining, not by the header's loop
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        want += std::string(h == 0 ? "" : h + 1 == kMaxHeads ? " or " : ", ") + kHeadLetters[h];
    }
    EXPECT_EQ(std::string(kHeadChoices.text), want);
    EXPECT_LT(want.size(), sizeof(kHeadChoices.text));
}

// The HAL's roles cannot be generated (an enum): one kChu<letter> per head is
// static_asserted in channel_config.hpp, and its name is checked here.
TEST(Heads, HalRolesAreOnePerHeadNamedByItsLetter) {
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        const auto r = static_cast<std::uint8_t>(hal::chu_role(h));
        ASSERT_LT(r, hal::kRoleCount);
        EXPECT_EQ(std::string(hal::kRoleNames[r]),
                  std::string("chu_") + static_cast<char>(std::tolower(static_cast<unsigned char>(head_letter(h)))));
    }
}

// Where the documentation states the heads, in the words it uses; {first},
// {last}, {next} (the letter after the last), {count} and {last_index} are
// filled in from heads.hpp. A head added to heads.hpp fails this test until
// these statements are brought along.
struct DocStatement {
    const char* file;
    const char* text;
};

std::string fill(std::string s) {
    const auto put = [&](const std::string& key, const std::string& value) {
        for (std::size_t p = s.find(key); p != std::string::npos; p = s.find(key, p + value.size())) {
            s.replace(p, key.size(), value);
        }
    };
    put("{first}", std::string(1, first_letter()));
    put("{last}", std::string(1, last_letter()));
    put("{next}", std::string(1, static_cast<char>(last_letter() + 1)));
    put("{count}", std::to_string(kMaxHeads));
    put("{last_index}", std::to_string(kMaxHeads - 1));
    return s;
}

TEST(Heads, DocumentationStatesTheHeadsOfHeadsHpp) {
    const std::vector<DocStatement> statements = {
        {"docs/contract.md", "`{first}`, `B` or `C` (`{last}` accepted too)"},
        {"docs/contract.md", "`chu` (n,) of `\"{first}\"`…`\"{last}\"` strings or head indices 0…{last_index}"},
        {"docs/bad-input.md", "`chu` not {first}–{last}, head index ≥ {count}"},
        {"docs/bad-input.md", "head `\"{next}\"` or index ≥ {count}"},
        {"firmware/link-protocol.md", "head u8 (0–{last_index})"},
        {"hal/linux/include/ascorr_hal_linux/config_file.hpp", "chu_a … chu_{last_lower}"},
        {"hal/linux/include/ascorr_hal_linux/simulated_source.hpp", "({first}–{last})"},
    };
    for (const DocStatement& d : statements) {
        std::string want = fill(d.text);
        const std::string key = "{last_lower}";
        if (const auto p = want.find(key); p != std::string::npos) {
            want.replace(p, key.size(), std::string(1, static_cast<char>(std::tolower(last_letter()))));
        }
        EXPECT_NE(source_file(d.file).find(want), std::string::npos)
            << d.file << " no longer says \"" << want << "\" (ascorr/core/heads.hpp): bring it in step";
    }
}

// Any other range of head letters in the documentation ("A–D", "'A'..'D'",
// "\"A\"…\"D\"") must end at the last head. Ranges ending at B or C are the
// inter-boresight pairs of Swarm's three heads (A–B, A–C), not head ranges.
// Returns the ranges that end elsewhere, and counts every range seen.
std::vector<std::string> stray_ranges(const std::string& text, int& seen) {
    const std::regex range(std::string("(?:^|[^A-Za-z0-9_])[`'\"]{0,2}") + first_letter() +
                           "[`'\"]{0,2}(–|\\.\\.|…)[`'\"]{0,2}([A-Z])\\b");
    std::vector<std::string> bad;
    for (auto it = std::sregex_iterator(text.begin(), text.end(), range); it != std::sregex_iterator(); ++it) {
        ++seen;
        const char end = (*it)[2].str()[0];
        const bool pair = kMaxHeads >= 3 && (end == kHeadLetters[1] || end == kHeadLetters[2]);
        if (end != last_letter() && !pair) {
            bad.push_back(it->str());
        }
    }
    return bad;
}

TEST(Heads, NoLetterRangeInTheDocumentationEndsElsewhere) {
    int seen = 0;
    for (const char* file :
         {"README.md", "DEVELOPERS.md", "docs/bad-input.md", "docs/contract.md", "docs/ground.md", "docs/firmware.md",
          "docs/testing.md", "firmware/link-protocol.md", "python/ascorr/__init__.py", "python/ascorr/__init__.pyi"}) {
        for (const std::string& r : stray_ranges(source_file(file), seen)) {
            ADD_FAILURE() << file << ": '" << r << "' is a range of heads that does not end at " << last_letter()
                          << " (ascorr/core/heads.hpp)";
        }
    }
    EXPECT_GT(seen, 2);  // the statements above are found, so the scan is not vacuous
    // Mutation: a range one head too long is caught.
    int m = 0;
    EXPECT_EQ(stray_ranges(fill("heads {first}–{next}, `\"{first}\"`…`\"{last}\"`"), m).size(), 1U);
    EXPECT_EQ(m, 2);
}

// The 3 × 7 coefficients of one head, back in double.
template <typename T>
std::vector<double> values(const HeadThermalModel<T>& h) {
    using Tr = ScalarTraits<T>;
    std::vector<double> v;
    for (const AxisPolynomial<T>* a : {&h.alpha, &h.beta, &h.gamma}) {
        for (const auto& c : {a->c0, a->c1, a->c2, a->c3}) {
            v.push_back(Tr::to_double(c));
        }
        for (const auto& c : {a->c1_2, a->c2_2, a->c3_2}) {
            v.push_back(Tr::to_double(c));
        }
    }
    return v;
}

// ---- Table 2 (ascorr/core/table2.hpp)

std::string contract_table2_path() {
    return std::string(ASCORR_TEST_DATA) + "/model_table2.csv";
}

// Coefficients (and presence) of `file` that differ from the core's kTable2.
int differences_from_table2(const host::ModelFile& file) {
    int n = 0;
    for (std::size_t h = 0; h < kMaxHeads; ++h) {
        n += file.present[h] != kTable2.present[h] ? 1 : 0;
        for (std::size_t a = 0; a < kModelAxes; ++a) {
            for (std::size_t i = 0; i < kModelTerms; ++i) {
                // Bit for bit: the file's decimal and the header's literal round to the same double.
                n += file.coefficients[h][a][i] != kTable2.coefficient[h][a][i] ? 1 : 0;
            }
        }
    }
    return n;
}

// The core's table is the data contract's Table 2 (tests/data/model_table2.csv,
// itself the specification's file by tests/data/SHA256SUMS), bit for bit.
TEST(Table2, TheCoresTableIsTheContractsFileBitForBit) {
    const host::ModelFile file = host::read_model_file(contract_table2_path());
    EXPECT_FALSE(file.quadratic);
    EXPECT_EQ(differences_from_table2(file), 0);
    // Mutation: one coefficient off in its last printed digit is caught.
    std::string text = source_file("tests/data/model_table2.csv");
    const std::string digit = "1.17996e+01";
    ASSERT_NE(text.find(digit), std::string::npos);
    text.replace(text.find(digit), digit.size(), "1.17997e+01");
    EXPECT_EQ(differences_from_table2(host::parse_model("mutated", text)), 1);
}

// The files that carry Table 2 besides the contract's: the README's example
// model and the fuzzer's seed, byte for byte the contract's.
TEST(Table2, EveryFileCopyIsTheContractsFile) {
    const std::string contract = source_file("tests/data/model_table2.csv");
    EXPECT_EQ(source_file("host_sim/data/model_table2.csv"), contract);
    EXPECT_EQ(source_file("tests/fuzz/corpus/model_csv/table2.csv"), contract);
}

// What is built from it: `simulate`'s default truth, and the flight
// application's model (firmware/app/flight_data.hpp, compiled here in the
// flight scalar float; the Q30 image converts the same kTable2 through the
// same thermal_model()) equals the contract's file converted by the host.
TEST(Table2, TheFlightModelAndTheSimulatorsTruthAreTheContractsFile) {
    const host::ModelFile file = host::read_model_file(contract_table2_path());
    EXPECT_EQ(differences_from_table2(host::table2_model()), 0);
    EXPECT_EQ(host::table2_model().coefficients, file.coefficients);
    static_assert(std::is_same_v<app::Scalar, float>, "the host sees the float flight build");
    const ThermalModel<float> want = host::to_core<float>(file);
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        EXPECT_EQ(app::kThermalModel.head[h].present, file.present[h]) << head_letter(h);
        EXPECT_EQ(values(app::kThermalModel.head[h]), values(want.head[h])) << head_letter(h);
    }
    EXPECT_NE(values(app::kThermalModel.head[2]), values(ThermalModel<float>{}.head[2]));  // not vacuous
    // The Cortex-M3 image flies the same expression in Q30 (flight_data.hpp,
    // Scalar = Q30): it equals the contract's file converted by the host, bit
    // for bit.
    constexpr ThermalModel<Q30> q30_flight = thermal_model<Q30>(kTable2, kArcsecToRad);
    const ThermalModel<Q30> q30_want = host::to_core<Q30>(file);
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        EXPECT_EQ(q30_flight.head[h].present, file.present[h]) << head_letter(h);
        EXPECT_EQ(values(q30_flight.head[h]), values(q30_want.head[h])) << head_letter(h);
    }
    EXPECT_NE(values(q30_flight.head[2]), values(ThermalModel<Q30>{}.head[2]));  // not vacuous
}

// ---- The model → core conversion (ascorr/core/model_coefficients.hpp)

host::ModelFile random_model(std::mt19937_64& rng) {
    std::uniform_real_distribution<double> c0(-200.0, 200.0);
    std::uniform_real_distribution<double> c1(-5.0, 5.0);
    std::uniform_real_distribution<double> c2(-0.02, 0.02);
    host::ModelFile m;
    m.quadratic = true;
    for (std::size_t h = 0; h + 1 < kMaxHeads; ++h) {  // the last head absent
        m.present[h] = true;
        for (auto& axis : m.coefficients[h]) {
            axis = {c0(rng), c1(rng), c1(rng), c1(rng), c2(rng), c2(rng), c2(rng)};
        }
    }
    return m;
}

// Every path into the core's model (the host's model files and Python's
// Model: host::to_core; the target vectors: target::to_core_model) gives the
// same bits, and those are the file's arcsec in radians rounded once to the
// scalar's format: checked against π/648000 in long double, to half a unit of
// the format (double and float: of the last place; Q30: 2⁻³⁷ linear, 2⁻⁴⁹
// quadratic, fixed_point.hpp).
template <typename T>
void check_conversion(const host::ModelFile& m, double linear_bound, double quadratic_bound, bool relative) {
    const ThermalModel<T> host_model = host::to_core<T>(m);
    const ThermalModel<T> target_model = target::to_core_model<T>(target::model_record(m));
    const long double arcsec = std::acos(-1.0L) / 648000.0L;
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        EXPECT_EQ(host_model.head[h].present, m.present[h]);
        EXPECT_EQ(target_model.head[h].present, m.present[h]);
        const std::vector<double> got = values(host_model.head[h]);
        EXPECT_EQ(got, values(target_model.head[h])) << head_letter(h);
        for (std::size_t k = 0; k < got.size(); ++k) {
            const long double want = static_cast<long double>(m.coefficients[h][k / 7][k % 7]) * arcsec;
            const double bound =
                (k % 7 < 4 ? linear_bound : quadratic_bound) * (relative ? static_cast<double>(std::fabs(want)) : 1.0);
            EXPECT_LE(static_cast<double>(std::fabs(static_cast<long double>(got[k]) - want)), bound)
                << head_letter(h) << " axis " << k / 7 << " term " << k % 7;
        }
    }
}

TEST(ModelConversion, EveryPathGivesTheCoresBitsWithinHalfAUnitOfTheFormat) {
    std::mt19937_64 rng(14);
    for (int i = 0; i < 20; ++i) {
        const host::ModelFile m = random_model(rng);
        check_conversion<double>(m, 0x1p-52, 0x1p-52, true);  // the product's rounding, then none
        check_conversion<float>(m, 0x1p-24 + 0x1p-52, 0x1p-24 + 0x1p-52, true);
        check_conversion<Q30>(m, 0x1p-37 + 1e-18, 0x1p-49 + 1e-20, false);
    }
    // Mutation: the same numbers taken as radians (no arcsec conversion) are caught.
    const host::ModelFile m = random_model(rng);
    const ThermalModel<double> wrong = thermal_model<double>(host::coefficients_of(m), 1.0);
    EXPECT_NE(values(wrong.head[0]), values(host::to_core<double>(m).head[0]));
}

// ---- Model terms (ascorr/core/model_terms.hpp)

TEST(ModelTerms, EachTermIsFoundByItsRegressorAndPower) {
    for (std::uint8_t k = 0; k < kModelTerms; ++k) {
        const ModelTerm& t = kModelTermTable[k];
        EXPECT_EQ(term_index(t.regressor, t.power), k) << t.name;
        EXPECT_EQ(host::kCoefficientNames[k], std::string(t.name));
        EXPECT_EQ(quadratic_term(k), k >= kLinearModelTerms) << t.name;
    }
    EXPECT_EQ(term_index(Regressor::kOne, 1), kModelTerms);  // none: the end
}

// The contract's "Model file" names the columns in the table's order.
TEST(ModelTerms, TheContractsModelFileHasTheTablesColumns) {
    const std::string contract = source_file("docs/contract.md");
    const std::string linear = "Header `chu,axis," + host::coefficient_columns(0, kLinearModelTerms, ",") + "`";
    const std::string quadratic = "`" + host::coefficient_columns(kLinearModelTerms, kModelTerms, ",") + "`";
    EXPECT_NE(contract.find(linear), std::string::npos) << linear;
    EXPECT_NE(contract.find("optionally followed by " + quadratic), std::string::npos) << quadratic;
    EXPECT_EQ(host::model_header(kModelTerms), "chu,axis,c0,c1,c2,c3,c1_2,c2_2,c3_2\n");
}

// model_polynomial (the estimator's checks, the fit's gauge) is the contract's
// polynomial summed left to right, bit for bit; thermal_angle<double> (the
// core, grouped by regressor) agrees to rounding.
TEST(ModelTerms, ThePolynomialIsTheContractsSumBitForBit) {
    std::mt19937_64 rng(29);
    std::uniform_real_distribution<double> coef(-50.0, 50.0);
    std::uniform_real_distribution<double> temp(-60.0, 60.0);
    for (int i = 0; i < 1000; ++i) {
        double c[kModelTerms];
        for (std::uint8_t k = 0; k < kModelTerms; ++k) {
            c[k] = coef(rng) * (quadratic_term(k) ? 1e-3 : 1.0);
        }
        const double x[kRegressors] = {temp(rng), temp(rng), temp(rng)};
        const double want = c[0] + c[1] * x[0] + c[2] * x[1] + c[3] * x[2] + c[4] * x[0] * x[0] + c[5] * x[1] * x[1] +
                            c[6] * x[2] * x[2];
        EXPECT_EQ(model_polynomial(c, x), want);
        AxisPolynomial<double> p{};
        for_each_term(p, [&c](auto k, double& field) { field = c[k]; });
        const double core = thermal_angle<double>(p, x[0], x[0] + x[1], x[0] + x[2]);
        EXPECT_NEAR(core, want, 1e-9 * (1.0 + std::fabs(want)));
        // Mutation: two regressors swapped are caught.
        std::swap(c[2], c[3]);
        EXPECT_TRUE(model_polynomial(c, x) != want || c[2] == c[3] || x[1] == x[2]);
    }
}

}  // namespace
}  // namespace ascorr
