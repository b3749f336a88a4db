// ascorr/core/correct.hpp: the per-solution entry point.
//
// correct_solution() takes one raw µASC attitude solution and returns the
// corrected one with its status bits (status.hpp):
//   1. validate: head in range, quaternion finite and unit within
//      ScalarTraits<T>::unit_norm_tolerance; otherwise kRejected and the input
//      quaternion is returned unchanged;
//   2. aberration (if enabled): q ← q ⊗ q_ab*  (aberration.hpp);
//   3. thermal (if a model is given): q ← q_th ⊗ q  (thermal.hpp); with a
//      SunTermInput, the heads' Sun terms folded into q_th (sun_term.hpp's
//      flight form, thermal_stage() below);
//   4. renormalise (one Newton step) and return with w ≥ 0.
// A stage whose inputs are missing or outside the core's domain is skipped
// and flagged, never evaluated. No allocation, no exceptions, no loops, no
// I/O: the function is straight-line code with a bounded instruction count.
#pragma once

#include <cstdint>
#include <type_traits>

#include "aberration.hpp"
#include "quaternion.hpp"
#include "scalar_traits.hpp"
#include "status.hpp"
#include "sun_term.hpp"
#include "thermal.hpp"

namespace ascorr {

template <typename T>
struct SolutionInput {
    Quaternion<T> q_chu_icrf;  // raw attitude, maps ICRF into CHU components
    std::uint8_t head;         // head index (heads.hpp): 0 = A, 1 = B, …
    HeadTemperatures<T> temperatures;
    ObserverVelocity<T> velocity;
};

template <typename T>
struct CorrectionConfig {
    bool aberration;                 // apply stellar aberration when a velocity is given
    const ThermalModel<T>* thermal;  // nullptr: no thermal stage
};

template <typename T>
struct CorrectedSolution {
    Quaternion<T> q_chu_icrf;
    StatusBits status;
};

// Why an input is rejected; kRejected in the status, this for the message.
enum class Rejection : std::uint8_t { kNone, kHeadOutOfRange, kQuaternionNotFinite, kQuaternionNotUnit };

template <typename T>
constexpr Rejection check_solution(const SolutionInput<T>& in) noexcept {
    if (in.head >= kMaxHeads) {
        return Rejection::kHeadOutOfRange;
    }
    if (!is_finite(in.q_chu_icrf)) {
        return Rejection::kQuaternionNotFinite;
    }
    if (!norm_within(in.q_chu_icrf, ScalarTraits<T>::unit_norm_tolerance)) {
        return Rejection::kQuaternionNotUnit;
    }
    return Rejection::kNone;
}

// The verdict of check_solution() == kNone without telling the reasons apart:
// norm_within() is false for a non-finite quaternion too. Used on every
// solution; check_solution() says why, for messages.
template <typename T>
constexpr bool solution_acceptable(const SolutionInput<T>& in) noexcept {
    return in.head < kMaxHeads && norm_within(in.q_chu_icrf, ScalarTraits<T>::unit_norm_tolerance);
}

// The thermal stage's rotation for one solution, or the bits that say why it
// is skipped. Split out so that the host can report the angles it applied.
template <typename T>
struct ThermalStage {
    SmallRotation<T> q_th;
    StatusBits skip;  // 0: apply q_th
};

// Whether a thermal angle is within the core's domain, ±kMaxThermalAngleRad
// (false for a NaN). Float compares bit patterns (abs_within_bits: on the M4F
// 3 instructions a check instead of 4; 4 fewer per solution in the core, 4
// fewer in the Sun term's second check).
template <typename T>
constexpr bool angle_in_domain(const T& x) noexcept {
    constexpr T lim = constant<T>(kMaxThermalAngleRad);
    if constexpr (std::is_same_v<T, float>) {
        return abs_within_bits(x, lim);
    } else {
        return abs_within(x, lim);
    }
}

// Whether three thermal angles are within the core's domain.
template <typename T>
constexpr bool angles_in_domain(const T& alpha, const T& beta, const T& gamma) noexcept {
    return angle_in_domain(alpha) && angle_in_domain(beta) && angle_in_domain(gamma);
}

// The polynomial's angles for one solution (rad), or the bits that say why
// the stage is skipped.
template <typename T>
struct ThermalAngles {
    T alpha;
    T beta;
    T gamma;
    StatusBits skip;  // 0: the angles are within the core's domain
};

template <typename T>
[[gnu::always_inline]] constexpr ThermalAngles<T> thermal_angles(const ThermalModel<T>& model, std::uint8_t head,
                                                                 const HeadTemperatures<T>& temps) noexcept {
    constexpr T zero = constant<T>(0.0);
    ThermalAngles<T> out{zero, zero, zero, 0U};
    if (head >= kMaxHeads || !model.head[head].present) {
        out.skip = status::kNoModelForHead;
        return out;
    }
    if (!(temps.t_chu.valid && temps.t_029.valid && temps.t_032.valid)) {
        out.skip = status::kNoTemperature;
        return out;
    }
    if (!(temperature_in_domain<T>(temps.t_chu.value) && temperature_in_domain<T>(temps.t_029.value) &&
          temperature_in_domain<T>(temps.t_032.value))) {
        out.skip = status::kNoTemperature | status::kTemperatureInvalid;
        return out;
    }
    const HeadThermalModel<T>& m = model.head[head];
    const Celsius<T>& t1 = temps.t_chu.value;
    const Celsius<T>& t2 = temps.t_029.value;
    const Celsius<T>& t3 = temps.t_032.value;
    out.alpha = thermal_angle<T>(m.alpha, t1, t2, t3);
    out.beta = thermal_angle<T>(m.beta, t1, t2, t3);
    out.gamma = thermal_angle<T>(m.gamma, t1, t2, t3);
    if (!angles_in_domain(out.alpha, out.beta, out.gamma)) {
        out.skip = status::kThermalOutOfRange;
    }
    return out;
}

template <typename T>
[[gnu::always_inline]] constexpr ThermalStage<T> stage_of(const ThermalAngles<T>& a) noexcept {
    constexpr T zero = constant<T>(0.0);
    if (a.skip != 0U) {
        return {{zero, {zero, zero, zero}}, a.skip};
    }
    return {thermal_rotation(a.alpha, a.beta, a.gamma), 0U};
}

template <typename T>
constexpr ThermalStage<T> thermal_stage(const ThermalModel<T>& model, std::uint8_t head,
                                        const HeadTemperatures<T>& temps) noexcept {
    return stage_of(thermal_angles(model, head, temps));
}

// The Sun term of a solution's head, as the flight loop evaluates it: its
// model and the Sun's direction, formed at the velocity service's rate.
// Preconditions: model not null, its coefficients within the term's domain
// (|S| row sums ≤ kMaxThermalAngleRad per head and axis: the loader and the
// link check it; the Q30 kernel's range needs it), present[h] only where h
// has a term (keep_present_where_terms); s_icrf unit where known.
template <typename T>
struct SunTermInput {
    const SunTermModel<T>* model;  // the heads' Sun terms (sun_term.hpp); present[h]: h has one
    Vector3<T> s_icrf;             // the Sun's unit direction, ICRF components
    bool known;                    // false: s_icrf not formed (a time outside nav/sun_direction.hpp's span)
};

// The thermal stage with the Sun term folded into it, the flight form: for a
// head with a term, its angles (sun_term.hpp) are added to the polynomial's
// before the one rotation, ŝ_chu formed from the raw attitude q_chu_icrf.
// docs/contract.md ("The Sun term") defines the term as a rotation of its own
// after the polynomial's, ŝ_chu from the attitude after aberration and the
// polynomial; this form differs from that by at most
//   ‖S‖_F·(|θ_ab| + |θ_th|)  (ŝ_chu from the raw attitude: the angle vector
//                             S·Δŝ, |Δŝ| ≤ the attitude's turn)
//   + |θ_th|·|θ_sun|         (the two rotations' commutator and the split of
//                             one rotation into three elementary ones), rad:
// 4e-3″ for 2″ per coefficient (‖S‖_F = 6″), a 25″ aberration and a 60″
// polynomial (SunTerm.TheFlightFormIsTheContractsWithinItsBound).
// Skipped: as thermal_stage(); for a head with a term, kThermalOutOfRange
// alone where ŝ is not known, and where the summed angles leave the core's
// domain (±1°: a model whose polynomial and term together reach it, which
// the contract's form would still apply as two rotations; the link's loader
// is to refuse such a model before the target evaluates it).
template <typename T>
[[gnu::always_inline]] constexpr ThermalStage<T> folded_thermal_stage(const ThermalModel<T>& model, std::uint8_t head,
                                                                      const HeadTemperatures<T>& temps,
                                                                      const SunTermInput<T>& sun,
                                                                      const Quaternion<T>& q_chu_icrf) noexcept {
    ThermalAngles<T> a = thermal_angles(model, head, temps);
    if (a.skip != 0U || !sun.model->present[head]) {
        return stage_of(a);
    }
    if (!sun.known) {
        a.skip = status::kThermalOutOfRange;
        return stage_of(a);
    }
    const Vector3<T> sum =
        plus_sun_term_angles(Vector3<T>{a.alpha, a.beta, a.gamma}, *sun.model, head, q_chu_icrf, sun.s_icrf);
    a.alpha = sum.x;
    a.beta = sum.y;
    a.gamma = sum.z;
    if (!angles_in_domain(a.alpha, a.beta, a.gamma)) {
        a.skip = status::kThermalOutOfRange;
    }
    return stage_of(a);
}

// The same, as a function of its own: GCC then spills less of the Q30 kernel
// on Armv7-M (M3: 136 instructions for the term instead of 189 inlined),
// while float is cheapest inlined into the core (M4F: 63 instead of 102);
// correct_solution() picks by scalar (toolchain/run-target-bench).
template <typename T>
constexpr ThermalStage<T> thermal_stage(const ThermalModel<T>& model, std::uint8_t head,
                                        const HeadTemperatures<T>& temps, const SunTermInput<T>& sun,
                                        const Quaternion<T>& q_chu_icrf) noexcept {
    return folded_thermal_stage(model, head, temps, sun, q_chu_icrf);
}

namespace detail {

// The corrected attitude is q_th ⊗ q ⊗ q_ab*. Both corrections are near the
// identity, so it is computed as q + d with the increment
//   d = q ⊗ (q_ab* − 1) + (q_th − 1) ⊗ (q + q ⊗ (q_ab* − 1)),
// formed from small terms only, and q is rounded once, in renormalized_sum().
// stage(model) is the thermal stage of in's head.
template <typename T, typename Stage>
[[gnu::always_inline]] constexpr CorrectedSolution<T> correct_solution(const SolutionInput<T>& in,
                                                                       const CorrectionConfig<T>& cfg,
                                                                       const Stage& stage) noexcept {
    if (!solution_acceptable(in)) {
        return {in.q_chu_icrf, status::kRejected};
    }
    StatusBits st = 0U;
    const Quaternion<T>& q = in.q_chu_icrf;
    constexpr T zero = constant<T>(0.0);
    Quaternion<T> d{zero, zero, zero, zero};

    if (cfg.aberration) {
        const ObserverVelocity<T>& v = in.velocity;
        if (!v.valid) {
            st |= status::kNoVelocity;
        } else if (!velocity_in_domain(v)) {
            st |= status::kNoVelocity | status::kVelocityInvalid;
        } else {
            // The boresight of q before renormalisation: for ‖q‖² = 1 + ε it is
            // off by ≤ |ε| rad in direction and length, which changes a 25"
            // correction by ≤ 25"·|ε| (2.5e-5" at the double tolerance).
            const SmallRotation<T> q_ab = aberration_rotation(boresight(q), v.beta_icrf, v.inv_sun_distance_au);
            d = right_increment(q, conjugate(q_ab));
            st |= status::kAberrationApplied;
        }
    }

    if (cfg.thermal != nullptr) {
        const ThermalStage<T> th = stage(*cfg.thermal);
        if (th.skip != 0U) {
            st |= th.skip;
        } else {
            d = add_left_increment(d, th.q_th, q);
            st |= status::kThermalApplied;
        }
    }

    return {canonical(renormalized_sum(q, d)), st};
}

}  // namespace detail

template <typename T>
constexpr CorrectedSolution<T> correct_solution(const SolutionInput<T>& in, const CorrectionConfig<T>& cfg) noexcept {
    return detail::correct_solution(
        in, cfg, [&in](const ThermalModel<T>& m) { return thermal_stage(m, in.head, in.temperatures); });
}

// As above, with the heads' Sun terms folded into the thermal stage (its
// flight form, thermal_stage() above): the target's loop. sun.model not null.
template <typename T>
constexpr CorrectedSolution<T> correct_solution(const SolutionInput<T>& in, const CorrectionConfig<T>& cfg,
                                                const SunTermInput<T>& sun) noexcept {
    return detail::correct_solution(in, cfg, [&in, &sun](const ThermalModel<T>& m) {
        if constexpr (std::is_same_v<T, Q30>) {
            return thermal_stage(m, in.head, in.temperatures, sun, in.q_chu_icrf);
        } else {
            return folded_thermal_stage(m, in.head, in.temperatures, sun, in.q_chu_icrf);
        }
    });
}

}  // namespace ascorr
