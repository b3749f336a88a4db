// ascorr/calib/estimator_orbit.hpp: the estimator's per-orbit work, one bounded
// phase per step() (averages, update, candidate, gate, re-gauge) and the rule
// for the common rotation. Part of estimator.hpp (its conventions are there); include
// that one.
#pragma once

#include <cmath>
#include <cstdint>

#include "estimator.hpp"

namespace ascorr::calib {

// Phase 1: the orbit's means, F, the heads' angles; the next reference.
template <typename T, std::size_t N>
inline bool Estimator<T, N>::averages() noexcept {
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
            if (h == 0U) {  // the rule's centre: this first orbit's T029, T032
                rule_memory_.set_centre(o.t2(), o.t3());
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
template <typename T, std::size_t N>
inline std::uint32_t Estimator<T, N>::further_min_count(std::uint32_t n) const noexcept {
    const double cover = std::ceil(cfg_.min_coverage * static_cast<double>(n));
    const std::uint32_t c = cover > 0.0 ? static_cast<std::uint32_t>(cover) : 0U;
    return c > cfg_.min_epochs_per_orbit ? c : cfg_.min_epochs_per_orbit;
}

// Phase 2: the innovation test, forgetting, the filter update.
template <typename T, std::size_t N>
inline void Estimator<T, N>::update() noexcept {
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

template <typename T, std::size_t N>
inline void Estimator<T, N>::feed(const OrbitRecord<N>& o) noexcept {
    if (last_fed_valid_ && o.bin > last_fed_bin_) {
        const double dt_days =
            static_cast<double>(o.bin - last_fed_bin_) * (static_cast<double>(cfg_.orbit_period_us) * 1e-6 / 86400.0);
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
template <typename T, std::size_t N>
inline bool Estimator<T, N>::candidate() noexcept {
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
template <typename T, std::size_t N>
inline bool Estimator<T, N>::further_solved(std::size_t h, double (&b)[kUnknowns][3]) noexcept {
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
// favour the active model, made for the bench before the change. false: no
// candidate adopted; nor while a ground model loaded since the orbit closed
// waits to start (the back buffer is its).
template <typename T, std::size_t N>
inline bool Estimator<T, N>::gate() noexcept {
    if (swap_pending_) {
        return false;
    }
    const std::uint32_t n = since_change_ < cfg_.window_orbits ? since_change_ : cfg_.window_orbits;
    candidate_rms_ = window_rms(cand_, window_, n_mat_, n, solved_);
    if (has_[active_]) {
        active_rms_ = window_rms(model_[active_], window_, n_mat_, n, solved_);
        if (!(candidate_rms_ <= (1.0 - cfg_.adoption_margin) * active_rms_)) {
            refuse(Refusal::kNoGain);
            return false;
        }
    }
    last_refusal_ = Refusal::kNone;
    keep_heads_not_learnt(cand_, solved_);
    const std::uint8_t moved = rule_on_kept_heads();
    if (moved != 0U && !within_limits(cand_, window_, cfg_.angle_check_margin_c, moved)) {
        refuse(Refusal::kAngleLimit);  // a kept head the rule moved beyond the limits
        return false;
    }
    prepare(cand_, has_[active_] ? version_[active_] + 1U : 1U, solved_, cand_omega_, b_);
    active_rms_ = candidate_rms_;
    swap_pending_ = true;
    return true;
}

// The heads candidate m did not learn (not in `learnt`) keep the active
// model's presence and coefficients.
template <typename T, std::size_t N>
inline void Estimator<T, N>::keep_heads_not_learnt(ModelCoefficients& m, std::uint8_t learnt) const noexcept {
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
template <typename T, std::size_t N>
inline void Estimator<T, N>::apply_rule() noexcept {
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
template <typename T, std::size_t N>
inline std::uint8_t Estimator<T, N>::rule_on_kept_heads() noexcept {
    if (cfg_.common_rotation.heads == 0U || !has_[active_] || !omega_valid_[active_]) {
        return 0U;
    }
    return turn_seen_heads(omega_minus(cand_omega_, omega_[active_]), solved_);
}

template <typename T, std::size_t N>
inline typename Estimator<T, N>::Omega Estimator<T, N>::omega_minus(const Omega& a, const Omega& b) noexcept {
    Omega d{};
    for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) {
            d.w[r][c] = a.w[r][c] - b.w[r][c];
        }
    }
    return d;
}

// cand_'s heads that are present and have an orbit since the start or the
// last reset (an orientation N_h), but not those of `skip`, turned by the
// common rotation d; the heads turned. A head without N_h cannot be turned.
template <typename T, std::size_t N>
inline std::uint8_t Estimator<T, N>::turn_seen_heads(const Omega& d, std::uint8_t skip) noexcept {
    std::uint8_t moved = 0U;
    for (std::size_t h = 0; h < N; ++h) {
        if (!learns_head(h, skip) && cand_.present[h] && learns_head(h, n_heads_)) {
            add_common_rotation(n_mat_[h], d.w, cand_.coefficient[h]);
            moved = static_cast<std::uint8_t>(moved | (1U << h));
        }
    }
    return moved;
}

// Phase 5, after an orbit that adopted no candidate: the active adopted
// model's ω re-solved over the rule's memory (its solution b is kept with
// it), and the difference d added to every head that carries ω (learnt, and
// kept ones seen: rule_on_kept_heads), so no IBA among them changes. A new
// version when |d(T029, T032)| at this orbit exceeds regauge_arcsec: the
// bench's motion from the model changes by exactly d (common_rotation.hpp,
// "The rule"). Not after a held orbit (the memory is as it was; its
// temperatures may be a fault's), nor over a ground model waiting to start.
template <typename T, std::size_t N>
inline void Estimator<T, N>::regauge() noexcept {
    const std::size_t k = active_;
    Omega w{};
    const bool adopted = has_[k] && omega_valid_[k] && learnt_[k] != 0U;
    if (cfg_.common_rotation.heads == 0U || record_.held || swap_pending_ || !adopted ||
        !rule_memory_.solve(solution_[k], n_mat_, learnt_[k], cfg_.common_rotation, w.w)) {
        return;
    }
    const double t2 = record_.t2();
    const double t3 = record_.t3();
    const Omega d = omega_minus(w, omega_[k]);
    double move2 = 0.0;
    for (const auto& axis : d.w) {
        const double m = axis[0] + axis[1] * t2 + axis[2] * t3;
        move2 += m * m;
    }
    if (!(move2 > cfg_.regauge_arcsec * cfg_.regauge_arcsec)) {
        return;  // also NaN: the model stays
    }
    cand_ = model_[k];
    const std::uint8_t moved = turn_seen_heads(d, 0U);
    if (!within_limits(cand_, window_, cfg_.angle_check_margin_c, moved)) {
        ++regauges_.beyond_limits;
        return;
    }
    prepare(cand_, version_[k] + 1U, learnt_[k], w, solution_[k]);
    swap_pending_ = true;
    ++regauges_.made;
}

}  // namespace ascorr::calib
