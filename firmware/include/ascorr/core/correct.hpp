// ascorr/core/correct.hpp: the per-solution entry point.
//
// correct_solution() takes one raw µASC attitude solution and returns the
// corrected one with its status bits (status.hpp):
//   1. validate: head in range, quaternion finite and unit within
//      ScalarTraits<T>::unit_norm_tolerance; otherwise kRejected and the input
//      quaternion is returned unchanged;
//   2. aberration (if enabled): q ← q ⊗ q_ab*  (aberration.hpp);
//   3. thermal (if a model is given): q ← q_th ⊗ q  (thermal.hpp);
//   4. renormalise (one Newton step) and return with w ≥ 0.
// A stage whose inputs are missing or outside the core's domain is skipped
// and flagged, never evaluated. No allocation, no exceptions, no loops, no
// I/O: the function is straight-line code with a bounded instruction count.
#pragma once

#include <cstdint>

#include "aberration.hpp"
#include "quaternion.hpp"
#include "scalar_traits.hpp"
#include "status.hpp"
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

template <typename T>
constexpr ThermalStage<T> thermal_stage(const ThermalModel<T>& model, std::uint8_t head,
                                        const HeadTemperatures<T>& temps) noexcept {
    constexpr T zero = constant<T>(0.0);
    ThermalStage<T> out{{zero, {zero, zero, zero}}, 0U};
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
    const T alpha = thermal_angle<T>(m.alpha, t1, t2, t3);
    const T beta = thermal_angle<T>(m.beta, t1, t2, t3);
    const T gamma = thermal_angle<T>(m.gamma, t1, t2, t3);
    constexpr T lim = constant<T>(kMaxThermalAngleRad);
    if (!(abs_within(alpha, lim) && abs_within(beta, lim) && abs_within(gamma, lim))) {  // false for NaN
        out.skip = status::kThermalOutOfRange;
        return out;
    }
    out.q_th = thermal_rotation(alpha, beta, gamma);
    return out;
}

// The corrected attitude is q_th ⊗ q ⊗ q_ab*. Both corrections are near the
// identity, so it is computed as q + d with the increment
//   d = q ⊗ (q_ab* − 1) + (q_th − 1) ⊗ (q + q ⊗ (q_ab* − 1)),
// formed from small terms only, and q is rounded once, in renormalized_sum().
template <typename T>
constexpr CorrectedSolution<T> correct_solution(const SolutionInput<T>& in, const CorrectionConfig<T>& cfg) noexcept {
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
        const ThermalStage<T> th = thermal_stage(*cfg.thermal, in.head, in.temperatures);
        if (th.skip != 0U) {
            st |= th.skip;
        } else {
            d = add_left_increment(d, th.q_th, q);
            st |= status::kThermalApplied;
        }
    }

    return {canonical(renormalized_sum(q, d)), st};
}

}  // namespace ascorr
