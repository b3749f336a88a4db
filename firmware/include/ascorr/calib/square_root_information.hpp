// ascorr/calib/square_root_information.hpp: a fixed-size square-root
// information filter (SRIF) for a linear least-squares problem with several
// right-hand sides, exponential forgetting, and its condition number.
//
// Conventions (Bierman 1977, ch. V; Carpenter & D'Souza, NASA/TP-2018-219822,
// §5): the information of N unknowns x (one column of M right-hand sides each)
// is held as an upper-triangular R (N × N) and Z (N × M) with
//   Σ_k λ^(K−k)·‖a_kᵀ·x − y_k‖² = ‖R·x − Z‖² + const,
// so that RᵀR is the information matrix and the estimate solves R·x = Z.
//  - forget(λ): R, Z ← √λ·(R, Z)  (exponential forgetting, 0 < λ ≤ 1);
//  - add(a, y, w): the row √w·[aᵀ | yᵀ] is rotated into [R | Z] by N Givens
//    rotations (one per column, a bounded loop of N·(N + M) products). The
//    information is never formed: a condition number κ of RᵀR costs only
//    √κ in R, the reason for the square-root form (half the digits otherwise).
//  - solve(): back substitution, one per right-hand side; refuses (false) when
//    a pivot is zero or not finite.
//  - condition(): κ₂ of the column-equilibrated information matrix
//    D⁻¹RᵀRD⁻¹ (D² its diagonal), the measure that does not depend on the
//    regressors' units (the ground fit reports the same for its design). Its
//    eigenvalues by cyclic Jacobi with a fixed number of sweeps (kSweeps; for
//    N ≤ 8 six sweeps reach double rounding from any start, quadratic
//    convergence), so the work is bounded.
//
// Numerics: double throughout (the filter runs once per orbit, outside the
// correction). The regressors are centred by the caller (estimator.hpp) so
// that the intercept and the slopes are nearly orthogonal; with κ ≤ 1e6 (the
// estimator refuses beyond its configured limit, far below) the solution
// keeps ≥ 10 significant digits: R's condition is √κ ≤ 1e3 and back
// substitution is backward stable (relative error ≲ N·√κ·2⁻⁵³).
// No allocation, no exception, fixed trip counts.
#pragma once

#include <cmath>
#include <cstddef>
#include <limits>

#include "portable_math.hpp"

namespace ascorr::calib {

template <std::size_t N, std::size_t M>
class SquareRootInformation {
public:
    static constexpr std::size_t kSweeps = 6;

    void clear() noexcept { *this = SquareRootInformation{}; }

    void forget(double lambda) noexcept {
        const double s = std::sqrt(lambda);
        for (std::size_t i = 0; i < N; ++i) {
            for (std::size_t j = i; j < N + M; ++j) {
                rz_[i][j] *= s;
            }
        }
    }

    // One observation row a (N regressors) of the M right-hand sides y, with
    // weight w ≥ 0.
    void add(const double (&a)[N], const double (&y)[M], double w) noexcept {
        const double sw = std::sqrt(w);
        double row[N + M];
        for (std::size_t j = 0; j < N; ++j) {
            row[j] = sw * a[j];
        }
        for (std::size_t j = 0; j < M; ++j) {
            row[N + j] = sw * y[j];
        }
        for (std::size_t i = 0; i < N; ++i) {
            const double p = rz_[i][i];
            const double q = row[i];
            if (q == 0.0) {
                continue;
            }
            const double r = hypot2(p, q);  // portable_math.hpp: the same bits on the DPU
            const double c = p / r;
            const double s = q / r;
            for (std::size_t j = i; j < N + M; ++j) {
                const double u = rz_[i][j];
                const double v = row[j];
                rz_[i][j] = c * u + s * v;
                row[j] = c * v - s * u;
            }
        }
    }

    // x (N × M) with R·x = Z; false when R is singular or not finite.
    bool solve(double (&x)[N][M]) const noexcept {
        for (std::size_t m = 0; m < M; ++m) {
            for (std::size_t ii = N; ii-- > 0;) {
                double s = rz_[ii][N + m];
                for (std::size_t j = ii + 1; j < N; ++j) {
                    s -= rz_[ii][j] * x[j][m];
                }
                const double d = rz_[ii][ii];
                if (!(std::fabs(d) > 0.0) || !std::isfinite(d)) {
                    return false;
                }
                x[ii][m] = s / d;
            }
        }
        return true;
    }

    // κ₂ of the equilibrated information matrix (see the top); infinity when
    // a column has no information.
    double condition() const noexcept {
        double a[N][N];
        double d[N];
        for (std::size_t j = 0; j < N; ++j) {
            double s = 0.0;
            for (std::size_t i = 0; i <= j; ++i) {
                s += rz_[i][j] * rz_[i][j];
            }
            if (!(s > 0.0) || !std::isfinite(s)) {
                return std::numeric_limits<double>::infinity();
            }
            d[j] = 1.0 / std::sqrt(s);
        }
        for (std::size_t i = 0; i < N; ++i) {
            for (std::size_t j = 0; j < N; ++j) {
                double s = 0.0;
                for (std::size_t k = 0; k <= (i < j ? i : j); ++k) {
                    s += rz_[k][i] * rz_[k][j];
                }
                a[i][j] = s * d[i] * d[j];
            }
        }
        jacobi_eigenvalues(a);
        double lo = a[0][0];
        double hi = a[0][0];
        for (std::size_t i = 1; i < N; ++i) {
            lo = a[i][i] < lo ? a[i][i] : lo;
            hi = a[i][i] > hi ? a[i][i] : hi;
        }
        return lo > 0.0 ? hi / lo : std::numeric_limits<double>::infinity();
    }

    // Forgets all information on unknown 0 and keeps the others' marginal
    // information: with unknown 0 first, rows 1 … N−1 of [R | Z] hold exactly
    // the information of unknowns 1 … N−1 with unknown 0 free, so row 0 is
    // cleared. (A step in the intercept: the slopes stay.)
    void release_first() noexcept {
        for (std::size_t j = 0; j < N + M; ++j) {
            rz_[0][j] = 0.0;
        }
    }

    // The information matrix's diagonal entry j (RᵀR)_jj.
    double information(std::size_t j) const noexcept {
        double s = 0.0;
        for (std::size_t i = 0; i <= j && i < N; ++i) {
            s += rz_[i][j] * rz_[i][j];
        }
        return s;
    }

private:
    // Cyclic Jacobi on a symmetric matrix: on return its diagonal holds the
    // eigenvalues (Golub & Van Loan, alg. 8.5.3), kSweeps sweeps.
    static void jacobi_eigenvalues(double (&a)[N][N]) noexcept {
        for (std::size_t sweep = 0; sweep < kSweeps; ++sweep) {
            for (std::size_t p = 0; p + 1 < N; ++p) {
                for (std::size_t q = p + 1; q < N; ++q) {
                    if (a[p][q] == 0.0) {
                        continue;
                    }
                    const double theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
                    const double t = (theta >= 0.0 ? 1.0 : -1.0) / (std::fabs(theta) + std::sqrt(theta * theta + 1.0));
                    const double c = 1.0 / std::sqrt(t * t + 1.0);
                    const double s = t * c;
                    for (std::size_t k = 0; k < N; ++k) {
                        const double akp = a[k][p];
                        const double akq = a[k][q];
                        a[k][p] = c * akp - s * akq;
                        a[k][q] = s * akp + c * akq;
                    }
                    for (std::size_t k = 0; k < N; ++k) {
                        const double apk = a[p][k];
                        const double aqk = a[q][k];
                        a[p][k] = c * apk - s * aqk;
                        a[q][k] = s * apk + c * aqk;
                    }
                }
            }
        }
    }

    double rz_[N][N + M]{};  // [R | Z], R upper triangular (below the diagonal: 0)
};

}  // namespace ascorr::calib
