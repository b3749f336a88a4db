#include "ascorr_host/analysis/align.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "ascorr/combine/mountings.hpp"
#include "ascorr/core/constants.hpp"
#include "ascorr/core/rotation_vector.hpp"
#include "ascorr_host/formats/csv.hpp"

namespace ascorr::host {

namespace {

Eigen::Matrix3d rotation_matrix_of(const Quaternion<double>& q) noexcept {
    return Eigen::Quaterniond(q.w, q.x, q.y, q.z).toRotationMatrix();
}

}  // namespace

Eigen::Vector3d rotation_arcsec(const Quaternion<double>& a, const Quaternion<double>& b) noexcept {
    const Vector3<double> v = rotation_vector_arcsec(a, b);
    return {v.x, v.y, v.z};
}

Quaternion<double> rotation_quaternion(const Eigen::Vector3d& theta_arcsec) noexcept {
    return exp_arcsec({theta_arcsec.x(), theta_arcsec.y(), theta_arcsec.z()});
}

Eigen::Vector3d boresight_crf(const Quaternion<double>& q_chu_crf) noexcept {
    return rotation_matrix_of(q_chu_crf).row(2).transpose();
}

Eigen::Matrix3d information_crf(const Quaternion<double>& q_chu_crf, double sigma_cross_arcsec,
                                double sigma_about_arcsec) noexcept {
    const combine::Matrix3 w = combine::information({true, q_chu_crf, sigma_cross_arcsec, sigma_about_arcsec});
    Eigen::Matrix3d e;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) {
            e(i, j) = w.m[i][j];
        }
    }
    return e;
}

// ---- The sums

AlignSums::AlignSums(double noise_window_s) : window_s_(noise_window_s) {
    for (std::size_t s = 0; s < kHeadSets; ++s) {
        const std::size_t dim =
            3U * (head_count(static_cast<HeadMask>(s)) > 0 ? head_count(static_cast<HeadMask>(s)) - 1U : 0U);
        total_[s].sum = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(dim));
        total_[s].scatter = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(dim), static_cast<Eigen::Index>(dim));
    }
}

void AlignSums::add(double t, const std::array<std::optional<Quaternion<double>>, kMaxHeads>& q_crf_icrf) {
    HeadMask s = 0U;
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        s |= q_crf_icrf[h] ? head_bit(h) : HeadMask{0};
    }
    if (head_count(s) < 2U) {
        single_ += head_count(s) == 1U ? 1U : 0U;
        return;
    }
    const HeadList l = heads_of(s);  // the first is the reference of the set's differences
    const auto dim = static_cast<Eigen::Index>(3U * (l.count - 1U));
    Eigen::VectorXd d(dim);
    const Quaternion<double>& ref = *q_crf_icrf[l.head[0]];
    for (std::size_t k = 1; k < l.count; ++k) {
        d.segment<3>(static_cast<Eigen::Index>(3U * (k - 1U))) = rotation_arcsec(*q_crf_icrf[l.head[k]], ref);
    }
    ++joint_;
    heads_ |= s;
    for (std::size_t k = 0; k < l.count; ++k) {
        ++head_epochs_[l.head[k]];
    }
    total_[s].n += 1U;
    total_[s].sum += d;

    if (!t0_) {
        t0_ = t;
    }
    const long long key = window_s_ > 0.0 ? static_cast<long long>(std::floor((t - *t0_) / window_s_)) : 0LL;
    // Windows end as the data move on; rows out of time order reopen a window,
    // which is still a valid (smaller) window.
    for (auto it = open_.begin(); it != open_.end();) {
        if (it->first < key - 1 || it->first > key + 1) {
            close(it->second);
            it = open_.erase(it);
        } else {
            ++it;
        }
    }
    Window& w = open_[key];
    if (w.n[s] == 0U) {
        w.sum[s] = Eigen::VectorXd::Zero(dim);
        w.sum_sq[s] = Eigen::MatrixXd::Zero(dim, dim);
    }
    w.n[s] += 1U;
    w.sum[s] += d;
    w.sum_sq[s].selfadjointView<Eigen::Lower>().rankUpdate(d);
}

void AlignSums::close(Window& w) {
    for (std::size_t s = 0; s < kHeadSets; ++s) {
        if (w.n[s] < 2U) {
            continue;  // one epoch: all of it goes into its own mean
        }
        const auto n = static_cast<double>(w.n[s]);
        const Eigen::MatrixXd sq = w.sum_sq[s].selfadjointView<Eigen::Lower>();
        total_[s].scatter += sq - w.sum[s] * w.sum[s].transpose() / n;
        total_[s].dof += n - 1.0;
    }
}

void AlignSums::finish() {
    for (auto& kv : open_) {
        close(kv.second);
    }
    open_.clear();
}

// ---- The noise

const char* noise_model_text(NoiseModel m) noexcept {
    return m == NoiseModel::kEqualCross ? "one sigma_cross shared by the heads (two heads do not identify four)"
                                        : "sigma_cross and sigma_about of each head";
}

namespace {

// The variance components: x = P·y, x = (σc², σa²) of each head in `heads`
// order; y the free parameters.
struct Components {
    HeadList heads;
    Eigen::MatrixXd p;  // 2·heads × parameters
};

Components components_of(HeadMask heads, NoiseModel model) {
    Components c;
    c.heads = heads_of(heads);
    const auto n = static_cast<Eigen::Index>(c.heads.count);
    if (model == NoiseModel::kPerHead) {
        c.p = Eigen::MatrixXd::Identity(2 * n, 2 * n);
    } else {
        c.p = Eigen::MatrixXd::Zero(2 * n, n + 1);
        for (Eigen::Index k = 0; k < n; ++k) {
            c.p(2 * k, 0) = 1.0;          // the shared σc²
            c.p(2 * k + 1, k + 1) = 1.0;  // each head's σa²
        }
    }
    return c;
}

// The 3(k−1) square covariance of head set s's differences d per unit of a
// component `unit` (I − bbᵀ or bbᵀ) of head h: the reference head (the
// set's first) is in every difference, every other head in its own.
Eigen::MatrixXd unit_covariance(const HeadList& l, std::uint8_t h, const Eigen::Matrix3d& unit) {
    const auto dim = static_cast<Eigen::Index>(3U * (l.count - 1U));
    Eigen::MatrixXd m = Eigen::MatrixXd::Zero(dim, dim);
    if (h == l.head[0]) {
        for (Eigen::Index i = 0; i < dim; i += 3) {
            for (Eigen::Index j = 0; j < dim; j += 3) {
                m.block<3, 3>(i, j) = unit;
            }
        }
        return m;
    }
    std::size_t pos = 1;
    while (l.head[pos] != h) {
        ++pos;
    }
    const auto i = static_cast<Eigen::Index>(3U * (pos - 1U));
    m.block<3, 3>(i, i) = unit;
    return m;
}

// For head set s: A_k for every component k (x's order); zero for heads not in s.
std::vector<Eigen::MatrixXd> unit_covariances(HeadMask s, const Components& c,
                                              const std::array<Eigen::Vector3d, kMaxHeads>& b) {
    const HeadList l = heads_of(s);
    const auto dim = static_cast<Eigen::Index>(3U * (l.count - 1U));
    std::vector<Eigen::MatrixXd> a(2U * c.heads.count, Eigen::MatrixXd::Zero(dim, dim));
    for (std::size_t k = 0; k < c.heads.count; ++k) {
        const std::uint8_t h = c.heads.head[k];
        if (has_head(s, h)) {
            const Eigen::Matrix3d about = b[h] * b[h].transpose();
            a[2U * k] = unit_covariance(l, h, Eigen::Matrix3d::Identity() - about);
            a[2U * k + 1U] = unit_covariance(l, h, about);
        }
    }
    return a;
}

struct SetModel {
    double dof = 0.0;
    Eigen::MatrixXd scatter;
    std::vector<Eigen::MatrixXd> a;  // per free parameter (A·P)
};

std::vector<SetModel> set_models(const AlignSums& sums, const Components& c,
                                 const std::array<Eigen::Vector3d, kMaxHeads>& b) {
    std::vector<SetModel> out;
    HeadMask all = 0U;
    for (std::size_t k = 0; k < c.heads.count; ++k) {
        all |= head_bit(c.heads.head[k]);
    }
    for (std::size_t s = 0; s < kHeadSets; ++s) {
        const auto set = static_cast<HeadMask>(s);
        const AlignSums::SetSums& ss = sums.set(set);
        if (head_count(set) < 2U || ss.dof <= 0.0 || (set & ~all) != 0U) {
            continue;
        }
        const std::vector<Eigen::MatrixXd> a = unit_covariances(set, c, b);
        SetModel m;
        m.dof = ss.dof;
        m.scatter = ss.scatter;
        for (Eigen::Index l = 0; l < c.p.cols(); ++l) {
            Eigen::MatrixXd al = Eigen::MatrixXd::Zero(ss.scatter.rows(), ss.scatter.cols());
            for (Eigen::Index k = 0; k < c.p.rows(); ++k) {
                if (c.p(k, l) != 0.0) {
                    al += c.p(k, l) * a[static_cast<std::size_t>(k)];
                }
            }
            m.a.push_back(al);
        }
        out.push_back(std::move(m));
    }
    return out;
}

// The unweighted normal matrix Σ f·tr(A_l A_m) and its right side Σ tr(A_l T):
// the starting solution, and (scaled) the test of identifiability.
void unweighted_equations(const std::vector<SetModel>& sets, Eigen::MatrixXd& n, Eigen::VectorXd& r) {
    const Eigen::Index p = sets.empty() ? 0 : static_cast<Eigen::Index>(sets[0].a.size());
    n = Eigen::MatrixXd::Zero(p, p);
    r = Eigen::VectorXd::Zero(p);
    for (const SetModel& m : sets) {
        for (Eigen::Index l = 0; l < p; ++l) {
            const auto ul = static_cast<std::size_t>(l);
            r(l) += (m.a[ul].cwiseProduct(m.scatter)).sum();
            for (Eigen::Index k = 0; k < p; ++k) {
                n(l, k) += m.dof * (m.a[ul].cwiseProduct(m.a[static_cast<std::size_t>(k)])).sum();
            }
        }
    }
}

bool identifiable(const Eigen::MatrixXd& n) {
    if (n.rows() == 0) {
        return false;
    }
    const Eigen::VectorXd d = n.diagonal().cwiseMax(0.0).cwiseSqrt();
    if ((d.array() <= 0.0).any()) {
        return false;
    }
    const Eigen::MatrixXd corr = d.cwiseInverse().asDiagonal() * n * d.cwiseInverse().asDiagonal();
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es(corr, Eigen::EigenvaluesOnly);
    return es.eigenvalues()(0) > 1e-8 * es.eigenvalues()(es.eigenvalues().size() - 1);
}

// One Fisher-scoring step of REML: y ← N⁻¹ r with
// N_lm = Σ f/2·tr(Σ⁻¹A_l Σ⁻¹A_m), r_l = Σ ½·tr(Σ⁻¹A_l Σ⁻¹T), Σ = Σ y_l A_l.
void reml_equations(const std::vector<SetModel>& sets, const Eigen::VectorXd& y, Eigen::MatrixXd& n,
                    Eigen::VectorXd& r) {
    const Eigen::Index p = y.size();
    n = Eigen::MatrixXd::Zero(p, p);
    r = Eigen::VectorXd::Zero(p);
    for (const SetModel& m : sets) {
        Eigen::MatrixXd sigma = Eigen::MatrixXd::Zero(m.scatter.rows(), m.scatter.cols());
        for (Eigen::Index l = 0; l < p; ++l) {
            sigma += y(l) * m.a[static_cast<std::size_t>(l)];
        }
        const Eigen::LLT<Eigen::MatrixXd> llt(sigma);
        std::vector<Eigen::MatrixXd> b;  // Σ⁻¹A_l
        b.reserve(static_cast<std::size_t>(p));
        for (Eigen::Index l = 0; l < p; ++l) {
            b.push_back(llt.solve(m.a[static_cast<std::size_t>(l)]));
        }
        const Eigen::MatrixXd st = llt.solve(m.scatter);  // Σ⁻¹T
        for (Eigen::Index l = 0; l < p; ++l) {
            const auto ul = static_cast<std::size_t>(l);
            r(l) += 0.5 * (b[ul] * st).trace();
            for (Eigen::Index k = 0; k < p; ++k) {
                n(l, k) += 0.5 * m.dof * (b[ul] * b[static_cast<std::size_t>(k)]).trace();
            }
        }
    }
}

constexpr std::size_t kMaxRemlIterations = 50;
constexpr double kRemlTolerance = 1e-10;  // relative change of every component

}  // namespace

NoiseEstimate estimate_noise(const AlignSums& sums, HeadMask heads,
                             const std::array<Eigen::Vector3d, kMaxHeads>& boresight_crf) {
    NoiseEstimate est;
    est.heads = heads;
    Components c = components_of(heads, NoiseModel::kPerHead);
    std::vector<SetModel> sets = set_models(sums, c, boresight_crf);
    if (sets.empty()) {
        throw std::invalid_argument(
            "the noise has no degree of freedom: no noise window (" + number_text(sums.noise_window_s()) +
            " s) holds two epochs of the same heads; give a window longer than the data's step");
    }
    Eigen::MatrixXd n;
    Eigen::VectorXd r;
    unweighted_equations(sets, n, r);
    if (!identifiable(n)) {
        est.model = NoiseModel::kEqualCross;
        c = components_of(heads, NoiseModel::kEqualCross);
        sets = set_models(sums, c, boresight_crf);
        unweighted_equations(sets, n, r);
        if (!identifiable(n)) {
            throw std::invalid_argument("the heads' noise is not identifiable from their relative attitudes (heads " +
                                        head_letters(heads) + ", even with one sigma_cross shared by them)");
        }
    }
    for (const SetModel& m : sets) {
        est.dof += m.dof;
    }
    // Start: the unweighted solution, each component kept positive.
    Eigen::VectorXd y = n.ldlt().solve(r);
    const double floor = 1e-6 * std::max(1e-12, y.cwiseAbs().maxCoeff());
    y = y.cwiseMax(floor);
    for (est.iterations = 1; est.iterations <= kMaxRemlIterations; ++est.iterations) {
        reml_equations(sets, y, n, r);
        const Eigen::VectorXd next = n.ldlt().solve(r).cwiseMax(floor);
        const double change = ((next - y).cwiseAbs().array() / next.array()).maxCoeff();
        y = next;
        if (change < kRemlTolerance) {
            est.converged = true;
            break;
        }
    }
    est.iterations = std::min(est.iterations, kMaxRemlIterations);
    reml_equations(sets, y, n, r);
    const Eigen::MatrixXd cov_y = n.inverse();
    const Eigen::VectorXd x = c.p * y;
    const Eigen::MatrixXd cov_x = c.p * cov_y * c.p.transpose();
    for (std::size_t k = 0; k < c.heads.count; ++k) {
        HeadNoise& hn = est.head[c.heads.head[k]];
        const auto i = static_cast<Eigen::Index>(2U * k);
        hn.sigma_cross_arcsec = std::sqrt(x(i));
        hn.sigma_about_arcsec = std::sqrt(x(i + 1));
        // σ = √x: sd(σ) = sd(x) / (2σ)
        hn.sd_cross_arcsec = std::sqrt(cov_x(i, i)) / (2.0 * hn.sigma_cross_arcsec);
        hn.sd_about_arcsec = std::sqrt(cov_x(i + 1, i + 1)) / (2.0 * hn.sigma_about_arcsec);
    }
    return est;
}

// ---- The mountings

namespace {

// Heads joined by a common epoch to the first head of `heads`; a head outside
// is named in the refusal.
void refuse_unconnected(const AlignSums& sums, HeadMask heads) {
    const HeadList l = heads_of(heads);
    HeadMask reached = l.count > 0 ? head_bit(l.head[0]) : HeadMask{0};
    for (bool grew = true; grew;) {
        grew = false;
        for (std::size_t s = 0; s < kHeadSets; ++s) {
            const auto set = static_cast<HeadMask>(s & heads);
            if (sums.set(static_cast<HeadMask>(s)).n > 0 && (set & reached) != 0U && (set & ~reached) != 0U) {
                reached |= set;
                grew = true;
            }
        }
    }
    for (std::size_t k = 0; k < l.count; ++k) {
        if (!has_head(reached, l.head[k])) {
            throw std::invalid_argument(std::string("CHU ") + kHeadLetters[l.head[k]] +
                                        " shares no clean epoch with CHU " + kHeadLetters[l.head[0]] +
                                        " (directly or through other heads): its mounting relative to theirs is "
                                        "not observable");
        }
    }
}

}  // namespace

Alignment solve_alignment(const AlignSums& sums, HeadMask heads,
                          const std::array<Eigen::Matrix3d, kMaxHeads>& information,
                          const std::array<Eigen::Vector3d, kMaxHeads>& turned_arcsec) {
    refuse_unconnected(sums, heads);
    const HeadList all = heads_of(heads);
    const auto n3 = static_cast<Eigen::Index>(3U * all.count);
    std::array<Eigen::Index, kMaxHeads> pos{};  // head → its block in the unknowns
    for (std::size_t k = 0; k < all.count; ++k) {
        pos[all.head[k]] = static_cast<Eigen::Index>(3U * k);
    }
    Eigen::MatrixXd n = Eigen::MatrixXd::Zero(n3, n3);
    Eigen::VectorXd r = Eigen::VectorXd::Zero(n3);
    for (std::size_t s = 0; s < kHeadSets; ++s) {
        const auto set = static_cast<HeadMask>(s);
        const AlignSums::SetSums& ss = sums.set(set);
        if (ss.n == 0U || (set & ~heads) != 0U) {
            continue;
        }
        const HeadList l = heads_of(set);
        const auto cnt = static_cast<double>(ss.n);
        // Mean θ of each head relative to the set's first (whose own is zero).
        std::array<Eigen::Vector3d, kMaxHeads> m{};
        Eigen::Matrix3d w_sum = Eigen::Matrix3d::Zero();
        Eigen::Vector3d wm_sum = Eigen::Vector3d::Zero();
        for (std::size_t k = 0; k < l.count; ++k) {
            m[k] = k == 0 ? Eigen::Vector3d::Zero()
                          : Eigen::Vector3d(ss.sum.segment<3>(static_cast<Eigen::Index>(3U * (k - 1U))) / cnt);
            w_sum += information[l.head[k]];
            wm_sum += information[l.head[k]] * m[k];
        }
        const Eigen::Matrix3d w_inv = w_sum.inverse();
        const Eigen::Vector3d combined = w_inv * wm_sum;  // the set's mean combined attitude
        for (std::size_t i = 0; i < l.count; ++i) {
            const Eigen::Matrix3d& wi = information[l.head[i]];
            const Eigen::Index pi = pos[l.head[i]];
            r.segment<3>(pi) += cnt * wi * (m[i] - combined);
            n.block<3, 3>(pi, pi) += cnt * wi;
            for (std::size_t j = 0; j < l.count; ++j) {
                n.block<3, 3>(pi, pos[l.head[j]]) -= cnt * wi * w_inv * information[l.head[j]];
            }
        }
    }
    // Bordered system: [N Gᵀ; G 0]·[δ; λ] = [r; 0], G = [W_1 … W_k] (the datum).
    Eigen::MatrixXd k = Eigen::MatrixXd::Zero(n3 + 3, n3 + 3);
    k.topLeftCorner(n3, n3) = n;
    for (std::size_t i = 0; i < all.count; ++i) {
        k.block<3, 3>(n3, pos[all.head[i]]) = information[all.head[i]];
        k.block<3, 3>(pos[all.head[i]], n3) = information[all.head[i]].transpose();
    }
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(n3 + 3);
    rhs.head(n3) = r;
    for (std::size_t i = 0; i < all.count; ++i) {
        rhs.tail<3>() -= information[all.head[i]] * turned_arcsec[all.head[i]];
    }
    const Eigen::PartialPivLU<Eigen::MatrixXd> lu(k);
    const Eigen::MatrixXd k_inv = lu.inverse();
    const Eigen::VectorXd sol = k_inv * rhs;
    Alignment a;
    a.heads = heads;
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {  // Eigen's types start uninitialised
        a.delta_arcsec[h].setZero();
        a.covariance[h].setZero();
    }
    Eigen::Matrix3d w_total = Eigen::Matrix3d::Zero();
    Eigen::Vector3d wd = Eigen::Vector3d::Zero();
    for (std::size_t i = 0; i < all.count; ++i) {
        const std::uint8_t h = all.head[i];
        a.delta_arcsec[h] = sol.segment<3>(pos[h]);
        // The constrained cofactor block is the covariance of the solution (minimal datum).
        a.covariance[h] = k_inv.block<3, 3>(pos[h], pos[h]);
        w_total += information[h];
        wd += information[h] * (turned_arcsec[h] + a.delta_arcsec[h]);
    }
    a.weighted_mean_arcsec = w_total.inverse() * wd;
    return a;
}

Alignment solve_alignment(const AlignSums& sums, HeadMask heads,
                          const std::array<Eigen::Matrix3d, kMaxHeads>& information) {
    std::array<Eigen::Vector3d, kMaxHeads> zero{};
    for (Eigen::Vector3d& z : zero) {
        z.setZero();
    }
    return solve_alignment(sums, heads, information, zero);
}

}  // namespace ascorr::host
