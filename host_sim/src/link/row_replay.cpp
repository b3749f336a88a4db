// `ascorr replay`'s rows: each through the target and the host, in time order, and the answers compared (RowReplay).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <limits>
#include <numeric>
#include <optional>
#include <ostream>
#include <thread>
#include <vector>

#include "ascorr/core/correct.hpp"
#include "ascorr_host/analysis/combine.hpp"
#include "ascorr_host/correct/correct_row.hpp"
#include "ascorr_host/correct/selection.hpp"
#include "ascorr_host/correct/solution_input.hpp"
#include "ascorr_host/formats/corrected_csv.hpp"
#include "replay_parts.hpp"

namespace ascorr::host::detail {

namespace {

// Rotation angle between two attitudes, arcsec, from the vector part of a*⊗b.
double angle_arcsec(const Quaternion<double>& a, const Quaternion<double>& b) {
    const Quaternion<double> d = conjugate(a) * b;
    const double s = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z) / std::sqrt(squared_norm(d));
    return 2.0 * std::asin(std::min(1.0, s)) * kRadToArcsec;
}

// One row through the target and the host: the target's velocity service
// fed the states up to the row's time (mirrored in its scalar and in
// double), the row corrected by the target, by the host's pipeline and, in
// double, by the reference, and the three compared.
template <typename T>
class RowReplay {
public:
    RowReplay(const ReplayOptions& opt, LinkClient<T>& client, const std::optional<StatesFile>& states,
              const VelocityServiceConfig& service, HostSide<T>& host, const ThermalModel<double>& model_d,
              EpochCombination<T>* combination, ReplaySummary& sum, std::chrono::steady_clock::time_point start,
              std::ostream& log)
        : opt_(opt),
          client_(client),
          states_(states),
          mirror_(service),
          mirror_d_(service),
          host_(host),
          model_d_(model_d),
          combination_(combination),
          sum_(sum),
          start_(start),
          log_(log) {}

    WrittenRow operator()(const SolutionRecord& rec) {
        pace(rec.t);
        SentRow s = send_inputs(rec);
        if (combination_ != nullptr) {
            combination_->before(rec.t);
        }
        const link::SolutionOut<T> got =
            client_.correct(id_, s.in.head, s.in.q_chu_icrf, s.timed ? s.t : TtTime{0}, s.from_states,
                            s.from_states && s.in.velocity.valid, s.calib_use);
        ++sum_.returned;
        // The host's answer: the target's pipeline on the host, fed alike.
        const pipeline::VelocityAnswer<T> velocity{s.in.velocity, s.service_status, s.from_states};
        const CorrectedSolution<T> host =
            host_solution(rec, s.in, velocity, s.timed ? s.t.us : 0, s.timed, s.calib_use, got);
        const CorrectedSolution<double> ref = reference(rec, s);
        if (combination_ != nullptr) {
            combination_->after(rec.t);
        }
        compare(rec, got, host, ref);
        const StatusBits written = written_status(rec, got.status, s.time_unusable);
        ++id_;
        return {(got.status & status::kRejected) != 0U ? std::nullopt : std::optional(widen(got.q_chu_icrf)), written};
    }

    double instructions() const noexcept { return instructions_; }
    std::size_t costed() const noexcept { return costed_; }

private:
    static constexpr int kMaxRowMessages = 20;  // of each kind, as the diagnostics of `ascorr correct`

    // A row as sent to the target: the core's inputs in its scalar and in
    // double, its time on the on-board clock, where its velocity came from
    // and how the estimator and the combination take it.
    struct SentRow {
        SolutionInput<T> in;
        SolutionInput<double> in_d;
        TtTime t{};
        bool timed = false;
        bool from_states = false;
        // A time the on-board clock cannot hold (|t| > 1e11 s): the states
        // cannot give a velocity, 4|32 as in `ascorr correct --states`.
        bool time_unusable = false;
        StatusBits service_status = 0U;
        StatusBits service_status_d = 0U;
        std::uint8_t calib_use = 0U;
    };

    // Everything before the solution: the velocity (the states up to the
    // row's time, or the row's own) and the head's temperatures.
    SentRow send_inputs(const SolutionRecord& rec) {
        SentRow s{to_core_input<T>(rec, &earth_), to_core_input<double>(lagged_d(rec), &earth_)};
        s.timed = tt_from_seconds(rec.t, s.t);
        const bool wants_states = states_ && rec.velocity_components == 0;
        s.from_states = wants_states && s.timed;
        s.time_unusable = wants_states && !s.from_states;
        if (s.from_states) {
            velocity_from_states(s.t, s.in, s.in_d, s.service_status, s.service_status_d);
        } else {
            client_.set_velocity(s.in.velocity);
        }
        client_.set_temperatures(s.in.head, s.in.temperatures);
        ++sum_.frames;
        s.calib_use = calib_use_of(rec, s.timed);
        return s;
    }

    // The row as the reference's terms take it: lagged in double over the
    // whole file, as `ascorr correct` lags (the target lags in its scalar,
    // row by row: the host's pipeline mirrors that).
    SolutionRecord lagged_d(const SolutionRecord& rec) const {
        SolutionRecord r = rec;
        if (host_.lagged_d) {
            host_.lagged_d->apply(r);
        }
        return r;
    }

    // The reference: the same rows and models in double, the Sun term in the
    // contract's form (as `ascorr correct`; the target's flight form differs
    // from it by core/correct.hpp's bound). A row whose Sun term cannot be
    // evaluated (t outside 2000-2051) is named, as `ascorr correct` names it.
    CorrectedSolution<double> reference(const SolutionRecord& rec, SentRow& s) {
        const pipeline::VelocityAnswer<double> velocity_d{s.in_d.velocity, s.service_status_d, s.from_states};
        bool sun_unknown = false;
        const CorrectedSolution<double> ref = correct_stage_with_sun(
            s.in_d, velocity_d,
            CorrectionConfig<double>{true, host_.schedule_d ? &host_.schedule_d->at(rec.t) : &model_d_},
            host_.schedule_d ? host_.schedule_d->sun_at(rec.t) : (host_.sun_d ? &*host_.sun_d : nullptr), rec.t,
            sun_unknown);
        if (sun_unknown && sun_messages_ < kMaxRowMessages) {
            ++sun_messages_;
            log_ << opt_.in << ":" << rec.line << ": " << kSunUnknownText << "\n";
        }
        return ref;
    }

    // --realtime: the rows at the pace of their times.
    void pace(double t) {
        if (!opt_.realtime) {
            return;
        }
        if (id_ == 0) {
            t0_ = t;
        }
        std::this_thread::sleep_until(start_ + std::chrono::duration<double>(t - t0_));
    }

    void velocity_from_states(const TtTime& t, SolutionInput<T>& in, SolutionInput<double>& in_d, StatusBits& status,
                              StatusBits& status_d) {
        const auto& a = states_->accepted;
        for (; next_state_ < a.size() && a[next_state_].t <= t; ++next_state_) {  // the bus's time order
            const StateRecord& s = a[next_state_];
            const StateFrame frame = states_->frame;
            client_.send_state({s.t, static_cast<std::uint8_t>(frame == StateFrame::kGcrs ? 1U : 0U), s.r_km, s.v_kms},
                               true);
            mirror_.push_state(s.t, s.r_km, s.v_kms, frame);
            mirror_d_.push_state(s.t, s.r_km, s.v_kms, frame);
        }
        mirror_.advance(t, OnBoardEarth{});
        mirror_d_.advance(t, OnBoardEarth{});
        const ServiceVelocity<T> v = mirror_.velocity_at(t);
        const ServiceVelocity<double> vd = mirror_d_.velocity_at(t);
        in.velocity = v.velocity;
        in_d.velocity = vd.velocity;
        status = v.status;
        status_d = vd.status;
    }

    // SOLUTION_IN's calibration use: kCalibNoTime for a row with no time, and
    // the clean bit: the selection of what the target learns from,
    // as the host's self-calibration over the file (calibration_clean, which
    // also needs the row's own velocity and temperatures); otherwise the
    // combination's, as `correct --combined` (the camera head's own: flags 0,
    // confidence <= 5; the target's pipeline adds the status, usable.hpp).
    std::uint8_t calib_use_of(const SolutionRecord& rec, bool timed) const {
        // No time: in no epoch while calibrating, nor when its head lags.
        const std::uint8_t no_time = timed ? 0U : link::kCalibNoTime;
        bool clean = false;
        if (opt_.self_calibrate) {
            clean = timed && calibration_clean(rec);
        } else if (combination_ != nullptr) {
            clean = clean_for_combination(CorrectedRow::of(rec, std::nullopt));
        }
        return static_cast<std::uint8_t>(no_time | (clean ? link::kCalibClean : 0U));
    }

    CorrectedSolution<T> host_solution(const SolutionRecord& rec, const SolutionInput<T>& in,
                                       const pipeline::VelocityAnswer<T>& velocity, std::int64_t t_us, bool timed,
                                       std::uint8_t calib_use, const link::SolutionOut<T>& got) {
        const auto answer = [&velocity] { return velocity; };
        link::LinkPipeline<T>& p = host_.pipeline;
        CorrectedSolution<T> host{};
        std::optional<std::uint32_t> host_version;
        if (!p.in_epoch(in.head, timed)) {
            host = p.untimed_solution(in, answer);
        } else {
            (void)p.begin(t_us);
            follow_version(p);
            host = p.solution(in, answer, (calib_use & link::kCalibClean) != 0U);
            if (p.calibrating() && p.model() != nullptr) {
                host_version = p.version();
            }
        }
        if (opt_.self_calibrate) {
            check_model_version(client_, opt_.in, rec, got.model_version, host_version, sum_, host_.target_history,
                                log_, *host_.sc);
        }
        return host;
    }

    // At an epoch of a model version new to the pipeline: that version's
    // Sun term (--sun-term auto), as the target's server follows its own.
    void follow_version(link::LinkPipeline<T>& p) {
        if (!opt_.sun_auto || !p.calibrating() || p.model() == nullptr || host_.sun_version == p.version()) {
            return;
        }
        host_.sun_version = p.version();
        const auto term = host_.version_sun.find(p.version());
        p.use_sun_term(term != host_.version_sun.end() ? &term->second : nullptr);
    }

    void compare(const SolutionRecord& rec, const link::SolutionOut<T>& got, const CorrectedSolution<T>& host,
                 const CorrectedSolution<double>& ref) {
        const bool same =
            got.status == host.status && std::memcmp(&got.q_chu_icrf, &host.q_chu_icrf, sizeof host.q_chu_icrf) == 0;
        if (!same) {
            ++sum_.mismatches;
            if (sum_.mismatches <= 20) {
                log_ << opt_.in << ":" << rec.line << ": the target's answer differs from the host core (status "
                     << got.status << " vs " << host.status << ")\n";
            }
        }
        if ((got.status & status::kRejected) == 0U && (ref.status & status::kRejected) == 0U) {
            sum_.max_error_arcsec =
                std::max(sum_.max_error_arcsec, angle_arcsec(widen(got.q_chu_icrf), ref.q_chu_icrf));
        }
        if ((got.status & (status::kAberrationApplied | status::kThermalApplied)) ==
            (status::kAberrationApplied | status::kThermalApplied)) {
            instructions_ += got.instructions;
            ++costed_;
        }
    }

    // The bits the host adds (velocity given but unusable before the core
    // sees it), as `ascorr correct` does.
    StatusBits written_status(const SolutionRecord& rec, StatusBits got, bool time_unusable) {
        StatusBits written = host_status(rec, true, got);
        if (time_unusable && (written & status::kNoVelocity) != 0U) {
            written = static_cast<StatusBits>(written | status::kVelocityInvalid);
        }
        if (written != got && velocity_messages_ < kMaxRowMessages) {
            ++velocity_messages_;
            log_ << opt_.in << ":" << rec.line << ": "
                 << (time_unusable ? "t is outside the on-board clock's range: no velocity from the states"
                                   : velocity_problem(rec))
                 << ": aberration skipped\n";
        }
        return written;
    }

    const ReplayOptions& opt_;
    LinkClient<T>& client_;
    const std::optional<StatesFile>& states_;
    VelocityService<T> mirror_;  // the target's velocity service, in its scalar
    VelocityService<double> mirror_d_;
    std::size_t next_state_ = 0;
    HostSide<T>& host_;
    const ThermalModel<double>& model_d_;
    EpochCombination<T>* combination_;
    ReplaySummary& sum_;
    std::chrono::steady_clock::time_point start_;
    std::ostream& log_;
    EarthVelocity earth_;
    double t0_ = 0.0;
    std::uint32_t id_ = 0;
    double instructions_ = 0.0;
    std::size_t costed_ = 0;
    int velocity_messages_ = 0;
    int sun_messages_ = 0;
};

}  // namespace

// (replay_parts.hpp) As the target and the host's self-calibration take them.
std::vector<std::size_t> time_order(const std::vector<SolutionRecord>& rows) {
    const auto key = [&](std::size_t i) {
        TtTime tt{};
        return tt_from_seconds(rows[i].t, tt) ? tt.us : std::numeric_limits<std::int64_t>::max();
    };
    std::vector<std::size_t> order(rows.size());
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return key(a) < key(b); });
    return order;
}

template <typename T>
ReplayedRows replay_rows(const ReplayOptions& opt, const std::vector<SolutionRecord>& rows, LinkClient<T>& client,
                         const std::optional<StatesFile>& states, const VelocityServiceConfig& service,
                         HostSide<T>& host, const ThermalModel<double>& model_d, EpochCombination<T>* combination,
                         ReplaySummary& sum, std::chrono::steady_clock::time_point start, std::ostream& log) {
    RowReplay<T> replay_row(opt, client, states, service, host, model_d, combination, sum, start, log);
    std::vector<WrittenRow> written_rows(rows.size());
    for (const std::size_t k : time_order(rows)) {
        written_rows[k] = replay_row(rows[k]);
    }
    return {std::move(written_rows), replay_row.instructions(), replay_row.costed()};
}

template ReplayedRows replay_rows(const ReplayOptions&, const std::vector<SolutionRecord>&, LinkClient<float>&,
                                  const std::optional<StatesFile>&, const VelocityServiceConfig&, HostSide<float>&,
                                  const ThermalModel<double>&, EpochCombination<float>*, ReplaySummary&,
                                  std::chrono::steady_clock::time_point, std::ostream&);
template ReplayedRows replay_rows(const ReplayOptions&, const std::vector<SolutionRecord>&, LinkClient<Q30>&,
                                  const std::optional<StatesFile>&, const VelocityServiceConfig&, HostSide<Q30>&,
                                  const ThermalModel<double>&, EpochCombination<Q30>*, ReplaySummary&,
                                  std::chrono::steady_clock::time_point, std::ostream&);

}  // namespace ascorr::host::detail
