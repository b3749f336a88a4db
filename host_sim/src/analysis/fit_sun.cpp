#include "ascorr_host/analysis/fit_sun.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <limits>
#include <optional>

#include "ascorr/calib/frame.hpp"
#include "ascorr/calib/head_rotation.hpp"
#include "ascorr/core/correct.hpp"
#include "ascorr/nav/sun_direction.hpp"
#include "ascorr_host/formats/solutions_csv.hpp"
#include "ascorr_text/c_format.hpp"

namespace ascorr::host {

namespace {

constexpr int kMaxStacked = 3 * kMaxHeads;  // e or s of every head, stacked
using Stacked = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxStacked, 1>;
using Moment = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxStacked, kMaxStacked>;

Eigen::Vector3d to_eigen(const Vector3<double>& v) {
    return {v.x, v.y, v.z};
}

// One orbit's sums of the stacked e and s (3 per head, in the order of the
// fit's heads) and of their products.
struct OrbitMoments {
    explicit OrbitMoments(int n)
        : e(Stacked::Zero(n)), s(Stacked::Zero(n)), ss(Moment::Zero(n, n)), es(Moment::Zero(n, n)) {}
    std::size_t count = 0;
    Stacked e;
    Stacked s;
    Moment ss;
    Moment es;
    void add(const Stacked& e_t, const Stacked& s_t) {
        ++count;
        e += e_t;
        s += s_t;
        ss.noalias() += s_t * s_t.transpose();
        es.noalias() += e_t * s_t.transpose();
    }
};

// Sums over the orbits of the products about each orbit's own mean, and the
// references N_h (the first epoch's rotation of each head in F).
class SunMoments {
public:
    SunMoments(HeadMask heads, const std::array<std::uint8_t, 2>& frame_heads, double period)
        : list_(heads_of(heads)),
          frame_(frame_heads),
          period_(period),
          n_(3 * static_cast<int>(list_.count)),
          ss_(Moment::Zero(n_, n_)),
          es_(Moment::Zero(n_, n_)),
          orbit_(n_) {}

    // One epoch, its heads already corrected by the polynomial; false when the
    // Sun's direction is not known at t (outside nav/sun_direction.hpp's span).
    bool add(double t, const std::array<Quaternion<double>, kMaxHeads>& q_chu_icrf) {
        Vector3<double> s_icrf{};
        if (!nav::sun_direction_icrf(t, s_icrf)) {
            return false;
        }
        const auto bin = static_cast<long long>(std::floor(t / period_));
        if (orbit_.count != 0 && bin != bin_) {
            close_orbit();
        }
        bin_ = bin;
        const Quaternion<double> q_f_icrf = calib::q_f_icrf(q_chu_icrf[frame_[0]], q_chu_icrf[frame_[1]]);
        Stacked e(n_);
        Stacked s(n_);
        for (std::size_t i = 0; i < list_.count; ++i) {
            const std::size_t h = list_.head[i];
            const Quaternion<double> q_head_f = calib::q_head_f(q_chu_icrf[h], q_f_icrf);
            if (!reference_[h]) {
                reference_[h] = q_head_f;
            }
            const Vector3<double> e_rad = calib::small_angle(calib::relative_to(q_head_f, *reference_[h]));
            e.segment<3>(3 * static_cast<int>(i)) = to_eigen(e_rad) * kRadToArcsec;
            s.segment<3>(3 * static_cast<int>(i)) = to_eigen(rotated(q_chu_icrf[h], s_icrf));
        }
        orbit_.add(e, s);
        return true;
    }

    // The fit: the projected normal equations, their pseudo-inverse, the rule.
    SunFit solve(const CommonRotation& rule) {
        close_orbit();
        SunFit out;
        out.epochs = epochs_;
        out.orbits = orbits_;
        if (orbits_ == 0) {
            return out;
        }
        Eigen::MatrixXd normal;
        Eigen::VectorXd rhs;
        normal_equations(normal, rhs);
        const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(normal);
        const Eigen::VectorXd& lambda = eig.eigenvalues();
        const double floor = kSunRankTolerance * lambda.maxCoeff();
        Eigen::VectorXd theta = Eigen::VectorXd::Zero(rhs.size());
        for (Eigen::Index k = 0; k < rhs.size(); ++k) {
            if (lambda(k) > floor) {
                const Eigen::VectorXd v = eig.eigenvectors().col(k);
                theta += v * (v.dot(rhs) / lambda(k));
                ++out.rank;
            }
        }
        std::array<Eigen::Matrix3d, kMaxHeads> s_head{};
        for (std::size_t i = 0; i < list_.count; ++i) {
            for (int a = 0; a < 3; ++a) {
                for (int m = 0; m < 3; ++m) {
                    s_head[list_.head[i]](a, m) = theta(9 * static_cast<int>(i) + 3 * a + m);
                }
            }
        }
        apply_rule(rule, s_head);
        for (std::size_t i = 0; i < list_.count; ++i) {
            const std::size_t h = list_.head[i];
            for (std::size_t a = 0; a < kModelAxes; ++a) {
                for (std::size_t m = 0; m < kSunComponents; ++m) {
                    out.sun[h][a][m] = s_head[h](static_cast<int>(a), static_cast<int>(m));
                }
            }
        }
        return out;
    }

private:
    void close_orbit() {
        if (orbit_.count == 0) {
            return;
        }
        const double inv = 1.0 / static_cast<double>(orbit_.count);
        ss_ += orbit_.ss - (orbit_.s * orbit_.s.transpose()) * inv;
        es_ += orbit_.es - (orbit_.e * orbit_.s.transpose()) * inv;
        epochs_ += orbit_.count;
        ++orbits_;
        orbit_ = OrbitMoments(n_);
    }

    // The normal equations of the projected equations, from the sums: with
    // P = projection(), unknown (i, a, m) = S_head(i)[a][m] at 9i + 3a + m and
    // equation row r = (i, a) = 3i + a, Σ XᵀPX = P[r][r2]·SS[(i, m)][(j, m2)]
    // and Σ XᵀPe = Σ_r2 P[r][r2]·ES[r2][(i, m)] (X's rows are s's, a Kronecker product).
    void normal_equations(Eigen::MatrixXd& normal, Eigen::VectorXd& rhs) const {
        const Eigen::MatrixXd p = projection();
        normal = Eigen::MatrixXd::Zero(3 * n_, 3 * n_);
        rhs = Eigen::VectorXd::Zero(3 * n_);
        for (int r = 0; r < n_; ++r) {
            for (int m = 0; m < 3; ++m) {
                const int col = 3 * r + m;
                const int im = 3 * (r / 3) + m;
                for (int r2 = 0; r2 < n_; ++r2) {
                    rhs(col) += p(r, r2) * es_(r2, im);
                    normal.block<1, 3>(col, 3 * r2) = p(r, r2) * ss_.block<1, 3>(im, 3 * (r2 / 3));
                }
            }
        }
    }

    // N_h: maps F's components into head h's (the reference's rotation matrix).
    Eigen::Matrix3d n_of(std::size_t h) const {
        const Quaternion<double>& q = *reference_[h];
        return Eigen::Quaterniond(q.w, q.x, q.y, q.z).toRotationMatrix();
    }

    // I − Ñ(ÑᵀÑ)⁻¹Ñᵀ, Ñ the N_h stacked: removes F's own rotation at each epoch.
    Eigen::MatrixXd projection() const {
        Eigen::MatrixXd stacked(n_, 3);
        for (std::size_t i = 0; i < list_.count; ++i) {
            stacked.block<3, 3>(3 * static_cast<int>(i), 0) = n_of(list_.head[i]);
        }
        const Eigen::Matrix3d gram = stacked.transpose() * stacked;
        return Eigen::MatrixXd::Identity(n_, n_) - stacked * gram.inverse() * stacked.transpose();
    }

    // The rotation common to every head, S_h + N_h·C·N_hᵀ for any C, fixed by
    // the rule; the pseudo-inverse's is the smallest coefficients'.
    void apply_rule(const CommonRotation& rule, std::array<Eigen::Matrix3d, kMaxHeads>& s) const {
        Eigen::Matrix3d c = Eigen::Matrix3d::Zero();
        if (rule.rule == CommonRotationRule::kCombined) {
            // The combined attitude moves by Σ A_h·(S_h + N_h·C·N_hᵀ)·N_h·s_F: zero for every s_F.
            Eigen::Matrix3d an = Eigen::Matrix3d::Zero();
            Eigen::Matrix3d asn = Eigen::Matrix3d::Zero();
            for (std::size_t i = 0; i < list_.count; ++i) {
                const std::size_t h = list_.head[i];
                an += rule.motion[h] * n_of(h);
                asn += rule.motion[h] * s[h] * n_of(h);
            }
            c = -an.inverse() * asn;
        } else if (rule.rule == CommonRotationRule::kRigid) {
            const Eigen::Matrix3d n = n_of(rule.rigid_head);
            c = -n.transpose() * s[rule.rigid_head] * n;
        }
        for (std::size_t i = 0; i < list_.count; ++i) {
            const Eigen::Matrix3d n = n_of(list_.head[i]);
            s[list_.head[i]] += n * c * n.transpose();
        }
        if (rule.rule == CommonRotationRule::kRigid) {
            s[rule.rigid_head].setZero();  // exactly: the rounding of the sum is no term
        }
    }

    HeadList list_;
    std::array<std::uint8_t, 2> frame_;
    double period_;
    int n_;
    Moment ss_;
    Moment es_;
    OrbitMoments orbit_;
    long long bin_ = 0;
    std::size_t epochs_ = 0;
    std::size_t orbits_ = 0;
    std::array<std::optional<Quaternion<double>>, kMaxHeads> reference_{};
};

// The model with the Sun term s (none: its polynomial alone).
ModelFile with_sun(const ModelFile& m, const SunCoefficients& s = {}) {
    ModelFile out = m;
    out.sun = s;
    return out;
}

// Why a fitted term is beyond what a model may hold (sun_axis_problem), or empty.
std::string outside_the_domain(const SunCoefficients& sun, HeadMask heads) {
    const HeadList list = heads_of(heads);
    for (std::size_t i = 0; i < list.count; ++i) {
        for (std::size_t a = 0; a < kModelAxes; ++a) {
            const std::string why = sun_axis_problem(sun[list.head[i]][a]);
            if (!why.empty()) {
                return std::string("head ") + head_name(static_cast<std::uint8_t>(list.head[i])) + " " + kAxisNames[a] +
                       ": " + why;
            }
        }
    }
    return {};
}

std::string verdict_of(const SunSelection& s) {
    const double gain = 1.0 - s.sun_rms / s.none_rms;
    char buf[400];
    text::c_snprintf(buf, sizeof buf,
                     "%s: fitted inside the orbit before the held-out part (rank %d), it %s the held-out IBA RMS "
                     "(mean over the pairs) from %.4f to %.4f arcsec (%+.2f %%), %s the %.2f %% margin",
                     s.taken ? "taken" : "none", s.fit.rank, gain >= 0.0 ? "lowers" : "raises", s.none_rms, s.sun_rms,
                     -100.0 * gain, s.taken ? "more than" : "not more than", 100.0 * kSunSelectionMargin);
    return buf;
}

}  // namespace

SunFit fit_sun_term(const std::vector<FitEpoch>& epochs, double from, double to, const ModelFile& m, HeadMask heads,
                    const std::array<std::uint8_t, 2>& frame_heads, double period, const CommonRotation& rule) {
    const ThermalModel<double> core = to_core<double>(m);
    const CorrectionConfig<double> thermal_only{false, &core};
    const HeadList list = heads_of(heads);
    SunMoments moments(heads, frame_heads, period);
    for (const FitEpoch& e : epochs) {
        if (!(e.t >= from && e.t < to)) {
            continue;
        }
        std::array<Quaternion<double>, kMaxHeads> q{};
        bool all = true;
        for (std::size_t i = 0; i < list.count; ++i) {
            const std::size_t h = list.head[i];
            const CorrectedSolution<double> c = correct_solution(thermal_input(e, h), thermal_only);
            all = all && (c.status & status::kThermalApplied) != 0U;
            q[h] = c.q_chu_icrf;
        }
        if (all) {
            moments.add(e.t, q);
        }
    }
    return moments.solve(rule);
}

SunSelection select_sun_term(const SunSearchInput& in) {
    SunSelection s;
    const double inf = std::numeric_limits<double>::infinity();
    const PairList pairs = pairs_of(in.heads);
    if (in.model_before_split == nullptr) {
        s.verdict = "none: " + in.no_split;
        return s;
    }
    const ModelFile before = with_sun(*in.model_before_split);
    const SunFit trial =
        fit_sun_term(*in.epochs, -inf, in.t_split, before, in.heads, in.frame_heads, in.period, in.rule);
    const auto held_out_rms = [&](const ModelFile& m) {
        return mean_pair_rms(corrected_iba_rms(*in.epochs, in.heads, in.t_split, inf, m, kWhereTheSunIsKnown), pairs);
    };
    s.none_rms = held_out_rms(before);
    s.sun_rms = held_out_rms(with_sun(before, trial.sun));
    if (!(s.none_rms > 0.0 && s.sun_rms > 0.0)) {
        s.verdict = "none: a pair has no held-out epoch";
        return s;
    }
    s.decided = true;
    s.taken = 1.0 - s.sun_rms / s.none_rms > kSunSelectionMargin;
    s.fit = trial;
    s.verdict = verdict_of(s);
    if (s.taken) {
        s.fit = fit_sun_term(*in.epochs, -inf, inf, with_sun(*in.model), in.heads, in.frame_heads, in.period, in.rule);
        const std::string why = outside_the_domain(s.fit.sun, in.heads);
        if (!why.empty()) {
            s.taken = false;
            s.verdict += "; but the whole period's term is not taken: " + why;
        }
    }
    return s;
}

}  // namespace ascorr::host
