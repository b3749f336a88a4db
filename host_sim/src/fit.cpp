#include "ascorr_host/fit.hpp"

#include <Eigen/Geometry>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include <map>
#include <sstream>
#include <vector>
#include "ascorr_host/atomic_file.hpp"

#include "ascorr/correct.hpp"
#include "ascorr_host/earth_velocity.hpp"
#include "ascorr_host/epochs.hpp"
#include "ascorr_host/solution_input.hpp"

namespace ascorr::host {

namespace {

constexpr double kMuEarth = 398600.4418;  // km³/s²
constexpr double kDay = 86400.0;

struct Row {
    Eigen::Quaterniond q;        // aberration-corrected, ICRF into head
    std::array<double, 3> temp;  // T1, T2, T3
};

// Sums over one orbit of e_i and of the regressors, per head.
// Sums over one orbit's epochs. q: the rotations a = q_head_f ⊗ r⁻¹ relative
// to a provisional reference r (4-vectors, w ≥ 0); e: filled at the end, the
// small angles relative to the final reference, derived exactly from q (see
// fit_model), so that the result does not depend on which epoch came first.
struct OrbitSums {
    std::size_t count = 0;
    std::array<Eigen::Vector4d, 3> q{Eigen::Vector4d::Zero(), Eigen::Vector4d::Zero(), Eigen::Vector4d::Zero()};
    std::array<Eigen::Vector3d, 3> e{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
    std::array<Eigen::Vector3d, 3> x{Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
};

Eigen::Vector3d icrf_boresight(const Eigen::Quaterniond& q) {
    return q.toRotationMatrix().row(2).transpose();
}

std::string time_text(double t) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.3f", t);
    return buf;
}

}  // namespace

Drop fit_selection(const SolutionRecord& rec) noexcept {
    if ((rec.flags & 1) != 0) {
        return Drop::kHighRate;
    }
    if ((rec.flags & 2) != 0) {
        return Drop::kBrightObject;
    }
    if ((rec.flags & 4) != 0) {
        return Drop::kInvalid;
    }
    if (rec.confidence > 5.0) {
        return Drop::kConfidence;
    }
    if (!(rec.temperature_present[0] && rec.temperature_present[1] && rec.temperature_present[2])) {
        return Drop::kTemperature;
    }
    if (rec.velocity_components != 3) {
        return Drop::kVelocity;
    }
    return Drop::kNone;
}

const char* drop_name(Drop d) noexcept {
    switch (d) {
        case Drop::kNone:
            return "selected";
        case Drop::kHighRate:
            return "high-rate mode";
        case Drop::kBrightObject:
            return "bright object";
        case Drop::kInvalid:
            return "invalid";
        case Drop::kConfidence:
            return "confidence > 5";
        case Drop::kTemperature:
            return "temperature missing";
        case Drop::kVelocity:
            return "velocity missing";
        case Drop::kRejected:
            return "not correctable";
    }
    return "?";
}

namespace {
FitReport fit_pass(const FitOptions& opt, std::optional<double> earliest_period);

// NaN, zero or negative thresholds would silently accept or refuse everything.
void refuse_bad_fit_options(const FitOptions& opt) {
    if (opt.from && !std::isfinite(*opt.from)) {
        throw FitRefused("--from " + std::to_string(*opt.from) + ": not a finite time");
    }
    if (opt.to && !std::isfinite(*opt.to)) {
        throw FitRefused("--to " + std::to_string(*opt.to) + ": not a finite time");
    }
    if (!(opt.min_span_days > 0.0 && std::isfinite(opt.min_span_days))) {
        throw FitRefused("--min-days " + std::to_string(opt.min_span_days) + ": must be a positive number of days");
    }
    if (!(opt.max_condition > 0.0) || std::isnan(opt.max_condition)) {
        throw FitRefused("--max-condition " + std::to_string(opt.max_condition) + ": must be positive");
    }
}
}  // namespace

FitReport fit_model(const FitOptions& opt) {
    refuse_output_over_input({{"--in", opt.in}}, {{"--out", opt.out}}, true);
    refuse_bad_fit_options(opt);
    if (opt.from && opt.to && !(*opt.from < *opt.to)) {
        throw FitRefused("the modelling period is empty: --from " + time_text(*opt.from) + " is not before --to " +
                         time_text(*opt.to));
    }
    if (opt.orbit_period_s && !(*opt.orbit_period_s >= 600.0 && *opt.orbit_period_s <= 86400.0)) {
        throw FitRefused("--orbit-period must be in [600, 86400] s");
    }
    refuse_corrected_file(opt.in);  // fit applies the aberration itself: never twice
    return fit_pass(opt, std::nullopt);
}

namespace {
FitReport fit_pass(const FitOptions& opt, std::optional<double> earliest_period) {
    EarthVelocity earth;
    const CorrectionConfig<double> ab_only{true, nullptr};
    // Row order must not matter (issue 11). The reference N_i is the earliest
    // epoch's (re-based exactly at the end), and the orbit period, when not
    // given, comes from the earliest selected row: if that is not the first
    // one read, the file is read again with that period (unordered files only).
    // (earliest_period: that second reading.)
    FitReport r;
    std::optional<double> period;
    std::array<std::optional<Eigen::Quaterniond>, 3> reference;  // provisional r, then N_i
    std::array<Eigen::Quaterniond, 3> earliest_a;                // the earliest epoch's a
    double earliest_epoch = 0.0;
    double earliest_row = 0.0;
    double earliest_row_period = 0.0;
    std::map<long long, OrbitSums> orbits;
    bool any = false;
    const bool period_given = opt.orbit_period_s.has_value() || earliest_period.has_value();
    period = earliest_period ? earliest_period : opt.orbit_period_s;
    bool any_row = false;

    EpochAssembler<Row> epochs(opt.in, [&](const Epoch<Row>& e) {
        if (!(e.head[0] && e.head[1] && e.head[2])) {
            return;  // F needs A and C; the same epochs serve all heads
        }
        // Frame F (eqs. 1–3), rows X_F, Y_F, Z_F in ICRF.
        const Eigen::Vector3d za = icrf_boresight(e.head[0]->q);
        const Eigen::Vector3d zc = icrf_boresight(e.head[2]->q);
        const Eigen::Vector3d z_f = za.cross(zc).normalized();
        const Eigen::Vector3d x_f = (za + zc).normalized();
        const Eigen::Vector3d y_f = z_f.cross(x_f).normalized();
        Eigen::Matrix3d r_f_icrf;
        r_f_icrf.row(0) = x_f.transpose();
        r_f_icrf.row(1) = y_f.transpose();
        r_f_icrf.row(2) = z_f.transpose();
        const Eigen::Quaterniond q_f_icrf(r_f_icrf);
        const auto bin = static_cast<long long>(std::floor(e.t / *period));
        OrbitSums& o = orbits[bin];
        ++o.count;
        for (std::size_t h = 0; h < 3; ++h) {
            const Eigen::Quaterniond q_head_f = e.head[h]->q * q_f_icrf.conjugate();
            if (!reference[h]) {
                reference[h] = q_head_f;
            }
            Eigen::Quaterniond d = q_head_f * reference[h]->conjugate();
            if (d.w() < 0.0) {
                d.coeffs() = -d.coeffs();
            }
            o.q[h] += Eigen::Vector4d(d.w(), d.x(), d.y(), d.z());
            if (!any || e.t < earliest_epoch) {
                earliest_a[h] = d;
            }
            const auto& t = e.head[h]->temp;
            o.x[h] += Eigen::Vector3d(t[0], t[1] - t[0], t[2] - t[0]);
        }
        ++r.epochs;
        if (!any || e.t < earliest_epoch) {
            earliest_epoch = e.t;
        }
        if (!any || e.t < r.t_first) {
            r.t_first = e.t;
        }
        if (!any || e.t > r.t_last) {
            r.t_last = e.t;
        }
        any = true;
    });
    for_each_solution(
        opt.in,
        [&](const SolutionRecord& rec) {
            if ((opt.from && rec.t < *opt.from) || (opt.to && rec.t > *opt.to) || rec.head > 2) {
                return;
            }
            ++r.rows;
            Drop d = fit_selection(rec);
            CorrectedSolution<double> c{};
            if (d == Drop::kNone) {
                c = correct_solution(to_core_input<double>(rec, &earth), ab_only);
                if ((c.status & status::kAberrationApplied) == 0U) {
                    d = Drop::kRejected;
                }
            }
            ++r.dropped[static_cast<std::size_t>(d)];
            if (d != Drop::kNone) {
                return;
            }
            if (!period_given && (!any_row || rec.t < earliest_row)) {
                const double v = std::sqrt(squared_norm(rec.v_sc_kms));
                if (!(v > 1.0 && v < 12.0)) {
                    throw InputError(opt.in, rec.line, 1,
                                     "spacecraft speed " + std::to_string(v) +
                                         " km/s is not that of an Earth orbit: give --orbit-period");
                }
                earliest_row = rec.t;
                earliest_row_period = 2.0 * kPi * kMuEarth / (v * v * v);
                if (!period) {
                    period = earliest_row_period;
                }
            }
            any_row = true;
            Row row;
            row.q = Eigen::Quaterniond(c.q_chu_icrf.w, c.q_chu_icrf.x, c.q_chu_icrf.y, c.q_chu_icrf.z);
            row.temp = rec.temperature;
            epochs.add(rec.t, rec.head, rec.line, row);
        },
        "fit");
    epochs.finish();
    if (!period_given && period && *period != earliest_row_period) {
        return fit_pass(opt, earliest_row_period);  // rows out of time order: again, with the earliest row's period
    }
    r.orbit_period_s = period.value_or(0.0);
    // Re-base on the earliest epoch: with b = earliest a, each epoch's small
    // angle is 2·vec(a ⊗ b⁻¹), bilinear in a, so an orbit's sum is exactly
    // 2·vec(Σa ⊗ b⁻¹) (Σa as an unnormalised quaternion). Small angle: error ~ θ³/24.
    for (std::size_t h = 0; h < 3 && r.epochs != 0; ++h) {
        const Eigen::Quaterniond b_inv = earliest_a[h].conjugate();
        for (auto& kv : orbits) {
            const Eigen::Vector4d& s = kv.second.q[h];
            const Eigen::Quaterniond sum(s(0), s(1), s(2), s(3));
            kv.second.e[h] = 2.0 * (sum * b_inv).vec() * kRadToArcsec;
        }
        reference[h] = (earliest_a[h] * *reference[h]).normalized();
    }

    const std::string period_text = "t = " + time_text(r.t_first) + " .. " + time_text(r.t_last);
    if (r.epochs == 0) {
        throw FitRefused(opt.in +
                         ": no epoch in the modelling period has solutions of A, B and C that pass the selection");
    }
    const double span_days = (r.t_last - r.t_first) / kDay;
    if (span_days < opt.min_span_days) {
        char buf[200];
        std::snprintf(buf, sizeof buf,
                      "modelling period too short: the selected data span %.1f days (%s); at least %.1f days (one "
                      "thermal period; --min-days) are needed",
                      span_days, period_text.c_str(), opt.min_span_days);
        throw FitRefused(opt.in + ": " + buf);
    }

    // Orbits with at least half the typical number of epochs: a short one
    // (a gap, the ends of the period) is dominated by its part of the orbit.
    std::vector<std::size_t> counts;
    for (const auto& kv : orbits) {
        counts.push_back(kv.second.count);
    }
    std::nth_element(counts.begin(), counts.begin() + static_cast<long>(counts.size() / 2), counts.end());
    const std::size_t min_count = std::max<std::size_t>(2, counts[counts.size() / 2] / 2);
    std::vector<const OrbitSums*> used;
    for (const auto& kv : orbits) {
        if (kv.second.count >= min_count) {
            used.push_back(&kv.second);
        }
    }
    r.orbits_used = used.size();
    r.orbits_left_out = orbits.size() - used.size();
    if (used.size() < opt.min_orbits) {
        throw FitRefused(opt.in + ": too few orbits in the modelling period (" + period_text +
                         "): " + std::to_string(used.size()) + " with enough data, at least " +
                         std::to_string(opt.min_orbits) + " are needed (--min-orbits)");
    }

    // Joint least squares over the orbits k. With y_k = (e_A, e_B, e_C) the
    // orbit-averaged rotations relative to F (9 values) and c the 36
    // coefficients (head, axis, term), the model is
    //     y_k = A_k·c + G·g_k,   G = (N_A; N_B; N_C),
    // g_k being F's own rotation in that orbit (eq. 1–3 make F move with the
    // A and C boresights, i.e. with their temperatures): unknown, and common
    // to all heads. It is removed by projecting each orbit's 9 equations on
    // the complement of G's columns, P = I − G·Gᵀ/3 (GᵀG = 3·I). What remains
    // determines c up to a common rotation linear in T029 and T032 (the only
    // regressors all heads share): 9 directions the data cannot see.
    const auto n = static_cast<Eigen::Index>(used.size());
    Eigen::Matrix<double, 9, 3> g;
    for (std::size_t h = 0; h < 3; ++h) {
        g.block<3, 3>(static_cast<Eigen::Index>(3 * h), 0) = reference[h]->toRotationMatrix();
    }
    const Eigen::Matrix<double, 9, 9> proj = Eigen::Matrix<double, 9, 9>::Identity() - g * g.transpose() / 3.0;
    Eigen::MatrixXd y(n, 9);
    std::vector<std::array<Eigen::Vector4d, 3>> x(used.size());
    for (Eigen::Index k = 0; k < n; ++k) {
        const OrbitSums& o = *used[static_cast<std::size_t>(k)];
        const double w = 1.0 / static_cast<double>(o.count);
        for (std::size_t h = 0; h < 3; ++h) {
            y.block<1, 3>(k, static_cast<Eigen::Index>(3 * h)) = (o.e[h] * w).transpose();
            x[static_cast<std::size_t>(k)][h] << 1.0, o.x[h] * w;
        }
    }
    // Centre e on its mean, so that c0 refers to the mean orientation.
    const Eigen::RowVectorXd mean = y.colwise().mean();
    y.rowwise() -= mean;
    Eigen::MatrixXd design = Eigen::MatrixXd::Zero(9 * n, kUnknowns);
    Eigen::VectorXd target(9 * n);
    for (Eigen::Index k = 0; k < n; ++k) {
        Eigen::Matrix<double, 9, kUnknowns> a = Eigen::Matrix<double, 9, kUnknowns>::Zero();
        for (Eigen::Index h = 0; h < 3; ++h) {
            for (Eigen::Index ax = 0; ax < 3; ++ax) {
                a.block<1, 4>(3 * h + ax, 12 * h + 4 * ax) =
                    x[static_cast<std::size_t>(k)][static_cast<std::size_t>(h)];
            }
        }
        design.block<9, kUnknowns>(9 * k, 0) = proj * a;
        target.segment<9>(9 * k) = proj * y.row(k).transpose();
    }
    // Unit-norm columns: the singular values then measure how independent
    // the regressors are, not their units.
    const Eigen::VectorXd scale = design.colwise().norm().transpose();
    design = design * scale.cwiseInverse().asDiagonal();
    Eigen::BDCSVD<Eigen::MatrixXd> svd(design, Eigen::ComputeThinU | Eigen::ComputeThinV);
    const Eigen::VectorXd sv = svd.singularValues();
    r.singular_values.assign(sv.data(), sv.data() + sv.size());
    constexpr Eigen::Index kRank = kUnknowns - kGaugeDims;
    r.condition = sv(kRank - 1) > 0.0 ? sv(0) / sv(kRank - 1) : std::numeric_limits<double>::infinity();
    if (!(r.condition <= opt.max_condition)) {
        // Name the head whose coefficients dominate the weakest direction.
        const Eigen::VectorXd weakest = svd.matrixV().col(kRank - 1);
        Eigen::Index head = 0;
        Eigen::Vector3d share(weakest.segment<12>(0).squaredNorm(), weakest.segment<12>(12).squaredNorm(),
                              weakest.segment<12>(24).squaredNorm());
        share.maxCoeff(&head);
        char buf[400];
        std::snprintf(buf, sizeof buf,
                      "rank-deficient design: condition number %.3g exceeds %.3g (singular value %d of %d is %.3g, "
                      "the largest %.3g; the weakest direction is mostly CHU %c's coefficients): T_CHU, T029 - T_CHU "
                      "and T032 - T_CHU do not vary independently in the modelling period (%s)",
                      r.condition, opt.max_condition, static_cast<int>(kRank), static_cast<int>(kUnknowns),
                      sv(kRank - 1), sv(0), head_name(static_cast<std::uint8_t>(head)), period_text.c_str());
        throw FitRefused(opt.in + ": " + buf);
    }
    // Least squares on the observable directions only (truncated SVD).
    const Eigen::MatrixXd u = svd.matrixU().leftCols(kRank);
    const Eigen::MatrixXd v = svd.matrixV().leftCols(kRank);
    const Eigen::VectorXd c_scaled = v * (u.transpose() * target).cwiseQuotient(sv.head(kRank));
    Eigen::VectorXd c = scale.cwiseInverse().asDiagonal() * c_scaled;

    // The gauge: of all models the star trackers cannot tell apart (c plus a
    // common rotation w0 + w2·T029 + w3·T032), write the one whose corrections
    // are smallest (RMS over the orbits of the period).
    {
        Eigen::MatrixXd gd(9 * n, 9);
        Eigen::VectorXd gt(9 * n);
        for (Eigen::Index k = 0; k < n; ++k) {
            for (Eigen::Index h = 0; h < 3; ++h) {
                const Eigen::Vector4d& xh = x[static_cast<std::size_t>(k)][static_cast<std::size_t>(h)];
                const double t2 = xh(1) + xh(2);
                const double t3 = xh(1) + xh(3);
                const Eigen::Matrix3d nh = g.block<3, 3>(3 * h, 0);
                gd.block<3, 3>(9 * k + 3 * h, 0) = nh;
                gd.block<3, 3>(9 * k + 3 * h, 3) = nh * t2;
                gd.block<3, 3>(9 * k + 3 * h, 6) = nh * t3;
                for (Eigen::Index ax = 0; ax < 3; ++ax) {
                    gt(9 * k + 3 * h + ax) = -xh.dot(c.segment<4>(12 * h + 4 * ax));
                }
            }
        }
        const Eigen::VectorXd wv = gd.bdcSvd(Eigen::ComputeThinU | Eigen::ComputeThinV).solve(gt);
        for (Eigen::Index h = 0; h < 3; ++h) {
            const Eigen::Matrix3d nh = g.block<3, 3>(3 * h, 0);
            const Eigen::Vector3d w0 = nh * wv.segment<3>(0);
            const Eigen::Vector3d w2 = nh * wv.segment<3>(3);
            const Eigen::Vector3d w3 = nh * wv.segment<3>(6);
            for (Eigen::Index ax = 0; ax < 3; ++ax) {
                c(12 * h + 4 * ax + 0) += w0(ax);
                c(12 * h + 4 * ax + 1) += w2(ax) + w3(ax);  // T2 = T1 + (T2 − T1), likewise T3
                c(12 * h + 4 * ax + 2) += w2(ax);
                c(12 * h + 4 * ax + 3) += w3(ax);
            }
        }
    }

    // Residuals, with each orbit's common rotation removed (as in the fit).
    r.model.present = {true, true, true, false};
    Eigen::VectorXd res = target - design * c_scaled;
    for (std::size_t h = 0; h < 3; ++h) {
        for (std::size_t ax = 0; ax < 3; ++ax) {
            double ss = 0.0;
            double sy = 0.0;
            for (Eigen::Index k = 0; k < n; ++k) {
                const Eigen::Index row = 9 * k + static_cast<Eigen::Index>(3 * h + ax);
                ss += res(row) * res(row);
                sy += target(row) * target(row);
            }
            r.head[h].residual_rms[ax] = std::sqrt(ss / static_cast<double>(n));
            r.head[h].signal_rms[ax] = std::sqrt(sy / static_cast<double>(n));
            for (std::size_t t = 0; t < 4; ++t) {
                r.model.coefficients[h][ax][t] = c(static_cast<Eigen::Index>(12 * h + 4 * ax + t));
            }
        }
    }
    write_model_file(opt.out, r.model);
    return r;
}

}  // namespace

std::string describe(const FitReport& r) {
    std::ostringstream o;
    char buf[400];
    std::snprintf(buf, sizeof buf, "modelling period t = %.3f .. %.3f (%.1f days), orbit period %.1f s\n", r.t_first,
                  r.t_last, (r.t_last - r.t_first) / kDay, r.orbit_period_s);
    o << buf;
    o << "rows in the period " << r.rows << ", selected " << r.dropped[0] << "; dropped:";
    for (std::size_t d = 1; d < kDropKinds; ++d) {
        o << (d > 1 ? "," : "") << ' ' << drop_name(static_cast<Drop>(d)) << ' ' << r.dropped[d];
    }
    o << "\nepochs with A, B and C selected " << r.epochs << "; orbit averages used " << r.orbits_used
      << " (left out, too few epochs: " << r.orbits_left_out << ")\n";
    o << "fitted: the heads' rotations relative to the frame F of heads A and C (eqs. 1-3), orbit-averaged,\n"
         "jointly against [1, T_CHU, T029 - T_CHU, T032 - T_CHU] of each head, with F's own rotation in each orbit\n"
         "as a nuisance. Rotations common to all heads are not observable by the star trackers (they change no\n"
         "IBA): of the models that differ by one linear in T029 and T032 (9 directions), the one with the smallest\n"
         "corrections over the period is written. c0 refers to the mean orientations over the period.\n";
    std::snprintf(buf, sizeof buf,
                  "design %zu x %d (columns scaled to unit norm): singular values %.3g .. %.3g (%d observable), "
                  "condition number %.1f; unobservable directions at %.1e\n",
                  9 * r.orbits_used, static_cast<int>(kUnknowns), r.singular_values.front(),
                  r.singular_values[kUnknowns - kGaugeDims - 1], static_cast<int>(kUnknowns - kGaugeDims), r.condition,
                  r.singular_values[kUnknowns - kGaugeDims]);
    o << buf;
    o << "CHU  residual RMS alpha/beta/gamma (arcsec)   signal RMS alpha/beta/gamma (arcsec), orbit averages\n";
    for (std::size_t h = 0; h < 3; ++h) {
        const HeadFit& f = r.head[h];
        std::snprintf(buf, sizeof buf, "%c    %6.3f %6.3f %6.3f                      %6.3f %6.3f %6.3f\n",
                      head_name(static_cast<std::uint8_t>(h)), f.residual_rms[0], f.residual_rms[1], f.residual_rms[2],
                      f.signal_rms[0], f.signal_rms[1], f.signal_rms[2]);
        o << buf;
    }
    return o.str();
}

}  // namespace ascorr::host
