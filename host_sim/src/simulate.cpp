#include "ascorr_host/simulate.hpp"

#include <erfa.h>
#include <erfam.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdio>
#include <random>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "ascorr/correct.hpp"
#include "ascorr_host/atomic_file.hpp"
#include "ascorr_host/csv.hpp"
#include "ascorr_host/earth_velocity.hpp"
#include "ascorr_host/embedded_model.hpp"
#include "ascorr_host/input_error.hpp"
#include "ascorr_host/model_csv.hpp"
#include "ascorr_host/progress.hpp"
#include "ascorr_host/solution_input.hpp"

namespace ascorr::host {

namespace {

constexpr double kMuEarth = 398600.4418;  // km³/s²
constexpr double kEarthRadiusKm = 6378.137;
constexpr double kDay = 86400.0;
constexpr double kDeg = kPi / 180.0;

// Star-tracker noise (1σ per axis, arcsec): good across, worse about the boresight.
constexpr double kNoiseCrossArcsec = 1.5;
constexpr double kNoiseAboutArcsec = 10.0;
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
            eraEpv00(ERFA_DJ00, tc / kDay, pvh, pvb);
            sun_ = -Eigen::Vector3d(pvh[0][0], pvh[0][1], pvh[0][2]).normalized();
            double pv[2][3];
            eraMoon98(ERFA_DJ00, tc / kDay, pv);
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
    static constexpr double kTau = 0.5 * kDay;
    void schedule(double after) {
        std::uniform_real_distribution<double> gap(40.0 * kDay, 80.0 * kDay);
        std::uniform_real_distribution<double> len(3.0 * kDay, 5.0 * kDay);
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
    const double az = kAzimuthDeg[head] * kDeg;
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

std::string heaters_csv(const std::vector<HeaterEvent>& events) {
    std::string s = "start,end,heater\n";
    char line[96];
    for (const HeaterEvent& e : events) {
        std::snprintf(line, sizeof line, "%.3f,%.3f,%s\n", e.start, e.end, e.operational ? "operational" : "survival");
        s += line;
    }
    return s;
}

std::string floor_json(const std::array<Rms, kPairs>& floor) {
    std::ostringstream s;
    s.precision(6);
    s << std::fixed << "{\"floor\": {";
    for (std::size_t p = 0; p < kPairs; ++p) {
        // A pair without clean epochs has no RMS: null (JSON has no NaN either).
        const auto value = [n = floor[p].n](double x) {
            std::ostringstream v;
            v.precision(6);
            v << std::fixed << x;
            return n != 0 && std::isfinite(x) ? v.str() : std::string("null");
        };
        s << (p ? ", " : "") << '"' << kPairNames[p] << "\": {\"rms\": " << value(floor[p].rms)
          << ", \"rms_200s\": " << value(floor[p].rms_smoothed) << ", \"n\": " << floor[p].n << '}';
    }
    s << "}}\n";
    return s.str();
}

std::string describe(const SimulateSummary& s) {
    std::ostringstream o;
    o << s.epochs << " epochs, " << s.rows << " rows; blinded (Sun/Moon) rows A/B/C: " << s.outage_rows[0] << '/'
      << s.outage_rows[1] << '/' << s.outage_rows[2] << "; flagged " << s.flagged_rows << ", without temperatures "
      << s.rows_without_temperature << ", without velocity " << s.rows_without_velocity
      << "\nnoise floor (IBA RMS, arcsec):";
    char buf[96];
    for (std::size_t p = 0; p < kPairs; ++p) {
        std::snprintf(buf, sizeof buf, "  %s %.3f (200 s: %.3f)", kPairNames[p], s.floor[p].rms,
                      s.floor[p].rms_smoothed);
        o << buf;
    }
    o << "\ntruth model: " << s.truth_path << "\nfloor: " << s.floor_path << "\nheater events (" << s.heaters.size()
      << "): " << s.heaters_path;
    return o.str();
}

SimulateSummary simulate(const SimulateOptions& opt) {
    refuse_output_over_input({{"--truth", opt.truth}}, {{"--out", opt.out},
                                                        {"--out (truth model)", opt.out + ".truth.csv"},
                                                        {"--out (noise floor)", opt.out + ".floor.json"}});
    if (!(opt.days > 0.0 && opt.days <= 36600.0)) {
        throw std::invalid_argument("--days must be in (0, 36600], got " + std::to_string(opt.days));
    }
    if (!(opt.step_s >= 1.0 && opt.step_s <= 600.0)) {
        throw std::invalid_argument("--step must be in [1, 600] s (the orbit must be resolved), got " +
                                    std::to_string(opt.step_s));
    }
    if (!in_ephemeris_span(opt.start_t) || !in_ephemeris_span(opt.start_t + opt.days * kDay)) {
        throw std::invalid_argument("--start " + std::to_string(opt.start_t) +
                                    ": the mission must lie within the Earth ephemeris (1900-2100; s since J2000 TT)");
    }
    const ModelFile truth_file = opt.truth.empty() ? table2_model() : read_model_file(opt.truth);
    for (std::size_t h = 0; h < 3; ++h) {
        if (!truth_file.present[h]) {
            throw std::invalid_argument((opt.truth.empty() ? std::string("truth model") : opt.truth) +
                                        ": no coefficients for CHU " + head_name(static_cast<std::uint8_t>(h)));
        }
    }
    const ThermalModel<double> truth = to_core<double>(truth_file);

    std::mt19937_64 rng(opt.seed);
    std::normal_distribution<double> normal(0.0, 1.0);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);

    // Orbit.
    const double a = kEarthRadiusKm + kSimAltitudeKm;
    const double n = std::sqrt(kMuEarth / (a * a * a));
    const double inc = kSimInclinationDeg * kDeg;
    const double sun_rate = 2.0 * kPi / (365.2422 * kDay);
    const double node_rate = sun_rate - 2.0 * kPi / (kPlaneSunPeriodDays * kDay);
    SunMoon sky;
    Eigen::Vector3d sun0;
    Eigen::Vector3d moon0;
    sky.at(opt.start_t, sun0, moon0);
    const double node0 = std::atan2(sun0.y(), sun0.x()) + 30.0 * kDeg;

    std::array<Eigen::Matrix3d, 3> mount;
    for (int h = 0; h < 3; ++h) {
        mount[static_cast<std::size_t>(h)] = head_mounting(h);
    }

    EarthVelocity earth;
    Heaters heaters(opt.start_t, rng);
    std::array<Wander, 5> wander;  // T_CHU A, B, C, T029, T032
    Gap telemetry_gap;
    Gap gps_gap;

    SimulateSummary sum;
    AtomicFile out(opt.out);
    std::string buf;
    buf.reserve(2U << 20);
    buf += "t,chu,qw,qx,qy,qz,t_chu,t_029,t_032,vx,vy,vz,flags,confidence\n";
    std::array<std::vector<double>, kPairs> floor_t;
    std::array<std::vector<double>, kPairs> floor_v;

    const auto epochs = static_cast<std::size_t>(std::floor(opt.days * kDay / opt.step_s)) + 1;
    Progress progress("simulate");
    for (std::size_t k = 0; k < epochs; ++k) {
        if ((k & 4095U) == 0) {
            progress.update(static_cast<double>(k) / static_cast<double>(epochs));
        }
        const double dt = static_cast<double>(k) * opt.step_s;
        const double t = std::round((opt.start_t + dt) * 1000.0) / 1000.0;  // as written
        // Orbit and spacecraft attitude.
        const double u = n * dt;
        const double node = node0 + node_rate * dt;
        const Eigen::Vector3d P(std::cos(node), std::sin(node), 0.0);
        const Eigen::Vector3d Q(-std::cos(inc) * std::sin(node), std::cos(inc) * std::cos(node), std::sin(inc));
        const Eigen::Vector3d r_hat = std::cos(u) * P + std::sin(u) * Q;
        const Eigen::Vector3d v_dir = -std::sin(u) * P + std::cos(u) * Q;
        Eigen::Vector3d v_sc = a * n * v_dir;
        for (int i = 0; i < 3; ++i) {
            v_sc[i] = std::round(v_sc[i] * 1e6) / 1e6;  // as written
        }
        Eigen::Matrix3d body_icrf;
        body_icrf.row(0) = v_dir.transpose();
        body_icrf.row(2) = -r_hat.transpose();
        body_icrf.row(1) = (-r_hat).cross(v_dir).transpose();
        Eigen::Vector3d sun;
        Eigen::Vector3d moon;
        sky.at(t, sun, moon);

        // Temperatures: seasonal (sine of the Sun's angle to the orbital plane),
        // orbital (sunlit side), independent wander, heater events, read noise.
        const double sinb = sun.dot(P.cross(Q));
        const double orb = r_hat.dot(sun);
        double op = 0.0;
        double surv = 0.0;
        heaters.at(t, op, surv);
        for (auto& w : wander) {
            w.step(opt.step_s, 3.0 * kDay, 0.6, rng);
        }
        const double s2 = sinb * sinb;
        double temp[5] = {
            10.0 + 5.0 * sinb + 2.0 * s2 + 0.8 * orb + wander[0].x + 2.5 * op,
            14.0 - 7.0 * sinb + 1.0 * s2 + 1.2 * orb + wander[1].x + 3.0 * op,
            8.0 - 4.0 * sinb + 3.0 * s2 + 0.6 * orb + wander[2].x + 2.0 * op,
            -9.0 + 3.0 * sinb - 2.0 * s2 + 0.3 * orb + wander[3].x + 3.0 * surv,
            -20.0 + 2.0 * sinb + 4.0 * s2 + 0.2 * orb + wander[4].x + 2.0 * op,
        };
        for (double& x : temp) {
            x = std::round((x + 0.02 * normal(rng)) * 1000.0) / 1000.0;  // as written
        }
        const bool no_temperature = telemetry_gap.step(2e-4, 10, 120, rng);
        const bool no_velocity = gps_gap.step(1e-4, 5, 60, rng);

        std::array<bool, 3> written{};
        std::array<bool, 3> clean{};
        std::array<Vector3<double>, 3> z_floor{};
        for (std::size_t h = 0; h < 3; ++h) {
            const Eigen::Matrix3d r_true = mount[h] * body_icrf;
            const Eigen::Vector3d z_icrf = r_true.row(2).transpose();
            const double sun_deg = std::acos(std::clamp(z_icrf.dot(sun), -1.0, 1.0)) / kDeg;
            const double moon_deg = std::acos(std::clamp(z_icrf.dot(moon), -1.0, 1.0)) / kDeg;
            if (sun_deg < kSunExclusionDeg || moon_deg < kMoonExclusionDeg) {
                ++sum.outage_rows[h];
                continue;
            }
            // Flags and confidence.
            long long flags = 0;
            if (uniform(rng) < 0.002) {
                flags |= 1;
            }
            if (moon_deg < kMoonBrightDeg || uniform(rng) < 0.001) {
                flags |= 2;
            }
            if (uniform(rng) < 0.0005) {
                flags |= 4;
            }
            double confidence = std::min(4.9, 1.0 + 0.5 * std::fabs(normal(rng)));
            if (uniform(rng) < 0.003) {
                confidence = 5.5 + 10.0 * uniform(rng);
            }
            const bool bad = flags != 0 || confidence > 5.0;
            const bool chu_temperature_missing = uniform(rng) < 0.001;

            // Measured attitude: noise ⊗ deformation⁻¹ ⊗ truth (see the header).
            const double sx = bad ? kFlaggedNoiseArcsec : kNoiseCrossArcsec;
            const double sz = bad ? kFlaggedNoiseArcsec : kNoiseAboutArcsec;
            const Eigen::Vector3d noise(sx * normal(rng), sx * normal(rng), sz * normal(rng));
            const Eigen::Vector3d noise_rad = noise * kArcsecToRad;
            const Eigen::Quaterniond q_noise(Eigen::AngleAxisd(noise_rad.norm(), noise_rad.normalized()));
            const Eigen::Quaterniond q_true(r_true);
            const Eigen::Quaterniond q_noisy_true = (q_noise * q_true).normalized();

            HeadTemperatures<double> ht{{temp[h], true}, {temp[3], true}, {temp[4], true}};
            const ThermalStage<double> th = thermal_stage(truth, static_cast<std::uint8_t>(h), ht);
            if (th.skip != 0U) {
                char what[200];
                std::snprintf(what, sizeof what,
                              "CHU %c: the truth model gives an angle beyond 1 degree at t = %.17g s (T_CHU %g, "
                              "T029 %g, T032 %g degC)",
                              head_name(static_cast<std::uint8_t>(h)), t, temp[h], temp[3], temp[4]);
                throw InputError(opt.truth.empty() ? std::string("truth model (Table 2)") : opt.truth,
                                 truth_file.line[h][0], 0, what);
            }
            const Quaternion<double> q_meas =
                renormalized(conjugate(to_quaternion(th.q_th)) * from_eigen(q_noisy_true));
            // Undo the aberration correction: q_raw = q_meas ⊗ q_ab(z_raw), by
            // fixed-point iteration (contraction ≈ |β| ≈ 1e-4 per step).
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
            q_raw = canonical(q_raw);

            // The row.
            char line[256];
            char* p = line;
            char* const end = line + sizeof line;
            p = put(p, end, t, 3);
            *p++ = ',';
            *p++ = head_name(static_cast<std::uint8_t>(h));
            for (double c : {q_raw.w, q_raw.x, q_raw.y, q_raw.z}) {
                *p++ = ',';
                p = put(p, end, c, 15);
            }
            for (std::size_t i = 0; i < 3; ++i) {
                *p++ = ',';
                const double value = i == 0 ? temp[h] : temp[i + 2];
                if (!(no_temperature || (i == 0 && chu_temperature_missing))) {
                    p = put(p, end, value, 3);
                }
            }
            for (int i = 0; i < 3; ++i) {
                *p++ = ',';
                if (!no_velocity) {
                    p = put(p, end, v_sc[i], 6);
                }
            }
            p += std::snprintf(p, static_cast<std::size_t>(end - p), ",%lld,", flags);
            p = put(p, end, confidence, 2);
            *p++ = '\n';
            buf.append(line, static_cast<std::size_t>(p - line));

            ++sum.rows;
            sum.flagged_rows += bad ? 1U : 0U;
            const bool temps_missing = no_temperature || chu_temperature_missing;
            sum.rows_without_temperature += temps_missing ? 1U : 0U;
            sum.rows_without_velocity += no_velocity ? 1U : 0U;
            written[h] = true;
            clean[h] = !bad && !temps_missing && !no_velocity;
            const Eigen::Vector3d zf = q_noisy_true.toRotationMatrix().row(2).transpose();
            z_floor[h] = {zf.x(), zf.y(), zf.z()};
        }
        for (std::size_t pr = 0; pr < kPairs; ++pr) {
            const auto i = kPairHeads[pr][0];
            const auto j = kPairHeads[pr][1];
            if (written[i] && written[j] && clean[i] && clean[j]) {
                floor_t[pr].push_back(t);
                floor_v[pr].push_back(angle_arcsec(z_floor[i], z_floor[j]));
            }
        }
        ++sum.epochs;
        if (buf.size() > (1U << 20)) {
            out.write(buf);
            buf.clear();
        }
    }
    out.write(buf);
    progress.done();
    for (std::size_t pr = 0; pr < kPairs; ++pr) {
        sum.floor[pr] = rms_about_mean(floor_t[pr], floor_v[pr]);
    }
    sum.truth_path = opt.out + ".truth.csv";
    sum.floor_path = opt.out + ".floor.json";
    sum.heaters_path = opt.out + ".heaters.csv";
    const double t_last = opt.start_t + static_cast<double>(epochs - 1) * opt.step_s;
    for (const HeaterEvent& e : heaters.events()) {
        if (e.start <= t_last) {
            sum.heaters.push_back(e);
        }
    }
    out.commit();
    write_model_file(sum.truth_path, truth_file);
    write_file_atomically(sum.floor_path, floor_json(sum.floor));
    write_file_atomically(sum.heaters_path, heaters_csv(sum.heaters));
    return sum;
}

}  // namespace ascorr::host
