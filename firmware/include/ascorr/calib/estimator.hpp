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

    enum class Phase : std::uint8_t { kIdle, kAverages, kUpdate, kCandidate, kGate };

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
        orbit_.drop();
    }
    void resume() noexcept { frozen_ = false; }
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

    // Phase 1: the orbit's means, F, the heads' angles; the next reference.
    bool averages() noexcept {
        closed_.sums.flush();
        const std::uint32_t n = closed_.sums.count;
        const double cover = cfg_.min_coverage * static_cast<double>(typical_count_);
        typical_count_ = n > typical_count_ ? n : typical_count_ - typical_count_ / 16U;
        if (n < cfg_.min_epochs_per_orbit || static_cast<double>(n) < cover || n == 0U) {
            ++orbits_short_;
            return false;
        }
        const OrbitMeans<N> means = orbit_means(closed_, further_min_count(n));
        const Quaternion<double> q_f_in_a = q_f_a(means.d[1]);  // d[1]: C relative to A
        Quaternion<double> q_head_in_f[N];
        q_head_in_f[0] = conjugate(q_f_in_a);
        for (std::size_t h = 1; h < N; ++h) {
            q_head_in_f[h] = means.has[h] ? q_head_f(means.d[h - 1], q_f_in_a) : Quaternion<double>{};
        }
        OrbitRecord<N>& o = record_;
        o.bin = closed_.bin;
        o.held = false;
        for (std::size_t h = 0; h < N; ++h) {
            o.has[h] = means.has[h];
            if (!means.has[h]) {
                continue;
            }
            const bool first = ((static_cast<unsigned>(n_heads_) >> h) & 1U) == 0U;  // its first orbit
            if (first) {
                n_ref_[h] = q_head_in_f[h];
                n_mat_[h] = rotation_matrix(q_head_in_f[h]);
            }
            const Vector3<double> e = small_angle(relative_to(q_head_in_f[h], n_ref_[h]));
            o.e[h][0] = e.x * kRadToArcsec;
            o.e[h][1] = e.y * kRadToArcsec;
            o.e[h][2] = e.z * kRadToArcsec;
            o.x[h][0] = means.t[h][0];
            o.x[h][1] = means.t[h][1] - means.t[h][0];
            o.x[h][2] = means.t[h][2] - means.t[h][0];
            if (first) {
                for (std::size_t j = 0; j < 3; ++j) {
                    centre_[h][j] = o.x[h][j];
                }
                if (h == 0U) {  // T2 and T3 are head A's T1 + D2, T1 + D3
                    rule_memory_.set_centre(o.x[0][0] + o.x[0][1], o.x[0][0] + o.x[0][2]);
                }
            }
        }
        n_heads_ = static_cast<std::uint8_t>(n_heads_ | o.heads());
        // the references of the next orbit opened (a head without means keeps its own)
        orbit_.set_next_reference(reference_from<T>(means, orbit_.latest_reference()));
        return true;
    }

    // A further head's cycles for its orbit means: min_epochs_per_orbit, and
    // min_coverage of the orbit's n counted cycles.
    std::uint32_t further_min_count(std::uint32_t n) const noexcept {
        const double cover = std::ceil(cfg_.min_coverage * static_cast<double>(n));
        const std::uint32_t c = cover > 0.0 ? static_cast<std::uint32_t>(cover) : 0U;
        return c > cfg_.min_epochs_per_orbit ? c : cfg_.min_epochs_per_orbit;
    }

    // Phase 2: the innovation test, forgetting, the filter update.
    void update() noexcept {
        OrbitRecord<N>& o = record_;
        if (has_solution_) {
            double nu[3 * N];
            residual<N>(b_, centre_, o, nu);
            double d[iba_pairs(N)];
            const std::size_t pairs = iba_residuals<N>(n_mat_, nu, d, static_cast<std::uint8_t>(solved_ & o.heads()));
            double ss = 0.0;
            for (const double dk : d) {
                ss += dk * dk;
            }
            if (pairs != kFramePairs) {
                ss *= static_cast<double>(kFramePairs) / static_cast<double>(pairs);  // per the frame heads' 3 pairs
            }
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
        window_.push(o);
        since_change_ = since_change_ < kWindow ? since_change_ + 1U : since_change_;
        if (o.held && held_run_ < cfg_.persistence_orbits) {
            return;
        }
        if (o.held) {
            // A real change (a mount that shifted): the intercepts' information
            // is released, the slopes' kept; then the held orbits still in the
            // window are fed, oldest first. The running RMS is kept, so that the
            // end of a transient step is the next change, and undoes this one.
            for (auto& f : srif_) {
                f.release_first();
            }
            ++changes_;
            for (std::size_t i = 0; i < window_.size(); ++i) {
                OrbitRecord<N>& r = window_.at(i);
                if (r.held) {
                    r.held = false;
                    feed(r);
                }
            }
            since_change_ = held_run_;  // the change began with the first held orbit
            held_run_ = 0;
            return;
        }
        feed(window_.at(window_.size() - 1U));
    }

    void feed(const OrbitRecord<N>& o) noexcept {
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
        for (std::size_t h = 0; h < N; ++h) {
            if (!o.has[h]) {
                continue;
            }
            const double a[kUnknowns] = {1.0, o.x[h][0] - centre_[h][0], o.x[h][1] - centre_[h][1],
                                         o.x[h][2] - centre_[h][2]};
            const double y[3] = {o.e[h][0], o.e[h][1], o.e[h][2]};
            srif_[h].add(a, y, 1.0);
            ++head_orbits_[h];
        }
        if (cfg_.common_rotation.heads != 0U) {
            rule_memory_.add(o, centre_);
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
        double b[N][kUnknowns][3];
        for (std::size_t h = 0; h < kFrameHeads; ++h) {
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
        std::uint8_t heads = kFrameMask;
        for (std::size_t h = kFrameHeads; h < N; ++h) {
            if (further_solved(h, b[h])) {
                heads = static_cast<std::uint8_t>(heads | (1U << h));
            }
        }
        for (std::size_t h = 0; h < N; ++h) {
            for (std::size_t j = 0; j < kUnknowns && ((static_cast<unsigned>(heads) >> h) & 1U) != 0U; ++j) {
                for (std::size_t a = 0; a < 3; ++a) {
                    b_[h][j][a] = b[h][j][a];
                }
            }
        }
        has_solution_ = true;
        solved_ = heads;
        centred_to_model<N>(b_, centre_, cand_, heads);
        apply_rule();
        if (!within_limits(cand_, window_, cfg_.angle_check_margin_c, heads)) {
            refuse(Refusal::kAngleLimit);
            return false;
        }
        return true;
    }

    // A further head joins the candidate when its filter holds min_orbits
    // orbits, its condition is within max_condition and it solves (its
    // condition then counts in the report's); otherwise the model keeps it.
    bool further_solved(std::size_t h, double (&b)[kUnknowns][3]) noexcept {
        if (head_orbits_[h] < cfg_.min_orbits) {
            return false;
        }
        const double c = srif_[h].condition();
        if (!(c <= cfg_.max_condition) || !srif_[h].solve(b)) {
            return false;
        }
        condition_ = c > condition_ ? c : condition_;
        return true;
    }

    // Phase 4: the comparison with the active model; the back buffer and swap.
    // After a change, only the orbits since it are compared: the older ones
    // favour the active model, made for the bench before the change.
    void gate() noexcept {
        const std::uint32_t n = since_change_ < cfg_.window_orbits ? since_change_ : cfg_.window_orbits;
        candidate_rms_ = window_rms(cand_, window_, n_mat_, n, solved_);
        if (has_[active_]) {
            active_rms_ = window_rms(model_[active_], window_, n_mat_, n, solved_);
            if (!(candidate_rms_ <= (1.0 - cfg_.adoption_margin) * active_rms_)) {
                refuse(Refusal::kNoGain);
                return;
            }
        }
        last_refusal_ = Refusal::kNone;
        keep_heads_not_learnt(cand_, solved_);
        const std::uint8_t moved = rule_on_kept_heads();
        if (moved != 0U && !within_limits(cand_, window_, cfg_.angle_check_margin_c, moved)) {
            refuse(Refusal::kAngleLimit);  // a kept head the rule moved beyond the limits
            return;
        }
        prepare(cand_, has_[active_] ? version_[active_] + 1U : 1U, solved_, cand_omega_);
        active_rms_ = candidate_rms_;
        swap_pending_ = true;
    }

    // The heads candidate m did not learn (not in `learnt`) keep the active
    // model's presence and coefficients.
    void keep_heads_not_learnt(ModelCoefficients& m, std::uint8_t learnt) const noexcept {
        if (!has_[active_]) {
            return;
        }
        const ModelCoefficients& a = model_[active_];
        for (std::size_t h = 0; h < kMaxHeads; ++h) {
            if (learns_head(h, learnt)) {
                continue;
            }
            m.present[h] = a.present[h];
            for (std::size_t x = 0; x < kModelAxes; ++x) {
                for (std::size_t t = 0; t < kModelTerms; ++t) {
                    m.coefficient[h][x][t] = a.coefficient[h][x][t];
                }
            }
        }
    }

    // The rule's common rotation ω (common_rotation_memory.hpp) added to every
    // head the candidate solved; cand_omega_ keeps it (zero without the rule).
    void apply_rule() noexcept {
        cand_omega_ = {};
        if (cfg_.common_rotation.heads == 0U ||
            !rule_memory_.solve(b_, n_mat_, solved_, cfg_.common_rotation, cand_omega_.w)) {
            cand_omega_ = {};
            return;
        }
        for (std::size_t h = 0; h < N; ++h) {
            if (learns_head(h, solved_)) {
                add_common_rotation(n_mat_[h], cand_omega_.w, cand_.coefficient[h]);
            }
        }
    }

    // A head kept from the active model gets the candidate's ω less the active
    // model's, so that its IBAs with the heads learnt stay as they were (a
    // head never seen has no N_h, and after a reset the active ω is in the
    // frame forgotten: kept as it was). The heads it moved (their limits are
    // checked before adoption).
    std::uint8_t rule_on_kept_heads() noexcept {
        if (cfg_.common_rotation.heads == 0U || !has_[active_] || !omega_valid_[active_]) {
            return 0U;
        }
        Omega d{};
        for (int r = 0; r < 3; ++r) {
            for (int c = 0; c < 3; ++c) {
                d.w[r][c] = cand_omega_.w[r][c] - omega_[active_].w[r][c];
            }
        }
        std::uint8_t moved = 0U;
        for (std::size_t h = 0; h < N; ++h) {
            if (!learns_head(h, solved_) && cand_.present[h] && learns_head(h, n_heads_)) {
                add_common_rotation(n_mat_[h], d.w, cand_.coefficient[h]);
                moved = static_cast<std::uint8_t>(moved | (1U << h));
            }
        }
        return moved;
    }

    void refuse(Refusal r) noexcept {
        last_refusal_ = r;
        ++refusals_[static_cast<std::size_t>(r)];
    }

    // The back buffer: coefficients, the core's form, version and CRC.
    void prepare(const ModelCoefficients& m, std::uint32_t version, std::uint8_t learnt = 0U,
                 const Omega& omega = Omega{}) noexcept {
        const std::size_t k = back();
        learnt_[k] = learnt;
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
    Omega omega_[2]{};       // per buffer: the ω its learnt heads carry (0: given, loaded)
    bool omega_valid_[2]{};  // false: adopted before a reset (its ω is in the frame forgotten)
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
