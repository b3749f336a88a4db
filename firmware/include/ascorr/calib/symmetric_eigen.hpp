// ascorr/calib/symmetric_eigen.hpp: the eigen-decomposition of a small
// symmetric matrix by the cyclic Jacobi method (Golub & Van Loan, Matrix
// Computations, 4th ed., §8.5: Algorithm 8.5.1, the 2 × 2 symmetric Schur
// decomposition, swept row by row as in Algorithm 8.5.3), for the Sun term's
// pseudo-inverse (sun_moments.hpp), on board and on the ground.
//
// Why Jacobi: the matrices are at most 36 × 36 and formed once per orbit; the
// method needs only +, −, ×, ÷ and √ (the same bits on the DPU and the host,
// portable_math.hpp's reason), keeps small eigenvalues to a relative accuracy
// the rank decision needs, and its loops have fixed bounds.
// Convergence: quadratic once the off-diagonal part is small. The sweeps
// stop when the off-diagonal Frobenius norm is ≤ kJacobiTolerance of the
// matrix's, or after kMaxJacobiSweeps: 7 to 8 sweeps for the learner's
// 27 × 27 from the identity, 3 to 4 from the last orbit's basis
// (jacobi_to_basis).
// Double only; no allocation, no recursion.
#pragma once

#include <cmath>
#include <cstddef>

namespace ascorr::calib {

inline constexpr int kMaxJacobiSweeps = 30;
// The off-diagonal part left, relative: a = V·diag·Vᵀ to kJacobiTolerance
// of ‖a‖_F, the eigenvalues to that (Hoffman–Wielandt; to its square for
// separated ones). The Sun term keeps eigenvalues above 1e-3 of the largest
// (kSunRankTolerance), so its fit moves by at most about
// kJacobiTolerance·‖a‖_F/λ_kept ≤ √27·1e3·1e-12 ≈ 5e-9 relative (measured:
// 1.5e-12 over 70 synthetic orbits, 1.1e-10 on random 27 × 27 matrices whose
// 12 kept eigenvalues spread down to 1.2e-3): 5e-9″ of a 1″ term; the rank's
// cut is then decided to that too. Closer to double's rounding the sweeps
// chase the rounding of the null space's entries: 1e-15 took 2.2× the warm
// solves' rotations and 1.35× the cold ones' (70 synthetic orbits).
inline constexpr double kJacobiTolerance = 1e-12;

// One Jacobi rotation J(p, q, θ) zeroing a[p][q]: a ← Jᵀ·a·J, v ← v·J
// (Algorithm 8.5.1: τ = (a_qq − a_pp)/(2·a_pq), t the smaller root of
// t² + 2τt − 1 = 0, c = 1/√(1 + t²), s = t·c). a must be symmetric to the
// bit (jacobi_start makes it so), and stays so: outside the 2 × 2 block,
// rows p and q of Jᵀ·(a·J) are columns p and q of a·J, whose products they
// would repeat with the same operands in the same order, so they are copied
// (a third fewer operations; the same bits as forming them).
template <std::size_t N>
void jacobi_rotation(double (&a)[N][N], double (&v)[N][N], std::size_t n, std::size_t p, std::size_t q) noexcept {
    const double apq = a[p][q];
    if (apq == 0.0) {
        return;
    }
    const double tau = (a[q][q] - a[p][p]) / (2.0 * apq);
    // For |τ| beyond 1e150 τ² overflows; t = 1/(2τ) there to relative 1e-300.
    const double t =
        std::fabs(tau) > 1e150 ? 0.5 / tau : (tau >= 0.0 ? 1.0 : -1.0) / (std::fabs(tau) + std::sqrt(1.0 + tau * tau));
    const double c = 1.0 / std::sqrt(1.0 + t * t);
    const double s = t * c;
    for (std::size_t k = 0; k < n; ++k) {  // a·J: columns p and q
        const double akp = a[k][p];
        const double akq = a[k][q];
        a[k][p] = c * akp - s * akq;
        a[k][q] = s * akp + c * akq;
    }
    // Jᵀ·(a·J): rows p and q; in the block, from a·J's block (its off-diagonal
    // pair is zero by construction, its rounding not kept) ...
    const double app = a[p][p];
    const double aqp = a[q][p];
    const double apq1 = a[p][q];
    const double aqq = a[q][q];
    a[p][p] = c * app - s * aqp;
    a[q][q] = s * apq1 + c * aqq;
    a[p][q] = 0.0;
    a[q][p] = 0.0;
    for (std::size_t k = 0; k < n; ++k) {  // ... and elsewhere by symmetry
        if (k != p && k != q) {
            a[p][k] = a[k][p];
            a[q][k] = a[k][q];
        }
    }
    for (std::size_t k = 0; k < n; ++k) {
        const double vkp = v[k][p];
        const double vkq = v[k][q];
        v[k][p] = c * vkp - s * vkq;
        v[k][q] = s * vkp + c * vkq;
    }
}

// The decomposition in bounded steps (on board, in idle time: one row p of a
// sweep per step, its n − 1 − p rotations): JacobiProgress holds where it is,
// jacobi_start() begins it, jacobi_row() does the next row (at a sweep's
// first row the convergence test first). The same operations in the same
// order as symmetric_eigen() below, which is made of them: the same bits.
struct JacobiProgress {
    std::size_t n = 0;    // the matrix's order
    double bound = 0.0;   // the off-diagonal sum of squares that ends the sweeps
    int sweep = 0;        // sweeps done
    std::size_t row = 0;  // the next row p of the current sweep
    double skip = 0.0;    // a_pq² at or below this is not rotated: bound / n²
};

enum class JacobiStep : unsigned char {
    kRunning,       // a row done; more to do
    kConverged,     // the off-diagonal part within the tolerance: done (progress.sweep sweeps)
    kNotConverged,  // kMaxJacobiSweeps sweeps done first (the result is that of the last)
};

// The most jacobi_row() calls of one decomposition of order n: a row per
// call, n − 1 per sweep, and the call that ends it (converged, or the
// sweeps' bound reached). n ≤ 1 converges at its first call; its bound is
// kept above that only to keep the formula one line.
constexpr int jacobi_max_steps(std::size_t n) noexcept {
    return kMaxJacobiSweeps * static_cast<int>(n > 1U ? n - 1U : 1U) + 1;
}

// Begins the decomposition of a (n × n of N × N, symmetric: its lower
// triangle is set from its upper one, a no-op when it is symmetric to the
// bit, which jacobi_rotation needs): v = I, or with `keep_vectors` v as it
// is (jacobi_resume). false when a is not finite or n > N (a and v then left
// as they are, resp. v the identity).
template <std::size_t N>
bool jacobi_start(double (&a)[N][N], double (&v)[N][N], std::size_t n, JacobiProgress& progress,
                  bool keep_vectors = false) noexcept {
    if (n > N) {
        return false;
    }
    double total = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
        for (std::size_t j = 0; j < n; ++j) {
            const double x = j < i ? a[j][i] : a[i][j];  // the upper triangle's
            v[i][j] = keep_vectors ? v[i][j] : (i == j ? 1.0 : 0.0);
            total += x * x;
        }
    }
    if (!std::isfinite(total)) {
        return false;
    }
    for (std::size_t i = 0; i < n; ++i) {
        for (std::size_t j = 0; j < i; ++j) {
            a[i][j] = a[j][i];
        }
    }
    const double bound = kJacobiTolerance * kJacobiTolerance * total;
    progress = {n, bound, 0, 0U, n > 0U ? bound / static_cast<double>(n * n) : 0.0};
    return true;
}

// ---- From a known basis (the Sun learner's warm start, sun_moments.hpp)
//
// A matrix near one already decomposed, a ≈ V·Λ·Vᵀ, is nearly diagonal in
// V's basis: with a ← Vᵀ·a·V first and v = V, the sweeps begin from a small
// off-diagonal part, where cyclic Jacobi converges quadratically (Golub & Van
// Loan §8.5), and v ends as the eigenvectors of the original a (V·J·J…),
// its diagonal as their eigenvalues. V: the columns of an earlier
// decomposition's v, orthonormal to double's rounding (each rotation keeps
// them so to a few ulps; the caller bounds how many decompositions follow
// one from the identity).

// Row i of a·V into a (it needs only that row of a); t: a line's temporary.
template <std::size_t N>
void basis_row(double (&a)[N][N], const double (&v)[N][N], std::size_t n, std::size_t i, double (&t)[N]) noexcept {
    for (std::size_t j = 0; j < n; ++j) {
        double x = 0.0;
        for (std::size_t l = 0; l < n; ++l) {
            x += a[i][l] * v[l][j];
        }
        t[j] = x;
    }
    for (std::size_t j = 0; j < n; ++j) {
        a[i][j] = t[j];
    }
}

// Column j of Vᵀ·(a·V) into a, its upper triangle (it needs only that
// column of a·V); t: a line's temporary.
template <std::size_t N>
void basis_column(double (&a)[N][N], const double (&v)[N][N], std::size_t n, std::size_t j, double (&t)[N]) noexcept {
    for (std::size_t i = 0; i <= j; ++i) {
        double x = 0.0;
        for (std::size_t l = 0; l < n; ++l) {
            x += v[l][i] * a[l][j];
        }
        t[i] = x;
    }
    for (std::size_t i = 0; i <= j; ++i) {
        a[i][j] = t[i];
    }
}

// The basis change in bounded steps: `lines` more of its 2n lines per call
// (line < n: row `line` of a·V; then column line − n of Vᵀ·(a·V), its upper
// triangle), each n or fewer sums of n products, in place with one line's
// temporary. true once all 2n are done (a's lower triangle is then left to
// jacobi_resume, which mirrors the upper); `line` holds where it is. n > N:
// true at once, nothing done (jacobi_resume then refuses it); lines 0 is 1.
template <std::size_t N>
bool jacobi_to_basis(double (&a)[N][N], const double (&v)[N][N], std::size_t n, std::size_t& line,
                     std::size_t lines) noexcept {
    if (n > N) {
        return true;
    }
    const std::size_t count = lines > 0U ? lines : 1U;
    double t[N];  // one for both phases: a step's frame holds one line
    for (std::size_t k = 0; k < count && line < 2U * n; ++k, ++line) {
        if (line < n) {
            basis_row(a, v, n, line, t);
        } else {
            basis_column(a, v, n, line - n, t);
        }
    }
    return line >= 2U * n;
}

// The sweeps after jacobi_to_basis: as jacobi_start, with v = V kept.
template <std::size_t N>
bool jacobi_resume(double (&a)[N][N], double (&v)[N][N], std::size_t n, JacobiProgress& progress) noexcept {
    return jacobi_start(a, v, n, progress, true);
}

// The next row of the current sweep (progress from jacobi_start): its
// rotations J(row, q) for q > row, but for those whose a_pq² is at or below
// progress.skip (a threshold as Rutishauser's, Numer. Math. 9:1, 1966): the
// n(n − 1) off-diagonal entries all that small sum to less than the bound,
// so a skipped one never keeps the sweeps from ending, and the rotations
// late sweeps spend on what is already negligible are not done (a warm
// start's sweeps are mostly such).
template <std::size_t N>
JacobiStep jacobi_row(double (&a)[N][N], double (&v)[N][N], JacobiProgress& progress) noexcept {
    const std::size_t n = progress.n;
    if (progress.row == 0U) {
        if (progress.sweep >= kMaxJacobiSweeps) {
            return JacobiStep::kNotConverged;
        }
        double off = 0.0;
        for (std::size_t i = 0; i < n; ++i) {
            for (std::size_t j = 0; j < n; ++j) {
                off += i == j ? 0.0 : a[i][j] * a[i][j];
            }
        }
        if (off <= progress.bound) {
            return JacobiStep::kConverged;
        }
    }
    const std::size_t p = progress.row;
    for (std::size_t q = p + 1U; q < n; ++q) {
        if (a[p][q] * a[p][q] > progress.skip) {
            jacobi_rotation(a, v, n, p, q);
        }
    }
    if (p + 2U < n) {
        ++progress.row;
    } else {  // the sweep's last row (p = n − 2; n ≥ 2 here: n ≤ 1 has converged above)
        progress.row = 0U;
        ++progress.sweep;
    }
    return JacobiStep::kRunning;
}

// a (n × n of N × N, symmetric) is overwritten: its diagonal holds the
// eigenvalues; v's columns the eigenvectors (orthonormal), a = V·diag·Vᵀ.
// Returns the sweeps done, or −1 when a is not finite or n > N (a and v are
// then left as they are, resp. v the identity), or kMaxJacobiSweeps + 1 when
// the bound was reached first (the result is then that of the last sweep).
template <std::size_t N>
int symmetric_eigen(double (&a)[N][N], double (&v)[N][N], std::size_t n) noexcept {
    JacobiProgress progress;
    if (!jacobi_start(a, v, n, progress)) {
        return -1;
    }
    JacobiStep s = JacobiStep::kRunning;
    for (int i = 0; i < jacobi_max_steps(n) && s == JacobiStep::kRunning; ++i) {
        s = jacobi_row(a, v, progress);
    }
    return s == JacobiStep::kConverged ? progress.sweep : kMaxJacobiSweeps + 1;
}

}  // namespace ascorr::calib
