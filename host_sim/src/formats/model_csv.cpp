#include "ascorr_host/formats/model_csv.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "ascorr/core/fixed_point.hpp"
#include "ascorr/pipeline/temperature_lag.hpp"
#include "ascorr_host/formats/atomic_file.hpp"
#include "ascorr_host/formats/csv.hpp"
#include "ascorr_host/formats/solutions_csv.hpp"
#include "ascorr_text/c_format.hpp"
#include "ascorr_text/input_error.hpp"
#include "ascorr_text/input_name.hpp"

namespace ascorr::host {

std::string coefficient_columns(std::size_t first, std::size_t last, const char* separator) {
    std::string out;
    for (std::size_t k = first; k < last; ++k) {
        out += (k == first ? "" : separator);
        out += kCoefficientNames[k];
    }
    return out;
}

std::string model_header(std::size_t terms) {
    return "chu,axis," + coefficient_columns(0, terms, ",") + "\n";
}

namespace {
constexpr std::string_view kRigidPrefix = "rigid-";
constexpr const char* kCommonRotationColumn = "common_rotation";
constexpr const char* kLagColumn = "lag_s";
}  // namespace

bool lag_acceptable(double lag_s) noexcept {
    return lag_s == 0.0 || (lag_s >= pipeline::kMinLagTauS && lag_s <= pipeline::kMaxLagTauS);
}

std::string bad_lag_text(const std::optional<std::array<double, kMaxHeads>>& lag_s) {
    for (std::uint8_t h = 0; lag_s && h < kMaxHeads; ++h) {
        if (!lag_acceptable((*lag_s)[h])) {
            return std::string("--lag: head ") + head_name(h) + "'s " + number_text((*lag_s)[h]) + " is not " +
                   lag_range_text();
        }
    }
    return {};
}

std::string lag_range_text() {
    return "0 (no lag) or [" + number_text(pipeline::kMinLagTauS) + ", " + number_text(pipeline::kMaxLagTauS) + "] s";
}

void refuse_lagged_model(const ModelFile& m, const std::string& path, const std::string& why) {
    if (has_lag(m)) {
        throw std::runtime_error(text::input_name(path) +
                                 ": the model's lag_s makes its terms take lagged temperatures: " + why);
    }
}

namespace {

// |sun_x| + |sun_y| + |sun_z| of one axis, arcsec: the largest angle its term
// can give (ŝ_chu a unit vector).
double sun_row_sum_arcsec(const std::array<double, kSunComponents>& sun) {
    return std::abs(sun[0]) + std::abs(sun[1]) + std::abs(sun[2]);
}

// float_term_sum() of head h's axis a, arcsec.
double axis_term_sum_arcsec(const ModelFile& m, std::uint8_t h, std::size_t a) {
    double c[kModelTerms];
    std::copy(m.coefficients[h][a].begin(), m.coefficients[h][a].end(), c);
    return float_term_sum(c, 1.0);
}

// Throws `what` of head h's axis a, at its line of m's file when it has one.
// A thermal angle's limit (kMaxThermalAngleRad) in the model file's unit.
constexpr double kMaxThermalAngleArcsec = kMaxThermalAngleRad * kRadToArcsec;

[[noreturn]] void refuse_axis(const ModelFile& m, const std::string& path, std::uint8_t h, std::size_t a,
                              const std::string& what) {
    const std::string where = std::string(1, head_name(h)) + " " + kAxisNames[a] + ": ";
    if (m.line[h][a] != 0) {
        throw text::InputError(path, m.line[h][a], 1, where + what);
    }
    throw std::runtime_error(text::input_name(path) + ": " + where + what);
}

}  // namespace

std::string sun_axis_problem(const std::array<double, kSunComponents>& sun) {
    for (std::size_t c = 0; c < kSunComponents; ++c) {
        if (!std::isfinite(sun[c])) {
            return std::string(kSunColumns[c]) + " = " + number_text(sun[c]) + " is not a finite number";
        }
    }
    const double largest = sun_row_sum_arcsec(sun);
    if (!(largest <= kMaxThermalAngleArcsec)) {
        return "the Sun term's |sun_x| + |sun_y| + |sun_z| = " + number_text(largest) +
               " arcsec is beyond a thermal angle's " + number_text(kMaxThermalAngleArcsec) + " arcsec";
    }
    return {};
}

void refuse_sun_term(const ModelFile& m, const std::string& path, const std::string& why) {
    if (has_sun_term(m)) {
        throw std::runtime_error(text::input_name(path) +
                                 ": the model has a Sun term (its sun_x, sun_y, sun_z): " + why);
    }
}

void refuse_sun_term_for_link(const ModelFile& m, const std::string& path,
                              const bool (&has_term_in_scalar)[kMaxHeads]) {
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        std::size_t first = kModelAxes;  // the first axis with a term
        for (std::size_t a = 0; m.present[h] && a < kModelAxes; ++a) {
            const double polynomial = axis_term_sum_arcsec(m, h, a);
            const double term = sun_row_sum_arcsec(m.sun[h][a]);
            first = first == kModelAxes && term != 0.0 ? a : first;
            if (term != 0.0 && !(polynomial + term <= kMaxThermalAngleArcsec)) {
                refuse_axis(m, path, h, a,
                            "the polynomial (up to " + number_text(polynomial) + " arcsec over temperatures within " +
                                number_text(kMaxAbsTemperatureC) + " degrees C) and the Sun term (up to " +
                                number_text(term) + " arcsec) together can pass a thermal angle's " +
                                number_text(kMaxThermalAngleArcsec) +
                                " arcsec, where the target's form of the term skips the stage: the target does not "
                                "take it");
            }
        }
        if (first != kModelAxes && !has_term_in_scalar[h]) {
            refuse_axis(m, path, h, first,
                        "the Sun term rounds to 0 in the target's scalar, which would then evaluate it as none "
                        "(no status 128 where the Sun's direction is unknown): the target does not take it");
        }
    }
}

std::string common_rotation_name(const CommonRotationId& c) {
    switch (c.rule) {
        case CommonRotationRule::kCombined:
            return "combined";
        case CommonRotationRule::kRigid:
            return std::string(kRigidPrefix) + head_name(c.rigid_head);
        case CommonRotationRule::kSmallest:
            break;
    }
    return "smallest";
}

std::optional<CommonRotationId> common_rotation_named(std::string_view name) {
    CommonRotationId c;
    if (name == "smallest") {
        return c;
    }
    if (name == "combined") {
        c.rule = CommonRotationRule::kCombined;
        return c;
    }
    if (name.size() == kRigidPrefix.size() + 1 && name.substr(0, kRigidPrefix.size()) == kRigidPrefix &&
        head_index(name.back()) < kMaxHeads) {
        c.rule = CommonRotationRule::kRigid;
        c.rigid_head = head_index(name.back());
        return c;
    }
    return std::nullopt;
}

std::string common_rotation_choices() {
    return std::string("smallest, combined or rigid-X (X a head: ") + kHeadChoices.text + ")";
}

namespace {

// A coefficient's unit in the model file, by its term's power.
const char* unit_of(std::size_t k) {
    static constexpr const char* kUnitOfPower[3] = {"arcsec", "arcsec/degC", "arcsec/degC^2"};
    return kUnitOfPower[kModelTermTable[k].power];
}

}  // namespace

void check_fixed_point_range(const ModelFile& m, const std::string& path) {
    for (std::size_t h = 0; h < kMaxHeads; ++h) {
        for (std::size_t a = 0; a < kModelAxes; ++a) {
            for (std::uint8_t i = 0; i < kModelTerms; ++i) {
                const double c = m.coefficients[h][a][i];
                const double lim = quadratic_term(i) ? ScalarTraits<Q30>::max_quadratic_coefficient
                                                     : ScalarTraits<Q30>::max_coefficient;
                if (!(std::abs(c * kArcsecToRad) < lim)) {
                    char limit[160];
                    text::c_snprintf(limit, sizeof limit, " is beyond the fixed-point coefficient range (|%s| < %g %s)",
                                     kCoefficientNames[i], lim * kRadToArcsec, unit_of(i));
                    const std::string what = std::string(1, head_name(static_cast<std::uint8_t>(h))) + " " +
                                             kAxisNames[a] + " " + kCoefficientNames[i] + " = " + number_text(c) + " " +
                                             unit_of(i) + limit;
                    if (m.line[h][a] != 0) {
                        throw text::InputError(path, m.line[h][a], m.column[h][a][i], what);
                    }
                    throw std::runtime_error(text::input_name(path) + ": " + what);
                }
            }
        }
    }
}

void check_float_range(const ModelFile& m, const std::string& path) {
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        for (std::size_t a = 0; m.present[h] && a < kModelAxes; ++a) {
            const double s = axis_term_sum_arcsec(m, h, a) * kArcsecToRad;
            if (!(s <= kFloatMaxTermSumRad)) {
                char limit[200];
                text::c_snprintf(
                    limit, sizeof limit,
                    " is beyond what the float core evaluates within %g arcsec over +-%g degC (%.0f arcsec): "
                    "use --scalar double or fixed",
                    kFloatAngleErrorRad * kRadToArcsec, kMaxAbsTemperatureC, kFloatMaxTermSumRad * kRadToArcsec);
                refuse_axis(m, path, h, a,
                            "|c0| + 200|c1| + 400(|c2| + |c3|) + 200^2|c1_2| + 400^2(|c2_2| + |c3_2|) = " +
                                number_text(s * kRadToArcsec) + " arcsec" + limit);
            }
        }
    }
}

namespace {

void refuse_missing_columns(int col_chu, int col_axis, const int (&col_c)[kModelTerms], const std::string& file_name) {
    bool missing = col_chu < 0 || col_axis < 0;
    for (std::size_t i = 0; i < kLinearModelTerms; ++i) {
        missing = missing || col_c[i] < 0;
    }
    if (missing) {
        throw text::InputError(file_name, 1, 1,
                               "the model header must have chu,axis," + coefficient_columns(0, kLinearModelTerms, ","));
    }
}

// An unknown column is a misspelt coefficient (e.g. c1_2x): never dropped silently.
void refuse_unknown_columns(const Header& header, const std::string& file_name) {
    std::size_t column = 1;
    for (const std::string& name : header.names()) {
        bool known = name == "chu" || name == "axis" || name == kCommonRotationColumn || name == kLagColumn;
        for (const char* c : kCoefficientNames) {
            known = known || name == c;
        }
        for (const char* c : kSunColumns) {
            known = known || name == c;
        }
        if (!known) {
            throw text::InputError(file_name, 1, column,
                                   "unknown column '" + name + "' (a model has chu, axis, " +
                                       coefficient_columns(0, kLinearModelTerms, ", ") + " and, for a quadratic one, " +
                                       coefficient_columns(kLinearModelTerms, kModelTerms, ", ") +
                                       "; optionally common_rotation, lag_s and sun_x, sun_y, sun_z)");
        }
        column += name.size() + 1;
    }
}

// The index of an axis name in kAxisNames, -1 when it is none.
int axis_index(std::string_view axis_name) {
    int axis = -1;
    for (int a = 0; a < 3; ++a) {
        if (axis_name == kAxisNames[a]) {
            axis = a;
        }
    }
    return axis;
}

// Coefficient i of line n (column col) into value, its 1-based column into
// column; a field that is not a finite number is refused.
void read_coefficient(const std::string& file_name, std::size_t n, std::size_t i, std::size_t col,
                      const std::vector<std::string_view>& fields, const std::vector<std::size_t>& starts,
                      double& value, std::size_t& column) {
    const auto f = fields[col];
    const auto x = parse_double(f);
    if (!x || !std::isfinite(*x)) {
        throw text::InputError(
            file_name, n, starts[col] + 1,
            std::string("column '") + kCoefficientNames[i] +
                "': " + (x ? "expected a finite number, got '" + std::string(f) + "'" : why_not_a_number(f)));
    }
    value = *x;
    column = starts[col] + 1;
}

// Whether head h has its three axes' rows; some but not all is refused.
bool head_complete(const bool (&seen)[3], std::uint8_t h, std::size_t line_of_head, const std::string& file_name) {
    const int count = int(seen[0]) + int(seen[1]) + int(seen[2]);
    if (count != 0 && count != 3) {
        for (int a = 0; a < 3; ++a) {
            if (!seen[a]) {
                throw text::InputError(file_name, line_of_head, 1,
                                       std::string("head ") + head_name(h) + " has no " + kAxisNames[a] + " row");
            }
        }
    }
    return count == 3;
}

// The head of line n (its chu field), refused when it is none.
std::uint8_t row_head(const std::string& file_name, std::size_t n, const std::vector<std::string_view>& fields,
                      const std::vector<std::size_t>& starts, int col_chu) {
    const auto chu = fields[static_cast<std::size_t>(col_chu)];
    const std::uint8_t head = head_from_name(chu);
    if (head == kUnknownHead) {
        throw text::InputError(file_name, n, starts[static_cast<std::size_t>(col_chu)] + 1,
                               "chu must be " + std::string(kHeadChoices.text) + ", got '" + std::string(chu) + "'");
    }
    return head;
}

// The axis of line n (its axis field), refused when it is none.
int row_axis(const std::string& file_name, std::size_t n, const std::vector<std::string_view>& fields,
             const std::vector<std::size_t>& starts, int col_axis) {
    const auto axis_name = fields[static_cast<std::size_t>(col_axis)];
    const int axis = axis_index(axis_name);
    if (axis < 0) {
        throw text::InputError(file_name, n, starts[static_cast<std::size_t>(col_axis)] + 1,
                               "axis must be alpha, beta or gamma, got '" + std::string(axis_name) + "'");
    }
    return axis;
}

// The common_rotation field of line n: a rule's name, the same on every row.
void read_common_rotation(const std::string& file_name, std::size_t n, std::string_view field, std::size_t column,
                          bool first_row, ModelFile& m) {
    const std::optional<CommonRotationId> c = common_rotation_named(field);
    if (!c) {
        throw text::InputError(
            file_name, n, column,
            "column 'common_rotation': expected " + common_rotation_choices() + ", got '" + std::string(field) + "'");
    }
    if (!first_row && common_rotation_name(*c) != common_rotation_name(m.common_rotation)) {
        throw text::InputError(file_name, n, column,
                               "column 'common_rotation': '" + std::string(field) + "' differs from the rows above ('" +
                                   common_rotation_name(m.common_rotation) + "'): one model has one rule");
    }
    m.common_rotation = *c;
}

// The lag_s field of line n into head's lag: 0 or an accepted time
// constant, the same on the head's three rows.
void read_lag(const std::string& file_name, std::size_t n, std::string_view field, std::size_t column,
              std::uint8_t head, bool head_seen, ModelFile& m) {
    const auto x = parse_double(field);
    if (!x || !lag_acceptable(*x)) {
        throw text::InputError(file_name, n, column,
                               "column 'lag_s': expected " + lag_range_text() + ", got '" + std::string(field) + "'");
    }
    if (head_seen && *x != m.lag_s[head]) {
        throw text::InputError(file_name, n, column,
                               "column 'lag_s': " + number_text(*x) + " differs from head " + head_name(head) +
                                   "'s rows above (" + number_text(m.lag_s[head]) + "): one lag per head");
    }
    m.lag_s[head] = *x;
}

// The Sun term's columns: all three or none (-1 each).
std::array<int, kSunComponents> sun_columns(const Header& header, const std::string& file_name) {
    std::array<int, kSunComponents> col{};
    int found = 0;
    for (std::size_t c = 0; c < kSunComponents; ++c) {
        col[c] = header.index(kSunColumns[c]);
        found += col[c] >= 0 ? 1 : 0;
    }
    if (found != 0 && found != kSunComponents) {
        throw text::InputError(file_name, 1, 1, "the Sun term needs all three columns sun_x, sun_y, sun_z");
    }
    return col;
}

// The Sun term's three fields of line n into sun (arcsec), each a finite
// number, their magnitudes' sum (the axis' largest angle) within the core's
// domain of a thermal angle (kMaxThermalAngleRad).
void read_sun(const std::string& file_name, std::size_t n, const std::array<int, kSunComponents>& col,
              const std::vector<std::string_view>& fields, const std::vector<std::size_t>& starts,
              std::array<double, kSunComponents>& sun) {
    for (std::size_t c = 0; c < kSunComponents; ++c) {
        const auto i = static_cast<std::size_t>(col[c]);
        const auto x = parse_double(fields[i]);
        if (!x || !std::isfinite(*x)) {
            throw text::InputError(file_name, n, starts[i] + 1,
                                   std::string("column '") + kSunColumns[c] + "': " +
                                       (x ? "expected a finite number, got '" + std::string(fields[i]) + "'"
                                          : why_not_a_number(fields[i])));
        }
        sun[c] = *x;
    }
    const std::string why = sun_axis_problem(sun);
    if (!why.empty()) {
        throw text::InputError(file_name, n, starts[static_cast<std::size_t>(col[0])] + 1, why);
    }
}

}  // namespace

ModelFile parse_model(const std::string& file_name, std::string_view text) {
    if (text.empty()) {
        throw text::InputError(
            file_name, 1, 1,
            "empty model file: expected the header chu,axis," + coefficient_columns(0, kLinearModelTerms, ","));
    }
    LineReader lines(text);
    std::string_view line;
    lines.next(line);
    const Header header(line, file_name);
    const int col_chu = header.index("chu");
    const int col_axis = header.index("axis");
    int col_c[kModelTerms];
    for (std::size_t i = 0; i < kModelTerms; ++i) {
        col_c[i] = header.index(kCoefficientNames[i]);
    }
    refuse_missing_columns(col_chu, col_axis, col_c, file_name);
    refuse_unknown_columns(header, file_name);

    ModelFile m;
    for (std::size_t i = kLinearModelTerms; i < kModelTerms; ++i) {
        m.quadratic = m.quadratic || col_c[i] >= 0;
    }
    const int col_rule = header.index(kCommonRotationColumn);
    const int col_lag = header.index(kLagColumn);
    const std::array<int, kSunComponents> col_sun = sun_columns(header, file_name);
    bool first_row = true;
    bool seen[kMaxHeads][3] = {};
    std::vector<std::string_view> fields;
    std::vector<std::size_t> starts;
    std::size_t line_of_head[kMaxHeads] = {};
    while (lines.next(line)) {
        if (line.empty()) {
            continue;
        }
        const std::size_t n = lines.line_number();
        split_row(line, header.size(), file_name, n, fields, starts);
        const std::uint8_t head = row_head(file_name, n, fields, starts, col_chu);
        const int axis = row_axis(file_name, n, fields, starts, col_axis);
        if (seen[head][axis]) {
            throw text::InputError(file_name, n, 1,
                                   std::string("second row for ") + head_name(head) + " " + kAxisNames[axis]);
        }
        if (col_rule >= 0) {
            const auto c = static_cast<std::size_t>(col_rule);
            read_common_rotation(file_name, n, fields[c], starts[c] + 1, first_row, m);
        }
        if (col_lag >= 0) {
            const auto c = static_cast<std::size_t>(col_lag);
            read_lag(file_name, n, fields[c], starts[c] + 1, head, seen[head][0] || seen[head][1] || seen[head][2], m);
        }
        if (col_sun[0] >= 0) {
            read_sun(file_name, n, col_sun, fields, starts, m.sun[head][static_cast<std::size_t>(axis)]);
        }
        first_row = false;
        seen[head][axis] = true;
        line_of_head[head] = n;
        m.line[head][static_cast<std::size_t>(axis)] = n;
        for (std::size_t i = 0; i < kModelTerms; ++i) {
            if (col_c[i] >= 0) {
                read_coefficient(file_name, n, i, static_cast<std::size_t>(col_c[i]), fields, starts,
                                 m.coefficients[head][static_cast<std::size_t>(axis)][i],
                                 m.column[head][static_cast<std::size_t>(axis)][i]);
            }
        }
    }
    for (std::size_t h = 0; h < kMaxHeads; ++h) {
        m.present[h] = head_complete(seen[h], static_cast<std::uint8_t>(h), line_of_head[h], file_name);
    }
    if (!(m.present[0] || m.present[1] || m.present[2] || m.present[3])) {
        throw text::InputError(file_name, lines.line_number(), 1, "the model has no rows");
    }
    return m;
}

ModelFile read_model_file(const std::string& path) {
    return parse_model(path, read_text_file(path));
}

std::string format_model(const ModelFile& m) {
    const std::size_t ncoef = m.quadratic ? kModelTerms : kLinearModelTerms;
    const bool rule_column = m.common_rotation.rule != CommonRotationRule::kSmallest;
    const bool lag_column = has_lag(m);
    std::string out = model_header(ncoef);
    if (rule_column) {
        out.insert(out.size() - 1, std::string(",") + kCommonRotationColumn);
    }
    if (lag_column) {
        out.insert(out.size() - 1, std::string(",") + kLagColumn);
    }
    const bool sun_column = has_sun_term(m);
    if (sun_column) {
        out.insert(out.size() - 1, std::string(",") + kSunColumns[0] + "," + kSunColumns[1] + "," + kSunColumns[2]);
    }
    char buf[64];
    for (std::size_t h = 0; h < kMaxHeads; ++h) {
        if (!m.present[h]) {
            continue;
        }
        for (std::size_t a = 0; a < kModelAxes; ++a) {
            out += head_name(static_cast<std::uint8_t>(h));
            out += ',';
            out += kAxisNames[a];
            for (std::size_t i = 0; i < ncoef; ++i) {
                // 17 significant digits: a model survives a write/read round trip exactly.
                text::c_snprintf(buf, sizeof buf, ",%.16e", m.coefficients[h][a][i]);
                out += buf;
            }
            if (rule_column) {
                out += ',' + common_rotation_name(m.common_rotation);
            }
            if (lag_column) {
                // %.17g: the lag survives a write/read round trip exactly (an integer reads as one).
                text::c_snprintf(buf, sizeof buf, ",%.17g", m.lag_s[h]);
                out += buf;
            }
            for (std::size_t c = 0; sun_column && c < kSunComponents; ++c) {
                text::c_snprintf(buf, sizeof buf, ",%.16e", m.sun[h][a][c]);
                out += buf;
            }
            out += '\n';
        }
    }
    return out;
}

void write_model_file(const std::string& path, const ModelFile& model) {
    write_file_atomically(path, format_model(model));
}

}  // namespace ascorr::host
