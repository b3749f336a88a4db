// The parts of `ascorr simulate` (ascorr_host/analysis/simulate.hpp) its sources share;
// private to the analysis library: simulate.cpp (the mission, epoch by epoch),
// simulate_environment.cpp (sky, orbit, heaters, temperatures),
// simulate_heads.cpp (a head's solution and row), simulate_options.cpp (the
// options' refusals, the truth models) and simulate_report.cpp (the summary's text).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <climits>
#include <cmath>
#include <cstddef>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "ascorr/core/correct.hpp"
#include "ascorr/nav/orbit_propagation.hpp"
#include "ascorr_host/analysis/simulate.hpp"
#include "ascorr_host/correct/earth_velocity.hpp"
#include "ascorr_host/formats/model_csv.hpp"

namespace ascorr::host::detail {

// A, B and C, the heads the simulator models itself; a head beyond them
// (index h ≥ kOwnHeads) is derived from head h − kOwnHeads (simulate.hpp).
constexpr std::size_t kOwnHeads = head_count(kPaperHeads);

inline Quaternion<double> from_eigen(const Eigen::Quaterniond& q) {
    return {q.w(), q.x(), q.y(), q.z()};
}

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

// Sun and Moon directions (GCRS), cached per hour: they move < 0.6° in that time,
// far less than the exclusion angles.
class SunMoon {
public:
    void at(double t, Eigen::Vector3d& sun, Eigen::Vector3d& moon);

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
    Heaters(double t0, std::mt19937_64& rng);
    // Every event scheduled so far, in time order (the last may lie beyond the data).
    const std::vector<HeaterEvent>& events() const { return events_; }
    // Profile 0..1 of the operational and survival heater at t.
    void at(double t, double& op, double& surv);

private:
    static constexpr double kTau = 0.5 * kSecondsPerDay;
    void schedule(double after);
    std::mt19937_64& rng_;
    double start_ = 0.0;
    double end_ = 0.0;
    bool operational_ = false;
    std::vector<HeaterEvent> events_;
};

// A run of consecutive epochs with something missing (telemetry or GPS gaps).
struct Gap {
    std::size_t left = 0;
    bool step(double p_start, std::size_t min_len, std::size_t max_len, std::mt19937_64& rng);
};

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
    Orbit(double start_t, SunMoon& sky);
    SpacecraftPose at(double dt) const;

private:
    double a_ = kEarthEquatorialRadiusKm + kSimAltitudeKm;
    double n_ = std::sqrt(kEarthGmKm3S2 / (a_ * a_ * a_));
    double inc_ = kSimInclinationDeg * kDegToRad;
    double node_rate_ = 2.0 * kPi / (365.2422 * kSecondsPerDay) - 2.0 * kPi / (kPlaneSunPeriodDays * kSecondsPerDay);
    double node0_ = 0.0;
};

// The geometry the temperatures follow at an epoch.
struct Exposure {
    double sinb = 0.0;  // sine of the Sun's angle to the orbital plane
    double orb = 0.0;   // cosine of the Sun from the position
};

Exposure exposure(const SpacecraftPose& o, const Eigen::Vector3d& sun);

// T_CHU A, B, C, T029, T032 (°C, rounded as written) at an epoch (simulate_environment.cpp).
std::array<double, 5> temperatures(const SpacecraftPose& o, const Eigen::Vector3d& sun, double op, double surv,
                                   std::array<Wander, 5>& wander, double step_s, Random& rnd);
// The recorded T_CHU of a head beyond C (simulate_environment.cpp).
double extra_chu_temperature(std::size_t h, const Exposure& x, double op, Wander& wander, double step_s, Random& rnd);

// The truth from t_from (s since J2000 TT, as written) on.
struct Truth {
    ModelFile file;
    ThermalModel<double> model;
    std::string name;
    double t_from = 0.0;
};

// --truth (from the first epoch), then each --truth-change (simulate_options.cpp).
std::vector<Truth> truth_models(const SimulateOptions& opt);
// The truths as a model history (simulate_report.cpp).
std::string truth_history_csv(const std::vector<Truth>& truths);
// The options' refusals (simulate_options.cpp).
void refuse_bad_options(const SimulateOptions& opt);

// Flags, confidence and a missing T_CHU of one head's solution.
struct Quality {
    long long flags = 0;
    double confidence = 0.0;
    bool bad = false;  // flagged or confidence > 5
    bool chu_temperature_missing = false;
};

// Everything one epoch shares between its heads.
struct EpochState {
    double t = 0.0;
    SpacecraftPose orbit;
    Eigen::Vector3d sun;
    Eigen::Vector3d moon;
    std::array<double, 5> temp{};               // T_CHU A, B, C, T029, T032
    std::array<double, kMaxHeads> extra_chu{};  // T_CHU of the heads beyond C, by head index
    // What the bench deforms with (BenchDynamics): temp and extra_chu through
    // the lag (equal to them without one), and the orbit term's angle A·(v̂·ŝ), arcsec.
    std::array<double, 5> bench{};
    std::array<double, kMaxHeads> bench_extra_chu{};
    double orbit_term_arcsec = 0.0;
    bool no_temperature = false;  // telemetry gap
    bool no_velocity = false;     // GPS gap
};

// Head h's T_CHU at the epoch, as recorded and as the bench feels it.
inline double t_chu(const EpochState& e, std::size_t h) {
    return h < kOwnHeads ? e.temp[h] : e.extra_chu[h];
}
inline double bench_t_chu(const EpochState& e, std::size_t h) {
    return h < kOwnHeads ? e.bench[h] : e.bench_extra_chu[h];
}

// --bench-lag: each temperature through a first-order filter of time
// constant τ sampled every step (exact for a temperature constant over the
// step), started at its first value; τ = 0 passes every value through as it is.
class BenchLag {
public:
    BenchLag(double tau_s, double step_s) : gain_(tau_s > 0.0 ? -std::expm1(-step_s / tau_s) : 1.0), on_(tau_s > 0.0) {}
    // The bench's value of temperature `slot` (0 … 4: e.temp; 5 + h: T_CHU of
    // head h beyond C, slots 5 … 7 unused) for the reading x.
    double follow(std::size_t slot, double x) {
        if (!on_) {
            return x;
        }
        std::optional<double>& l = lagged_[slot];
        l = l ? *l + gain_ * (x - *l) : x;
        return *l;
    }

private:
    double gain_;
    bool on_;
    std::array<std::optional<double>, 5 + kMaxHeads> lagged_{};
};

// --orbit-term: head h's axis of the orbit term, head axes (simulate.hpp's top).
Eigen::Vector3d orbit_term_axis(std::size_t h);

// One head's solution at an epoch (when the head is not blinded).
struct HeadSolution {
    Quality quality;
    Quaternion<double> q_raw{};
    Vector3<double> z_floor{};  // boresight with noise only: for the noise floor
};

// A head's solution at an epoch (simulate_heads.cpp).
HeadSolution solve_head(std::size_t h, const Eigen::Matrix3d& r_true, double moon_deg, const EpochState& e,
                        const Truth& truth, double bias_rad, EarthVelocity& earth, Random& rnd);
// Its row of the solutions file (simulate_heads.cpp).
void append_row(std::string& buf, const EpochState& e, std::size_t h, const HeadSolution& s,
                const std::array<double, 3>& temps);

}  // namespace ascorr::host::detail
