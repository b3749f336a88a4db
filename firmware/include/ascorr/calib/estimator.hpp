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
//           est.accumulate_head(h, ...);  // a further head selected after them
//   idle:   while (time left && est.step()) {}   // bounded work per call
//   ground: freeze(), resume(), reset(), load_model(m), report().
//
// The selection is the ground fit's (`ascorr fit`): a head's solution counts
// when flags 1, 2 and 4 are clear, confidence ≤ 5, its three temperatures are
// valid, and the aberration stage was applied; its quaternion without the
// thermal stage is what is given (feed.hpp forms it, for the flight loop, the
// link server and the host alike). A cycle counts when A, B and C all do; a
// further head is learnt from the counted cycles it passes too (per-head
// selection: estimator_types.hpp, README.md).
//
// N: the heads learnt, 3 to the core's kMaxHeads (heads.hpp; the flight loop
// and the link: kMaxHeads); F needs A and C, the IBAs are all N·(N − 1)/2 pairs.
//
// The estimate, its numerics and the per-cycle and per-orbit work: README.md
// in this folder ("The estimator").
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
//     to the N heads' IBAs, so a common rotation or a roll about a boresight
//     counts for nothing) is not below (1 − adoption_margin) × the active
//     model's. Not about their mean: within a window the orbit means'
//     temperatures hardly move, so a wrong slope shows as an offset there.
// Outlier orbits are held back, and a persistent change is taken as real
// (README.md, "Outliers and changes").
//
// The rule for the common rotation (cfg.common_rotation) gauges each
// candidate over the rule's memory; an orbit that adopts none re-gauges the
// active adopted model over the memory as it has grown since (it changes no
// IBA among the heads it turns, so no gate): a new version when the bench
// moves by more than cfg.regauge_arcsec at the orbit's T029 and T032 and the
// limits hold (otherwise the active model stays; regauges() counts both).
//
// Model versions: the model given at start is version 0; each adopted or
// loaded model is the active version + 1 (the first is 1 without one). Its identity is the
// CRC-32C of its coefficients (model_identity.hpp). Models are kept in
// arcsec as ModelCoefficients and converted once into the core's
// ThermalModel<T> (model_coefficients.hpp) when prepared, in the back buffer.
// An adopted model is learnt for A, B, C and the further heads that joined
// it (active_learnt()); its other heads are the active model's.
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
#include "common_rotation_memory.hpp"
#include "estimator_types.hpp"
#include "frame.hpp"
#include "head_rotation.hpp"
#include "model_checks.hpp"
#include "model_identity.hpp"
#include "orbit_collector.hpp"
#include "orbit_window.hpp"
#include "square_root_information.hpp"

namespace ascorr::calib {

template <typename T, std::size_t N = kCalibHeads>
class Estimator {
    static_assert(kCalibHeadCountOk<N>, "the estimator learns 3 to kMaxHeads heads");

public:
    static constexpr std::size_t kHeads = N;

    enum class Phase : std::uint8_t { kIdle, kAverages, kUpdate, kCandidate, kGate, kRegauge };
    // The most step() calls an orbit's work takes (one per phase but kIdle).
    static constexpr int kPhases = static_cast<int>(Phase::kRegauge);

    explicit Estimator(const EstimatorConfig& cfg = EstimatorConfig{},
                       const ModelCoefficients* initial = nullptr) noexcept
        : cfg_(cfg), orbit_(cfg.orbit_period_us) {
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
            initial_unused_ = true;  // active from the first cycle: its time is taken there
        }
    }

    // ---- The cycle (22 Hz) ----

    // The model for this cycle's corrections; applies a pending swap first.
    const ThermalModel<T>* model_for_cycle(std::int64_t t_us) noexcept {
        if (initial_unused_) {
            initial_unused_ = false;
            adopted_at_us_ = t_us;
        }
        if (swap_pending_) {
            active_ = back();
            swap_pending_ = false;
            adopted_at_us_ = t_us;
        }
        return has_[active_] ? &core_[active_] : nullptr;
    }

    // One counted cycle (A, B and C selected; the further heads in c.heads)
    // into the current orbit's sums.
    void accumulate(const CalibCycle<T, N>& c) noexcept {
        if (frozen_) {
            return;
        }
        if (orbit_.starts_orbit(c.t_us)) {
            close_orbit();
            orbit_.open(c);
        }
        orbit_.add(c);
    }

    // Further head h (≥ kFrameHeads) selected at t_us after that cycle was
    // accumulated (solutions that come one by one); false: not taken (no
    // such cycle in the open orbit, frozen).
    bool accumulate_head(std::size_t h, std::int64_t t_us, const Quaternion<T>& q_chu_icrf,
                         const HeadTemperatures<T>& temperatures) noexcept {
        return !frozen_ && orbit_.add_head(h, t_us, q_chu_icrf, temperatures);
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
                phase_ = candidate() ? Phase::kGate : Phase::kRegauge;
                return true;
            case Phase::kGate:
                phase_ = gate() ? Phase::kIdle : Phase::kRegauge;
                return true;
            case Phase::kRegauge:
                regauge();
                phase_ = Phase::kIdle;
                return true;
        }
        return false;
    }

    // ---- Commands ----

    void freeze() noexcept {
        frozen_ = true;
        orbit_.drop();
    }
    void resume() noexcept { frozen_ = false; }
    bool frozen() const noexcept { return frozen_; }
    // Forget everything learnt; the active model stays.
    void reset() noexcept {
        rule_memory_.clear();
        for (std::size_t k = 0; k < 2; ++k) {  // an adopted model's ω is in the frame F being forgotten
            omega_valid_[k] = learnt_[k] == 0U;
        }
        for (auto& s : srif_) {
            s.clear();
        }
        n_heads_ = 0;
        for (auto& k : head_orbits_) {
            k = 0;
        }
        solved_ = 0;
        orbits_used_ = 0;
        window_.clear();
        held_run_ = 0;
        since_change_ = kWindow;
        ms_count_ = 0;
        ms_ = 0.0;
        has_solution_ = false;
        last_fed_valid_ = false;
        orbit_.drop();
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
        r.active_version = active_version();
        r.active_crc = active_crc();
        r.last_refusal = last_refusal_;
        for (std::size_t i = 0; i < kRefusalKinds; ++i) {
            r.refusals[i] = refusals_[i];
        }
        r.frozen = frozen_;
        return r;
    }

    // The active model's coefficients (arcsec), nullptr: none.
    const ModelCoefficients* active_coefficients() const noexcept { return has_[active_] ? &model_[active_] : nullptr; }
    // The active model's version and CRC-32C (model_crc); 0 when there is none.
    std::uint32_t active_version() const noexcept { return has_[active_] ? version_[active_] : 0U; }
    std::uint32_t active_crc() const noexcept { return has_[active_] ? crc_[active_] : 0U; }
    // The heads the active model learnt (bit h; 0: given or loaded).
    std::uint8_t active_learnt() const noexcept { return has_[active_] ? learnt_[active_] : 0U; }
    RegaugeCounts regauges() const noexcept { return regauges_; }
    // When the active model became active (the t of the first cycle using it).
    std::int64_t adopted_at_us() const noexcept { return adopted_at_us_; }
    const EstimatorConfig& config() const noexcept { return cfg_; }

private:
    struct Omega {
        double w[3][3];  // the rule's common rotation, w[axis] = {w0, w2, w3} (F axes, arcsec)
    };

    static constexpr std::size_t kFramePairs = iba_pairs(kFrameHeads);

    std::size_t back() const noexcept { return active_ ^ 1U; }

    void close_orbit() noexcept {
        if (!orbit_.is_open()) {
            return;
        }
        if (phase_ != Phase::kIdle) {
            orbit_.drop();
            ++orbits_late_;  // the previous orbit is still being processed
            return;
        }
        orbit_.close(closed_);
        phase_ = Phase::kAverages;
    }

    // The per-orbit work, one phase per step() (estimator_orbit.hpp).
    bool averages() noexcept;
    std::uint32_t further_min_count(std::uint32_t n) const noexcept;
    void update() noexcept;
    void feed(const OrbitRecord<N>& o) noexcept;
    bool candidate() noexcept;
    bool further_solved(std::size_t h, double (&b)[kUnknowns][3]) noexcept;
    bool gate() noexcept;
    void keep_heads_not_learnt(ModelCoefficients& m, std::uint8_t learnt) const noexcept;
    void apply_rule() noexcept;
    std::uint8_t rule_on_kept_heads() noexcept;
    void regauge() noexcept;
    static Omega omega_minus(const Omega& a, const Omega& b) noexcept;
    std::uint8_t turn_seen_heads(const Omega& d, std::uint8_t skip) noexcept;

    void refuse(Refusal r) noexcept {
        last_refusal_ = r;
        ++refusals_[static_cast<std::size_t>(r)];
    }

    // The back buffer: coefficients, the core's form, version and CRC; for
    // an adopted model (learnt ≠ 0) its ω and the centred solution b it was
    // formed from.
    void prepare(const ModelCoefficients& m, std::uint32_t version, std::uint8_t learnt = 0U,
                 const Omega& omega = Omega{}, const double (*b)[kUnknowns][3] = nullptr) noexcept {
        const std::size_t k = back();
        learnt_[k] = learnt;
        for (std::size_t h = 0; h < N && b != nullptr; ++h) {
            for (std::size_t u = 0; u < kUnknowns; ++u) {
                for (std::size_t a = 0; a < 3; ++a) {
                    solution_[k][h][u][a] = b[h][u][a];
                }
            }
        }
        omega_[k] = omega;
        omega_valid_[k] = true;
        model_[k] = m;
        core_[k] = thermal_model<T>(m, kArcsecToRad);
        version_[k] = version;
        crc_[k] = model_crc(m);
        has_[k] = true;
    }

    EstimatorConfig cfg_;
    // The memory of the rule for the common rotation (cfg_.common_rotation).
    CommonRotationMemory<N> rule_memory_{};
    Omega cand_omega_{};
    Omega omega_[2]{};                       // per buffer: the ω its learnt heads carry (0: given, loaded)
    bool omega_valid_[2]{};                  // false: adopted before a reset (its ω is in the frame forgotten)
    double solution_[2][N][kUnknowns][3]{};  // per buffer: an adopted model's b_ (its learnt heads)
    // The cycle's side.
    bool frozen_ = false;
    OrbitCollector<T, N> orbit_;
    // The closed orbit being processed.
    Phase phase_ = Phase::kIdle;
    ClosedOrbit<T, N> closed_{};
    std::uint32_t typical_count_ = 0;
    OrbitRecord<N> record_{};
    // The filter.
    std::uint8_t n_heads_ = 0;  // heads with n_ref_, n_mat_, centre_ (bit h)
    Quaternion<double> n_ref_[N]{};
    Matrix3 n_mat_[N]{};
    double centre_[N][3]{};
    SquareRootInformation<kUnknowns, 3> srif_[N]{};
    bool last_fed_valid_ = false;
    std::int64_t last_fed_bin_ = 0;
    std::uint32_t head_orbits_[N]{};  // orbits fed per head
    bool has_solution_ = false;
    std::uint8_t solved_ = 0;  // heads of the last solution b_ (bit h)
    double b_[N][kUnknowns][3]{};
    double ms_ = 0.0;
    std::uint32_t ms_count_ = 0;
    std::uint32_t held_run_ = 0;
    std::uint32_t since_change_ = kWindow;  // orbits since the last change taken as real (saturating)
    OrbitWindow<N> window_{};
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
    RegaugeCounts regauges_{};
    // The models: double-buffered.
    ModelCoefficients cand_{};
    ModelCoefficients model_[2]{};
    ThermalModel<T> core_[2]{};
    std::uint32_t version_[2]{};
    std::uint32_t crc_[2]{};
    std::uint8_t learnt_[2]{};
    bool has_[2]{};
    std::size_t active_ = 0;
    bool swap_pending_ = false;
    bool initial_unused_ = false;  // the model given at start, before its first cycle
    std::int64_t adopted_at_us_ = 0;
};

}  // namespace ascorr::calib

#include "estimator_orbit.hpp"  // the per-orbit work's definitions
