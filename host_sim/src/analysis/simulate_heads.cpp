// `ascorr simulate`'s heads: their mountings, and a head's solution (quality, noise, deformation, aberration), row.
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "ascorr_host/correct/solution_input.hpp"
#include "ascorr_host/formats/csv.hpp"
#include "ascorr_host/formats/solutions_csv.hpp"
#include "ascorr_text/c_format.hpp"
#include "ascorr_text/input_error.hpp"
#include "simulate_parts.hpp"

namespace ascorr::host {

using detail::from_eigen;
using detail::kOwnHeads;

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

MountingsFile simulated_mountings(HeadMask heads) {
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

namespace detail {

namespace {

// Star-tracker noise of clean rows: kSimNoiseCrossArcsec, kSimNoiseAboutArcsec (simulate.hpp).
constexpr double kFlaggedNoiseArcsec = 40.0;  // flagged solutions are bad in every axis
constexpr double kMoonBrightDeg = 30.0;       // Moon near the field: "big bright object" flag

char* put(char* p, char* end, double x, int decimals) {
    return format_fixed(p, end, x, decimals);
}

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
                     head_name(static_cast<std::uint8_t>(h)), kAxisNames[axis], angle * 180.0 / kPi, e.t,
                     bench_t_chu(e, h), e.bench[3], e.bench[4]);
    throw text::InputError(truth.name, truth.file.line[h][axis], 0, what);
}

}  // namespace

Eigen::Vector3d orbit_term_axis(std::size_t h) {
    const double r = std::sqrt(0.5);
    const Eigen::Vector3d own[kOwnHeads] = {Eigen::Vector3d::UnitX(), Eigen::Vector3d::UnitY(), {-r, r, 0.0}};
    return h < kOwnHeads ? own[h] : Eigen::Vector3d(-own[(h - kOwnHeads) % kOwnHeads]);
}

// Measured attitude: noise ⊗ deformation⁻¹ ⊗ truth (see the header), the
// deformation at the bench's temperatures, then the orbit term's rotation
// and bias_rad about the head's x axis (--head-bias), then the raw attitude
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

    HeadTemperatures<double> ht{{bench_t_chu(e, h), true}, {e.bench[3], true}, {e.bench[4], true}};
    const ThermalStage<double> th = thermal_stage(truth.model, static_cast<std::uint8_t>(h), ht);
    if (th.skip != 0U) {
        refuse_truth_angle(h, e, ht, truth);
    }
    Quaternion<double> q_meas = renormalized(conjugate(to_quaternion(th.q_th)) * from_eigen(q_noisy_true));
    if (e.orbit_term_arcsec != 0.0) {  // --orbit-term: no thermistor reads it
        const Eigen::Quaterniond q_orbit(Eigen::AngleAxisd(e.orbit_term_arcsec * kArcsecToRad, orbit_term_axis(h)));
        q_meas = renormalized(from_eigen(q_orbit) * q_meas);
    }
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

}  // namespace detail

}  // namespace ascorr::host
