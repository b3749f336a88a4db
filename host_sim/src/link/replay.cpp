#include "ascorr_host/link/replay.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <functional>
#include <limits>
#include <memory>
#include <numeric>
#include <optional>
#include <ostream>
#include <stdexcept>
#include <thread>
#include <type_traits>
#include <vector>

#include "ascorr/core/correct.hpp"
#include "ascorr/core/fixed_point.hpp"
#include "ascorr/pipeline/common_rotation_weights.hpp"
#include "ascorr/pipeline/epoch_key.hpp"
#include "ascorr/pipeline/epoch_pipeline.hpp"
#include "ascorr_host/analysis/combine.hpp"
#include "ascorr_host/analysis/iba.hpp"
#include "ascorr_host/correct/selection.hpp"
#include "ascorr_host/correct/self_calibration.hpp"
#include "ascorr_host/correct/solution_input.hpp"
#include "ascorr_host/correct/states_velocity.hpp"
#include "ascorr_host/formats/atomic_file.hpp"
#include "ascorr_host/formats/combined_csv.hpp"
#include "ascorr_host/formats/corrected_csv.hpp"
#include "ascorr_host/formats/csv.hpp"
#include "ascorr_host/formats/model_csv.hpp"
#include "ascorr_host/formats/mountings_csv.hpp"
#include "ascorr_host/formats/states_csv.hpp"
#include "ascorr_host/link/link_client.hpp"
#include "ascorr_host/link/link_transport.hpp"
#include "ascorr_host/link/qemu_targets.hpp"
#include "ascorr_link/server.hpp"
#include "ascorr_text/c_format.hpp"

namespace ascorr::host {

namespace {

// Rotation angle between two attitudes, arcsec, from the vector part of a*⊗b.
double angle_arcsec(const Quaternion<double>& a, const Quaternion<double>& b) {
    const Quaternion<double> d = conjugate(a) * b;
    const double s = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z) / std::sqrt(squared_norm(d));
    return 2.0 * std::asin(std::min(1.0, s)) * kRadToArcsec;
}

template <typename T>
Quaternion<double> widen(const Quaternion<T>& q) {
    const auto d = [](const T& x) { return ScalarTraits<T>::to_double(x); };
    return {d(q.w), d(q.x), d(q.y), d(q.z)};
}

// The in-process target: the firmware's LinkServer behind a loopback.
template <typename T>
class LoopbackTarget {
public:
    struct NoCounter {
        std::uint32_t operator()() const { return 0; }  // no instruction counter in process
    };
    LoopbackTarget()
        : server_(0x4C4F4F50U, NoCounter{}),
          transport_([this](const std::uint8_t* p, std::size_t n, const LoopbackTransport::Reply& reply) {
              for (std::size_t i = 0; i < n; ++i) {
                  server_.on_byte(p[i], reply);
              }
          }) {}
    Transport& transport() { return transport_; }

private:
    link::LinkServer<T, NoCounter> server_;
    LoopbackTransport transport_;
};

// Whether two doubles are the same value: bit for bit, or both NaN (the
// targets' and the host's default NaNs differ in sign).
bool same_double(double a, double b) {
    return (std::isnan(a) && std::isnan(b)) || std::memcmp(&a, &b, sizeof a) == 0;
}

// The first field in which a (the target's) and b (the host's) differ, with
// both values; empty when they are the same (doubles: same_double).
std::string first_report_difference(const calib::EstimatorReport& a, const calib::EstimatorReport& b) {
    const auto u = [](const char* name, std::uint64_t x, std::uint64_t y) {
        return x == y ? std::string()
                      : std::string(name) + ": target " + std::to_string(x) + ", host " + std::to_string(y);
    };
    const auto d = [](const char* name, double x, double y) {
        return same_double(x, y) ? std::string()
                                 : std::string(name) + ": target " + number_text(x) + ", host " + number_text(y);
    };
    const std::string fields[] = {
        u("orbits used", a.orbits_used, b.orbits_used),
        u("orbits short", a.orbits_short, b.orbits_short),
        u("orbits held back", a.orbits_held, b.orbits_held),
        u("orbits late", a.orbits_late, b.orbits_late),
        u("changes", a.changes, b.changes),
        d("condition", a.condition, b.condition),
        d("residual RMS", a.residual_rms_arcsec, b.residual_rms_arcsec),
        d("candidate RMS", a.candidate_rms_arcsec, b.candidate_rms_arcsec),
        u("has a model", a.has_active, b.has_active),
        u("active version", a.active_version, b.active_version),
        u("active CRC-32C", a.active_crc, b.active_crc),
        u("last refusal", static_cast<unsigned>(a.last_refusal), static_cast<unsigned>(b.last_refusal)),
        u("frozen", a.frozen, b.frozen)};
    for (const std::string& f : fields) {
        if (!f.empty()) {
            return f;
        }
    }
    for (std::size_t i = 1; i < calib::kRefusalKinds; ++i) {
        if (a.refusals[i] != b.refusals[i]) {
            return std::string("refusals '") + calib::refusal_name(static_cast<calib::Refusal>(i)) + "': target " +
                   std::to_string(a.refusals[i]) + ", host " + std::to_string(b.refusals[i]);
        }
    }
    return {};
}

// The target's model `version`, head by head (CALIB_MODEL), as a history entry
// active from t (the first solution corrected with it).
template <typename T>
ActiveModel target_model(LinkClient<T>& client, double t) {
    ActiveModel a{t, 0, 0, 0, ModelFile{}};
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        const link::CalibModel m = client.calib_model(h);
        a.t_us = m.active_from_us;
        a.version = m.version;
        a.crc = m.crc;
        a.model.present[h] = m.present == 1U;
        for (std::size_t x = 0; x < kModelAxes; ++x) {
            for (std::size_t i = 0; i < kLinearModelTerms; ++i) {
                a.model.coefficients[h][x][i] = m.c[x][i];
            }
        }
    }
    return a;
}

// What differs first between a (the target's) and b (the host's) model of
// one version: the epoch, a head's presence, a coefficient or the CRC; empty
// when they are the same model, active from the same epoch.
std::string first_model_difference(const ActiveModel& a, const ActiveModel& b) {
    if (a.t_us != b.t_us) {
        return "active from TT " + std::to_string(a.t_us) + " us on the target, " + std::to_string(b.t_us) +
               " us on the host";
    }
    for (std::size_t h = 0; h < kMaxHeads; ++h) {
        const std::string head(1, head_name(static_cast<std::uint8_t>(h)));
        if (a.model.present[h] != b.model.present[h]) {
            return "head " + head + (a.model.present[h] ? " present" : " absent") + " on the target only";
        }
        for (std::size_t x = 0; x < kModelAxes; ++x) {
            for (std::size_t i = 0; i < kModelTerms; ++i) {
                if (!same_double(a.model.coefficients[h][x][i], b.model.coefficients[h][x][i])) {
                    return "head " + head + " " + kAxisNames[x] + " c" + std::to_string(i) + ": target " +
                           number_text(a.model.coefficients[h][x][i]) + ", host " +
                           number_text(b.model.coefficients[h][x][i]);
                }
            }
        }
    }
    if (a.crc == b.crc) {
        return {};
    }
    char buf[64];
    text::c_snprintf(buf, sizeof buf, "CRC-32C %08x on the target, %08x on the host", a.crc, b.crc);
    return buf;
}

constexpr std::size_t kMaxCalibMessages = 20;  // per kind, as the diagnostics of `ascorr correct`

// A solution's model version on the target against the host's (`want`); a
// version the target uses for the first time is fetched (CALIB_MODEL) and
// compared with the host's model of that version.
template <typename T>
void check_model_version(LinkClient<T>& client, const std::string& file, const SolutionRecord& rec, std::uint32_t got,
                         const std::optional<std::uint32_t>& want, ReplaySummary& sum,
                         std::vector<ActiveModel>& target_history, std::ostream& log, const SelfCalibration& host_sc) {
    const bool same = want ? got == *want : got == link::kNoModelVersion;
    if (!same && ++sum.version_mismatches <= kMaxCalibMessages) {
        log << file << ":" << rec.line << ": the target corrected with model version "
            << (got == link::kNoModelVersion ? std::string("none") : std::to_string(got)) << ", the host with "
            << (want ? std::to_string(*want) : std::string("none")) << "\n";
    }
    if (got == link::kNoModelVersion || (!target_history.empty() && target_history.back().version == got)) {
        return;
    }
    target_history.push_back(target_model(client, rec.t));
    ActiveModel& mine = target_history.back();
    const auto host = std::find_if(host_sc.history.begin(), host_sc.history.end(),
                                   [&](const ActiveModel& a) { return a.version == mine.version; });
    if (host != host_sc.history.end()) {
        mine.learnt = host->learnt;  // the link does not say; the comparison below checks the coefficients
    }
    const std::string difference =
        host == host_sc.history.end() ? "the host has no such version" : first_model_difference(mine, *host);
    if (!difference.empty()) {
        if (++sum.history_mismatches <= kMaxCalibMessages) {
            char buf[200];
            text::c_snprintf(buf, sizeof buf, "model version %u (crc32c %08x) differs from the host's: ", mine.version,
                             mine.crc);
            log << "ascorr replay: the target's " << buf << difference << "\n";
        }
    }
}

// The end of a self-calibrating replay: the host's models the target never
// used, and the final report.
template <typename T>
void finish_self_calibration(LinkClient<T>& client, ReplaySummary& sum, const std::vector<ActiveModel>& target_history,
                             std::ostream& log, const SelfCalibration& host_sc) {
    sum.models = target_history.size();
    for (const ActiveModel& a : host_sc.history) {
        const bool seen = std::any_of(target_history.begin(), target_history.end(),
                                      [&](const ActiveModel& b) { return b.version == a.version; });
        if (!seen && ++sum.history_mismatches <= kMaxCalibMessages) {
            log << "ascorr replay: the host's model version " << a.version << " was never used by the target\n";
        }
    }
    const calib::EstimatorReport r = client.calib_report();
    const std::string difference = first_report_difference(r, host_sc.report);
    sum.report_matches = difference.empty();
    if (!sum.report_matches) {
        log << "ascorr replay: the target's estimator report differs from the host's: " << difference << "\n";
    }
    SelfCalibration on_target = host_sc;
    on_target.history = target_history;
    on_target.report = r;
    log << "ascorr replay: on the target, " << describe(on_target) << "\n";
}

// --mountings/--combined: each epoch (rows whose t agree to the
// millisecond, pipeline/epoch_key.hpp; in time order they come together) is
// combined on the target (COMBINE_REQUEST after its last solution) and on the
// host by the same pipeline stage in the same scalar, and the two compared
// bit for bit; the target's is the combined file's row, with the formal σ of
// the host's tables (the same mountings, the head set only). A row in no
// epoch is combined alone and dropped on both sides.
template <typename T>
class EpochCombination {
public:
    EpochCombination(const MountingsFile& m, const combine::CombinerConfig& gate, LinkClient<T>& client,
                     link::LinkPipeline<T>& host, std::string file, std::ostream& log)
        : client_(client), host_(host), combiner_(m.mountings, gate), file_(std::move(file)), log_(log) {
        client_.load_mountings(m.mountings, gate);
        host_.use_combiner(&combiner_);
        text_ = std::string(kCombinedHeader) + "\n";
    }

    // Before a row at t is sent: the open epoch ends when t is of another.
    void before(double t) {
        const std::optional<std::int64_t> key = pipeline::epoch_key_of(t);
        if (grouper_.ends_before(key)) {
            close(true);
        }
        if (key && grouper_.add(*key)) {
            t_ = t;
        }
    }
    // After a row at t is sent: a row in no epoch is combined alone, dropped.
    void after(double t) {
        if (!pipeline::has_epoch_key(t)) {
            close(false);
        }
    }
    void finish(ReplaySummary& sum) {
        if (grouper_.is_open()) {
            close(true);
        }
        sum.combined = true;
        sum.combined_epochs = epochs_;
        sum.combined_mismatches = mismatches_;
        sum.combination_instructions_per_epoch = costed_ == 0 ? 0.0 : instructions_ / static_cast<double>(costed_);
    }
    const std::string& text() const noexcept { return text_; }

private:
    void close(bool write) {
        grouper_.close();
        const link::Combined<T> got = client_.combine_epoch();
        const combine::CombinedAttitude<T> want = host_.close();
        const bool same = got.status == want.status && got.used == want.used && got.left_out == want.left_out &&
                          got.inconsistent == want.inconsistent &&
                          std::memcmp(&got.q_crf_icrf, &want.q_crf_icrf, sizeof got.q_crf_icrf) == 0;
        if (!same && ++mismatches_ <= kMaxCalibMessages) {
            log_ << file_ << ": epoch t = " << number_text(t_) << ": the target's combined attitude differs from the "
                 << "host's (status " << unsigned{got.status} << " vs " << unsigned{want.status} << ", heads "
                 << head_letters(got.used) << " vs " << head_letters(want.used) << ")\n";
        }
        if (!write) {
            return;
        }
        ++epochs_;
        if ((got.status & combine::combined_status::kTwoOrMoreHeads) != 0U) {
            instructions_ += got.instructions;
            ++costed_;
        }
        AttitudeRow row;
        row.t = t_;
        row.has_q = (got.status & combine::combined_status::kNoHead) == 0U;
        row.q_crf_icrf = widen(got.q_crf_icrf);
        row.heads = row.has_q ? got.used : 0U;
        const double* sigma = combiner_.sigma_arcsec(got.used);
        row.sigma_arcsec = {sigma[0], sigma[1], sigma[2]};
        row.status = got.status;
        append_combined_row(text_, row);
    }

    LinkClient<T>& client_;
    link::LinkPipeline<T>& host_;
    combine::Combiner<T> combiner_;
    std::string file_;
    std::ostream& log_;
    pipeline::ConsecutiveEpochs grouper_;  // consecutive rows with one key
    double t_ = 0.0;                       // the epoch's first (earliest) row's
    std::size_t epochs_ = 0;
    std::size_t mismatches_ = 0;
    double instructions_ = 0.0;
    std::size_t costed_ = 0;
    std::string text_;
};

// --model read and checked for the target's scalar (refused before the
// target sees it, as by `correct`); none without --model.
template <typename T>
std::optional<ModelFile> read_replay_model(const ReplayOptions& opt) {
    if (opt.model.empty()) {
        return std::nullopt;
    }
    ModelFile mf = read_model_file(opt.model);
    check_model_for_scalar(mf, scalar_kind_of<T>(), opt.model);
    if (opt.self_calibrate) {
        refuse_quadratic_initial_model(mf, opt.model);
    }
    return mf;
}

std::optional<StatesFile> read_replay_states(const ReplayOptions& opt, std::ostream& log) {
    if (opt.states.empty()) {
        return std::nullopt;
    }
    Diagnostics diag(log);
    std::optional<StatesFile> states =
        read_states_file(opt.states, opt.states_gcrs ? StateFrame::kGcrs : StateFrame::kItrf, diag);
    diag.summarize();
    return states;
}

// The host's side of a replay: the target's pipeline on the host, with
// --self-calibrate the host's run of the estimator over the file.
template <typename T>
struct HostSide {
    std::optional<SelfCalibration> sc;
    std::optional<ModelSchedule<double>> schedule_d;  // the host's models in double, for the reference
    std::optional<link::LinkEstimator<T>> estimator;  // the link's
    link::LinkPipeline<T> pipeline;
    std::vector<ActiveModel> target_history;
};

// --self-calibrate: the host's run of the estimator over the file, and the
// target's started alike; otherwise the model uploaded and used on both.
// rule: the estimator's rule for the rotation common to all heads (the
// mountings of --combined, already loaded on the target; none: its frame).
template <typename T>
void start_host(const ReplayOptions& opt, const std::vector<SolutionRecord>& rows, const std::optional<ModelFile>& mf,
                const ThermalModel<T>& model_t, LinkClient<T>& client, HostSide<T>& host, ReplaySummary& sum,
                const calib::CommonRotationWeights& rule) {
    if (!opt.self_calibrate) {
        client.upload_model(model_t);
        host.pipeline.use_model(&model_t);
        return;
    }
    calib::EstimatorConfig ecfg;
    ecfg.time_constant_days = opt.time_constant_days;
    ecfg.common_rotation = rule;
    host.sc = self_calibrate<T>(
        opt.in,
        [&](const std::function<void(const SolutionRecord&)>& fn) {
            for (const SolutionRecord& r : rows) {
                fn(r);
            }
        },
        mf, ecfg, opt.orbit_period_s);
    host.schedule_d.emplace(host.sc->history);
    std::optional<ModelCoefficients> initial;
    if (mf) {
        initial = coefficients_of(*mf);
    }
    const std::int64_t period_us = std::llround(host.sc->orbit_period_s * 1e6);
    client.start_calibration(period_us, opt.time_constant_days, initial ? &*initial : nullptr, rule.heads != 0U);
    calib::EstimatorConfig host_cfg{};  // as the target's CALIB_START makes it
    host_cfg.orbit_period_us = period_us;
    host_cfg.time_constant_days = opt.time_constant_days;
    host_cfg.common_rotation = rule;
    host.estimator.emplace(host_cfg, initial ? &*initial : nullptr);
    host.pipeline.use_estimator(&*host.estimator);
    sum.self_calibrate = true;
}

// Time order is the on-board clock's (TT µs; rows within one microsecond
// in file order, as the target and the host's self-calibration take
// them); rows whose t the clock cannot hold come last.
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

struct WrittenRow {
    std::optional<Quaternion<double>> q;  // none: rejected, the input text unchanged
    StatusBits status;
};

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
        SolutionInput<T> in = to_core_input<T>(rec, &earth_);
        SolutionInput<double> in_d = to_core_input<double>(rec, &earth_);
        TtTime t{};
        const bool timed = tt_from_seconds(rec.t, t);
        const bool wants_states = states_ && rec.velocity_components == 0;
        const bool from_states = wants_states && timed;
        // A time the on-board clock cannot hold (|t| > 1e11 s): the states
        // cannot give a velocity, 4|32 as in `ascorr correct --states`.
        const bool time_unusable = wants_states && !from_states;
        StatusBits service_status = 0U;
        StatusBits service_status_d = 0U;
        if (from_states) {
            velocity_from_states(t, in, in_d, service_status, service_status_d);
        } else {
            client_.set_velocity(in.velocity);
        }
        client_.set_temperatures(in.head, in.temperatures);
        ++sum_.frames;
        const std::uint8_t calib_use = calib_use_of(rec, timed);
        if (combination_ != nullptr) {
            combination_->before(rec.t);
        }
        const link::SolutionOut<T> got = client_.correct(id_, in.head, in.q_chu_icrf, timed ? t : TtTime{0},
                                                         from_states, from_states && in.velocity.valid, calib_use);
        ++sum_.returned;
        // The host's answer: the target's pipeline on the host, fed alike.
        const pipeline::VelocityAnswer<T> velocity{in.velocity, service_status, from_states};
        const CorrectedSolution<T> host = host_solution(rec, in, velocity, timed ? t.us : 0, timed, calib_use, got);
        // The reference: the same rows and models in double.
        const pipeline::VelocityAnswer<double> velocity_d{in_d.velocity, service_status_d, from_states};
        const CorrectedSolution<double> ref = pipeline::correct_stage(
            in_d, velocity_d,
            CorrectionConfig<double>{true, host_.schedule_d ? &host_.schedule_d->at(rec.t) : &model_d_});
        if (combination_ != nullptr) {
            combination_->after(rec.t);
        }
        compare(rec, got, host, ref);
        const StatusBits written = written_status(rec, got.status, time_unusable);
        ++id_;
        return {(got.status & status::kRejected) != 0U ? std::nullopt : std::optional(widen(got.q_chu_icrf)), written};
    }

    double instructions() const noexcept { return instructions_; }
    std::size_t costed() const noexcept { return costed_; }

private:
    static constexpr int kMaxVelocityMessages = 20;  // as the diagnostics of `ascorr correct`

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

    // SOLUTION_IN's clean bit: the selection of what the target learns from,
    // as the host's self-calibration over the file (calibration_clean, which
    // also needs the row's own velocity and temperatures); otherwise the
    // combination's, as `correct --combined` (the camera head's own: flags 0,
    // confidence <= 5; the target's pipeline adds the status, usable.hpp).
    std::uint8_t calib_use_of(const SolutionRecord& rec, bool timed) const {
        std::uint8_t calib_use = 0U;
        if (opt_.self_calibrate) {
            calib_use = !timed ? link::kCalibNoTime : (calibration_clean(rec) ? link::kCalibClean : 0U);
        } else if (combination_ != nullptr) {
            calib_use = clean_for_combination(CorrectedRow::of(rec, false, 0U)) ? link::kCalibClean : 0U;
        }
        return calib_use;
    }

    CorrectedSolution<T> host_solution(const SolutionRecord& rec, const SolutionInput<T>& in,
                                       const pipeline::VelocityAnswer<T>& velocity, std::int64_t t_us, bool timed,
                                       std::uint8_t calib_use, const link::SolutionOut<T>& got) {
        const auto answer = [&velocity] { return velocity; };
        link::LinkPipeline<T>& p = host_.pipeline;
        CorrectedSolution<T> host{};
        std::optional<std::uint32_t> host_version;
        if (p.calibrating() && !timed) {
            host = p.untimed_solution(in, answer);
        } else {
            (void)p.begin(t_us);
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
        if (written != got && velocity_messages_ < kMaxVelocityMessages) {
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
};

template <typename T>
ReplaySummary run(const ReplayOptions& opt, Transport& raw, OutputSet& outputs, std::ostream& log) {
    const std::string text = read_text_file(opt.in);
    SolutionsReader reader(opt.in, text);
    refuse_corrected_input(reader);
    // The thermal model: --model's, or with --self-calibrate the estimator's
    // (--model, if given, is its version 0).
    const std::optional<ModelFile> mf = read_replay_model<T>(opt);
    const ThermalModel<T> model_t = mf ? to_core<T>(*mf) : ThermalModel<T>{};
    const ThermalModel<double> model_d = mf ? to_core<double>(*mf) : ThermalModel<double>{};

    std::unique_ptr<FaultInjector> injector;
    Transport* transport = &raw;
    if (opt.inject_errors > 0.0) {
        injector = std::make_unique<FaultInjector>(raw, opt.inject_errors, opt.seed);
        transport = injector.get();
    }
    LinkClient<T> client(*transport, opt.timeout_ms, opt.max_attempts);
    const link::Hello hello = client.connect();
    log << "ascorr replay: target " << opt.target << " (boot id " << hello.boot_id << ", scalar kind "
        << static_cast<int>(hello.scalar_kind) << ")\n";
    const std::optional<StatesFile> states = read_replay_states(opt, log);
    // The target's velocity service, mirrored in its scalar and in double.
    const VelocityServiceConfig service =
        opt.max_propagation_s ? service_config(*opt.max_propagation_s) : default_velocity_service_config();
    if (opt.max_propagation_s) {
        client.set_service_horizon(service.horizon_us);
    }

    const RowWriter writer(reader);
    AtomicFile& out = outputs["--out"];
    out.write(writer.header_line());
    std::string buf;
    SolutionRecord record;
    const auto start = std::chrono::steady_clock::now();
    // The rows go to the target in time order, as a DPU takes them (its
    // velocity service is causal: a row earlier than a state it already has
    // would get none), so that any row order gives `ascorr correct`'s answers;
    // they are written in file order.
    std::vector<SolutionRecord> rows;
    while (reader.next(record)) {
        rows.push_back(record);
    }
    ReplaySummary sum;
    HostSide<T> host;
    // The mountings first: the target's estimator takes its rule's weights
    // from those staged when CALIB_START comes (correct --self-calibrate
    // --combined's rule).
    std::optional<EpochCombination<T>> combination;
    calib::CommonRotationWeights rule{};
    if (!opt.combined.empty()) {
        const MountingsFile m = read_mountings_file(opt.mountings);
        // The target combines as the flight loop does (its gate, pre-flight
        // mountings), unless --gate-sigmas/--gate-floor say otherwise.
        const combine::CombinerConfig gate = gate_config(opt.gate, combine::flight_gate());
        refuse_unusable_mountings(m, opt.mountings, std::vector<combine::CombinerConfig>{gate});
        combination.emplace(m, gate, client, host.pipeline, opt.in, log);
        rule = pipeline::common_rotation_weights(m.mountings);
    }
    start_host(opt, rows, mf, model_t, client, host, sum, rule);
    RowReplay<T> replay_row(opt, client, states, service, host, model_d, combination ? &*combination : nullptr, sum,
                            start, log);
    std::vector<WrittenRow> written_rows(rows.size());
    for (const std::size_t k : time_order(rows)) {
        written_rows[k] = replay_row(rows[k]);
    }
    SolutionsReader again(opt.in, text);
    for (std::size_t k = 0; again.next(record); ++k) {
        writer.row(again, written_rows[k].q, written_rows[k].status, buf);
    }
    out.write(buf);
    if (opt.self_calibrate) {
        finish_self_calibration(client, sum, host.target_history, log, *host.sc);
        if (outputs.has("--model-history")) {
            outputs["--model-history"].write(format_model_history(host.target_history, rule.heads != 0U));
        }
    }
    if (combination) {
        combination->finish(sum);
        outputs["--combined"].write(combination->text());
    }
    const LinkStats& st = client.stats();
    sum.crc_errors = st.naks + st.broken_answers;
    sum.retries = st.retries;
    sum.restarts = st.restarts;
    sum.instructions_per_solution =
        replay_row.costed() == 0 ? 0.0 : replay_row.instructions() / static_cast<double>(replay_row.costed());
    if (injector) {
        sum.injected = injector->to_target().total() + injector->to_host().total();
    }
    return sum;
}

}  // namespace

namespace {

// Refuses, naming the file and why, an image QEMU would fail on only after
// starting (a register dump, then a closed link): not a 32-bit little-endian
// ARM executable ELF, a hard-float image for a board without an FPU (the
// toolchain's cpus with an FPU are named so: cortex-m4f), or an entry point outside the MPS2
// boards' code memory, where the images are linked (__flash = 0, 4 MiB:
// toolchain/arm-none-eabi-picolibc.cmake).
void check_link_image(const std::string& path, const QemuTarget& board) {
    constexpr std::uint32_t kCodeMemoryBytes = 0x400000U;
    constexpr std::uint16_t kElfExecutable = 2U;
    constexpr std::uint16_t kElfMachineArm = 40U;
    constexpr std::uint32_t kArmFloatHard = 0x400U;  // EF_ARM_ABI_FLOAT_HARD
    std::ifstream f(path, std::ios::binary);
    unsigned char h[52] = {};
    f.read(reinterpret_cast<char*>(h), sizeof h);
    const auto u16 = [&](std::size_t at) { return static_cast<std::uint16_t>(h[at] | (h[at + 1] << 8)); };
    const auto u32 = [&](std::size_t at) {
        return static_cast<std::uint32_t>(h[at]) | (static_cast<std::uint32_t>(h[at + 1]) << 8) |
               (static_cast<std::uint32_t>(h[at + 2]) << 16) | (static_cast<std::uint32_t>(h[at + 3]) << 24);
    };
    const std::string where = "--firmware " + path + ": not a link image for --target " + std::string(board.replay) +
                              " (" + std::string(board.machine) + "): ";
    if (f.gcount() < static_cast<std::streamsize>(sizeof h) || h[0] != 0x7F || h[1] != 'E' || h[2] != 'L' ||
        h[3] != 'F') {
        throw std::runtime_error(where + "not an ELF file");
    }
    if (h[4] != 1 || h[5] != 1) {
        throw std::runtime_error(where + "not a 32-bit little-endian ELF (class " + std::to_string(h[4]) + ", data " +
                                 std::to_string(h[5]) + ")");
    }
    if (u16(18) != kElfMachineArm) {
        throw std::runtime_error(where + "ELF machine " + std::to_string(u16(18)) + ", not ARM (40)");
    }
    if (u16(16) != kElfExecutable) {
        throw std::runtime_error(where + "ELF type " + std::to_string(u16(16)) + ", not an executable (2)");
    }
    const bool hard = (u32(36) & kArmFloatHard) != 0U;
    const bool fpu = !board.cpu.empty() && board.cpu.back() == 'f';
    if (hard && !fpu) {
        throw std::runtime_error(where + "a hard-float image, and the board's cpu (" + std::string(board.cpu) +
                                 ") has no FPU");
    }
    const std::uint32_t entry = u32(24);
    if (entry >= kCodeMemoryBytes) {
        char buf[120];
        text::c_snprintf(buf, sizeof buf, "entry point 0x%08x is outside the board's code memory [0, 0x%x)", entry,
                         kCodeMemoryBytes);
        throw std::runtime_error(where + buf);
    }
}

}  // namespace

namespace {

// The options' refusals that need no input read (nothing was written).
void check_options(const ReplayOptions& opt) {
    std::vector<NamedPath> outputs = {{"--out", opt.out}};
    if (!opt.model_history.empty()) {
        outputs.push_back({"--model-history", opt.model_history});
    }
    if (!opt.combined.empty()) {
        outputs.push_back({"--combined", opt.combined});
    }
    refuse_output_over_input({{"--in", opt.in},
                              {"--model", opt.model},
                              {"--firmware", opt.firmware},
                              {"--states", opt.states},
                              {"--mountings", opt.mountings}},
                             outputs, true);
    if (opt.combined.empty() != opt.mountings.empty()) {
        throw std::runtime_error("--mountings and --combined go together");
    }
    if (!opt.combined.empty()) {
        refuse_same_output({"--out", opt.out}, {"--combined", opt.combined});
        if (!opt.model_history.empty()) {
            refuse_same_output({"--model-history", opt.model_history}, {"--combined", opt.combined});
        }
    }
    if (opt.max_propagation_s && !max_propagation_acceptable(*opt.max_propagation_s)) {
        throw std::runtime_error("--max-propagation " + number_text(*opt.max_propagation_s) + ": " +
                                 kMaxPropagationRule);
    }
    if (opt.self_calibrate) {
        if (!opt.states.empty()) {  // as `ascorr correct --self-calibrate`
            throw std::runtime_error(
                "--self-calibrate learns from rows with their own vx,vy,vz: it cannot go with --states");
        }
        if (!opt.model_history.empty()) {
            refuse_same_output({"--out", opt.out}, {"--model-history", opt.model_history});
        }
        if (!calib::time_constant_acceptable(opt.time_constant_days)) {
            throw std::runtime_error("--time-constant " + number_text(opt.time_constant_days) + ": must be in " +
                                     time_constant_range() + " days");
        }
        if (opt.orbit_period_s && !orbit_period_acceptable(*opt.orbit_period_s)) {
            throw std::runtime_error("--orbit-period " + number_text(*opt.orbit_period_s) + ": must be in " +
                                     orbit_period_range() + " s");
        }
    } else {
        if (opt.model.empty()) {
            throw std::runtime_error(
                "--model is needed (the thermal model the target corrects with), unless "
                "--self-calibrate");
        }
        if (!opt.model_history.empty()) {
            throw std::runtime_error("--model-history needs --self-calibrate");
        }
        if (opt.orbit_period_s) {
            throw std::runtime_error("--orbit-period needs --self-calibrate");
        }
    }
}

// The session over a transport already open: the target's HELLO says which
// scalar it computes in, and the session speaks that one.
ReplaySummary run_as_announced(const ReplayOptions& o, Transport& transport, OutputSet& outputs, std::ostream& log) {
    const std::uint8_t kind = LinkClient<float>(transport, o.timeout_ms, o.max_attempts).request_hello().scalar_kind;
    if (kind == link::WireTraits<Q30>::kKind) {
        return run<Q30>(o, transport, outputs, log);
    }
    if (kind == link::WireTraits<float>::kKind) {
        return run<float>(o, transport, outputs, log);
    }
    throw LinkError(o.target + ": the target computes in scalar kind " + std::to_string(kind) +
                    ", which this host does not speak (1 = float, 2 = Q30)");
}

}  // namespace

std::vector<NamedPath> replay_inputs(const ReplayOptions& opt) {
    return {{"--in", opt.in},
            {"--model", opt.model},
            {"--firmware", opt.firmware},
            {"--states", opt.states},
            {"--mountings", opt.mountings}};
}

std::vector<NamedPath> replay_outputs(const ReplayOptions& opt) {
    std::vector<NamedPath> outputs = {{"--out", opt.out}};
    if (opt.self_calibrate && !opt.model_history.empty()) {
        outputs.push_back({"--model-history", opt.model_history});
    }
    if (!opt.combined.empty()) {
        outputs.push_back({"--combined", opt.combined});
    }
    return outputs;
}

ReplaySummary replay_over(const ReplayOptions& opt, Transport& transport, std::ostream& log) {
    check_options(opt);
    OutputSet outputs(replay_outputs(opt), replay_inputs(opt));
    ReplayOptions o = opt;
    o.timeout_ms = opt.timeout_ms > 0 ? opt.timeout_ms : 500;
    const ReplaySummary s = run_as_announced(o, transport, outputs, log);
    outputs.commit();
    return s;
}

ReplaySummary replay(const ReplayOptions& opt, std::ostream& log) {
    check_options(opt);
    OutputSet outputs(replay_outputs(opt), replay_inputs(opt));
    const ReplaySummary s = replay(opt, outputs, log);
    outputs.commit();
    return s;
}

ReplaySummary replay(const ReplayOptions& opt, OutputSet& outputs, std::ostream& log) {
    check_options(opt);
    ReplayOptions o = opt;
    if (opt.target == "loopback-float") {
        o.timeout_ms = opt.timeout_ms > 0 ? opt.timeout_ms : 1;  // answers are there at once or never
        LoopbackTarget<float> target;
        return run<float>(o, target.transport(), outputs, log);
    }
    if (const QemuTarget* board = find_qemu_target(opt.target)) {  // toolchain/targets.txt
        const bool fixed = board->scalar == ScalarKind::kFixed;
        // QEMU answers within a few milliseconds; a lost frame is resent soon after
        // (a late answer only costs a resend, answered from the cache).
        // With states the target's double propagation and Earth series (software
        // double on both boards) can delay an answer past 20 ms on a loaded machine.
        o.timeout_ms = opt.timeout_ms > 0 ? opt.timeout_ms : (opt.states.empty() ? 20 : 100);
        const std::string image = opt.firmware.empty() ? default_link_firmware(std::string(board->cpu)) : opt.firmware;
        if (!std::ifstream(image).good()) {
            throw std::runtime_error(image + ": cannot read the link firmware image");
        }
        check_link_image(image, *board);
        ProcessTransport qemu(qemu_link_command(std::string(board->machine), image));
        return fixed ? run<Q30>(o, qemu, outputs, log) : run<float>(o, qemu, outputs, log);
    }
    if (opt.target.rfind("/dev/", 0) == 0) {
        o.timeout_ms = opt.timeout_ms > 0 ? opt.timeout_ms : 500;
        SerialTransport serial(opt.target, opt.baud);
        return run_as_announced(o, serial, outputs, log);
    }
    throw std::runtime_error("--target " + opt.target + ": unknown target (loopback-float, " + qemu_target_names() +
                             " or a serial device such as /dev/ttyUSB0)");
}

std::vector<std::string> qemu_link_command(const std::string& machine, const std::string& image) {
    // UART0 on our stdin/stdout (no monitor, no mux, no signals from bytes
    // like 0x03); semihosting, unused by the link image, to a null device;
    // -icount shift=0: one instruction per nanosecond while the core runs, so
    // that the image's SysTick counts instructions (40 per count,
    // firmware/app/link_main.cpp); sleep=off keeps virtual time out of real
    // time (the image stops SysTick while it waits, so QEMU idles, with a
    // one-line warning that no timer is active).
    return {"qemu-system-arm",
            "-M",
            machine,
            "-display",
            "none",
            "-monitor",
            "none",
            "-chardev",
            "stdio,id=link,signal=off",
            "-serial",
            "chardev:link",
            "-chardev",
            "null,id=semi",
            "-semihosting-config",
            "enable=on,target=native,chardev=semi",
            "-icount",
            "shift=0,sleep=off",
            "-kernel",
            image};
}

std::string default_link_firmware(const std::string& target) {
#ifdef ASCORR_LINK_FIRMWARE_DIR
    const std::string path =
        std::string(ASCORR_LINK_FIRMWARE_DIR) + "/" + target + "/firmware/app/ascorr_link_firmware.elf";
    if (std::ifstream(path).good()) {
        return path;
    }
    throw std::runtime_error(path +
                             ": no link firmware image; build with the ci preset (ASCORR_TARGETS) or pass --firmware");
#else
    throw std::runtime_error("no link firmware image for " + target +
                             " in this build (configured without ASCORR_TARGETS): pass --firmware");
#endif
}

bool agrees(const ReplaySummary& s) {
    return s.mismatches == 0 &&
           (!s.self_calibrate || (s.version_mismatches == 0 && s.history_mismatches == 0 && s.report_matches)) &&
           (!s.combined || s.combined_mismatches == 0);
}

std::string disagreement(const ReplaySummary& s) {
    std::string out = "replay: the target disagrees with the host: " + std::to_string(s.mismatches) + " answer(s)";
    if (s.self_calibrate) {
        out += ", " + std::to_string(s.version_mismatches) + " model version(s), " +
               std::to_string(s.history_mismatches) + " model(s), the report " +
               (s.report_matches ? "agrees" : "differs");
    }
    if (s.combined) {
        out += ", " + std::to_string(s.combined_mismatches) + " combined attitude(s)";
    }
    return out + " (the outputs are written; see the messages above)";
}

std::string to_json(const ReplaySummary& s) {
    char buf[512];
    text::c_snprintf(buf, sizeof buf,
                     "{\"frames\": %zu, \"returned\": %zu, \"mismatches\": %zu, \"max_error_arcsec\": %.6g, "
                     "\"crc_errors\": %zu, \"retries\": %zu, \"instructions_per_solution\": %.1f, \"restarts\": %zu, "
                     "\"injected_faults\": %zu",
                     s.frames, s.returned, s.mismatches, s.max_error_arcsec, s.crc_errors, s.retries,
                     s.instructions_per_solution, s.restarts, s.injected);
    std::string out = buf;
    if (s.self_calibrate) {
        text::c_snprintf(buf, sizeof buf,
                         ", \"self_calibration\": {\"models\": %zu, \"version_mismatches\": %zu, "
                         "\"history_mismatches\": %zu, \"report_matches\": %s}",
                         s.models, s.version_mismatches, s.history_mismatches, s.report_matches ? "true" : "false");
        out += buf;
    }
    if (s.combined) {
        text::c_snprintf(buf, sizeof buf,
                         ", \"combined\": {\"epochs\": %zu, \"mismatches\": %zu, \"instructions_per_epoch\": %.1f}",
                         s.combined_epochs, s.combined_mismatches, s.combination_instructions_per_epoch);
        out += buf;
    }
    return out + "}";
}

}  // namespace ascorr::host
