#include "ascorr_host/analysis/simulate.hpp"

#include <erfa.h>
#include <erfam.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdio>
#include <optional>
#include <random>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "ascorr/core/correct.hpp"
#include "ascorr/nav/orbit_propagation.hpp"
#include "ascorr_host/correct/earth_velocity.hpp"
#include "ascorr_host/correct/solution_input.hpp"
#include "ascorr_host/formats/atomic_file.hpp"
#include "ascorr_host/formats/combined_csv.hpp"
#include "ascorr_host/formats/csv.hpp"
#include "ascorr_host/formats/embedded_model.hpp"
#include "ascorr_host/formats/model_csv.hpp"
#include "ascorr_host/formats/progress.hpp"
#include "ascorr_host/formats/solutions_csv.hpp"
#include "ascorr_text/c_format.hpp"
#include "ascorr_text/input_error.hpp"

namespace ascorr::host {

namespace {

// A, B and C, the heads the simulator models itself; a head beyond them
// (index h ≥ kOwnHeads) is derived from head h − kOwnHeads (simulate.hpp).
constexpr std::size_t kOwnHeads = head_count(kPaperHeads);

// Star-tracker noise of clean rows: kSimNoiseCrossArcsec, kSimNoiseAboutArcsec (simulate.hpp).
constexpr double kFlaggedNoiseArcsec = 40.0;  // flagged solutions are bad in every axis
// Exclusion angles from the boresight (head blinded: no solution).
constexpr double kSunExclusionDeg = 40.0;
constexpr double kMoonExclusionDeg = 20.0;
constexpr double kMoonBrightDeg = 30.0;  // Moon near the field: "big bright object" flag

Quaternion<double> from_eigen(const Eigen::Quaterniond& q) {
    return {q.w(), q.x(), q.y(), q.z()};
}

// Sun and Moon directions (GCRS), cached per hour: they move < 0.6° in that time,
// far less than the exclusion angles.
class SunMoon {
public:
    void at(double t, Eigen::Vector3d& sun, Eigen::Vector3d& moon) {
        const auto hour = static_cast<long long>(std::floor(t / 3600.0));
        if (hour != hour_) {
            hour_ = hour;
            const double tc = static_cast<double>(hour) * 3600.0 + 1800.0;
            double pvh[2][3];
            double pvb[2][3];
            eraEpv00(ERFA_DJ00, tc / kSecondsPerDay, pvh, pvb);
            sun_ = -Eigen::Vector3d(pvh[0][0], pvh[0][1], pvh[0][2]).normalized();
            double pv[2][3];
            eraMoon98(ERFA_DJ00, tc / kSecondsPerDay, pv);
            moon_ = Eigen::Vector3d(pv[0][0], pv[0][1], pv[0][2]).normalized();
        }
        sun = sun_;
        moon = moon_;
    }

private:
    long long hour_ = LLONG_MIN;
    Eigen::Vector3d sun_;
    Eigen::Vector3d moon_;
};

// A slowly varying independent temperature part: Ornstein–Uhlenbeck process.
struct Wander {
    double x = 0.0;
    void step(double dt, double tau, double sigma, std::mt19937_64& rng) {
        std::normal_distribution<double> n(0.0, 1.0);
        const double a = std::exp(-dt / tau);
        x = a * x + sigma * std::sqrt(1.0 - a * a) * n(rng);
    }
};

// Heater events: an operational heater (CHUs and THT00032 warm) and a survival
// heater (THT00029 only), alternating, every 40–80 days for 3–5 days, with a
// half-day thermal time constant.
class Heaters {
public:
    Heaters(double t0, std::mt19937_64& rng) : rng_(rng) { schedule(t0); }
    // Every event scheduled so far, in time order (the last may lie beyond the data).
    const std::vector<HeaterEvent>& events() const { return events_; }
    // Profile 0..1 of the operational and survival heater at t.
    void at(double t, double& op, double& surv) {
        while (t > end_ + 5.0 * kTau) {
            schedule(end_);
        }
        double p = 0.0;
        if (t >= start_) {
            const double on = std::min(t, end_) - start_;
            p = 1.0 - std::exp(-on / kTau);
            if (t > end_) {
                p *= std::exp(-(t - end_) / kTau);
            }
        }
        op = operational_ ? p : 0.0;
        surv = operational_ ? 0.0 : p;
    }

private:
    static constexpr double kTau = 0.5 * kSecondsPerDay;
    void schedule(double after) {
        std::uniform_real_distribution<double> gap(40.0 * kSecondsPerDay, 80.0 * kSecondsPerDay);
        std::uniform_real_distribution<double> len(3.0 * kSecondsPerDay, 5.0 * kSecondsPerDay);
        start_ = after + gap(rng_);
        end_ = start_ + len(rng_);
        operational_ = !operational_;
        events_.push_back({start_, end_, operational_});
    }
    std::mt19937_64& rng_;
    double start_ = 0.0;
    double end_ = 0.0;
    bool operational_ = false;
    std::vector<HeaterEvent> events_;
};

// A run of consecutive epochs with something missing (telemetry or GPS gaps).
struct Gap {
    std::size_t left = 0;
    bool step(double p_start, std::size_t min_len, std::size_t max_len, std::mt19937_64& rng) {
        if (left > 0) {
            --left;
            return true;
        }
        std::uniform_real_distribution<double> u(0.0, 1.0);
        if (u(rng) < p_start) {
            std::uniform_int_distribution<std::size_t> len(min_len, max_len);
            left = len(rng) - 1;
            return true;
        }
        return false;
    }
};

char* put(char* p, char* end, double x, int decimals) {
    return format_fixed(p, end, x, decimals);
}

}  // namespace

Eigen::Matrix3d head_mounting(int head) {
    static constexpr double kAzimuthDeg[3] = {90.0, 210.0, 330.0};
    const double zeta = std::acos(1.0 / std::sqrt(3.0));  // from the zenith: three mutually orthogonal boresights
    // A head beyond C (index h ≥ 3): halfway in azimuth between heads h − 3
    // and h − 2 (D between A and B, at 150°), at the same zenith distance.
    const auto h = static_cast<std::size_t>(head);
    const double az_deg = h < kOwnHeads ? kAzimuthDeg[h] : kAzimuthDeg[(h - kOwnHeads) % kOwnHeads] + 60.0;
    const double az = az_deg * kDegToRad;
    const Eigen::Vector3d up(0.0, 0.0, -1.0);  // body z is nadir
    const Eigen::Vector3d z = std::sin(zeta) * Eigen::Vector3d(std::cos(az), std::sin(az), 0.0) + std::cos(zeta) * up;
    const Eigen::Vector3d x = up.cross(z).normalized();
    const Eigen::Vector3d y = z.cross(x);
    Eigen::Matrix3d m;
    m.row(0) = x.transpose();
    m.row(1) = y.transpose();
    m.row(2) = z.transpose();
    return m;
}

MountingsFile simulated_mountings(HeadSet heads) {
    MountingsFile m;
    m.sigmas = true;
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        combine::HeadMounting& hm = m.mountings.head[h];
        hm.present = has_head(heads, h);
        // The CRF is the body frame: R(q_chu_icrf) = R(q_chu_crf) R(q_crf_icrf) with
        // R(q_chu_crf) = head_mounting(h) and R(q_crf_icrf) = R_body_icrf.
        hm.q_chu_crf = canonical(from_eigen(Eigen::Quaterniond(head_mounting(h))));
        hm.sigma_cross_arcsec = kSimNoiseCrossArcsec;
        hm.sigma_about_arcsec = kSimNoiseAboutArcsec;
    }
    return m;
}

std::string heaters_csv(const std::vector<HeaterEvent>& events) {
    std::string s = "start,end,heater\n";
    char line[96];
    for (const HeaterEvent& e : events) {
        text::c_snprintf(line, sizeof line, "%.3f,%.3f,%s\n", e.start, e.end,
                         e.operational ? "operational" : "survival");
        s += line;
    }
    return s;
}

std::string floor_json(const std::array<Rms, kMaxPairs>& floor, const PairList& pairs) {
    std::ostringstream s;
    s.precision(6);
    s << std::fixed << "{\"floor\": {";
    for (std::size_t p = 0; p < pairs.count; ++p) {
        // A pair without clean epochs has no RMS: null (JSON has no NaN either).
        const auto value = [n = floor[p].n](double x) {
            std::ostringstream v;
            v.precision(6);
            v << std::fixed << x;
            return n != 0 && std::isfinite(x) ? v.str() : std::string("null");
        };
        s << (p ? ", " : "") << '"' << pairs.pair[p].name << "\": {\"rms\": " << value(floor[p].rms)
          << ", \"rms_200s\": " << value(floor[p].rms_smoothed) << ", \"n\": " << floor[p].n << '}';
    }
    s << "}}\n";
    return s.str();
}

std::string describe(const SimulateSummary& s) {
    std::ostringstream o;
    const HeadList heads = heads_of(s.heads);
    o << s.epochs << " epochs, " << s.rows << " rows; blinded (Sun/Moon) rows ";
    for (std::size_t i = 0; i < heads.count; ++i) {
        o << (i ? "/" : "") << head_name(heads.head[i]);
    }
    o << ':';
    for (std::size_t i = 0; i < heads.count; ++i) {
        o << (i ? '/' : ' ') << s.outage_rows[heads.head[i]];
    }
    o << "; flagged " << s.flagged_rows << ", without temperatures " << s.rows_without_temperature
      << ", without velocity " << s.rows_without_velocity << "\nnoise floor (IBA RMS, arcsec):";
    char buf[96];
    for (std::size_t p = 0; p < s.pairs.count; ++p) {
        text::c_snprintf(buf, sizeof buf, "  %s %.3f (200 s: %.3f)", s.pairs.pair[p].name, s.floor[p].rms,
                         s.floor[p].rms_smoothed);
        o << buf;
    }
    o << "\ntruth model: " << s.truth_path << " (history: " << s.truth_history_path << ")\nfloor: " << s.floor_path
      << " (per day: " << s.floor_daily_path << ")\nheater events (" << s.heaters.size() << "): " << s.heaters_path
      << "\nmountings (true noise): " << s.mountings_path << "\ntrue CRF attitude: " << s.attitude_path;
    if (s.gap_epochs != 0) {
        o << "\nepochs without rows (--gap): " << s.gap_epochs;
    }
    return o.str();
}

namespace {

// The random streams, shared in one fixed order of draws: the same seed gives
// the same file. `normal` keeps state between calls (it draws in pairs), so
// there is one, used by every draw below, never a copy.
struct Random {
    explicit Random(std::uint64_t seed) : engine(seed) {}
    explicit Random(std::seed_seq& seq) : engine(seq) {}
    std::mt19937_64 engine;
    std::normal_distribution<double> normal{0.0, 1.0};
    std::uniform_real_distribution<double> uniform{0.0, 1.0};
    double gauss() { return normal(engine); }
    double unit() { return uniform(engine); }
};

std::string truth_name(const std::string& path) {
    return path.empty() ? std::string("truth model (Table 2)") : path;
}

// A model file (empty path: Table 2); heads A, B and C must all have
// coefficients. A head beyond C (index h ≥ 3) simulated that the file has
// none for takes head h − 3's with the opposite sign (D: −A's): a deformation
// of its own, not a rotation common to the heads.
ModelFile truth_model(const std::string& path, HeadSet heads) {
    ModelFile truth_file = path.empty() ? table2_model() : read_model_file(path);
    for (std::size_t h = 0; h < kOwnHeads; ++h) {
        if (!truth_file.present[h]) {
            throw std::invalid_argument((path.empty() ? std::string("truth model") : path) +
                                        ": no coefficients for CHU " + head_name(static_cast<std::uint8_t>(h)));
        }
    }
    for (std::size_t h = kOwnHeads; h < kMaxHeads; ++h) {
        if (!truth_file.present[h] && has_head(heads, static_cast<std::uint8_t>(h))) {
            truth_file.present[h] = true;
            for (std::size_t ax = 0; ax < kModelAxes; ++ax) {
                for (std::size_t c = 0; c < kModelTerms; ++c) {
                    truth_file.coefficients[h][ax][c] = -truth_file.coefficients[h - kOwnHeads][ax][c];
                }
            }
        }
    }
    return truth_file;
}

// The truth from t_from (s since J2000 TT, as written) on.
struct Truth {
    ModelFile file;
    ThermalModel<double> model;
    std::string name;
    double t_from = 0.0;
};

// --truth (from the first epoch), then each --truth-change.
std::vector<Truth> truth_models(const SimulateOptions& opt) {
    std::vector<Truth> truths;
    const auto add = [&truths, &opt](const std::string& path, double t_from) {
        ModelFile file = truth_model(path, opt.heads);
        ThermalModel<double> model = to_core<double>(file);
        truths.push_back({std::move(file), model, truth_name(path), t_from});
    };
    add(opt.truth, std::round(opt.start_t * 1000.0) / 1000.0);
    for (const TruthChange& c : opt.truth_changes) {
        add(c.model, std::round((opt.start_t + c.day * kSecondsPerDay) * 1000.0) / 1000.0);
    }
    return truths;
}

// The truths as a model history (docs/contract.md, "Self-calibration"):
// version v's rows are its model file's rows after t and v.
std::string truth_history_csv(const std::vector<Truth>& truths) {
    bool quadratic = false;
    for (const Truth& t : truths) {
        quadratic = quadratic || t.file.quadratic;
    }
    std::string s = "t,version," + model_header(quadratic ? kModelTerms : kLinearModelTerms);
    for (std::size_t v = 0; v < truths.size(); ++v) {
        ModelFile m = truths[v].file;
        m.quadratic = quadratic;
        const std::string rows = format_model(m);
        char prefix[64];
        text::c_snprintf(prefix, sizeof prefix, "%.3f,%zu,", truths[v].t_from, v);
        for (std::size_t at = rows.find('\n') + 1; at < rows.size();) {
            const std::size_t end = rows.find('\n', at) + 1;
            s += prefix;
            s.append(rows, at, end - at);
            at = end;
        }
    }
    return s;
}

bool in_window(const DayWindow& w, double day) {
    return day >= w.from_day && day < w.to_day;
}

// "OPTION FROM:TO: ..." for a window outside [0, days] or empty.
void refuse_window(const char* option, const char* form, const DayWindow& w, double days) {
    if (!(w.from_day >= 0.0 && w.from_day < w.to_day && w.to_day <= days)) {
        char what[256];
        text::c_snprintf(what, sizeof what, "%s %g:%g: expected %s with 0 <= FROM_DAY < TO_DAY <= %g (--days)", option,
                         w.from_day, w.to_day, form, days);
        throw std::invalid_argument(what);
    }
}

void refuse_bad_head(const char* option, std::size_t head, HeadSet heads) {
    if (head >= kMaxHeads || !has_head(heads, static_cast<std::uint8_t>(head))) {
        throw std::invalid_argument(std::string(option) + ": HEAD must be " + head_words(heads, " or ") +
                                    " (the heads simulated, --heads), got " +
                                    head_name(static_cast<std::uint8_t>(head)));
    }
}

void refuse_bad_truth_changes(const SimulateOptions& opt) {
    double previous = 0.0;
    for (const TruthChange& c : opt.truth_changes) {
        if (!(c.day > previous && c.day < opt.days) || c.model.empty()) {
            char what[256];
            text::c_snprintf(what, sizeof what,
                             "--truth-change %g:%s: expected DAY:MODEL, a model file from DAY in (0, %g) (--days), "
                             "DAY increasing from one change to the next (the previous: %g)",
                             c.day, c.model.c_str(), opt.days, previous);
            throw std::invalid_argument(what);
        }
        previous = c.day;
    }
}

void refuse_bad_thermistor_faults(const SimulateOptions& opt) {
    constexpr const char* kOption = "--thermistor-fault";
    for (const ThermistorFault& f : opt.thermistor_faults) {
        refuse_bad_head(kOption, f.head, opt.heads);
        if (f.channel > 2) {
            throw std::invalid_argument(std::string(kOption) + ": CHANNEL must be t_chu, t_029 or t_032");
        }
        refuse_window(kOption, "HEAD:CHANNEL:stuck|drift:FROM_DAY:TO_DAY[:RATE]", f.window, opt.days);
        const bool drift = f.kind == ThermistorFaultKind::kDrift;
        if (!(std::fabs(f.rate_c_per_day) <= 100.0) || (!drift && f.rate_c_per_day != 0.0)) {
            char what[160];
            text::c_snprintf(what, sizeof what,
                             "%s: RATE %g: expected a drift's RATE in [-100, 100] degC/day; a stuck channel has none",
                             kOption, f.rate_c_per_day);
            throw std::invalid_argument(what);
        }
    }
}

void refuse_bad_event_options(const SimulateOptions& opt) {
    if ((opt.heads & ~kAllHeads) != 0U || head_count(opt.heads) < 2) {
        throw std::invalid_argument("--heads " + head_letters(opt.heads) + ": expected two or more of the heads " +
                                    kHeadLetters + ", in that order");
    }
    refuse_bad_truth_changes(opt);
    for (const DayWindow& g : opt.gaps) {
        refuse_window("--gap", "FROM_DAY:TO_DAY", g, opt.days);
    }
    refuse_bad_thermistor_faults(opt);
    for (const HeadBias& b : opt.head_biases) {
        refuse_bad_head("--head-bias", b.head, opt.heads);
        refuse_window("--head-bias", "HEAD:FROM_DAY:TO_DAY:ARCSEC", b.window, opt.days);
        if (!(std::fabs(b.arcsec) <= 3600.0)) {
            char what[120];
            text::c_snprintf(what, sizeof what, "--head-bias: ARCSEC %g: expected a rotation in [-3600, 3600] arcsec",
                             b.arcsec);
            throw std::invalid_argument(what);
        }
    }
}

void refuse_bad_options(const SimulateOptions& opt) {
    if (!(opt.days > 0.0 && opt.days <= 36600.0)) {
        throw std::invalid_argument("--days must be in (0, 36600], got " + number_text(opt.days));
    }
    if (!(opt.step_s >= 1.0 && opt.step_s <= 600.0)) {
        throw std::invalid_argument("--step must be in [1, 600] s (the orbit must be resolved), got " +
                                    number_text(opt.step_s));
    }
    if (!in_ephemeris_span(opt.start_t) || !in_ephemeris_span(opt.start_t + opt.days * kSecondsPerDay)) {
        throw std::invalid_argument("--start " + number_text(opt.start_t) +
                                    ": the mission must lie within the Earth ephemeris (1900-2100; s since J2000 TT)");
    }
    refuse_bad_event_options(opt);
}

// The circular orbit (header: Sun-synchronous-like node drift) and the
// spacecraft's attitude at dt seconds after the start.
struct SpacecraftPose {
    Eigen::Vector3d P;      // node direction (ICRF)
    Eigen::Vector3d Q;      // 90° ahead in the orbital plane
    Eigen::Vector3d r_hat;  // position direction
    Eigen::Vector3d v_sc;   // velocity, km/s, rounded as written
    Eigen::Matrix3d body_icrf;
};

class Orbit {
public:
    Orbit(double start_t, SunMoon& sky) {
        Eigen::Vector3d sun0;
        Eigen::Vector3d moon0;
        sky.at(start_t, sun0, moon0);
        node0_ = std::atan2(sun0.y(), sun0.x()) + 30.0 * kDegToRad;
    }
    SpacecraftPose at(double dt) const {
        SpacecraftPose o;
        const double u = n_ * dt;
        const double node = node0_ + node_rate_ * dt;
        o.P = Eigen::Vector3d(std::cos(node), std::sin(node), 0.0);
        o.Q = Eigen::Vector3d(-std::cos(inc_) * std::sin(node), std::cos(inc_) * std::cos(node), std::sin(inc_));
        o.r_hat = std::cos(u) * o.P + std::sin(u) * o.Q;
        const Eigen::Vector3d v_dir = -std::sin(u) * o.P + std::cos(u) * o.Q;
        o.v_sc = a_ * n_ * v_dir;
        for (int i = 0; i < 3; ++i) {
            o.v_sc[i] = std::round(o.v_sc[i] * 1e6) / 1e6;  // as written
        }
        o.body_icrf.row(0) = v_dir.transpose();
        o.body_icrf.row(2) = -o.r_hat.transpose();
        o.body_icrf.row(1) = (-o.r_hat).cross(v_dir).transpose();
        return o;
    }

private:
    double a_ = kEarthEquatorialRadiusKm + kSimAltitudeKm;
    double n_ = std::sqrt(kEarthGmKm3S2 / (a_ * a_ * a_));
    double inc_ = kSimInclinationDeg * kDegToRad;
    double node_rate_ = 2.0 * kPi / (365.2422 * kSecondsPerDay) - 2.0 * kPi / (kPlaneSunPeriodDays * kSecondsPerDay);
    double node0_ = 0.0;
};

// A CHU's temperature response (°C): mean, per sine of the Sun's angle to the
// orbital plane (sinb), per sinb², per cosine of the Sun from the position
// (the sunlit side), per operational heater on.
struct ChuResponse {
    double mean;
    double season;
    double season2;
    double orbit;
    double heater;
};
constexpr ChuResponse kChuResponse[kOwnHeads] = {
    {10.0, 5.0, 2.0, 0.8, 2.5},   // A
    {14.0, -7.0, 1.0, 1.2, 3.0},  // B
    {8.0, -4.0, 3.0, 0.6, 2.0},   // C
};

// The response of head h: A, B, C's above; a head beyond C (h ≥ 3) has head
// h − 3's mirrored, as mounted on the other side: the seasonal (sinb) and
// orbital terms change sign.
ChuResponse chu_response(std::size_t h) {
    if (h < kOwnHeads) {
        return kChuResponse[h];
    }
    ChuResponse r = kChuResponse[(h - kOwnHeads) % kOwnHeads];
    r.season = -r.season;
    r.orbit = -r.orbit;
    return r;
}

// The geometry the temperatures follow at an epoch.
struct Exposure {
    double sinb = 0.0;  // sine of the Sun's angle to the orbital plane
    double orb = 0.0;   // cosine of the Sun from the position
};

Exposure exposure(const SpacecraftPose& o, const Eigen::Vector3d& sun) {
    return {sun.dot(o.P.cross(o.Q)), o.r_hat.dot(sun)};
}

double chu_temperature(std::size_t h, const Exposure& x, double wander, double op) {
    const ChuResponse r = chu_response(h);
    return r.mean + r.season * x.sinb + r.season2 * (x.sinb * x.sinb) + r.orbit * x.orb + wander + r.heater * op;
}

// T_CHU A, B, C, T029, T032 (°C, rounded as written): seasonal (sine of the
// Sun's angle to the orbital plane), orbital (sunlit side), independent
// wander, heater events, read noise.
std::array<double, 5> temperatures(const SpacecraftPose& o, const Eigen::Vector3d& sun, double op, double surv,
                                   std::array<Wander, 5>& wander, double step_s, Random& rnd) {
    const Exposure x = exposure(o, sun);
    const double sinb = x.sinb;
    const double orb = x.orb;
    for (auto& w : wander) {
        w.step(step_s, 3.0 * kSecondsPerDay, 0.6, rnd.engine);
    }
    const double s2 = sinb * sinb;
    std::array<double, 5> temp = {
        chu_temperature(0, x, wander[0].x, op),
        chu_temperature(1, x, wander[1].x, op),
        chu_temperature(2, x, wander[2].x, op),
        -9.0 + 3.0 * sinb - 2.0 * s2 + 0.3 * orb + wander[3].x + 3.0 * surv,
        -20.0 + 2.0 * sinb + 4.0 * s2 + 0.2 * orb + wander[4].x + 2.0 * op,
    };
    for (double& t : temp) {
        t = std::round((t + 0.02 * rnd.gauss()) * 1000.0) / 1000.0;  // as written
    }
    return temp;
}

// The recorded T_CHU of a head beyond C: its response, its own wander and
// read noise, drawn from its own stream (Mission::extra_).
double extra_chu_temperature(std::size_t h, const Exposure& x, double op, Wander& wander, double step_s, Random& rnd) {
    wander.step(step_s, 3.0 * kSecondsPerDay, 0.6, rnd.engine);
    const double t = chu_temperature(h, x, wander.x, op);
    return std::round((t + 0.02 * rnd.gauss()) * 1000.0) / 1000.0;  // as written
}

// Flags, confidence and a missing T_CHU of one head's solution.
struct Quality {
    long long flags = 0;
    double confidence = 0.0;
    bool bad = false;  // flagged or confidence > 5
    bool chu_temperature_missing = false;
};

Quality draw_quality(double moon_deg, Random& rnd) {
    Quality q;
    if (rnd.unit() < 0.002) {
        q.flags |= 1;
    }
    if (moon_deg < kMoonBrightDeg || rnd.unit() < 0.001) {  // no draw with the Moon near the field
        q.flags |= 2;
    }
    if (rnd.unit() < 0.0005) {
        q.flags |= 4;
    }
    q.confidence = std::min(4.9, 1.0 + 0.5 * std::fabs(rnd.gauss()));
    if (rnd.unit() < 0.003) {
        q.confidence = 5.5 + 10.0 * rnd.unit();
    }
    q.bad = q.flags != 0 || q.confidence > 5.0;
    q.chu_temperature_missing = rnd.unit() < 0.001;
    return q;
}

// Undoes the aberration correction: q_raw = q_meas ⊗ q_ab(z_raw), by
// fixed-point iteration (contraction ≈ |β| ≈ 1e-4 per step).
Quaternion<double> raw_attitude(const Quaternion<double>& q_meas, double t, std::size_t h, const Eigen::Vector3d& v_sc,
                                EarthVelocity& earth) {
    SolutionRecord rec;
    rec.t = t;
    rec.head = static_cast<std::uint8_t>(h);
    rec.q_chu_icrf = q_meas;
    rec.velocity_components = 3;
    rec.v_sc_kms = {v_sc.x(), v_sc.y(), v_sc.z()};
    const SolutionInput<double> in = to_core_input<double>(rec, &earth);
    Quaternion<double> q_raw = q_meas;
    for (int it = 0; it < 4; ++it) {
        const SmallRotation<double> q_ab =
            aberration_rotation(boresight(q_raw), in.velocity.beta_icrf, in.velocity.inv_sun_distance_au);
        q_raw = renormalized(q_meas * to_quaternion(q_ab));
    }
    return canonical(q_raw);
}

// Everything one epoch shares between its heads.
struct EpochState {
    double t = 0.0;
    SpacecraftPose orbit;
    Eigen::Vector3d sun;
    Eigen::Vector3d moon;
    std::array<double, 5> temp{};               // T_CHU A, B, C, T029, T032
    std::array<double, kMaxHeads> extra_chu{};  // T_CHU of the heads beyond C, by head index
    bool no_temperature = false;                // telemetry gap
    bool no_velocity = false;                   // GPS gap
};

// Head h's T_CHU at the epoch.
double t_chu(const EpochState& e, std::size_t h) {
    return h < kOwnHeads ? e.temp[h] : e.extra_chu[h];
}

// One head's solution at an epoch (when the head is not blinded).
struct HeadSolution {
    Quality quality;
    Quaternion<double> q_raw{};
    Vector3<double> z_floor{};  // boresight with noise only: for the noise floor
};

// A truth model whose angle exceeds 1 degree: the first such axis names the
// model row (line) to look at.
[[noreturn]] void refuse_truth_angle(std::size_t h, const EpochState& e, const HeadTemperatures<double>& ht,
                                     const Truth& truth) {
    const HeadThermalModel<double>& m = truth.model.head[h];
    const AxisPolynomial<double>* axes[3] = {&m.alpha, &m.beta, &m.gamma};
    std::size_t axis = 0;
    double angle = 0.0;
    for (std::size_t a = 0; a < 3; ++a) {
        angle = thermal_angle(*axes[a], ht.t_chu.value, ht.t_029.value, ht.t_032.value);
        axis = a;
        if (!(std::fabs(angle) <= kMaxThermalAngleRad)) {
            break;
        }
    }
    char what[240];
    text::c_snprintf(what, sizeof what,
                     "CHU %c %s: the truth model gives %g degrees, beyond 1 degree, at t = %.17g s (T_CHU %g, "
                     "T029 %g, T032 %g degC)",
                     head_name(static_cast<std::uint8_t>(h)), kAxisNames[axis], angle * 180.0 / kPi, e.t, t_chu(e, h),
                     e.temp[3], e.temp[4]);
    throw text::InputError(truth.name, truth.file.line[h][axis], 0, what);
}

// Measured attitude: noise ⊗ deformation⁻¹ ⊗ truth (see the header), rotated
// by bias_rad about the head's x axis (--head-bias), then the raw attitude
// before the aberration correction.
HeadSolution solve_head(std::size_t h, const Eigen::Matrix3d& r_true, double moon_deg, const EpochState& e,
                        const Truth& truth, double bias_rad, EarthVelocity& earth, Random& rnd) {
    HeadSolution out;
    out.quality = draw_quality(moon_deg, rnd);
    const bool bad = out.quality.bad;
    const double sx = bad ? kFlaggedNoiseArcsec : kSimNoiseCrossArcsec;
    const double sz = bad ? kFlaggedNoiseArcsec : kSimNoiseAboutArcsec;
    std::normal_distribution<double>& normal = rnd.normal;
    std::mt19937_64& rng = rnd.engine;
    const Eigen::Vector3d noise(sx * normal(rng), sx * normal(rng), sz * normal(rng));
    const Eigen::Vector3d noise_rad = noise * kArcsecToRad;
    const Eigen::Quaterniond q_noise(Eigen::AngleAxisd(noise_rad.norm(), noise_rad.normalized()));
    const Eigen::Quaterniond q_true(r_true);
    const Eigen::Quaterniond q_noisy_true = (q_noise * q_true).normalized();

    HeadTemperatures<double> ht{{t_chu(e, h), true}, {e.temp[3], true}, {e.temp[4], true}};
    const ThermalStage<double> th = thermal_stage(truth.model, static_cast<std::uint8_t>(h), ht);
    if (th.skip != 0U) {
        refuse_truth_angle(h, e, ht, truth);
    }
    Quaternion<double> q_meas = renormalized(conjugate(to_quaternion(th.q_th)) * from_eigen(q_noisy_true));
    if (bias_rad != 0.0) {
        const Eigen::Quaterniond q_bias(Eigen::AngleAxisd(bias_rad, Eigen::Vector3d::UnitX()));
        q_meas = renormalized(from_eigen(q_bias) * q_meas);
    }
    out.q_raw = raw_attitude(q_meas, e.t, h, e.orbit.v_sc, earth);
    const Eigen::Vector3d zf = q_noisy_true.toRotationMatrix().row(2).transpose();
    out.z_floor = {zf.x(), zf.y(), zf.z()};
    return out;
}

// The row of docs/contract.md's solutions file.
// temps: the recorded t_chu, t_029, t_032 of head h.
void append_row(std::string& buf, const EpochState& e, std::size_t h, const HeadSolution& s,
                const std::array<double, 3>& temps) {
    char line[256];
    char* p = line;
    char* const end = line + sizeof line;
    p = put(p, end, e.t, 3);
    *p++ = ',';
    *p++ = head_name(static_cast<std::uint8_t>(h));
    for (double c : {s.q_raw.w, s.q_raw.x, s.q_raw.y, s.q_raw.z}) {
        *p++ = ',';
        p = put(p, end, c, 15);
    }
    for (std::size_t i = 0; i < 3; ++i) {
        *p++ = ',';
        if (!(e.no_temperature || (i == 0 && s.quality.chu_temperature_missing))) {
            p = put(p, end, temps[i], 3);
        }
    }
    for (int i = 0; i < 3; ++i) {
        *p++ = ',';
        if (!e.no_velocity) {
            p = put(p, end, e.orbit.v_sc[i], 6);
        }
    }
    p += text::c_snprintf(p, static_cast<std::size_t>(end - p), ",%lld,", s.quality.flags);
    p = put(p, end, s.quality.confidence, 2);
    *p++ = '\n';
    buf.append(line, static_cast<std::size_t>(p - line));
}

// The temperatures each head's row records, by head index: t_chu, t_029, t_032.
using RecordedTemperatures = std::array<std::array<double, 3>, kMaxHeads>;

// The mission, epoch by epoch: everything simulate() writes and counts.
class Mission {
public:
    Mission(const SimulateOptions& opt, const std::vector<Truth>& truths)
        : opt_(opt),
          truths_(truths),
          rnd_(opt.seed),
          orbit_(opt.start_t, sky_),
          heaters_(opt.start_t, rnd_.engine),
          stuck_(opt.thermistor_faults.size()),
          solved_(kPaperHeads | opt.heads),
          pairs_(pairs_of(opt.heads)) {
        for (int h = 0; h < kMaxHeads; ++h) {
            mount_[static_cast<std::size_t>(h)] = head_mounting(h);
        }
        // A head beyond C draws from its own stream, mt19937_64 seeded by
        // seed_seq{seed, h}: A, B and C's rows do not depend on which other heads are simulated.
        for (std::uint8_t h = kOwnHeads; h < kMaxHeads; ++h) {
            if (has_head(opt.heads, h)) {
                std::seed_seq seq{static_cast<std::uint64_t>(opt.seed), static_cast<std::uint64_t>(h)};
                extra_[h].emplace(seq);
            }
        }
        sum_.heads = opt.heads;
        sum_.pairs = pairs_;
    }

    // Appends epoch k's rows to buf and its true CRF attitude to attitude.
    void epoch(std::size_t k, std::string& buf, std::string& attitude) {
        EpochState e;
        const double dt = static_cast<double>(k) * opt_.step_s;
        e.t = std::round((opt_.start_t + dt) * 1000.0) / 1000.0;  // as written
        e.orbit = orbit_.at(dt);
        append_attitude_row(attitude, e.t, from_eigen(Eigen::Quaterniond(e.orbit.body_icrf)));
        sky_.at(e.t, e.sun, e.moon);
        double op = 0.0;
        double surv = 0.0;
        heaters_.at(e.t, op, surv);
        e.temp = temperatures(e.orbit, e.sun, op, surv, wander_, opt_.step_s, rnd_);
        for (std::size_t h = kOwnHeads; h < kMaxHeads; ++h) {
            if (extra_[h]) {
                e.extra_chu[h] =
                    extra_chu_temperature(h, exposure(e.orbit, e.sun), op, extra_wander_[h], opt_.step_s, *extra_[h]);
            }
        }
        e.no_temperature = telemetry_gap_.step(2e-4, 10, 120, rnd_.engine);
        e.no_velocity = gps_gap_.step(1e-4, 5, 60, rnd_.engine);

        const double day = dt / kSecondsPerDay;
        const auto day_index = static_cast<std::size_t>(std::floor(day));
        daily_.resize(std::max(daily_.size(), day_index + 1));
        const bool gap =
            std::any_of(opt_.gaps.begin(), opt_.gaps.end(), [day](const DayWindow& w) { return in_window(w, day); });
        const HeadsAtEpoch heads = solve_heads(e, dt, recorded_temperatures(e, day), gap, buf);
        if (gap) {
            ++sum_.gap_epochs;
            return;
        }
        for (std::size_t pr = 0; pr < pairs_.count; ++pr) {
            const auto i = pairs_.pair[pr].first;
            const auto j = pairs_.pair[pr].second;
            if (heads.clean[i] && heads.clean[j]) {
                const double iba = angle_arcsec(heads.z_floor[i], heads.z_floor[j]);
                floor_t_[pr].push_back(e.t);
                floor_v_[pr].push_back(iba);
                FloorSums& f = daily_[day_index][pr];
                ++f.n;
                f.sum += static_cast<long double>(iba);
                f.sum_sq += static_cast<long double>(iba) * static_cast<long double>(iba);
            }
        }
        ++sum_.epochs;
    }

    // The summary, once every epoch is in (t_last: the last epoch's time).
    SimulateSummary finish(double t_last) {
        for (std::size_t pr = 0; pr < pairs_.count; ++pr) {
            sum_.floor[pr] = rms_about_mean(floor_t_[pr], floor_v_[pr]);
        }
        sum_.truth_path = opt_.out + ".truth.csv";
        sum_.truth_history_path = opt_.out + ".truth-history.csv";
        sum_.floor_path = opt_.out + ".floor.json";
        sum_.floor_daily_path = opt_.out + ".floor-daily.csv";
        sum_.heaters_path = opt_.out + ".heaters.csv";
        sum_.mountings_path = opt_.out + ".mountings.csv";
        sum_.attitude_path = opt_.out + ".attitude.csv";
        for (const HeaterEvent& ev : heaters_.events()) {
            if (ev.start <= t_last) {
                sum_.heaters.push_back(ev);
            }
        }
        return sum_;
    }

    const DailyFloor& daily() const { return daily_; }

private:
    // Which heads are written and clean at an epoch, and their floor boresights.
    struct HeadsAtEpoch {
        std::array<bool, kMaxHeads> clean{};
        std::array<Vector3<double>, kMaxHeads> z_floor{};
    };

    // Every head's solution at the epoch (drawn in a gap too: the random
    // streams stay those of a mission without gaps), written outside gaps.
    // A, B and C are drawn even when not simulated (--heads), so that the
    // others' draws stay the same; only the heads simulated are written.
    HeadsAtEpoch solve_heads(const EpochState& e, double dt, const RecordedTemperatures& recorded, bool gap,
                             std::string& buf) {
        HeadsAtEpoch out;
        const Truth& truth = truth_at(e.t);
        const HeadList solved = heads_of(solved_);
        for (std::size_t i = 0; i < solved.count; ++i) {
            const std::size_t h = solved.head[i];
            const bool written = has_head(opt_.heads, static_cast<std::uint8_t>(h));
            const Eigen::Matrix3d r_true = mount_[h] * e.orbit.body_icrf;
            const Eigen::Vector3d z_icrf = r_true.row(2).transpose();
            const double sun_deg = std::acos(std::clamp(z_icrf.dot(e.sun), -1.0, 1.0)) / kDegToRad;
            const double moon_deg = std::acos(std::clamp(z_icrf.dot(e.moon), -1.0, 1.0)) / kDegToRad;
            if (sun_deg < kSunExclusionDeg || moon_deg < kMoonExclusionDeg) {
                sum_.outage_rows[h] += gap || !written ? 0U : 1U;  // blinded: no solution
                continue;
            }
            Random& rnd = h < kOwnHeads ? rnd_ : *extra_[h];
            const HeadSolution s =
                solve_head(h, r_true, moon_deg, e, truth, bias_rad(h, dt / kSecondsPerDay), earth_, rnd);
            if (gap || !written) {
                continue;
            }
            append_row(buf, e, h, s, recorded[h]);
            count(e, s);
            out.clean[h] = !s.quality.bad && !(e.no_temperature || s.quality.chu_temperature_missing) && !e.no_velocity;
            out.z_floor[h] = s.z_floor;
        }
        return out;
    }

    // The truth in force at t: the last whose t_from is not after t.
    const Truth& truth_at(double t) const {
        std::size_t v = 0;
        while (v + 1 < truths_.size() && truths_[v + 1].t_from <= t) {
            ++v;
        }
        return truths_[v];
    }

    // --head-bias: the rotation of head h at `day`, radians (the sum of the windows holding it).
    double bias_rad(std::size_t h, double day) const {
        double arcsec = 0.0;
        for (const HeadBias& b : opt_.head_biases) {
            arcsec += b.head == h && in_window(b.window, day) ? b.arcsec : 0.0;
        }
        return arcsec * kArcsecToRad;
    }

    // The temperatures as each head's row records them: the real ones, but
    // for --thermistor-fault (stuck at the window's first value, or drifting),
    // rounded as written.
    RecordedTemperatures recorded_temperatures(const EpochState& e, double day) {
        RecordedTemperatures rec{};
        for (std::size_t h = 0; h < kMaxHeads; ++h) {
            rec[h] = {t_chu(e, h), e.temp[3], e.temp[4]};
        }
        for (std::size_t i = 0; i < opt_.thermistor_faults.size(); ++i) {
            const ThermistorFault& f = opt_.thermistor_faults[i];
            if (!in_window(f.window, day)) {
                continue;
            }
            double& x = rec[f.head][f.channel];
            if (f.kind == ThermistorFaultKind::kStuck) {
                stuck_[i] = stuck_[i].value_or(x);
                x = *stuck_[i];
            } else {
                x = std::round((x + f.rate_c_per_day * (day - f.window.from_day)) * 1000.0) / 1000.0;
            }
        }
        return rec;
    }

    void count(const EpochState& e, const HeadSolution& s) {
        ++sum_.rows;
        sum_.flagged_rows += s.quality.bad ? 1U : 0U;
        sum_.rows_without_temperature += e.no_temperature || s.quality.chu_temperature_missing ? 1U : 0U;
        sum_.rows_without_velocity += e.no_velocity ? 1U : 0U;
    }

    const SimulateOptions& opt_;
    const std::vector<Truth>& truths_;
    Random rnd_;
    SunMoon sky_;
    Orbit orbit_;
    std::array<Eigen::Matrix3d, kMaxHeads> mount_;
    EarthVelocity earth_;
    Heaters heaters_;
    std::array<Wander, 5> wander_;                        // T_CHU A, B, C, T029, T032
    std::array<std::optional<Random>, kMaxHeads> extra_;  // the streams of the heads beyond C simulated
    std::array<Wander, kMaxHeads> extra_wander_;          // their T_CHU
    Gap telemetry_gap_;
    Gap gps_gap_;
    SimulateSummary sum_;
    std::array<std::vector<double>, kMaxPairs> floor_t_;
    std::array<std::vector<double>, kMaxPairs> floor_v_;
    DailyFloor daily_;
    std::vector<std::optional<double>> stuck_;  // per --thermistor-fault: the stuck value once in its window
    HeadSet solved_;                            // A, B, C and the heads simulated
    PairList pairs_;                            // of the heads simulated
};

}  // namespace

void refuse_bad_events(const SimulateOptions& opt) {
    refuse_bad_event_options(opt);
}

std::vector<NamedPath> simulate_inputs(const SimulateOptions& opt) {
    std::vector<NamedPath> inputs = {{"--truth", opt.truth}};
    for (const TruthChange& c : opt.truth_changes) {
        inputs.push_back({"--truth-change", c.model});
    }
    return inputs;
}

std::vector<NamedPath> simulate_outputs(const SimulateOptions& opt) {
    return {{"--out", opt.out},
            {"--out (truth model)", opt.out + ".truth.csv"},
            {"--out (truth history)", opt.out + ".truth-history.csv"},
            {"--out (noise floor)", opt.out + ".floor.json"},
            {"--out (daily noise floor)", opt.out + ".floor-daily.csv"},
            {"--out (heater events)", opt.out + ".heaters.csv"},
            {"--out (mountings)", opt.out + ".mountings.csv"},
            {"--out (true attitude)", opt.out + ".attitude.csv"}};
}

SimulateSummary simulate(const SimulateOptions& opt, OutputSet& outputs) {
    refuse_output_over_input(simulate_inputs(opt), simulate_outputs(opt));
    refuse_bad_options(opt);
    const std::vector<Truth> truths = truth_models(opt);
    Mission mission(opt, truths);

    AtomicFile& out = outputs["--out"];
    std::string buf;
    buf.reserve(2U << 20);
    buf += kSolutionsHeader;
    buf += '\n';
    AtomicFile& attitude = outputs["--out (true attitude)"];
    std::string attitude_buf;
    attitude_buf.reserve(2U << 20);
    attitude_buf += kAttitudeHeader;
    attitude_buf += '\n';
    const auto epochs = static_cast<std::size_t>(std::floor(opt.days * kSecondsPerDay / opt.step_s)) + 1;
    Progress progress("simulate");
    for (std::size_t k = 0; k < epochs; ++k) {
        if ((k & 4095U) == 0) {
            progress.update(static_cast<double>(k) / static_cast<double>(epochs));
        }
        mission.epoch(k, buf, attitude_buf);
        if (buf.size() > (1U << 20)) {
            out.write(buf);
            buf.clear();
        }
        if (attitude_buf.size() > (1U << 20)) {
            attitude.write(attitude_buf);
            attitude_buf.clear();
        }
    }
    out.write(buf);
    attitude.write(attitude_buf);
    progress.done();
    const SimulateSummary sum = mission.finish(opt.start_t + static_cast<double>(epochs - 1) * opt.step_s);
    outputs["--out (mountings)"].write(format_mountings(simulated_mountings(opt.heads)));
    outputs["--out (truth model)"].write(format_model(truths.front().file));
    outputs["--out (truth history)"].write(truth_history_csv(truths));
    outputs["--out (noise floor)"].write(floor_json(sum.floor, sum.pairs));
    outputs["--out (daily noise floor)"].write(floor_daily_csv(mission.daily(), opt.start_t, sum.pairs));
    outputs["--out (heater events)"].write(heaters_csv(sum.heaters));
    return sum;
}

SimulateSummary simulate(const SimulateOptions& opt) {
    OutputSet outputs(simulate_outputs(opt), simulate_inputs(opt));
    const SimulateSummary sum = simulate(opt, outputs);
    outputs.commit();
    return sum;
}

}  // namespace ascorr::host
