#include "ascorr_host/analysis/fit_terms.hpp"

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <limits>
#include <optional>
#include <sstream>

#include "ascorr/calib/common_rotation.hpp"
#include "ascorr/core/correct.hpp"
#include "ascorr/core/sun_term.hpp"
#include "ascorr/nav/sun_direction.hpp"
#include "ascorr_host/formats/solutions_csv.hpp"
#include "ascorr_text/c_format.hpp"

namespace ascorr::host {

namespace {

constexpr int kGauge = 9;  // a rotation common to all heads, linear in T029 and T032 (fit.hpp)

// uncentre() and apply_gauge() expand each regressor's linear and quadratic
// term: the table must have both for each.
constexpr bool terms_expandable() noexcept {
    bool ok = term_index(Regressor::kOne, 0) == 0;
    for (std::uint8_t j = 1; j <= kRegressors; ++j) {
        ok = ok && term_index(static_cast<Regressor>(j), 1) < kLinearModelTerms &&
             term_index(static_cast<Regressor>(j), 2) < kModelTerms;
    }
    return ok;
}
static_assert(terms_expandable(), "fit_terms.cpp: every regressor has a linear and a quadratic term");

__attribute__((format(printf, 1, 2))) std::string format(const char* fmt, ...) {
    char buf[600];
    va_list ap;
    va_start(ap, fmt);
    text::c_vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    return buf;
}

// The orbit's design row of head h, a column per term (core/model_terms.hpp):
// [1, u1, u2, u3 (, avg u1², avg u2², avg u3²)], u_j = (x_j − m_j)/s_j.
Eigen::VectorXd regressors(const OrbitAverage& o, std::size_t h, const Centring& c, int per_axis) {
    Eigen::VectorXd r(per_axis);
    for (std::uint8_t k = 0; k < per_axis; ++k) {
        const ModelTerm& term = kModelTermTable[k];
        if (term.power == 0) {
            r(k) = 1.0;
            continue;
        }
        const std::size_t j = regressor_index(k);
        const double m = c.mean[h][j];
        const double s = c.scale[h][j];
        const auto ji = static_cast<Eigen::Index>(j);
        r(k) = term.power == 1 ? (o.x[h](ji) - m) / s : (o.x2[h](ji) - 2.0 * m * o.x[h](ji) + m * m) / (s * s);
    }
    return r;
}

// The model's angle (arcsec) for an orbit's averages, contract form: a
// quadratic term takes the orbit's average of the square.
double predicted(const std::array<double, kModelTerms>& c, const OrbitAverage& o, std::size_t h) {
    double sum = c[0];
    for (std::uint8_t k = 1; k < kModelTerms; ++k) {
        const auto ji = static_cast<Eigen::Index>(regressor_index(k));
        sum += c[k] * (kModelTermTable[k].power == 1 ? o.x[h](ji) : o.x2[h](ji));
    }
    return sum;
}

// Regressor j of head h: its mean, its scale (the standard deviation; 1
// for a constant one, a zero column refused by the condition) and range.
void centre_regressor(const std::vector<OrbitAverage>& orbits, std::size_t h, std::size_t j, Eigen::Index n,
                      Centring& centring) {
    const auto ji = static_cast<Eigen::Index>(j);
    double sum = 0.0;
    double lo = std::numeric_limits<double>::infinity();
    double hi = -lo;
    for (const OrbitAverage& o : orbits) {
        sum += o.x[h](ji);
        lo = std::min(lo, o.x[h](ji));
        hi = std::max(hi, o.x[h](ji));
    }
    const double mean = sum / static_cast<double>(n);
    double ss = 0.0;
    for (const OrbitAverage& o : orbits) {
        ss += (o.x[h](ji) - mean) * (o.x[h](ji) - mean);
    }
    const double sd = std::sqrt(ss / static_cast<double>(n));
    centring.mean[h][j] = mean;
    centring.scale[h][j] = sd > 0.0 ? sd : 1.0;  // a constant regressor: a zero column, refused below
    centring.range[h][j] = hi - lo;
}

// Centring and scaling of each head's regressors over the orbit averages.
void centre_regressors(const std::vector<OrbitAverage>& orbits, const HeadList& list, Centring& centring) {
    const auto n = static_cast<Eigen::Index>(orbits.size());
    for (std::size_t i = 0; i < list.count; ++i) {
        const std::size_t h = list.head[i];
        for (std::size_t j = 0; j < 3; ++j) {
            centre_regressor(orbits, h, j, n, centring);
        }
    }
}

// Whether every regressor spans min_range_c (quadratic terms); f.refused
// says which does not.
bool range_enough(TermsFit& f, const HeadList& list, double min_range_c) {
    for (std::size_t i = 0; i < list.count; ++i) {
        const std::size_t h = list.head[i];
        for (std::size_t j = 0; j < 3; ++j) {
            if (!(f.centring.range[h][j] >= min_range_c)) {
                f.refused = format(
                    "temperature range too small for quadratic terms: CHU %c's %s spans %.3f degC over the orbit "
                    "averages of the period; at least %.3f degC are needed to fit its square "
                    "(--min-temperature-range)",
                    head_name(static_cast<std::uint8_t>(h)), kRegressorNames[j], f.centring.range[h][j], min_range_c);
                return false;
            }
        }
    }
    return true;
}

// P = I − G·Gᵀ/heads over the heads' equations (calib/common_rotation.hpp).
Eigen::MatrixXd projector(const HeadOrientations& n_ref, const HeadList& list, Eigen::Index rows) {
    std::array<calib::Matrix3, kMaxHeads> n_core{};
    for (std::size_t i = 0; i < list.count; ++i) {
        for (Eigen::Index r = 0; r < 3; ++r) {
            for (Eigen::Index c = 0; c < 3; ++c) {
                n_core[i].m[r][c] = n_ref[list.head[i]](r, c);
            }
        }
    }
    std::vector<double> p_core(static_cast<std::size_t>(rows * rows));
    calib::common_rotation_projector(n_core.data(), list.count, p_core.data());
    Eigen::MatrixXd proj(rows, rows);
    for (Eigen::Index r = 0; r < rows; ++r) {
        for (Eigen::Index c = 0; c < rows; ++c) {
            proj(r, c) = p_core[static_cast<std::size_t>(r * rows + c)];
        }
    }
    return proj;
}

// The orbits' e by head, centred on their mean, so that c0 refers to the
// mean orientation.
Eigen::MatrixXd centred_errors(const std::vector<OrbitAverage>& orbits, const HeadList& list, Eigen::Index rows) {
    const auto n = static_cast<Eigen::Index>(orbits.size());
    Eigen::MatrixXd y(n, rows);
    for (Eigen::Index k = 0; k < n; ++k) {
        for (std::size_t i = 0; i < list.count; ++i) {
            y.block<1, 3>(k, static_cast<Eigen::Index>(3 * i)) =
                orbits[static_cast<std::size_t>(k)].e[list.head[i]].transpose();
        }
    }
    const Eigen::RowVectorXd mean = y.colwise().mean();
    y.rowwise() -= mean;
    return y;
}

// Orbit k's unprojected equations: each head's regressors on its axes' rows.
void orbit_equations(const OrbitAverage& o, const HeadList& list, const Centring& centring, int per_axis,
                     Eigen::MatrixXd& a) {
    a.setZero();
    for (std::size_t i = 0; i < list.count; ++i) {
        const Eigen::VectorXd r = regressors(o, list.head[i], centring, per_axis);
        for (Eigen::Index ax = 0; ax < 3; ++ax) {
            const Eigen::Index row = 3 * static_cast<Eigen::Index>(i) + ax;
            a.block(row, row * per_axis, 1, per_axis) = r.transpose();
        }
    }
}

// The projected design and target, orbit by orbit.
void fill_design(const std::vector<OrbitAverage>& orbits, const HeadList& list, const Centring& centring, int per_axis,
                 const Eigen::MatrixXd& proj, const Eigen::MatrixXd& y, Eigen::MatrixXd& design,
                 Eigen::VectorXd& target) {
    const auto n = static_cast<Eigen::Index>(orbits.size());
    const Eigen::Index rows = proj.rows();
    const auto unknowns = design.cols();
    Eigen::MatrixXd a(rows, unknowns);
    // Three heads: P fixed-size, the products as they always were, bit for bit.
    const Eigen::Matrix<double, 9, 9> proj3 =
        rows == 9 ? Eigen::Matrix<double, 9, 9>(proj) : Eigen::Matrix<double, 9, 9>::Zero();
    for (Eigen::Index k = 0; k < n; ++k) {
        orbit_equations(orbits[static_cast<std::size_t>(k)], list, centring, per_axis, a);
        if (rows == 9) {
            design.block(9 * k, 0, 9, unknowns) = proj3 * a;
            target.segment<9>(9 * k) = proj3 * y.row(k).transpose();
        } else {
            design.block(rows * k, 0, rows, unknowns) = proj * a;
            target.segment(rows * k, rows) = proj * y.row(k).transpose();
        }
    }
}

// Names the head, and the term, whose coefficients dominate the weakest direction.
std::string why_ill_conditioned(const TermsFit& f, const Eigen::BDCSVD<Eigen::MatrixXd>& svd, const HeadList& list,
                                int per_axis, double max_condition) {
    const Eigen::Index rank = f.rank;
    const int unknowns = f.unknowns;
    const Eigen::VectorXd sv = svd.singularValues();
    const Eigen::VectorXd weakest = svd.matrixV().col(rank - 1);
    std::array<double, kMaxHeads> head_share{};  // by position in list
    std::array<std::array<double, kModelTerms>, kMaxHeads> term_share{};
    for (Eigen::Index i = 0; i < unknowns; ++i) {
        const auto h = static_cast<std::size_t>(i / (3 * per_axis));
        const auto t = static_cast<std::size_t>(i % per_axis);
        head_share[h] += weakest(i) * weakest(i);
        term_share[h][t] += weakest(i) * weakest(i);
    }
    const auto head = static_cast<std::size_t>(
        std::max_element(head_share.begin(), head_share.begin() + static_cast<long>(list.count)) - head_share.begin());
    const auto term = static_cast<std::size_t>(
        std::max_element(term_share[head].begin(), term_share[head].begin() + per_axis) - term_share[head].begin());
    return format(
        "rank-deficient design: condition number %.3g exceeds %.3g (singular value %d of %d is %.3g, the largest "
        "%.3g; the weakest direction is mostly CHU %c's coefficients, most of all %s)",
        f.condition, max_condition, static_cast<int>(rank), unknowns, sv(rank - 1), sv(0), head_name(list.head[head]),
        kCoefficientNames[term]);
}

// Each head's and axis' residual and signal RMS over the orbits.
void residual_rms(const Eigen::VectorXd& res, const Eigen::VectorXd& target, const HeadList& list, Eigen::Index rows,
                  Eigen::Index n, TermsFit& f) {
    for (std::size_t i = 0; i < list.count; ++i) {
        const std::size_t h = list.head[i];
        for (std::size_t ax = 0; ax < 3; ++ax) {
            double ss = 0.0;
            double sy = 0.0;
            for (Eigen::Index k = 0; k < n; ++k) {
                const Eigen::Index row = rows * k + static_cast<Eigen::Index>(3 * i + ax);
                ss += res(row) * res(row);
                sy += target(row) * target(row);
            }
            f.head[h].residual_rms[ax] = std::sqrt(ss / static_cast<double>(n));
            f.head[h].signal_rms[ax] = std::sqrt(sy / static_cast<double>(n));
        }
    }
}

// The centred coefficients b back into the contract's form (see the header).
void uncentre(const Eigen::VectorXd& b, const HeadList& list, int per_axis, Terms terms, TermsFit& f) {
    ModelFile& m = f.model;
    m.present = {};
    m.quadratic = terms == Terms::kQuadratic;
    for (std::size_t i = 0; i < list.count; ++i) {
        const std::size_t h = list.head[i];
        m.present[h] = true;
        for (std::size_t ax = 0; ax < 3; ++ax) {
            const Eigen::Index base = static_cast<Eigen::Index>(3 * i + ax) * per_axis;
            auto& c = m.coefficients[h][ax];
            c = {};
            c[0] = b(base);
            for (std::uint8_t j = 0; j < kRegressors; ++j) {
                const auto x = static_cast<Regressor>(j + 1);
                const std::size_t k_lin = term_index(x, 1);
                const std::size_t k_quad = term_index(x, 2);
                const double mj = f.centring.mean[h][j];
                const double sj = f.centring.scale[h][j];
                const double lin = b(base + static_cast<Eigen::Index>(k_lin));
                const double quad =
                    static_cast<int>(k_quad) < per_axis ? b(base + static_cast<Eigen::Index>(k_quad)) : 0.0;
                c[0] += -lin * mj / sj + quad * mj * mj / (sj * sj);
                c[k_lin] = lin / sj - 2.0 * quad * mj / (sj * sj);
                c[k_quad] = quad / (sj * sj);
            }
        }
    }
}

// Adds the common rotation ω = w0 + w2·T029 + w3·T032 (F axes, arcsec) to
// every head's model: N_h·ω in head axes. The rule kSmallest's, in Eigen's
// operations as it always was (its models byte-identical); the other rules
// use calib::add_common_rotation, the estimator's.
void add_common_rotation(const HeadList& list, const HeadOrientations& n_ref, const Eigen::Vector3d& w0_f,
                         const Eigen::Vector3d& w2_f, const Eigen::Vector3d& w3_f, ModelFile& m) {
    for (std::size_t i = 0; i < list.count; ++i) {
        const std::size_t h = list.head[i];
        const Eigen::Vector3d w0 = n_ref[h] * w0_f;
        const Eigen::Vector3d w2 = n_ref[h] * w2_f;
        const Eigen::Vector3d w3 = n_ref[h] * w3_f;
        for (std::size_t ax = 0; ax < 3; ++ax) {
            const auto ai = static_cast<Eigen::Index>(ax);
            auto& c = m.coefficients[h][ax];
            c[term_index(Regressor::kOne, 0)] += w0(ai);
            c[term_index(Regressor::kT1, 1)] += w2(ai) + w3(ai);  // T2 = T1 + (T2 − T1), likewise T3
            c[term_index(Regressor::kT2MinusT1, 1)] += w2(ai);
            c[term_index(Regressor::kT3MinusT1, 1)] += w3(ai);
        }
    }
}

// The rule kSmallest: of all models the star trackers cannot tell apart (c
// plus a common rotation w0 + w2·T029 + w3·T032), the one whose corrections
// are smallest (RMS over the orbits of the period), solved as it always was
// (its models are byte-identical to those written before the rules had names;
// apply_rule with A_h = N_hᵀ gives the same to rounding).
void apply_gauge(const std::vector<OrbitAverage>& orbits, const HeadOrientations& n_ref, const HeadList& list,
                 Eigen::Index rows, ModelFile& m) {
    const auto n = static_cast<Eigen::Index>(orbits.size());
    const auto nh = static_cast<Eigen::Index>(list.count);
    Eigen::MatrixXd gd(rows * n, kGauge);
    Eigen::VectorXd gt(rows * n);
    for (Eigen::Index k = 0; k < n; ++k) {
        const OrbitAverage& o = orbits[static_cast<std::size_t>(k)];
        for (Eigen::Index i = 0; i < nh; ++i) {
            const std::size_t hs = list.head[static_cast<std::size_t>(i)];
            const double t2 = o.x[hs](0) + o.x[hs](1);
            const double t3 = o.x[hs](0) + o.x[hs](2);
            const Eigen::Matrix3d n_h = n_ref[hs];
            gd.block<3, 3>(rows * k + 3 * i, 0) = n_h;
            gd.block<3, 3>(rows * k + 3 * i, 3) = n_h * t2;
            gd.block<3, 3>(rows * k + 3 * i, 6) = n_h * t3;
            for (std::size_t ax = 0; ax < 3; ++ax) {
                gt(rows * k + 3 * i + static_cast<Eigen::Index>(ax)) = -predicted(m.coefficients[hs][ax], o, hs);
            }
        }
    }
    const Eigen::VectorXd wv = gd.bdcSvd(Eigen::ComputeThinU | Eigen::ComputeThinV).solve(gt);
    add_common_rotation(list, n_ref, wv.segment<3>(0), wv.segment<3>(3), wv.segment<3>(6), m);
}

// The rule's weights B_h by position in list (calib/common_rotation.hpp);
// false when no head carries weight.
bool rule_weights(const CommonRotation& rule, const HeadOrientations& n_ref, const HeadList& list,
                  std::array<calib::Matrix3, kMaxHeads>& b) {
    std::array<calib::Matrix3, kMaxHeads> a{};
    std::array<calib::Matrix3, kMaxHeads> n{};
    for (std::size_t i = 0; i < list.count; ++i) {
        const std::size_t h = list.head[i];
        Eigen::Matrix3d a_h = Eigen::Matrix3d::Zero();
        if (rule.rule == CommonRotationRule::kCombined) {
            a_h = rule.motion[h];
        } else if (rule.rule == CommonRotationRule::kRigid && h == rule.rigid_head) {
            a_h = Eigen::Matrix3d::Identity();
        }
        for (Eigen::Index r = 0; r < 3; ++r) {
            for (Eigen::Index c = 0; c < 3; ++c) {
                a[i].m[r][c] = a_h(r, c);
                n[i].m[r][c] = n_ref[h](r, c);
            }
        }
    }
    return calib::bench_weights(a.data(), n.data(), list.count, b.data());
}

// The rule (calib/common_rotation.hpp) over the orbits: of the models c + N_h·ω,
// the one whose weighted motion of the bench is least. False when the
// orbits do not fix it (no weight, or T029 and T032 never vary apart).
bool apply_rule(const std::vector<OrbitAverage>& orbits, const HeadOrientations& n_ref, const HeadList& list,
                const CommonRotation& rule, ModelFile& m) {
    std::array<calib::Matrix3, kMaxHeads> b{};
    if (!rule_weights(rule, n_ref, list, b)) {
        return false;
    }
    const std::size_t h0 = list.head[0];
    calib::CommonRotationSums sums;
    for (const OrbitAverage& o : orbits) {
        sums.t2_centre += (o.x[h0](0) + o.x[h0](1)) / static_cast<double>(orbits.size());
        sums.t3_centre += (o.x[h0](0) + o.x[h0](2)) / static_cast<double>(orbits.size());
    }
    for (const OrbitAverage& o : orbits) {
        double y[3] = {0.0, 0.0, 0.0};
        for (std::size_t i = 0; i < list.count; ++i) {
            const std::size_t h = list.head[i];
            double c[3];
            for (std::size_t ax = 0; ax < 3; ++ax) {
                c[ax] = predicted(m.coefficients[h][ax], o, h);
            }
            for (int r = 0; r < 3; ++r) {
                y[r] += b[i].m[r][0] * c[0] + b[i].m[r][1] * c[1] + b[i].m[r][2] * c[2];
            }
        }
        calib::add_to_common_rotation(sums, y, o.x[h0](0) + o.x[h0](1), o.x[h0](0) + o.x[h0](2));
    }
    double w[3][3];
    if (!calib::common_rotation_of(sums, w)) {
        return false;
    }
    for (std::size_t i = 0; i < list.count; ++i) {
        calib::Matrix3 n{};
        for (Eigen::Index r = 0; r < 3; ++r) {
            for (Eigen::Index c = 0; c < 3; ++c) {
                n.m[r][c] = n_ref[list.head[i]](r, c);
            }
        }
        calib::add_common_rotation(n, w, m.coefficients[list.head[i]]);  // the estimator's
    }
    return true;
}

}  // namespace

const char* terms_name(Terms t) noexcept {
    return t == Terms::kLinear ? "linear" : "quadratic";
}

TermsFit solve_terms(const std::vector<OrbitAverage>& orbits, const HeadOrientations& n_ref, HeadMask heads,
                     Terms terms, double max_condition, double min_range_c, const CommonRotation& rule) {
    TermsFit f;
    f.terms = terms;
    f.heads = heads;
    const HeadList list = heads_of(heads);
    const auto nh = static_cast<Eigen::Index>(list.count);
    const Eigen::Index rows = 3 * nh;  // an orbit's equations: 3 per head
    const int per_axis = terms_per_axis(terms);
    const int unknowns = static_cast<int>(rows) * per_axis;
    f.unknowns = unknowns;
    f.rank = unknowns - kGauge;
    const auto n = static_cast<Eigen::Index>(orbits.size());
    if (n == 0) {
        f.refused = "no orbit to fit";
        return f;
    }
    centre_regressors(orbits, list, f.centring);
    if (terms == Terms::kQuadratic && !range_enough(f, list, min_range_c)) {
        return f;
    }

    // The joint design (fit.hpp): each orbit's 3·heads equations projected
    // orthogonally to F's own rotation, P = I − G·Gᵀ/heads
    // (calib/common_rotation.hpp).
    const Eigen::MatrixXd proj = projector(n_ref, list, rows);
    const Eigen::MatrixXd y = centred_errors(orbits, list, rows);
    Eigen::MatrixXd design = Eigen::MatrixXd::Zero(rows * n, unknowns);
    Eigen::VectorXd target(rows * n);
    fill_design(orbits, list, f.centring, per_axis, proj, y, design, target);
    Eigen::VectorXd scale = design.colwise().norm().transpose();
    for (Eigen::Index i = 0; i < scale.size(); ++i) {
        scale(i) = scale(i) > 0.0 ? scale(i) : 1.0;  // a zero column stays zero: its singular value is 0
    }
    design = design * scale.cwiseInverse().asDiagonal();
    Eigen::BDCSVD<Eigen::MatrixXd> svd(design, Eigen::ComputeThinU | Eigen::ComputeThinV);
    const Eigen::VectorXd sv = svd.singularValues();
    f.singular_values.assign(sv.data(), sv.data() + sv.size());
    const Eigen::Index rank = f.rank;
    f.condition = sv(rank - 1) > 0.0 ? sv(0) / sv(rank - 1) : std::numeric_limits<double>::infinity();
    if (!(f.condition <= max_condition)) {
        f.refused = why_ill_conditioned(f, svd, list, per_axis, max_condition);
        return f;
    }
    // Least squares on the observable directions only (truncated SVD).
    const Eigen::VectorXd c_scaled =
        svd.matrixV().leftCols(rank) * (svd.matrixU().leftCols(rank).transpose() * target).cwiseQuotient(sv.head(rank));
    const Eigen::VectorXd b = scale.cwiseInverse().asDiagonal() * c_scaled;  // centred coefficients

    // Residuals, with each orbit's common rotation removed (as in the fit).
    const Eigen::VectorXd res = target - design * c_scaled;
    residual_rms(res, target, list, rows, n, f);
    uncentre(b, list, per_axis, terms, f);
    if (rule.rule == CommonRotationRule::kSmallest) {
        apply_gauge(orbits, n_ref, list, rows, f.model);
    } else if (!apply_rule(orbits, n_ref, list, rule, f.model)) {
        f.refused = "the common rotation (rule " + common_rotation_name(rule) +
                    ") is not fixed by the data: T029 and T032 do not vary independently, or no head carries weight";
    }
    return f;
}

double mean_pair_rms(const std::array<Rms, kMaxPairs>& r, const PairList& pairs) {
    double sum = 0.0;
    for (std::size_t p = 0; p < pairs.count; ++p) {
        if (r[p].n == 0) {
            return std::numeric_limits<double>::quiet_NaN();
        }
        sum += r[p].rms;
    }
    return sum / static_cast<double>(pairs.count);
}

SolutionInput<double> thermal_input(const FitEpoch& e, std::size_t h) {
    SolutionInput<double> in{};
    in.q_chu_icrf = e.q_chu_icrf[h];
    in.head = static_cast<std::uint8_t>(h);
    in.temperatures.t_chu = {ScalarTraits<double>::celsius(e.temp[h][0]), true};
    in.temperatures.t_029 = {ScalarTraits<double>::celsius(e.temp[h][1]), true};
    in.temperatures.t_032 = {ScalarTraits<double>::celsius(e.temp[h][2]), true};
    in.velocity.valid = false;
    return in;
}

std::array<Rms, kMaxPairs> corrected_iba_rms(const std::vector<FitEpoch>& epochs, HeadMask heads, double from,
                                             double to, const ModelFile& m, bool where_the_sun_is_known) {
    const ThermalModel<double> core = to_core<double>(m);
    const CorrectionConfig<double> thermal_only{false, &core};
    std::optional<SunTermModel<double>> sun;
    if (has_sun_term(m)) {
        sun = sun_term_of<double>(m);
    }
    const HeadList list = heads_of(heads);
    const PairList pairs = pairs_of(heads);
    std::array<std::vector<double>, kMaxPairs> t;
    std::array<std::vector<double>, kMaxPairs> v;
    for (const FitEpoch& e : epochs) {
        Vector3<double> s_icrf{};
        const bool sun_needed = sun || where_the_sun_is_known;
        if (!(e.t >= from && e.t < to) || (sun_needed && !nav::sun_direction_icrf(e.t, s_icrf))) {
            continue;  // a model with a Sun term corrects only where the Sun's direction is known
        }
        std::array<Vector3<double>, kMaxHeads> z{};
        std::array<bool, kMaxHeads> ok{};
        for (std::size_t i = 0; i < list.count; ++i) {
            const std::size_t h = list.head[i];
            const CorrectedSolution<double> c = correct_solution(thermal_input(e, h), thermal_only);
            ok[h] = (c.status & status::kThermalApplied) != 0U;
            z[h] = boresight(sun ? with_sun_term(c.q_chu_icrf, sun_term_rotation(*sun, static_cast<std::uint8_t>(h),
                                                                                 c.q_chu_icrf, s_icrf))
                                 : c.q_chu_icrf);
        }
        for (std::size_t p = 0; p < pairs.count; ++p) {
            const auto i = pairs.pair[p].first;
            const auto j = pairs.pair[p].second;
            if (ok[i] && ok[j]) {
                t[p].push_back(e.t);
                v[p].push_back(angle_arcsec(z[i], z[j]));
            }
        }
    }
    std::array<Rms, kMaxPairs> out{};
    for (std::size_t p = 0; p < pairs.count; ++p) {
        if (!t[p].empty()) {
            out[p] = rms_about_mean(t[p], v[p]);
        }
    }
    return out;
}

namespace {

// A model's held-out IBA RMS, mean over the pairs; NaN when a pair has no
// held-out epoch.
double mean_held_out_rms(const ModelScore& m, const PairList& pairs) {
    return mean_pair_rms(m.out, pairs);
}

}  // namespace

Selection select_terms(const std::vector<OrbitAverage>& orbits, const std::vector<FitEpoch>& epochs,
                       const HeadOrientations& n_ref, HeadMask heads, double t_first, double t_last, double holdout,
                       double max_condition, double min_range_c, const CommonRotation& rule) {
    Selection s;
    s.pairs = pairs_of(heads);
    s.holdout = holdout;
    const double inf = std::numeric_limits<double>::infinity();
    s.t_split = holdout > 0.0 ? t_first + (1.0 - holdout) * (t_last - t_first) : inf;
    std::vector<OrbitAverage> fitted;
    for (const OrbitAverage& o : orbits) {
        if (o.t_mid < s.t_split) {
            fitted.push_back(o);
        }
    }
    s.orbits_fitted = fitted.size();
    for (Terms terms : {Terms::kLinear, Terms::kQuadratic}) {
        ModelScore ms;
        ms.fit = solve_terms(fitted, n_ref, heads, terms, max_condition, min_range_c, rule);
        if (ms.fit.refused.empty()) {
            ms.in = corrected_iba_rms(epochs, heads, -inf, s.t_split, ms.fit.model);
            if (holdout > 0.0) {
                ms.out = corrected_iba_rms(epochs, heads, s.t_split, inf, ms.fit.model);
            }
        }
        s.models.push_back(ms);
    }
    const ModelScore& lin = s.models[0];
    const ModelScore& quad = s.models[1];
    if (!lin.fit.refused.empty()) {
        s.verdict = "no selection: the linear model is not supported either (" + lin.fit.refused + ")";
    } else if (holdout <= 0.0) {
        s.verdict = "no selection: nothing held out (--holdout 0)";
    } else if (!quad.fit.refused.empty()) {
        s.decided = true;
        s.preferred = Terms::kLinear;
        s.verdict = "linear: the data do not support quadratic terms (" + quad.fit.refused + ")";
    } else {
        const double l = mean_held_out_rms(lin, s.pairs);
        const double q = mean_held_out_rms(quad, s.pairs);
        if (!(l > 0.0 && q > 0.0)) {
            s.verdict = "no selection: a pair has no held-out epoch";
        } else {
            s.decided = true;
            s.preferred = 1.0 - q / l > kSelectionMargin ? Terms::kQuadratic : Terms::kLinear;
            s.verdict = selection_verdict(l, q);
        }
    }
    return s;
}

std::string selection_verdict(double linear_rms, double quadratic_rms) {
    const double gain = 1.0 - quadratic_rms / linear_rms;
    if (gain > kSelectionMargin) {
        return format(
            "quadratic: its held-out IBA RMS (mean over the pairs) is %.2f %% lower than the linear model's, more "
            "than the %.0f %% margin",
            100.0 * gain, 100.0 * kSelectionMargin);
    }
    if (gain >= 0.0) {
        return format(
            "linear: the quadratic terms lower the held-out IBA RMS (mean over the pairs) by %.2f %%, not more than "
            "the %.0f %% margin: they fit noise",
            100.0 * gain, 100.0 * kSelectionMargin);
    }
    return format(
        "linear: the quadratic terms raise the held-out IBA RMS (mean over the pairs) by %.2f %%: they fit noise",
        -100.0 * gain);
}

std::string describe_centring(const TermsFit& f) {
    std::ostringstream o;
    o << "regressors centred and scaled per head (mean +- standard deviation over the orbit averages, degC):\n";
    const HeadList list = heads_of(f.heads);
    for (std::size_t i = 0; i < list.count; ++i) {
        const std::size_t h = list.head[i];
        o << "  CHU " << head_name(static_cast<std::uint8_t>(h)) << ':';
        for (std::size_t j = 0; j < 3; ++j) {
            o << format("  %s %.2f +- %.2f (range %.2f)", kRegressorNames[j], f.centring.mean[h][j],
                        f.centring.scale[h][j], f.centring.range[h][j]);
        }
        o << '\n';
    }
    o << "the model file is in the contract's form: coefficients of T_CHU, T029 - T_CHU, T032 - T_CHU"
      << (f.terms == Terms::kQuadratic ? " and their squares" : "")
      << " in degC (not centred); c0 is the angle at 0 degC relative to the mean orientation over the period\n";
    return o.str();
}

std::string describe_selection(const Selection& s) {
    std::ostringstream o;
    if (s.holdout > 0.0) {
        o << format(
            "model selection: both models fitted on the first %.0f %% of the period (t < %.3f, %zu orbits), "
            "IBA RMS (arcsec, thermal-corrected) on it and on the last %.0f %%, held out:\n",
            100.0 * (1.0 - s.holdout), s.t_split, s.orbits_fitted, 100.0 * s.holdout);
    } else {
        o << format("model selection: both models fitted on the whole period (%zu orbits), nothing held out:\n",
                    s.orbits_fitted);
    }
    for (const ModelScore& m : s.models) {
        o << format("  %-9s ", terms_name(m.fit.terms));
        if (!m.fit.refused.empty()) {
            o << "not supported: " << m.fit.refused << '\n';
            continue;
        }
        o << format("condition number %.1f; residual RMS alpha/beta/gamma (orbit averages, arcsec):", m.fit.condition);
        const HeadList list = heads_of(m.fit.heads);
        for (std::size_t i = 0; i < list.count; ++i) {
            const std::size_t h = list.head[i];
            const HeadFit& hf = m.fit.head[h];
            o << format(" %c %.3f/%.3f/%.3f", head_name(static_cast<std::uint8_t>(h)), hf.residual_rms[0],
                        hf.residual_rms[1], hf.residual_rms[2]);
        }
        o << "\n            IBA RMS in the period";
        // A pair without an epoch there has no RMS: "n/a", never 0.000.
        const auto rms = [](const Rms& r) { return r.n == 0 ? std::string("n/a") : format("%.3f", r.rms); };
        for (std::size_t p = 0; p < s.pairs.count; ++p) {
            o << " " << s.pairs.pair[p].name << " " << rms(m.in[p]);
        }
        if (s.holdout > 0.0) {
            o << "; held out";
            for (std::size_t p = 0; p < s.pairs.count; ++p) {
                o << " " << s.pairs.pair[p].name << " " << rms(m.out[p]);
            }
        }
        o << '\n';
    }
    o << "supported by the data: " << s.verdict << '\n';
    return o.str();
}

}  // namespace ascorr::host
