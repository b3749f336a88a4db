// ascorr_host/formats/model_csv.hpp: the thermal-model file (docs/contract.md, "Model file").
//
// Header chu,axis and the linear terms' columns (c0,c1,c2,c3), optionally the
// quadratic ones (c1_2,c2_2,c3_2; absent = 0): the names of
// ascorr/core/model_terms.hpp, in its order.
// Optionally lag_s (after common_rotation, when that is written): the time
// constant of the head's bench lag in seconds, the same on its three rows; 0
// or absent: no lag. A lagged head's terms take its temperatures through the
// lag (ascorr/pipeline/temperature_lag.hpp; lagged_temperatures.hpp).
// Optionally sun_x,sun_y,sun_z (after lag_s, all three or none; absent = 0):
// the Sun term's coefficients of the axis, arcsec per unit of the Sun's
// direction's component in the head's frame (ascorr/core/sun_term.hpp).
// One row per head and axis; a head that appears must have all three axes.
// Values are arcsec and arcsec/°C (°C²) in the file; to_core() converts them to
// the core's radians (ascorr/core/model_coefficients.hpp).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "ascorr/core/constants.hpp"
#include "ascorr/core/model_coefficients.hpp"
#include "ascorr/core/sun_term.hpp"
#include "ascorr/core/thermal.hpp"
#include "ascorr/pipeline/head_lags.hpp"

namespace ascorr::host {

enum Axis : int { kAlpha = 0, kBeta = 1, kGamma = 2 };
inline constexpr const char* kAxisNames[kModelAxes] = {"alpha", "beta", "gamma"};
// The Sun term's columns, by component of ŝ_chu (core/sun_term.hpp).
inline constexpr const char* kSunColumns[kSunComponents] = {"sun_x", "sun_y", "sun_z"};
// The terms' columns, by term index (core/model_terms.hpp).
inline constexpr std::array<const char*, kModelTerms> kCoefficientNames = [] {
    std::array<const char*, kModelTerms> names{};
    for (std::size_t k = 0; k < kModelTerms; ++k) {
        names[k] = kModelTermTable[k].name;
    }
    return names;
}();

// The names of terms [first, last) joined by separator: "c0,c1,c2,c3".
std::string coefficient_columns(std::size_t first, std::size_t last, const char* separator);
// The model file's header: chu,axis and the first `terms` columns, with '\n'.
std::string model_header(std::size_t terms);

// The rule that fixed the rotation common to all heads, which no IBA sees
// (docs/contract.md, "The common rotation"; calib/common_rotation.hpp):
// kSmallest, the smallest corrections (a model file without the
// common_rotation column); kCombined, the full head set's combined attitude
// moves least (do no harm); kRigid, head rigid_head taken as rigid to the bench.
enum class CommonRotationRule : std::uint8_t { kSmallest, kCombined, kRigid };
struct CommonRotationId {
    CommonRotationRule rule = CommonRotationRule::kSmallest;
    std::uint8_t rigid_head = 0;  // kRigid
};
// Its name in the model file, the history and the options: "smallest",
// "combined", "rigid-A" (rigid-B, …).
std::string common_rotation_name(const CommonRotationId& c);
// The rule of a name (common_rotation_name's), or nullopt.
std::optional<CommonRotationId> common_rotation_named(std::string_view name);
// "smallest, combined or rigid-X (X a head: A, B, C or D)", for messages.
std::string common_rotation_choices();

struct ModelFile {
    std::array<bool, kMaxHeads> present{};
    // coefficients[head][axis][term] (c0, c1, … c3_2: kModelTermTable's order) in arcsec.
    std::array<std::array<std::array<double, kModelTerms>, kModelAxes>, kMaxHeads> coefficients{};
    bool quadratic = false;  // write the quadratic columns
    // The rule that fixed its common rotation: a column common_rotation after
    // the coefficients when it is not kSmallest (every row the same name).
    CommonRotationId common_rotation{};
    // By head index: the bench's lag in s (0 none, else within
    // [pipeline::kMinLagTauS, kMaxLagTauS]); a column lag_s when any is not 0.
    std::array<double, kMaxHeads> lag_s{};
    // sun[head][axis][m]: the Sun term's coefficients in arcsec (core/sun_term.hpp);
    // columns sun_x, sun_y, sun_z when any head's is not 0.
    std::array<std::array<std::array<double, kSunComponents>, kModelAxes>, kMaxHeads> sun{};
    // Where each head and axis was read (1-based line) and each coefficient
    // (1-based character column); 0 for a model not read from a file.
    std::array<std::array<std::size_t, kModelAxes>, kMaxHeads> line{};
    std::array<std::array<std::array<std::size_t, kModelTerms>, kModelAxes>, kMaxHeads> column{};
};

// The lag of each head the model has (0 for the others: a head without
// coefficients lags nothing), by head index.
inline std::array<double, kMaxHeads> head_lags(const ModelFile& m) noexcept {
    std::array<double, kMaxHeads> lag{};
    for (std::size_t h = 0; h < kMaxHeads; ++h) {
        lag[h] = m.present[h] ? m.lag_s[h] : 0.0;
    }
    return lag;
}
// Whether any head's terms take lagged temperatures.
inline bool has_lag(const ModelFile& m) noexcept {
    return pipeline::any_lagged(head_lags(m));
}
// Whether head h, which the model has, carries a Sun term (a coefficient
// not 0 in the file's double).
inline bool has_sun_term(const ModelFile& m, std::size_t h) noexcept {
    for (std::size_t a = 0; m.present[h] && a < kModelAxes; ++a) {
        for (const double c : m.sun[h][a]) {
            if (c != 0.0) {
                return true;
            }
        }
    }
    return false;
}
// Whether a head the model has carries a Sun term.
inline bool has_sun_term(const ModelFile& m) noexcept {
    bool any = false;
    for (std::size_t h = 0; h < kMaxHeads; ++h) {
        any = any || has_sun_term(m, h);
    }
    return any;
}
// What is wrong with one axis' Sun term (a coefficient not finite, or the
// largest angle |sun_x| + |sun_y| + |sun_z| beyond a thermal angle's 3600″:
// the core's domain); empty when nothing is.
std::string sun_axis_problem(const std::array<double, kSunComponents>& sun);
// Throws (naming the model's file, then `why`) when the model has a Sun
// term: for the consumers that do not evaluate it yet.
void refuse_sun_term(const ModelFile& m, const std::string& path, const std::string& why);
// The link's loader of a model's Sun term (replay): throws (naming the file,
// line, head and axis) where a head's polynomial and Sun term together can
// pass a thermal angle's ±1° at temperatures the core accepts (its terms'
// largest sum, float_term_sum(), plus |sun_x| + |sun_y| + |sun_z|: there the
// target's flight form skips the stage, 128, while the contract's form
// applies both rotations), and where a head's term is not 0 in double but
// has_term_in_scalar[h] (has_sun_term of sun_term_of<T>) says it rounds to
// 0 in the target's scalar (which would then give no 128 where `correct`
// does).
void refuse_sun_term_for_link(const ModelFile& m, const std::string& path, const bool (&has_term_in_scalar)[kMaxHeads]);
// Why a Sun term is refused to start a self-calibration, after refuse_sun_term's words.
inline constexpr const char* kSunTermNotLearnt =
    "the self-calibration learns a Sun term from none (--sun-term auto), not from a given one: start it from a "
    "model without one";
// The Sun term in the core's units (radians), for scalar T, as
// sun_term_from_arcsec (core/sun_term.hpp) converts it; present[h] where
// head h, one the model has, has a term in the file's double (has_sun_term).
template <typename T>
SunTermModel<T> sun_term_of(const ModelFile& m) {
    SunTermModel<T> out = sun_term_from_arcsec<T>(m.sun);
    for (std::size_t h = 0; h < kMaxHeads; ++h) {
        out.present[h] = has_sun_term(m, h);  // the heads the model has
    }
    return out;
}

// The model's Sun term in T, when it has one (m nullptr: none).
template <typename T = double>
std::optional<SunTermModel<T>> sun_term_if_any(const ModelFile* m) {
    if (m == nullptr || !has_sun_term(*m)) {
        return std::nullopt;
    }
    return sun_term_of<T>(*m);
}
template <typename T = double>
std::optional<SunTermModel<T>> sun_term_if_any(const std::optional<ModelFile>& m) {
    return sun_term_if_any<T>(m ? &*m : nullptr);
}

// The heads' lags of a run (correct, replay): `given` (--lag), otherwise the
// model's (head_lags), otherwise none.
inline std::array<double, kMaxHeads> run_lags(const std::optional<std::array<double, kMaxHeads>>& given,
                                              const std::optional<ModelFile>& model) {
    if (given) {
        return *given;
    }
    return model ? head_lags(*model) : std::array<double, kMaxHeads>{};
}
// What is wrong with a --lag its parser would refuse (an option set by a
// library caller): "--lag: head A's 0.5 is not 0 (no lag) or [1, 86400] s";
// empty when nothing is (or none is given).
std::string bad_lag_text(const std::optional<std::array<double, kMaxHeads>>& lag_s);
// Whether lag_s is 0 or a time constant the lag accepts (pipeline::TemperatureLag::configure).
bool lag_acceptable(double lag_s) noexcept;
// Why --lag (the lag the self-calibration learns with) is refused without
// --self-calibrate, after "--lag" or "--lag: ".
inline constexpr const char* kLagNeedsSelfCalibration =
    "needs --self-calibrate (a model's lag_s gives the lag otherwise)";
// Why correct's --sun-term (the Sun term the self-calibration learns) is
// refused without --self-calibrate, after "--sun-term" or "--sun-term: ".
inline constexpr const char* kSunTermNeedsSelfCalibration =
    "needs --self-calibrate (a model's sun_x, sun_y, sun_z give the Sun term otherwise)";
// "0 (no lag) or [1, 86400] s", for messages.
std::string lag_range_text();
// Throws (naming the model's file, then `why`) when the model's terms take
// lagged temperatures: for the consumers that do not lag them yet.
void refuse_lagged_model(const ModelFile& m, const std::string& path, const std::string& why);

ModelFile read_model_file(const std::string& path);
ModelFile parse_model(const std::string& file_name, std::string_view text);
// Writes atomically (temporary file, then rename).
void write_model_file(const std::string& path, const ModelFile& model);
std::string format_model(const ModelFile& model);

// Throws (InputError at file:line:column for a model read from a file, naming
// head, axis, coefficient, its value and the limit in %g) if a coefficient is
// beyond what the fixed-point core's formats hold (fixed_point.hpp): such a
// model is refused, never saturated.
void check_fixed_point_range(const ModelFile& m, const std::string& path);
// Throws (as above, naming head and axis, the sum and the limit in arcsec) if
// a head's axis is beyond what the float core evaluates within its bound over
// the whole temperature domain (float_term_sum > kFloatMaxTermSumRad,
// model_coefficients.hpp): such a model is refused for the float scalar.
void check_float_range(const ModelFile& m, const std::string& path);

// The model's numbers in the core's layout (arcsec, as in the file).
inline ModelCoefficients coefficients_of(const ModelFile& m) {
    ModelCoefficients c{};
    for (std::size_t h = 0; h < kMaxHeads; ++h) {
        c.present[h] = m.present[h];
        for (std::size_t a = 0; a < kModelAxes; ++a) {
            for (std::size_t i = 0; i < kModelTerms; ++i) {
                c.coefficient[h][a][i] = m.coefficients[h][a][i];
            }
        }
    }
    return c;
}

// Its inverse: a model file of the core's numbers (written linear: quadratic
// false; not read from a file: line and column 0).
inline ModelFile model_file_of(const ModelCoefficients& c) {
    ModelFile m;
    for (std::size_t h = 0; h < kMaxHeads; ++h) {
        m.present[h] = c.present[h];
        for (std::size_t a = 0; a < kModelAxes; ++a) {
            for (std::size_t i = 0; i < kModelTerms; ++i) {
                m.coefficients[h][a][i] = c.coefficient[h][a][i];
            }
        }
    }
    return m;
}

// The model in the core's units (radians), for scalar T: the core's one
// conversion (ascorr/core/model_coefficients.hpp).
template <typename T>
ThermalModel<T> to_core(const ModelFile& m) {
    return thermal_model<T>(coefficients_of(m), kArcsecToRad);
}

}  // namespace ascorr::host
