// ascorr/calib/estimator.hpp: the on-board estimator of the thermal model
// (self-calibration), its commands, its report and its safe adoption.
//
// Use (one object, one thread; the 22 Hz loop and its idle time alternate):
//   cycle:  const ThermalModel<T>* m = est.model_for_cycle(t_us);  // before the
//           corrections of the cycle: applies a pending swap, so a model
//           changes between solutions, never within one; nullptr: no model
//           (status 256, no thermal stage)
//           ... correct the cycle's solutions with m ...
//           est.accumulate(cycle);   // only when A, B and C passed the selection
//   idle:   while (time left && est.step()) {}   // bounded work per call
//   ground: freeze(), resume(), reset(), load_model(m), report().
//
// The selection is the ground fit's (`ascorr fit`): a head's solution counts
// when flags 1, 2 and 4 are clear, confidence ≤ 5, its three temperatures are
// valid, and the aberration stage was applied; its aberration-corrected
// quaternion is what is given. A cycle counts when A, B and C all do.
//
// The estimate (per head h of A, B, C, and per axis α, β, γ):
//   e_h(orbit) = b_h0 + b_h1·(T1 − T̄1) + b_h2·(D2 − D̄2) + b_h3·(D3 − D̄3),
//   D2 = T029 − T_CHU, D3 = T032 − T_CHU,
// where e_h is the orbit mean of head h's small rotation in the frame F of A
// and C (frame.hpp eqs. 1–3, head_rotation.hpp) relative to its orientation
// N_h in the first orbit used, in arcsec, and T̄ are that orbit's mean
// temperatures (the centre: the intercept and slopes are then nearly
// orthogonal, condition ≈ 10–40 instead of hundreds). Each head is one
// 4-unknown least-squares problem with three right-hand sides (the axes),
// kept as a square-root information filter (square_root_information.hpp)
// with exponential forgetting exp(−Δt/τ) per orbit (Δt the time since the
// previous update: a gap forgets too). Per head relative to F, not jointly
// with F's rotation as a nuisance (the ground fit): predicting every head's
// rotation relative to F is all an IBA needs (self-calibration.md), the
// three small problems are independent and well conditioned, and the 9
// unobservable directions never enter (F is defined by A and C). Linear terms
// only: quadratic ones are supported by the data only over long, wide
// temperature ranges, which forgetting does not keep.
//
// Per cycle: orbit_sums.hpp (four quaternion products in T, seventeen sums; no
// division, no square root, no floating point for Q30). Once per orbit, in
// double, in step(): the orbit's means, F from the mean of C relative to A,
// the heads' angles, an innovation test, the filter update, the candidate,
// the gate, the swap. Each step() call does one phase (Phase), each phase a
// fixed amount of work (the largest: kWindow orbits × 3 IBA residuals × 2
// models, or feeding up to kWindow held-back orbits).
//
// Safe adoption (a candidate becomes the active model only when all hold;
// otherwise the active one stays and the reason is counted, Refusal):
//   - kFewOrbits: fewer than min_orbits orbits in the filter;
//   - kCondition: a head's equilibrated information matrix has a condition
//     number above max_condition, or the solve failed;
//   - kAngleLimit: a coefficient beyond the Q30 formats' range, or a model
//     angle beyond the core's 1° (kMaxThermalAngleRad) at the recent orbits'
//     temperatures ± angle_check_margin_c;
//   - kNoGain: over the last window_orbits orbits, the RMS of the model's IBA
//     residuals (orbit means; iba_residuals(): what the residual rotations do
//     to the three IBAs, so a common rotation or a roll about a boresight
//     counts for nothing) is not below (1 − adoption_margin) × the active
//     model's. Not about their mean: within a window the orbit means'
//     temperatures hardly move, so a wrong slope shows as an offset there.
// Outlier orbits: once the filter has a model, an orbit whose innovation
// (the IBA residuals of its angles against the filter's prediction) exceeds
// outlier_gate × the running RMS is held back (a biased head, a thermistor
// fault). When persistence_orbits orbits in a row are held back, the change
// is taken as real (a settling bench, a mount that shifted): the intercepts'
// information is released (the slopes' kept), the held orbits still in the
// window are fed to the filter, and the running RMS restarts. Without the
// release, the least squares would explain the step by the slopes over the
// temperatures of the weeks after it.
//
// Model versions: the model given at start is version 0; each adopted or
// loaded model is the active version + 1 (the first is 1 without one). Its identity is the
// CRC-32C of its coefficients (model_identity.hpp). Models are kept in
// arcsec as ModelCoefficients and converted once into the core's
// ThermalModel<T> (model_coefficients.hpp) when prepared, in the back buffer.
//
// No allocation, no exception, no recursion, fixed-size state, every loop
// with a fixed bound. T: double, float or Q30 (the core's scalar).
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>

#include "../core/constants.hpp"
#include "../core/model_coefficients.hpp"
#include "../core/quaternion.hpp"
#include "../core/thermal.hpp"
#include "frame.hpp"
#include "head_rotation.hpp"
#include "model_identity.hpp"
#include "orbit_sums.hpp"
#include "square_root_information.hpp"

namespace ascorr::calib {

inline constexpr std::size_t kCalibHeads = 3;  // A, B, C: F needs A and C, the IBAs all three
inline constexpr std::size_t kUnknowns = 4;    // [1, T1, T2 − T1, T3 − T1] per axis
inline constexpr std::size_t kWindow = 32;     // recent orbits kept (gate and held-back orbits)

struct EstimatorConfig {
    std::int64_t orbit_period_us = 5'640'000'000;  // orbits are bins floor(t / period)
    double time_constant_days = 30.0;              // τ of the forgetting (chosen: docs/ground.md, Self-calibration)
    std::uint32_t min_orbits = 30;                 // orbits in the filter before a first model
    std::uint32_t min_epochs_per_orbit = 4;        // fewer: the orbit is not used
    double min_coverage = 0.5;                     // ... nor below this fraction of a typical orbit's count
    double max_condition = 1e4;                    // per head, equilibrated information matrix
    double adoption_margin = 0.03;                 // a candidate must beat the active model by 3 %
    std::uint32_t window_orbits = 30;              // orbits of the residual comparison (≤ kWindow)
    double angle_check_margin_c = 30.0;            // °C around the recent temperatures
    double outlier_gate = 3.0;                     // innovation RMS over the running RMS
    std::uint32_t persistence_orbits = 24;         // held back in a row: a real change (≤ kWindow)
};

enum class Refusal : std::uint8_t {
    kNone = 0,
    kFewOrbits = 1,
    kCondition = 2,
    kAngleLimit = 3,
    kNoGain = 4,
};
inline constexpr std::size_t kRefusalKinds = 5;

inline const char* refusal_name(Refusal r) noexcept {
    switch (r) {
        case Refusal::kNone:
            return "none";
        case Refusal::kFewOrbits:
            return "too few orbits";
        case Refusal::kCondition:
            return "condition number";
        case Refusal::kAngleLimit:
            return "angle beyond the core's limits";
        case Refusal::kNoGain:
            return "no gain over the active model";
    }
    return "?";
}

struct EstimatorReport {
    std::uint32_t orbits_used;              // orbits in the filter since start or reset
    std::uint32_t orbits_short;             // closed with too few epochs
    std::uint32_t orbits_held;              // held back as outliers (some fed later)
    std::uint32_t orbits_late;              // closed while the previous was still being processed
    std::uint32_t changes;                  // persistent changes taken as real (intercepts released)
    double condition;                       // the worst head's, of the last candidate
    double residual_rms_arcsec;             // the active model over the window (NaN: none)
    double candidate_rms_arcsec;            // the last candidate over the window (NaN: none)
    bool has_active;                        // false: no model (status 256)
    std::uint32_t active_version;           // 0: the model given at start
    std::uint32_t active_crc;               // model_crc() of the active model (0: none)
    Refusal last_refusal;                   // of the last candidate
    std::uint32_t refusals[kRefusalKinds];  // counts per reason (index 0 unused)
    bool frozen;
};

// One cycle's selected solutions of A, B and C at the same instant.
template <typename T>
struct CalibCycle {
    std::int64_t t_us;                              // time of the epoch, µs
    Quaternion<T> q_chu_icrf[kCalibHeads];          // aberration-corrected, unit
    HeadTemperatures<T> temperatures[kCalibHeads];  // all valid
};

template <typename T>
class Estimator {
public:
    enum class Phase : std::uint8_t { kIdle, kAverages, kUpdate, kCandidate, kGate };

    explicit Estimator(const EstimatorConfig& cfg = EstimatorConfig{},
                       const ModelCoefficients* initial = nullptr) noexcept
        : cfg_(cfg) {
        if (cfg_.window_orbits > kWindow) {
            cfg_.window_orbits = kWindow;
        }
        if (cfg_.window_orbits == 0U) {
            cfg_.window_orbits = 1U;
        }
        if (cfg_.persistence_orbits > kWindow) {
            cfg_.persistence_orbits = kWindow;
        }
        if (initial != nullptr) {
            prepare(*initial, 0U);
            active_ = back();
            swap_pending_ = false;
        }
    }

    // ---- The cycle (22 Hz) ----

    // The model for this cycle's corrections; applies a pending swap first.
    const ThermalModel<T>* model_for_cycle(std::int64_t t_us) noexcept {
        if (swap_pending_) {
            active_ = back();
            swap_pending_ = false;
            adopted_at_us_ = t_us;
        }
        return has_[active_] ? &core_[active_] : nullptr;
    }

    // One selected cycle (A, B and C) into the current orbit's sums.
    void accumulate(const CalibCycle<T>& c) noexcept {
        if (frozen_) {
            return;
        }
        // Two comparisons per cycle; the 64-bit division (a library call on
        // the M3) only when the orbit changes.
        if (!open_ || c.t_us < orbit_start_us_ || c.t_us >= orbit_end_us_) {
            const std::int64_t bin = floor_div(c.t_us, cfg_.orbit_period_us);
            close_orbit();
            open_orbit(bin, c);
            orbit_start_us_ = bin * cfg_.orbit_period_us;
            orbit_end_us_ = orbit_start_us_ + cfg_.orbit_period_us;
        }
        sums_.add(c.q_chu_icrf, c.temperatures, ref_);
    }

    // Ends the current orbit now (the end of a recording; a command).
    void close_now() noexcept { close_orbit(); }

    // ---- Idle time ----

    // One bounded phase of the per-orbit work; false when nothing is left.
    bool step() noexcept {
        switch (phase_) {
            case Phase::kIdle:
                return false;
            case Phase::kAverages:
                phase_ = averages() ? Phase::kUpdate : Phase::kIdle;
                return true;
            case Phase::kUpdate:
                update();
                phase_ = Phase::kCandidate;
                return true;
            case Phase::kCandidate:
                phase_ = candidate() ? Phase::kGate : Phase::kIdle;
                return true;
            case Phase::kGate:
                gate();
                phase_ = Phase::kIdle;
                return true;
        }
        return false;
    }

    // ---- Commands ----

    void freeze() noexcept {
        frozen_ = true;
        open_ = false;
    }
    void resume() noexcept { frozen_ = false; }
    // Forget everything learnt; the active model stays.
    void reset() noexcept {
        for (auto& s : srif_) {
            s.clear();
        }
        n_valid_ = false;
        orbits_used_ = 0;
        ring_size_ = 0;
        held_run_ = 0;
        ms_count_ = 0;
        ms_ = 0.0;
        has_solution_ = false;
        last_fed_valid_ = false;
        open_ = false;
        phase_ = Phase::kIdle;
    }
    // Active from the next cycle (between solutions); version = active + 1.
    void load_model(const ModelCoefficients& m) noexcept {
        prepare(m, has_[active_] ? version_[active_] + 1U : 1U);
        swap_pending_ = true;
    }

    EstimatorReport report() const noexcept {
        EstimatorReport r{};
        r.orbits_used = orbits_used_;
        r.orbits_short = orbits_short_;
        r.orbits_held = orbits_held_;
        r.orbits_late = orbits_late_;
        r.changes = changes_;
        r.condition = condition_;
        r.residual_rms_arcsec = active_rms_;
        r.candidate_rms_arcsec = candidate_rms_;
        r.has_active = has_[active_];
        r.active_version = has_[active_] ? version_[active_] : 0U;
        r.active_crc = has_[active_] ? crc_[active_] : 0U;
        r.last_refusal = last_refusal_;
        for (std::size_t i = 0; i < kRefusalKinds; ++i) {
            r.refusals[i] = refusals_[i];
        }
        r.frozen = frozen_;
        return r;
    }

    // The active model's coefficients (arcsec), nullptr: none.
    const ModelCoefficients* active_coefficients() const noexcept { return has_[active_] ? &model_[active_] : nullptr; }
    // When the active model became active (the t of the first cycle using it).
    std::int64_t adopted_at_us() const noexcept { return adopted_at_us_; }
    const EstimatorConfig& config() const noexcept { return cfg_; }

private:
    struct OrbitRecord {
        std::int64_t bin;
        double e[kCalibHeads][3];  // arcsec, relative to N_h
        double x[kCalibHeads][3];  // T1, T2 − T1, T3 − T1 (°C), orbit means
        bool held;                 // held back as an outlier, not (yet) in the filter
    };

    static std::int64_t floor_div(std::int64_t a, std::int64_t b) noexcept {
        const std::int64_t q = a / b;
        return (a % b != 0 && ((a < 0) != (b < 0))) ? q - 1 : q;
    }

    std::size_t back() const noexcept { return active_ ^ 1U; }

    void open_orbit(std::int64_t bin, const CalibCycle<T>& c) noexcept {
        bin_ = bin;
        open_ = true;
        sums_ = OrbitSums<T>{};
        if (next_ref_ready_) {
            ref_ = next_ref_;
            next_ref_ready_ = false;
        } else if (!ref_valid_) {
            // The first cycle is its own reference (the exact value of d_h).
            const Quaternion<T> q_icrf_a = conjugate(c.q_chu_icrf[0]);
            ref_.r[0] = c.q_chu_icrf[1] * q_icrf_a;
            ref_.r[1] = c.q_chu_icrf[2] * q_icrf_a;
            for (std::size_t h = 0; h < kCalibHeads; ++h) {
                ref_.t_ref[h][0] = c.temperatures[h].t_chu.value;
                ref_.t_ref[h][1] = c.temperatures[h].t_029.value;
                ref_.t_ref[h][2] = c.temperatures[h].t_032.value;
            }
        }
        ref_valid_ = true;
    }

    void close_orbit() noexcept {
        if (!open_) {
            return;
        }
        open_ = false;
        if (phase_ != Phase::kIdle) {
            ++orbits_late_;  // the previous orbit is still being processed
            return;
        }
        closed_ = sums_;
        closed_ref_ = ref_;
        closed_bin_ = bin_;
        phase_ = Phase::kAverages;
    }

    // Phase 1: the orbit's means, F, the heads' angles; the next reference.
    bool averages() noexcept {
        closed_.flush();
        const std::uint32_t n = closed_.count;
        const double cover = cfg_.min_coverage * static_cast<double>(typical_count_);
        typical_count_ = n > typical_count_ ? n : typical_count_ - typical_count_ / 16U;
        if (n < cfg_.min_epochs_per_orbit || static_cast<double>(n) < cover || n == 0U) {
            ++orbits_short_;
            return false;
        }
        const double inv = 1.0 / static_cast<double>(n);
        Quaternion<double> d[2];
        for (std::size_t k = 0; k < 2; ++k) {
            const Quaternion<double> mean{closed_.dq[k][0].value() * inv, closed_.dq[k][1].value() * inv,
                                          closed_.dq[k][2].value() * inv, closed_.dq[k][3].value() * inv};
            const double s = 1.0 / std::sqrt(squared_norm(mean));
            const Quaternion<T>& r = closed_ref_.r[k];
            const Quaternion<double> rd{to_d(r.w), to_d(r.x), to_d(r.y), to_d(r.z)};
            const Quaternion<double> unit{mean.w * s, mean.x * s, mean.y * s, mean.z * s};
            const Quaternion<double> dk = unit * rd;
            const double sn = 1.0 / std::sqrt(squared_norm(dk));
            d[k] = {dk.w * sn, dk.x * sn, dk.y * sn, dk.z * sn};
        }
        const Quaternion<double> q_f_in_a = q_f_a(d[1]);
        const Quaternion<double> q_head_in_f[kCalibHeads] = {conjugate(q_f_in_a), q_head_f(d[0], q_f_in_a),
                                                             q_head_f(d[1], q_f_in_a)};
        if (!n_valid_) {
            for (std::size_t h = 0; h < kCalibHeads; ++h) {
                n_ref_[h] = q_head_in_f[h];
                n_mat_[h] = rotation_matrix(q_head_in_f[h]);
            }
        }
        OrbitRecord& o = record_;
        o.bin = closed_bin_;
        o.held = false;
        double t_mean[kCalibHeads][3];
        for (std::size_t h = 0; h < kCalibHeads; ++h) {
            const Vector3<double> e = small_angle(relative_to(q_head_in_f[h], n_ref_[h]));
            o.e[h][0] = e.x * kRadToArcsec;
            o.e[h][1] = e.y * kRadToArcsec;
            o.e[h][2] = e.z * kRadToArcsec;
            for (std::size_t j = 0; j < 3; ++j) {
                t_mean[h][j] = to_d(closed_ref_.t_ref[h][j]) + closed_.dt[h][j].value() * inv;
            }
            o.x[h][0] = t_mean[h][0];
            o.x[h][1] = t_mean[h][1] - t_mean[h][0];
            o.x[h][2] = t_mean[h][2] - t_mean[h][0];
        }
        if (!n_valid_) {
            for (std::size_t h = 0; h < kCalibHeads; ++h) {
                for (std::size_t j = 0; j < 3; ++j) {
                    centre_[h][j] = o.x[h][j];
                }
            }
            n_valid_ = true;
        }
        // The next orbits' references: this orbit's means (in T).
        next_ref_.r[0] = from_d(d[0]);
        next_ref_.r[1] = from_d(d[1]);
        for (std::size_t h = 0; h < kCalibHeads; ++h) {
            for (std::size_t j = 0; j < 3; ++j) {
                next_ref_.t_ref[h][j] = ScalarTraits<T>::celsius(t_mean[h][j]);
            }
        }
        next_ref_ready_ = true;
        return true;
    }

    // Phase 2: the innovation test, forgetting, the filter update.
    void update() noexcept {
        OrbitRecord& o = record_;
        if (has_solution_) {
            double nu[9];
            residual(b_, o, nu);
            double d[3];
            iba_residuals(nu, d);
            const double ss = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
            if (ms_count_ >= 15U && ss > cfg_.outlier_gate * cfg_.outlier_gate * ms_) {
                o.held = true;
                ++orbits_held_;
                ++held_run_;
            } else {
                held_run_ = 0;
                ms_ = ms_count_ == 0U ? ss : ms_ + (ss - ms_) / 30.0;
                ++ms_count_;
            }
        }
        push_record(o);
        if (o.held && held_run_ < cfg_.persistence_orbits) {
            return;
        }
        if (o.held) {
            // A real change (a mount that shifted): the intercepts' information
            // is released, the slopes' kept; then the held orbits still in the
            // window are fed, oldest first.
            for (auto& f : srif_) {
                f.release_first();
            }
            ++changes_;
            for (std::size_t i = 0; i < ring_size_; ++i) {
                OrbitRecord& r = ring_at(i);
                if (r.held) {
                    r.held = false;
                    feed(r);
                }
            }
            held_run_ = 0;
            ms_count_ = 0;
            return;
        }
        feed(ring_at(ring_size_ - 1U));
    }

    void feed(const OrbitRecord& o) noexcept {
        if (last_fed_valid_ && o.bin > last_fed_bin_) {
            const double dt_days = static_cast<double>(o.bin - last_fed_bin_) *
                                   (static_cast<double>(cfg_.orbit_period_us) * 1e-6 / 86400.0);
            const double lambda = exp_nonpositive(-dt_days / cfg_.time_constant_days);  // portable_math.hpp
            for (auto& s : srif_) {
                s.forget(lambda);
            }
        }
        if (!last_fed_valid_ || o.bin > last_fed_bin_) {
            last_fed_bin_ = o.bin;
        }
        last_fed_valid_ = true;
        for (std::size_t h = 0; h < kCalibHeads; ++h) {
            const double a[kUnknowns] = {1.0, o.x[h][0] - centre_[h][0], o.x[h][1] - centre_[h][1],
                                         o.x[h][2] - centre_[h][2]};
            const double y[3] = {o.e[h][0], o.e[h][1], o.e[h][2]};
            srif_[h].add(a, y, 1.0);
        }
        ++orbits_used_;
    }

    // Phase 3: the candidate (solve, condition, coefficients, limits).
    bool candidate() noexcept {
        if (orbits_used_ < cfg_.min_orbits) {
            refuse(Refusal::kFewOrbits);
            return false;
        }
        condition_ = 0.0;
        double b[kCalibHeads][kUnknowns][3];
        for (std::size_t h = 0; h < kCalibHeads; ++h) {
            const double c = srif_[h].condition();
            condition_ = c > condition_ || std::isnan(c) ? c : condition_;
            if (!srif_[h].solve(b[h])) {
                condition_ = std::numeric_limits<double>::infinity();
            }
        }
        if (!(condition_ <= cfg_.max_condition)) {
            refuse(Refusal::kCondition);
            return false;
        }
        for (std::size_t h = 0; h < kCalibHeads; ++h) {
            for (std::size_t j = 0; j < kUnknowns; ++j) {
                for (std::size_t a = 0; a < 3; ++a) {
                    b_[h][j][a] = b[h][j][a];
                }
            }
        }
        has_solution_ = true;
        to_model(b_, cand_);
        if (!within_limits(cand_)) {
            refuse(Refusal::kAngleLimit);
            return false;
        }
        return true;
    }

    // Phase 4: the comparison with the active model; the back buffer and swap.
    void gate() noexcept {
        candidate_rms_ = window_rms(cand_);
        if (has_[active_]) {
            active_rms_ = window_rms(model_[active_]);
            if (!(candidate_rms_ <= (1.0 - cfg_.adoption_margin) * active_rms_)) {
                refuse(Refusal::kNoGain);
                return;
            }
        }
        last_refusal_ = Refusal::kNone;
        prepare(cand_, has_[active_] ? version_[active_] + 1U : 1U);
        active_rms_ = candidate_rms_;
        swap_pending_ = true;
    }

    void refuse(Refusal r) noexcept {
        last_refusal_ = r;
        ++refusals_[static_cast<std::size_t>(r)];
    }

    // The centred solution b as a model in the contract's form (arcsec).
    void to_model(const double (&b)[kCalibHeads][kUnknowns][3], ModelCoefficients& m) const noexcept {
        m = ModelCoefficients{};
        for (std::size_t h = 0; h < kCalibHeads; ++h) {
            m.present[h] = true;
            for (std::size_t a = 0; a < 3; ++a) {
                double* c = m.coefficient[h][a];
                c[0] = b[h][0][a];
                for (std::size_t j = 0; j < 3; ++j) {
                    c[1 + j] = b[h][1 + j][a];
                    c[0] -= b[h][1 + j][a] * centre_[h][j];
                }
            }
        }
    }

    static double model_angle(const ModelCoefficients& m, std::size_t h, std::size_t a, const double (&x)[3]) noexcept {
        const double* c = m.coefficient[h][a];
        return c[0] + c[1] * x[0] + c[2] * x[1] + c[3] * x[2] + c[4] * x[0] * x[0] + c[5] * x[1] * x[1] +
               c[6] * x[2] * x[2];
    }

    bool within_limits(const ModelCoefficients& m) const noexcept {
        constexpr double max_arcsec = kMaxThermalAngleRad * kRadToArcsec;
        const double max_coef = 0x1p-5 * kRadToArcsec;  // ScalarTraits<Q30>::max_coefficient
        for (std::size_t h = 0; h < kCalibHeads; ++h) {
            for (std::size_t a = 0; a < 3; ++a) {
                for (std::size_t t = 0; t < kLinearModelTerms; ++t) {
                    if (!(std::fabs(m.coefficient[h][a][t]) < max_coef)) {
                        return false;
                    }
                }
            }
        }
        if (ring_size_ == 0U) {
            return true;
        }
        const OrbitRecord& o = ring_at(ring_size_ - 1U);
        for (std::size_t h = 0; h < kCalibHeads; ++h) {
            for (std::size_t corner = 0; corner < 8U; ++corner) {
                double x[3];
                for (std::size_t j = 0; j < 3; ++j) {
                    x[j] = o.x[h][j] +
                           (((corner >> j) & 1U) != 0U ? cfg_.angle_check_margin_c : -cfg_.angle_check_margin_c);
                }
                for (std::size_t a = 0; a < 3; ++a) {
                    if (!(std::fabs(model_angle(m, h, a, x)) < max_arcsec)) {
                        return false;
                    }
                }
            }
        }
        return true;
    }

    // An orbit's angle residuals (arcsec, per head and axis) against the
    // centred solution b.
    void residual(const double (&b)[kCalibHeads][kUnknowns][3], const OrbitRecord& o, double (&r)[9]) const noexcept {
        for (std::size_t h = 0; h < kCalibHeads; ++h) {
            for (std::size_t a = 0; a < 3; ++a) {
                double p = b[h][0][a];
                for (std::size_t j = 0; j < 3; ++j) {
                    p += b[h][1 + j][a] * (o.x[h][j] - centre_[h][j]);
                }
                r[3 * h + a] = o.e[h][a] - p;
            }
        }
    }

    // What residual rotations r_h (head frames, arcsec) do to the three IBAs
    // (arcsec), to first order: head h's boresight in F is N_hᵀ·e_z, turned by
    // r_h into N_hᵀ·(e_z + e_z × r_h); an IBA θ_ij = acos(z_i·z_j) changes by
    // −(dz_i·z_j + z_i·dz_j)/sin θ_ij. A rotation common to all heads changes
    // none (common_rotation.hpp), a roll about a head's boresight neither.
    void iba_residuals(const double (&r)[9], double (&d)[3]) const noexcept {
        double z[kCalibHeads][3];
        double dz[kCalibHeads][3];
        for (std::size_t h = 0; h < kCalibHeads; ++h) {
            const double v[3] = {-r[3 * h + 1], r[3 * h], 0.0};  // e_z × r_h
            for (std::size_t c = 0; c < 3; ++c) {
                z[h][c] = n_mat_[h].m[2][c];
                dz[h][c] = n_mat_[h].m[0][c] * v[0] + n_mat_[h].m[1][c] * v[1];
            }
        }
        constexpr std::size_t kPair[3][2] = {{0, 1}, {0, 2}, {1, 2}};
        for (std::size_t p = 0; p < 3; ++p) {
            const auto& zi = z[kPair[p][0]];
            const auto& zj = z[kPair[p][1]];
            const auto& di = dz[kPair[p][0]];
            const auto& dj = dz[kPair[p][1]];
            const double cx = zi[1] * zj[2] - zi[2] * zj[1];
            const double cy = zi[2] * zj[0] - zi[0] * zj[2];
            const double cz = zi[0] * zj[1] - zi[1] * zj[0];
            const double sin_t = std::sqrt(cx * cx + cy * cy + cz * cz);
            const double num =
                di[0] * zj[0] + di[1] * zj[1] + di[2] * zj[2] + zi[0] * dj[0] + zi[1] * dj[1] + zi[2] * dj[2];
            d[p] = -num / sin_t;
        }
    }

    // RMS of a model's IBA residuals (orbit means, arcsec, iba_residuals) over
    // the last window_orbits orbits fed to the filter. Not about their mean:
    // within a day the orbit means' temperatures hardly move, so a wrong slope
    // shows as an offset there, and so does a shifted mount.
    double window_rms(const ModelCoefficients& m) const noexcept {
        double sq[3] = {};
        std::uint32_t n = 0;
        for (std::size_t i = ring_size_; i-- > 0 && n < cfg_.window_orbits;) {
            const OrbitRecord& o = ring_at(i);
            if (o.held) {
                continue;
            }
            double r[9];
            for (std::size_t h = 0; h < kCalibHeads; ++h) {
                for (std::size_t a = 0; a < 3; ++a) {
                    r[3 * h + a] = o.e[h][a] - model_angle(m, h, a, o.x[h]);
                }
            }
            double d[3];
            iba_residuals(r, d);
            for (std::size_t k = 0; k < 3; ++k) {
                sq[k] += d[k] * d[k];
            }
            ++n;
        }
        if (n < 2U) {
            return std::numeric_limits<double>::quiet_NaN();
        }
        return std::sqrt((sq[0] + sq[1] + sq[2]) / (3.0 * n));
    }

    void push_record(const OrbitRecord& o) noexcept {
        if (ring_size_ < kWindow) {
            ring_[(ring_first_ + ring_size_) % kWindow] = o;
            ++ring_size_;
        } else {
            ring_[ring_first_] = o;
            ring_first_ = (ring_first_ + 1U) % kWindow;
        }
    }
    OrbitRecord& ring_at(std::size_t i) noexcept { return ring_[(ring_first_ + i) % kWindow]; }
    const OrbitRecord& ring_at(std::size_t i) const noexcept { return ring_[(ring_first_ + i) % kWindow]; }

    // The back buffer: coefficients, the core's form, version and CRC.
    void prepare(const ModelCoefficients& m, std::uint32_t version) noexcept {
        const std::size_t k = back();
        model_[k] = m;
        core_[k] = thermal_model<T>(m, kArcsecToRad);
        version_[k] = version;
        crc_[k] = model_crc(m);
        has_[k] = true;
    }

    template <typename X>
    static double to_d(const X& x) noexcept {
        return ScalarTraits<T>::to_double(x);
    }
    static Quaternion<T> from_d(const Quaternion<double>& q) noexcept {
        using Tr = ScalarTraits<T>;
        return {Tr::from_double(q.w), Tr::from_double(q.x), Tr::from_double(q.y), Tr::from_double(q.z)};
    }

    EstimatorConfig cfg_;
    // The cycle's side.
    bool frozen_ = false;
    bool open_ = false;
    std::int64_t bin_ = 0;
    std::int64_t orbit_start_us_ = 0;  // [start, end) of the current orbit
    std::int64_t orbit_end_us_ = 0;
    OrbitSums<T> sums_{};
    OrbitReference<T> ref_{};
    bool ref_valid_ = false;
    OrbitReference<T> next_ref_{};
    bool next_ref_ready_ = false;
    // The closed orbit being processed.
    Phase phase_ = Phase::kIdle;
    OrbitSums<T> closed_{};
    OrbitReference<T> closed_ref_{};
    std::int64_t closed_bin_ = 0;
    std::uint32_t typical_count_ = 0;
    OrbitRecord record_{};
    // The filter.
    bool n_valid_ = false;
    Quaternion<double> n_ref_[kCalibHeads]{};
    Matrix3 n_mat_[kCalibHeads]{};
    double centre_[kCalibHeads][3]{};
    SquareRootInformation<kUnknowns, 3> srif_[kCalibHeads]{};
    bool last_fed_valid_ = false;
    std::int64_t last_fed_bin_ = 0;
    bool has_solution_ = false;
    double b_[kCalibHeads][kUnknowns][3]{};
    double ms_ = 0.0;
    std::uint32_t ms_count_ = 0;
    std::uint32_t held_run_ = 0;
    OrbitRecord ring_[kWindow]{};
    std::size_t ring_first_ = 0;
    std::size_t ring_size_ = 0;
    // Counters and the report.
    std::uint32_t orbits_used_ = 0;
    std::uint32_t orbits_short_ = 0;
    std::uint32_t orbits_held_ = 0;
    std::uint32_t orbits_late_ = 0;
    std::uint32_t changes_ = 0;
    double condition_ = std::numeric_limits<double>::quiet_NaN();
    double active_rms_ = std::numeric_limits<double>::quiet_NaN();
    double candidate_rms_ = std::numeric_limits<double>::quiet_NaN();
    Refusal last_refusal_ = Refusal::kNone;
    std::uint32_t refusals_[kRefusalKinds]{};
    // The models: double-buffered.
    ModelCoefficients cand_{};
    ModelCoefficients model_[2]{};
    ThermalModel<T> core_[2]{};
    std::uint32_t version_[2]{};
    std::uint32_t crc_[2]{};
    bool has_[2]{};
    std::size_t active_ = 0;
    bool swap_pending_ = false;
    std::int64_t adopted_at_us_ = 0;
};

}  // namespace ascorr::calib
