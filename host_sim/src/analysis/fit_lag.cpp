#include "ascorr_host/analysis/fit_lag.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "ascorr/nav/tt_time.hpp"
#include "ascorr_host/formats/csv.hpp"
#include "ascorr_text/c_format.hpp"

namespace ascorr::host {

namespace {

constexpr int kGridPoints = static_cast<int>(pipeline::kLagGridPoints);  // 300 … 6048 s (kLagGridS)
constexpr int kHeadSpan = 3;     // a head's own search: an octave either side of the common lag
constexpr int kGoldenSteps = 5;  // the bracket of two grid steps shrinks to 0.618⁵ ≈ 9 % of it (±2 % in τ)
constexpr std::int64_t kNoTime = std::numeric_limits<std::int64_t>::min();  // a t the clock cannot hold
using Lags = std::array<double, kMaxHeads>;

double grid_tau(int k) {
    return pipeline::kLagGridS[static_cast<std::size_t>(k)];
}

// The scores of candidate lags: the epochs' temperatures lagged per head (a
// head re-walked only when its τ changes), the orbits' regressors averaged
// again, the model fitted before t_split and scored after it.
class LagScorer {
public:
    explicit LagScorer(const LagSearchInput& in) : in_(in) {
        const std::vector<FitEpoch>& epochs = *in.epochs;
        std::int64_t t_end = std::numeric_limits<std::int64_t>::min();
        for (std::size_t h = 0; h < kMaxHeads; ++h) {
            t_us_[h].resize(epochs.size());
            for (std::size_t i = 0; i < epochs.size(); ++i) {
                TtTime t{};
                // A head's own time, as `correct` looks its row up; none: never lagged, as there.
                t_us_[h][i] = tt_from_seconds(epochs[i].t_head[h], t) ? t.us : kNoTime;
                t_end = std::max(t_end, t_us_[h][i]);
                raw_[h].push_back(epochs[i].temp[h]);
            }
        }
        std::map<long long, long long> index_of_bin;
        for (const OrbitAverage& o : *in.orbits) {
            if (o.t_mid < in.t_split) {
                index_of_bin[std::llround(o.t_mid / in.period - 0.5)] = static_cast<long long>(fitted_.size());
                fitted_.push_back(o);
            }
        }
        orbit_of_.resize(epochs.size(), -1);
        for (std::size_t i = 0; i < epochs.size(); ++i) {
            const auto it = index_of_bin.find(static_cast<long long>(std::floor(epochs[i].t / in.period)));
            orbit_of_[i] = it == index_of_bin.end() ? -1 : it->second;
        }
        // Each head's readings up to the last epoch (the later ones change no epoch's lag).
        const std::vector<LagReading>& r = *in.readings;
        for (std::size_t h = 0; h < kMaxHeads; ++h) {
            const auto before = [](const LagReading& x, const std::pair<std::size_t, std::int64_t>& k) {
                return x.head < k.first || (x.head == k.first && x.t_us < k.second);
            };
            const std::pair<std::size_t, std::int64_t> start{h, std::numeric_limits<std::int64_t>::min()};
            const std::pair<std::size_t, std::int64_t> end{
                h, t_end == std::numeric_limits<std::int64_t>::max() ? t_end : t_end + 1};
            first_[h] = static_cast<std::size_t>(std::lower_bound(r.begin(), r.end(), start, before) - r.begin());
            last_[h] = static_cast<std::size_t>(std::lower_bound(r.begin(), r.end(), end, before) - r.begin());
        }
    }
    LagScorer(const LagScorer&) = delete;
    LagScorer& operator=(const LagScorer&) = delete;
    ~LagScorer() {  // the epochs as they came
        for (std::size_t i = 0; i < in_.epochs->size(); ++i) {
            for (std::size_t h = 0; h < kMaxHeads; ++h) {
                (*in_.epochs)[i].temp[h] = raw_[h][i];
            }
        }
    }

    // The held-out IBA RMS, mean over the pairs (arcsec); +inf when the model
    // is refused, NaN when a pair has no held-out epoch.
    double score(const Lags& lag) {
        const auto key = std::vector<double>(lag.begin(), lag.end());
        const auto seen = scores_.find(key);
        if (seen != scores_.end()) {
            return seen->second;
        }
        const HeadList list = heads_of(in_.heads);
        for (std::size_t i = 0; i < list.count; ++i) {
            const std::size_t h = list.head[i];
            if (applied_[h] != lag[h]) {
                lag_head(h, lag[h]);
            }
        }
        average_regressors();
        const TermsFit fit =
            solve_terms(fitted_, in_.n_ref, in_.heads, Terms::kLinear, in_.max_condition, in_.min_range_c, in_.rule);
        double s = std::numeric_limits<double>::infinity();
        if (fit.refused.empty()) {
            const std::array<Rms, kMaxPairs> out = corrected_iba_rms(
                *in_.epochs, in_.heads, in_.t_split, std::numeric_limits<double>::infinity(), fit.model);
            const PairList pairs = pairs_of(in_.heads);
            s = 0.0;
            for (std::size_t p = 0; p < pairs.count; ++p) {
                s += out[p].n == 0 ? std::numeric_limits<double>::quiet_NaN() : out[p].rms;
            }
            s /= static_cast<double>(pairs.count);
        }
        ++trials_;
        scores_[key] = s;
        if (s < best_score_) {
            best_score_ = s;
            best_ = lag;
        }
        return s;
    }

    std::size_t trials() const noexcept { return trials_; }
    // The lowest score of all candidates, and its lags.
    double best_score() const noexcept { return best_score_; }
    const Lags& best() const noexcept { return best_; }

private:
    // Head h's temperatures at the epochs through a lag of tau (0: its readings).
    void lag_head(std::size_t h, double tau) {
        std::vector<FitEpoch>& epochs = *in_.epochs;
        for (std::size_t i = 0; i < epochs.size(); ++i) {
            epochs[i].temp[h] = raw_[h][i];
        }
        applied_[h] = tau;
        if (tau == 0.0 || first_[h] == last_[h]) {
            return;
        }
        const LagReading* r = in_.readings->data();
        const std::vector<std::int64_t>& t_us = t_us_[h];
        std::size_t i = 0;  // a head's own times rise with the epochs' (one millisecond key each)
        walk_lag(tau, r + first_[h], r + last_[h],
                 [&](std::int64_t t, const std::array<double, 3>& lagged, const std::array<bool, 3>& valid) {
                     while (i < epochs.size() && t_us[i] < t) {
                         ++i;
                     }
                     for (std::size_t j = i; j < epochs.size() && t_us[j] == t; ++j) {
                         for (std::size_t k = 0; k < 3; ++k) {
                             const double raw = raw_[h][j][k];
                             epochs[j].temp[h][k] = lagged_reading_usable(true, raw, valid[k]) ? lagged[k] : raw;
                         }
                     }
                 });
    }

    // The fitted orbits' regressors (x, x²) from the epochs' temperatures, as
    // the fit's pass averages them (fit.cpp, add_head).
    void average_regressors() {
        const HeadList list = heads_of(in_.heads);
        std::vector<std::size_t> count(fitted_.size(), 0);
        for (OrbitAverage& o : fitted_) {
            o.x.fill(Eigen::Vector3d::Zero());
            o.x2.fill(Eigen::Vector3d::Zero());
        }
        const std::vector<FitEpoch>& epochs = *in_.epochs;
        for (std::size_t i = 0; i < epochs.size(); ++i) {
            if (orbit_of_[i] < 0) {
                continue;
            }
            const auto o = static_cast<std::size_t>(orbit_of_[i]);
            ++count[o];
            for (std::size_t k = 0; k < list.count; ++k) {
                const std::size_t h = list.head[k];
                const std::array<double, 3>& t = epochs[i].temp[h];
                const Eigen::Vector3d x(t[0], t[1] - t[0], t[2] - t[0]);
                fitted_[o].x[h] += x;
                fitted_[o].x2[h] += x.cwiseProduct(x);
            }
        }
        for (std::size_t o = 0; o < fitted_.size(); ++o) {
            const double w = count[o] == 0 ? 0.0 : 1.0 / static_cast<double>(count[o]);
            for (std::size_t k = 0; k < list.count; ++k) {
                fitted_[o].x[list.head[k]] *= w;
                fitted_[o].x2[list.head[k]] *= w;
            }
        }
    }

    const LagSearchInput& in_;
    std::array<std::vector<std::int64_t>, kMaxHeads> t_us_;  // [head][epoch], kNoTime for none
    std::array<std::vector<std::array<double, 3>>, kMaxHeads> raw_;
    Lags applied_{};
    std::array<std::size_t, kMaxHeads> first_{};
    std::array<std::size_t, kMaxHeads> last_{};
    std::vector<OrbitAverage> fitted_;
    std::vector<long long> orbit_of_;
    std::map<std::vector<double>, double> scores_;
    std::size_t trials_ = 0;
    double best_score_ = std::numeric_limits<double>::infinity();
    Lags best_{};
};

struct Best {
    double tau = 0.0;
    double score = std::numeric_limits<double>::infinity();
};

// The τ of grid points k_lo … k_hi that minimises f, then (refine) refined
// by golden section (in log τ, whole seconds) between its neighbours on the grid.
template <typename F>
Best minimise_lag(F&& f, int k_lo, int k_hi, bool refine) {
    k_lo = std::max(k_lo, 0);
    k_hi = std::min(k_hi, kGridPoints - 1);
    Best best;
    int k_best = k_lo;
    for (int k = k_lo; k <= k_hi; ++k) {
        const double s = f(grid_tau(k));
        if (s < best.score) {
            best = {grid_tau(k), s};
            k_best = k;
        }
    }
    if (!refine || !std::isfinite(best.score)) {
        return best;
    }
    constexpr double kInvPhi = 0.6180339887498949;
    double a = std::log(grid_tau(std::max(k_best - 1, k_lo)));
    double b = std::log(grid_tau(std::min(k_best + 1, k_hi)));
    const auto g = [&](double x) {
        const double tau = std::round(std::exp(x));
        const double s = f(tau);
        if (s < best.score) {
            best = {tau, s};
        }
        return s;
    };
    double c = b - kInvPhi * (b - a);
    double d = a + kInvPhi * (b - a);
    double fc = g(c);
    double fd = g(d);
    for (int i = 0; i < kGoldenSteps; ++i) {
        if (fc < fd) {
            b = d;
            d = c;
            fd = fc;
            c = b - kInvPhi * (b - a);
            fc = g(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + kInvPhi * (b - a);
            fd = g(d);
        }
    }
    return best;
}

bool lower_by_margin(double s, double reference) {
    return s < reference * (1.0 - kLagSelectionMargin);
}

std::string lags_text(const Lags& lag, HeadMask heads) {
    std::string out;
    const HeadList list = heads_of(heads);
    for (std::size_t i = 0; i < list.count; ++i) {
        out += std::string(i == 0 ? "" : ", ") + head_name(list.head[i]) + " " + number_text(lag[list.head[i]]) + " s";
    }
    return out;
}

std::string verdict_of(const LagSelection& s, HeadMask heads) {
    const double change = 100.0 * (s.best_rms / s.none_rms - 1.0);
    const bool taken = pipeline::any_lagged(s.lag_s);
    char buf[512];
    text::c_snprintf(
        buf, sizeof buf,
        "%s: the best lags found (%s) %s the held-out IBA RMS (mean over the pairs) from %.4f to %.4f arcsec (%+.3f "
        "%%), %s the %.2f %% margin (%zu candidates)",
        taken ? "lagged" : "no lag", lags_text(s.best_lag_s, heads).c_str(), change < 0.0 ? "lower" : "change",
        s.none_rms, s.best_rms, change, taken ? "more than" : "not more than", 100.0 * kLagSelectionMargin, s.trials);
    return buf;
}

}  // namespace

LagSelection select_lags(const LagSearchInput& in) {
    LagSelection sel;
    if (!std::isfinite(in.t_split)) {
        sel.verdict = "no lag: nothing held out to choose one on (--holdout 0)";
        return sel;
    }
    LagScorer scorer(in);
    const HeadList list = heads_of(in.heads);
    sel.none_rms = scorer.score(Lags{});
    if (!std::isfinite(sel.none_rms)) {
        sel.verdict = "no lag: the model without a lag cannot be scored on the held-out part";
        return sel;
    }
    Lags cur{};
    const Best common = minimise_lag(
        [&](double tau) {
            Lags l{};
            for (std::size_t i = 0; i < list.count; ++i) {
                l[list.head[i]] = tau;
            }
            return scorer.score(l);
        },
        0, kGridPoints - 1, true);
    int k_lo = 0;
    int k_hi = kGridPoints - 1;
    if (lower_by_margin(common.score, sel.none_rms)) {
        for (std::size_t i = 0; i < list.count; ++i) {
            cur[list.head[i]] = common.tau;
        }
        const int k_common = pipeline::lag_grid_index(common.tau);
        k_lo = k_common - kHeadSpan;
        k_hi = k_common + kHeadSpan;
    }
    for (std::size_t i = 0; i < list.count; ++i) {
        const std::size_t h = list.head[i];
        const auto with = [&](double tau) {
            Lags l = cur;
            l[h] = tau;
            return scorer.score(l);
        };
        Best own = minimise_lag(with, k_lo, k_hi, false);  // the grid: a head rarely departs
        const double none = with(0.0);
        if (none < own.score) {
            own = {0.0, none};
        } else if (lower_by_margin(own.score, scorer.score(cur))) {
            const int k = pipeline::lag_grid_index(own.tau);
            own = minimise_lag(with, k - 1, k + 1, true);  // the grid's scores are remembered
        }
        if (lower_by_margin(own.score, scorer.score(cur))) {  // a head departs only on clear evidence
            cur[h] = own.tau;
        }
    }
    const double chosen = scorer.score(cur);
    sel.decided = std::isfinite(chosen);
    if (sel.decided && lower_by_margin(chosen, sel.none_rms)) {
        sel.lag_s = cur;
        sel.best_lag_s = cur;
        sel.best_rms = chosen;
    } else {  // the closest any candidate came, for the report
        sel.best_lag_s = scorer.best();
        sel.best_rms = scorer.best_score();
    }
    sel.trials = scorer.trials();
    sel.verdict = verdict_of(sel, in.heads);
    return sel;
}

}  // namespace ascorr::host
