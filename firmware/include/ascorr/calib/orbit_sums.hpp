// ascorr/calib/orbit_sums.hpp: the per-cycle accumulation of one orbit, in the
// core's scalar T (double on the ground, float on the M4F, Q30 on the M3).
//
// What is summed (the same epochs on all sides: a cycle counts only when
// heads A, B and C all pass the selection; a further head is summed over the
// counted cycles in which it passes too, estimator_types.hpp):
//   d_h = q_h_icrf ⊗ q_a_icrf⁻¹        (h ≠ A: the head relative to head A)
//   δ_h = canonical(d_h ⊗ r_h⁻¹)       (relative to a reference r_h near d_h)
//   Σ δ_h (4 components), Σ (T_hj − T_ref,hj) (3·N temperatures)
// With three heads: four quaternion products per cycle (sixteen multiplications each; in Q30
// one SMULL/SMLAL each, fixed_point.hpp), fifteen subtractions, seventeen
// additions (each further head: two products, four subtractions and seven
// additions more): no division, no square root, no branch but the sign of δ.
//
// Why relative to head A, and F once per orbit: F (frame.hpp, eqs. 1–3) needs
// two normalisations and a matrix-to-quaternion conversion per epoch. But F
// relative to A is a function of d_C alone (frame.hpp q_f_a), and each head's
// rotation in F is d_h ⊗ q_f_a⁻¹. Forming q_f_a from the orbit's mean d_C,
// and each head's rotation in F from the means, instead of averaging the
// per-epoch values, differs by terms second order in the within-orbit
// variations of d_h (a few arcseconds: (1e-5 rad)² = 1e-10 rad = 2e-5″, and
// the epoch noise's (≈1e-5 rad)² likewise), mostly constant, which the model's
// c0 absorbs. The reference r_h (the previous orbit's mean, fixed for an
// orbit) keeps δ_h within arcseconds of the identity, so the sums carry
// full precision in every scalar; likewise the temperatures relative to
// T_ref (the previous orbit's means).
//
// Sums (Sum<X>): double sums in double. float sums in float blocks of
// kFloatBlock cycles (|δ| ≤ 1e-4 rad, |ΔT| ≤ 400 °C: a block's rounding is
// ≤ 2⁻²⁴ of 64·|x|), each block added to a double: one double addition per
// sum every kFloatBlock cycles. Q30 and QCelsius sum their raw integers in
// int64: exact (|raw| < 2³¹, 2³² cycles fit), and no floating point on the M3
// in the cycle. The double value is read once per orbit (estimator step()).
// No allocation; fixed-size state.
#pragma once

#include <cstdint>

#include "../core/fixed_point.hpp"
#include "../core/quaternion.hpp"
#include "../core/thermal.hpp"
#include "estimator_types.hpp"
#include "head_rotation.hpp"

namespace ascorr::calib {

inline constexpr std::uint32_t kFloatBlock = 64;

template <typename X>
struct Sum;

template <>
struct Sum<double> {
    double s = 0.0;
    void add(double x) noexcept { s += x; }
    void add_difference(double x, double ref) noexcept { s += x - ref; }
    void flush() noexcept {}
    double value() const noexcept { return s; }
};

template <>
struct Sum<float> {
    float block = 0.0F;
    double s = 0.0;
    void add(float x) noexcept { block += x; }
    void add_difference(float x, float ref) noexcept { block += x - ref; }
    void flush() noexcept {
        s += static_cast<double>(block);
        block = 0.0F;
    }
    double value() const noexcept { return s + static_cast<double>(block); }
};

template <>
struct Sum<Q30> {
    std::int64_t raw = 0;
    void add(Q30 x) noexcept { raw += x.raw; }
    void flush() noexcept {}
    double value() const noexcept { return static_cast<double>(raw) * 0x1p-30; }
};

template <>
struct Sum<QCelsius> {
    std::int64_t raw = 0;
    void add_difference(QCelsius x, QCelsius ref) noexcept { raw += std::int64_t{x.raw} - ref.raw; }
    void flush() noexcept {}
    double value() const noexcept { return static_cast<double>(raw) * 0x1p-20; }
};

// The references of one orbit's sums of N heads (set once per orbit, between cycles).
template <typename T, std::size_t N = kCalibHeads>
struct OrbitReference {
    Quaternion<T> r[N - 1];  // r_B, r_C, …: near q_h ⊗ q_A⁻¹
    Celsius<T> t_ref[N][3];  // per head: T_CHU, T029, T032
};

// One orbit's sums in T of N heads (see the top). The frame heads' are
// summed over the orbit's counted cycles (count); a further head's over
// those of them in which it was selected (head_count[h], h ≥ kFrameHeads).
template <typename T, std::size_t N = kCalibHeads>
struct OrbitSums {
    std::uint32_t count = 0;
    std::uint32_t block = 0;
    Sum<T> dq[N - 1][4];            // Σ δ_B, Σ δ_C, …: w, x, y, z
    Sum<Celsius<T>> dt[N][3];       // Σ (T − T_ref), per head and sensor
    std::uint32_t head_count[N]{};  // further heads' cycles (the frame heads': count)

    // One counted cycle: q[h] = q_h_icrf (aberration-corrected, unit) of the
    // frame heads and of the further heads in `heads` (bit h); temps[h] their
    // three valid temperatures.
    void add(const Quaternion<T> (&q)[N], const HeadTemperatures<T> (&temps)[N], const OrbitReference<T, N>& ref,
             std::uint8_t heads = kFrameMask) noexcept {
        const Quaternion<T> q_icrf_a = conjugate(q[0]);
        for (std::size_t k = 0; k + 1 < kFrameHeads; ++k) {
            add_rotation(k, q[k + 1] * q_icrf_a, ref);
        }
        for (std::size_t h = 0; h < kFrameHeads; ++h) {
            add_temperatures(h, temps[h], ref);
        }
        if constexpr (N > kFrameHeads) {
            for (std::size_t h = kFrameHeads; h < N && heads != kFrameMask; ++h) {
                if (((static_cast<unsigned>(heads) >> h) & 1U) != 0U) {
                    add_head(h, q_icrf_a, q[h], temps[h], ref);
                }
            }
        }
        ++count;
        if (++block == kFloatBlock) {
            block = 0;
            flush();
        }
    }

    // Further head h (≥ kFrameHeads) of a cycle already counted: q_icrf_a is
    // that cycle's head A, inverted.
    void add_head(std::size_t h, const Quaternion<T>& q_icrf_a, const Quaternion<T>& q_h,
                  const HeadTemperatures<T>& temps_h, const OrbitReference<T, N>& ref) noexcept {
        add_rotation(h - 1U, q_h * q_icrf_a, ref);
        add_temperatures(h, temps_h, ref);
        ++head_count[h];
    }

    // The cycles head h was summed over.
    std::uint32_t count_of(std::size_t h) const noexcept { return h < kFrameHeads ? count : head_count[h]; }

    void flush() noexcept {
        for (auto& k : dq) {
            for (auto& s : k) {
                s.flush();
            }
        }
        for (auto& h : dt) {
            for (auto& s : h) {
                s.flush();
            }
        }
    }

    void add_rotation(std::size_t k, const Quaternion<T>& d_h, const OrbitReference<T, N>& ref) noexcept {
        const Quaternion<T> d = relative_to(d_h, ref.r[k]);
        dq[k][0].add(d.w);
        dq[k][1].add(d.x);
        dq[k][2].add(d.y);
        dq[k][3].add(d.z);
    }
    void add_temperatures(std::size_t h, const HeadTemperatures<T>& tp, const OrbitReference<T, N>& ref) noexcept {
        dt[h][0].add_difference(tp.t_chu.value, ref.t_ref[h][0]);
        dt[h][1].add_difference(tp.t_029.value, ref.t_ref[h][1]);
        dt[h][2].add_difference(tp.t_032.value, ref.t_ref[h][2]);
    }
};

}  // namespace ascorr::calib
