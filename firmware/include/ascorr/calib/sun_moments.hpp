// ascorr/calib/sun_moments.hpp: the Sun term's least squares inside the orbit
// (core/sun_term.hpp; issue 40, docs/ground.md, "The Sun term"), one
// implementation for `ascorr fit` (host fit_sun.cpp, every orbit kept) and
// the self-calibration's learner (sun_learner.hpp, with forgetting).
//
// The polynomial is fitted on orbit averages, which average the Sun's
// direction in the orbital plane away; the Sun term is fitted on what varies
// inside the orbit, after the polynomial has corrected each epoch. For each
// epoch with every head, each head's rotation e_h relative to the frame F of
// the corrected attitudes (head axes, arcsec; head_rotation.hpp, relative to
// the head's first epoch, N_h) and s_h, the Sun's direction in the corrected
// head's frame:
//     e_h(t) = S_h·s_h(t) + N_h·g(t) + b_h(orbit) + noise,
// S_h the head's 3 × 3 coefficients, g(t) F's own rotation at the epoch (a
// nuisance, eliminated by projecting each epoch's equations orthogonally to
// the N_h: common_rotation.hpp's P), b_h a constant per orbit and head
// (eliminated by taking each orbit's mean out of e and s: the orbit means are
// the polynomial's). The normal equations are formed from the sums over the
// orbits of s·sᵀ and e·sᵀ about each orbit's mean (Kronecker structure of the
// projection), so the epochs are read once and not kept. The solution is the
// pseudo-inverse's over the eigen-directions above kSunRankTolerance of the
// largest (symmetric_eigen.hpp): three of each head's nine do not vary inside
// the orbit (the orbit normal's component of s, constant over an orbit on a
// nadir-pointing spacecraft), and of the rotation common to every head, which
// no IBA sees, six more are in the plane that does (3H + 6 unseen of 9H, rank
// 6H − 6: 12 of 27 for three heads). The pseudo-inverse's solution has the
// smallest coefficients (it is orthogonal to every common rotation
// S_h + N_h·C·N_hᵀ); another rule fixes C from weights (SunRule, as
// common_rotation.hpp's rule: Σ_h A_h·(S_h + N_h·C·N_hᵀ)·N_h = 0, the bench's
// motion under the weights unmoved for every Sun direction), or a head rigid
// to the bench (its coefficients exactly 0). The term's orbit mean along the
// orbit normal is thereby left to the temperatures' polynomial.
// Double (per orbit: the learner's solve runs once an orbit, in bounded
// steps: solve_step); no allocation; every loop bounded by H.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>

#include "../core/constants.hpp"
#include "../core/heads.hpp"
#include "../core/quaternion.hpp"
#include "../core/sun_term.hpp"
#include "../core/vector3.hpp"
#include "common_rotation.hpp"
#include "frame.hpp"
#include "head_rotation.hpp"
#include "model_identity.hpp"
#include "symmetric_eigen.hpp"

namespace ascorr::calib {

// Eigen-directions of the normal equations below this fraction of the
// largest eigenvalue are left out (the pseudo-inverse's rank).
inline constexpr double kSunRankTolerance = 1e-3;
// The term is taken when it lowers the held-out (fit) or predicted
// (sun_learner.hpp) IBA RMS by more than this fraction: the lag's margin,
// 0.15 % of the RMS, 0.3 % of the mean square. On the static benches its gain
// was below 0.01 %.
inline constexpr double kSunSelectionMargin = 0.0015;

// How the rotation common to every head is fixed (above).
struct SunRule {
    const Matrix3* weight = nullptr;  // by head index: A_h, head axes to a frame common to all; nullptr: smallest
    int rigid_head = -1;              // ≥ 0: that head's term exactly 0 (weight ignored)
};

struct SunTermFit {
    double sun[kMaxHeads][kModelAxes][kSunComponents] = {};  // arcsec, by head index
    std::uint8_t heads = 0U;                                 // bit h: head h fitted
    int rank = 0;                                            // eigen-directions kept
    std::uint32_t orbits = 0U;                               // orbits closed
    std::uint64_t epochs = 0U;                               // epochs in them
    bool solved = false;  // false: no orbit, or equations that are not finite or did not converge
};

// A fit's coefficients as one CRC-32C (their bits, arcsec, head, axis and
// component ascending, each as model_identity.hpp's crc32c_of): what the
// flight loop's report and the link's SUN_LEARNER_REPORT give of a
// candidate whose 27 doubles they cannot carry.
inline std::uint32_t sun_fit_crc(const SunTermFit& f) noexcept {
    std::uint32_t crc = 0U;
    for (const auto& head : f.sun) {
        for (const auto& axis : head) {
            for (const double c : axis) {
                crc = crc32c_of(c, crc);
            }
        }
    }
    return crc;
}

// f's coefficients (arcsec) into out[h][a][m] for the heads it fitted that
// are in keep (bit h: head h), when it was solved; out is left as it was
// elsewhere. Out: any array indexable as SunTermFit::sun (a model's `sun`).
template <typename Out>
void copy_sun_coefficients(const SunTermFit& f, HeadMask keep, Out& out) noexcept {
    for (std::size_t h = 0; f.solved && h < kMaxHeads; ++h) {
        for (std::size_t a = 0;
             in_mask(static_cast<HeadMask>(f.heads & keep), static_cast<std::uint8_t>(h)) && a < kModelAxes; ++a) {
            for (std::size_t m = 0; m < kSunComponents; ++m) {
                out[h][a][m] = f.sun[h][a][m];
            }
        }
    }
}

// Whether every axis of every fitted head is within the core's domain
// (sun_term.hpp: Σ_m |S[a][m]| ≤ kMaxThermalAngleRad) and finite.
inline bool sun_fit_within_domain(const SunTermFit& f) noexcept {
    for (std::size_t h = 0; h < kMaxHeads; ++h) {
        for (std::size_t a = 0; ((f.heads >> h) & 1U) != 0U && a < kModelAxes; ++a) {
            double sum = 0.0;
            for (double c : f.sun[h][a]) {
                sum += std::fabs(c);
            }
            if (!(sum * kArcsecToRad <= kMaxThermalAngleRad)) {
                return false;
            }
        }
    }
    return true;
}

// The fit as the core evaluates it (rad).
inline SunTermModel<double> sun_term_model(const SunTermFit& f) noexcept {
    SunTermModel<double> m{};
    for (std::size_t h = 0; h < kMaxHeads; ++h) {
        m.present[h] = ((f.heads >> h) & 1U) != 0U;
        for (std::size_t a = 0; a < kModelAxes; ++a) {
            for (std::size_t c = 0; c < kSunComponents; ++c) {
                m.coefficient[h][a][c] = f.sun[h][a][c] * kArcsecToRad;
            }
        }
    }
    keep_present_where_terms(m);
    return m;
}

// A solve in steps (SunMoments::solve_step): what a step did, and where the
// next begins.
enum class SunSolveStep : unsigned char { kRunning, kSolved, kFailed };
enum class SunSolvePhase : unsigned char { kForm, kBasis, kEigen, kResult };

// H: the most heads (3 on board: A, B, C; kMaxHeads on the ground).
template <std::size_t H>
class SunMoments {
public:
    static constexpr std::size_t kRows = 3U * H;          // e or s of every head, stacked
    static constexpr std::size_t kUnknowns = 3U * kRows;  // S_h[a][m] at 9i + 3a + m

    // heads[0 … count − 1]: the head indices, in order (count ≤ H, 2 or more);
    // F of frame_a and frame_c's boresights (frame.hpp).
    SunMoments(const std::uint8_t* heads, std::size_t count, std::uint8_t frame_a, std::uint8_t frame_c) noexcept
        : count_(count <= H ? count : H), frame_a_(frame_a), frame_c_(frame_c) {
        for (std::size_t i = 0; i < count_; ++i) {
            head_[i] = heads[i];
        }
    }

    // One epoch: q_chu_icrf[h] (by head index) the heads' attitudes corrected
    // by the polynomial, s_icrf the Sun's unit direction. false, nothing
    // summed, when a rotation or direction formed from them is not finite (a
    // corrupted attitude: one NaN would otherwise spoil every later solve).
    bool add(const Quaternion<double>* q_chu_icrf, const Vector3<double>& s_icrf) noexcept {
        const Quaternion<double> q_f = q_f_icrf(q_chu_icrf[frame_a_], q_chu_icrf[frame_c_]);
        double e[kRows];
        double s[kRows];
        Quaternion<double> first[H]{};
        for (std::size_t i = 0; i < count_; ++i) {
            const Quaternion<double>& q = q_chu_icrf[head_[i]];
            const Quaternion<double> q_hf = q_head_f(q, q_f);
            const Quaternion<double>& ref = referenced_ ? reference_[i] : q_hf;  // the first epoch's, kept below
            if (!referenced_) {
                first[i] = q_hf;
            }
            const Vector3<double> e_rad = small_angle(relative_to(q_hf, ref));
            const Vector3<double> s_chu = rotated(q, s_icrf);
            const double ei[3] = {e_rad.x * kRadToArcsec, e_rad.y * kRadToArcsec, e_rad.z * kRadToArcsec};
            const double si[3] = {s_chu.x, s_chu.y, s_chu.z};
            for (std::size_t c = 0; c < 3; ++c) {
                e[3 * i + c] = ei[c];
                s[3 * i + c] = si[c];
            }
        }
        const std::size_t n = 3 * count_;
        bool finite = true;
        for (std::size_t r = 0; r < n; ++r) {
            finite = finite && std::isfinite(e[r]) && std::isfinite(s[r]);
        }
        if (!finite) {
            return false;
        }
        for (std::size_t i = 0; !referenced_ && i < count_; ++i) {
            reference_[i] = first[i];
        }
        referenced_ = true;
        for (std::size_t r = 0; r < n; ++r) {
            orbit_e_[r] += e[r];
            orbit_s_[r] += s[r];
            for (std::size_t c = 0; c < n; ++c) {
                orbit_ss_[r][c] += s[r] * s[c];
                orbit_es_[r][c] += e[r] * s[c];
            }
        }
        ++orbit_count_;
        return true;
    }

    // Closes the open orbit: the sums so far multiplied by `keep` (1: no
    // forgetting), then its products about its own mean added.
    void close_orbit(double keep) noexcept {
        if (orbit_count_ == 0U) {
            return;
        }
        const std::size_t n = 3 * count_;
        const double inv = 1.0 / static_cast<double>(orbit_count_);
        for (std::size_t r = 0; r < n; ++r) {
            for (std::size_t c = 0; c < n; ++c) {
                ss_[r][c] = keep * ss_[r][c] + (orbit_ss_[r][c] - orbit_s_[r] * orbit_s_[c] * inv);
                es_[r][c] = keep * es_[r][c] + (orbit_es_[r][c] - orbit_e_[r] * orbit_s_[c] * inv);
                orbit_ss_[r][c] = 0.0;
                orbit_es_[r][c] = 0.0;
            }
        }
        for (std::size_t r = 0; r < n; ++r) {  // after the loop above, which reads every one of them
            orbit_e_[r] = 0.0;
            orbit_s_[r] = 0.0;
        }
        epochs_ += orbit_count_;
        ++orbits_;
        orbit_count_ = 0U;
    }

    std::uint32_t open_count() const noexcept { return orbit_count_; }

    // The solve's workspace and progress (solve_step): on board the
    // learner's (sun_learner.hpp), so that no step needs the 12 KiB of the
    // normal equations and their eigenvectors on its stack.
    struct Solve {
        double normal[kUnknowns][kUnknowns];  // the normal equations, then their eigenvalues (diagonal)
        double vectors[kUnknowns][kUnknowns];
        double rhs[kUnknowns];
        JacobiProgress jacobi;
        SunSolvePhase phase = SunSolvePhase::kForm;
        SunTermFit fit;  // the result (fit.solved), once solve_step has returned kSolved
        // The warm start (solve_step): vectors hold a converged decomposition
        // of order jacobi.n, reached in `warm` warm starts from the identity.
        bool basis = false;
        int warm = 0;
        std::size_t basis_line = 0U;  // jacobi_to_basis's progress
    };
    // Of kWarmSolves solves in a row, the first starts from the identity:
    // what each warm start adds to V's rounding (a few ulps) stays bounded.
    static constexpr int kWarmSolves = 64;
    // Lines of the basis change per step: about a sweep's first row's cost
    // (8 × 27² multiply-adds; the target bench's worst step includes them).
    static constexpr std::size_t kBasisLinesPerStep = 8U;
    // The most solve_step() calls of one solve: forming, the basis change,
    // the eigen-decomposition a row per step, the result.
    static constexpr int kMaxSolveSteps =
        2 + static_cast<int>((2U * kUnknowns + kBasisLinesPerStep - 1U) / kBasisLinesPerStep) +
        jacobi_max_steps(kUnknowns);

    // The fit over the orbits closed (above); false (out.solved) when there is none,
    // or the equations are not finite, or the rule's weights are singular.
    // solve_step() to the end, at once (the ground fit).
    bool solve(const SunRule& rule, SunTermFit& out) const noexcept {
        Solve w;
        SunSolveStep s = SunSolveStep::kRunning;
        for (int i = 0; i < kMaxSolveSteps && s == SunSolveStep::kRunning; ++i) {
            s = solve_step(w, rule);
        }
        out = w.fit;
        return s == SunSolveStep::kSolved;
    }

    // One bounded step of a solve (w.phase kForm: a new one). The first
    // forms the normal equations from the sums as they are then (later
    // orbits closed do not change this solve); each of the eigen-
    // decomposition's does one row of a Jacobi sweep (at most n − 1
    // rotations, n = 3·3H); the last forms the fit (w.fit) under the rule. At most
    // kMaxSolveSteps; then kSolved or kFailed, and w.phase is kForm again.
    // Warm start: where w holds the last solve's converged eigenvectors (a
    // learner's own Solve, solve after solve: sun_learner.hpp), the
    // decomposition begins in their basis (symmetric_eigen.hpp,
    // jacobi_to_basis, kBasisLinesPerStep lines a step): the sums move
    // little from one orbit to the next, so it needs fewer sweeps (the same
    // decomposition to kJacobiTolerance: the fit too, to the bound
    // symmetric_eigen.hpp gives, unless an eigenvalue lies that close to
    // kSunRankTolerance's cut, where the rank may differ). A
    // fresh Solve (the ground fit's solve()) starts from the identity, as
    // does every kWarmSolves-th.
    SunSolveStep solve_step(Solve& w, const SunRule& rule) const noexcept {
        SunSolveStep s = SunSolveStep::kRunning;
        switch (w.phase) {
            case SunSolvePhase::kForm:
                s = form(w);
                break;
            case SunSolvePhase::kBasis:
                s = basis_lines(w);
                break;
            case SunSolvePhase::kEigen:
                s = eigen_row(w);
                break;
            case SunSolvePhase::kResult:
                s = result(w, rule);
                break;
        }
        if (s != SunSolveStep::kRunning) {
            w.phase = SunSolvePhase::kForm;
        }
        return s;
    }

private:
    // N_h: maps F's components into head h's (the reference's rotation matrix).
    void references(Matrix3 (&n)[H]) const noexcept {
        for (std::size_t i = 0; i < count_; ++i) {
            n[i] = rotation_matrix(reference_[i]);
        }
    }

    // The normal equations of the projected equations, from the sums: with
    // P the projector, unknown (i, a, m) at 9i + 3a + m and equation row
    // r = (i, a) = 3i + a, Σ XᵀPX = P[r][r2]·SS[(i, m)][(j, m2)] and
    // Σ XᵀPe = Σ_r2 P[r][r2]·ES[r2][(i, m)] (X's rows are s's: a Kronecker
    // product); then the eigen-decomposition begins.
    SunSolveStep form(Solve& w) const noexcept {
        w.fit = SunTermFit{};
        w.fit.orbits = orbits_;
        w.fit.epochs = epochs_;
        if (orbits_ == 0U || count_ < 2U) {
            return SunSolveStep::kFailed;
        }
        const std::size_t n = 3 * count_;
        Matrix3 nh[H];
        references(nh);
        double p[kRows * kRows];
        common_rotation_projector(nh, count_, p);
        for (double& r : w.rhs) {
            r = 0.0;
        }
        for (std::size_t r = 0; r < n; ++r) {
            for (std::size_t m = 0; m < 3; ++m) {
                const std::size_t col = 3 * r + m;
                const std::size_t im = 3 * (r / 3) + m;
                for (std::size_t r2 = 0; r2 < n; ++r2) {
                    const double prr = p[r * n + r2];
                    w.rhs[col] += prr * es_[r2][im];
                    for (std::size_t m2 = 0; m2 < 3; ++m2) {
                        w.normal[col][3 * r2 + m2] = prr * ss_[im][3 * (r2 / 3) + m2];
                    }
                }
            }
        }
        const bool warm = w.basis && w.jacobi.n == 3 * n && w.warm + 1 < kWarmSolves;
        w.basis = false;  // until this decomposition converges (eigen_row)
        if (warm) {
            ++w.warm;
            w.basis_line = 0U;
            w.phase = SunSolvePhase::kBasis;
            return SunSolveStep::kRunning;
        }
        w.warm = 0;
        if (!jacobi_start(w.normal, w.vectors, 3 * n, w.jacobi)) {
            return SunSolveStep::kFailed;
        }
        w.phase = SunSolvePhase::kEigen;
        return SunSolveStep::kRunning;
    }

    // The warm start's basis change, kBasisLinesPerStep lines; then the sweeps.
    static SunSolveStep basis_lines(Solve& w) noexcept {
        if (!jacobi_to_basis(w.normal, w.vectors, w.jacobi.n, w.basis_line, kBasisLinesPerStep)) {
            return SunSolveStep::kRunning;
        }
        if (!jacobi_resume(w.normal, w.vectors, w.jacobi.n, w.jacobi)) {
            return SunSolveStep::kFailed;
        }
        w.phase = SunSolvePhase::kEigen;
        return SunSolveStep::kRunning;
    }

    SunSolveStep eigen_row(Solve& w) const noexcept {
        switch (jacobi_row(w.normal, w.vectors, w.jacobi)) {
            case JacobiStep::kRunning:
                return SunSolveStep::kRunning;
            case JacobiStep::kConverged:
                w.basis = true;  // of order w.jacobi.n, which only the next start changes
                w.phase = SunSolvePhase::kResult;
                return SunSolveStep::kRunning;
            case JacobiStep::kNotConverged:
                break;
        }
        return SunSolveStep::kFailed;
    }

    // θ = Σ_k v_k·(v_k·rhs)/λ_k over λ_k > tolerance·λ_max (theta zero on
    // entry); the rank, or −1 when no eigenvalue is positive.
    static int pseudo_inverse(const Solve& w, double (&theta)[kUnknowns]) noexcept {
        const std::size_t u = w.jacobi.n;
        double largest = 0.0;
        for (std::size_t k = 0; k < u; ++k) {
            largest = w.normal[k][k] > largest ? w.normal[k][k] : largest;
        }
        if (!(largest > 0.0)) {
            return -1;
        }
        int rank = 0;
        for (std::size_t k = 0; k < u; ++k) {
            const double lambda = w.normal[k][k];
            if (lambda > kSunRankTolerance * largest) {
                double dot = 0.0;
                for (std::size_t j = 0; j < u; ++j) {
                    dot += w.vectors[j][k] * w.rhs[j];
                }
                for (std::size_t j = 0; j < u; ++j) {
                    theta[j] += w.vectors[j][k] * (dot / lambda);
                }
                ++rank;
            }
        }
        return rank;
    }

    // The fit from the decomposition, under the rule.
    SunSolveStep result(Solve& w, const SunRule& rule) const noexcept {
        double theta[kUnknowns] = {};
        const int rank = pseudo_inverse(w, theta);
        if (rank < 0) {
            return SunSolveStep::kFailed;
        }
        w.fit.rank = rank;
        double s[H][3][3];
        for (std::size_t i = 0; i < count_; ++i) {
            for (std::size_t a = 0; a < 3; ++a) {
                for (std::size_t m = 0; m < 3; ++m) {
                    s[i][a][m] = theta[9 * i + 3 * a + m];
                }
            }
        }
        if (!apply_rule(rule, s)) {
            return SunSolveStep::kFailed;
        }
        for (std::size_t i = 0; i < count_; ++i) {
            w.fit.heads = static_cast<std::uint8_t>(w.fit.heads | (1U << head_[i]));
            for (std::size_t a = 0; a < 3; ++a) {
                for (std::size_t m = 0; m < 3; ++m) {
                    w.fit.sun[head_[i]][a][m] = s[i][a][m];
                }
            }
        }
        w.fit.solved = true;
        return SunSolveStep::kSolved;
    }

    // The common rotation S_h + N_h·C·N_hᵀ fixed by the rule (above).
    bool apply_rule(const SunRule& rule, double (&s)[H][3][3]) const noexcept {
        if (rule.weight == nullptr && rule.rigid_head < 0) {
            return true;  // the pseudo-inverse's: the smallest coefficients
        }
        Matrix3 nh[H];
        references(nh);
        Matrix3 c{};
        std::size_t rigid = H;
        if (!common_part(rule, nh, s, c, rigid)) {
            return false;
        }
        for (std::size_t i = 0; i < count_; ++i) {
            const Matrix3 ncn = product(product(nh[i], c), transposed(nh[i]));
            for (std::size_t r = 0; r < 3; ++r) {
                for (std::size_t k = 0; k < 3; ++k) {
                    s[i][r][k] = i == rigid ? 0.0 : s[i][r][k] + ncn.m[r][k];  // rigid: exactly 0
                }
            }
        }
        return true;
    }

    // C of the rule: a rigid head X's C = −N_Xᵀ·S_X·N_X (its term then 0;
    // `rigid` its position); with weights C = −(Σ_h A_h·N_h)⁻¹·Σ_h A_h·S_h·N_h,
    // the sum inverted at unit Frobenius norm (its diagonal may be 0: F's
    // axes need not be near a head's). false: no such head, or the weights'
    // sum singular or not finite.
    bool common_part(const SunRule& rule, const Matrix3 (&nh)[H], const double (&s)[H][3][3], Matrix3& c,
                     std::size_t& rigid) const noexcept {
        if (rule.rigid_head >= 0) {
            for (std::size_t i = 0; i < count_; ++i) {
                rigid = static_cast<int>(head_[i]) == rule.rigid_head ? i : rigid;
            }
            if (rigid == H) {
                return false;
            }
            c = scaled(product(product(transposed(nh[rigid]), matrix_of(s[rigid])), nh[rigid]), -1.0);
            return true;
        }
        Matrix3 an{};
        Matrix3 asn{};
        for (std::size_t i = 0; i < count_; ++i) {
            const Matrix3& a = rule.weight[head_[i]];
            an = sum(an, product(a, nh[i]));
            asn = sum(asn, product(product(a, matrix_of(s[i])), nh[i]));
        }
        double norm = 0.0;
        for (const auto& row : an.m) {
            for (const double v : row) {
                norm += v * v;
            }
        }
        norm = std::sqrt(norm);
        Matrix3 inv{};
        if (!(norm > 0.0 && std::isfinite(norm)) || !inverse_scaled(scaled(an, 1.0 / norm), false, &inv)) {
            return false;
        }
        c = scaled(product(inv, asn), -1.0 / norm);
        return true;
    }

    static Matrix3 sum(const Matrix3& a, const Matrix3& b) noexcept {
        Matrix3 r{};
        for (std::size_t i = 0; i < 3; ++i) {
            for (std::size_t j = 0; j < 3; ++j) {
                r.m[i][j] = a.m[i][j] + b.m[i][j];
            }
        }
        return r;
    }

    static Matrix3 scaled(const Matrix3& a, double f) noexcept {
        Matrix3 r{};
        for (std::size_t i = 0; i < 3; ++i) {
            for (std::size_t j = 0; j < 3; ++j) {
                r.m[i][j] = a.m[i][j] * f;
            }
        }
        return r;
    }

    static Matrix3 matrix_of(const double (&s)[3][3]) noexcept {
        return {{{s[0][0], s[0][1], s[0][2]}, {s[1][0], s[1][1], s[1][2]}, {s[2][0], s[2][1], s[2][2]}}};
    }

    static Matrix3 transposed(const Matrix3& m) noexcept {
        Matrix3 t{};
        for (std::size_t r = 0; r < 3; ++r) {
            for (std::size_t k = 0; k < 3; ++k) {
                t.m[r][k] = m.m[k][r];
            }
        }
        return t;
    }

    std::size_t count_;
    std::uint8_t head_[H] = {};
    std::uint8_t frame_a_;
    std::uint8_t frame_c_;
    bool referenced_ = false;
    Quaternion<double> reference_[H]{};
    std::uint32_t orbit_count_ = 0U;
    double orbit_e_[kRows] = {};
    double orbit_s_[kRows] = {};
    double orbit_ss_[kRows][kRows] = {};
    double orbit_es_[kRows][kRows] = {};
    double ss_[kRows][kRows] = {};
    double es_[kRows][kRows] = {};
    std::uint32_t orbits_ = 0U;
    std::uint64_t epochs_ = 0U;
};

}  // namespace ascorr::calib
