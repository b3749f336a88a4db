// python/src/bind_self_calibration.cpp: self_calibrate(), `ascorr correct
// --self-calibrate` on arrays: the host's run of the on-board estimator
// (self_calibration.hpp), then each row corrected with the model active at its
// time, through host::correct_row() as on the command line.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "ascorr/core/correct.hpp"
#include "ascorr/core/fixed_point.hpp"
#include "ascorr/pipeline/common_rotation_weights.hpp"
#include "ascorr_host/correct/correct_file.hpp"
#include "ascorr_host/correct/correct_row.hpp"
#include "ascorr_host/correct/earth_velocity.hpp"
#include "ascorr_host/correct/lagged_temperatures.hpp"
#include "ascorr_host/correct/self_calibration.hpp"
#include "bind.hpp"
#include "docstrings.hpp"

namespace ascorr::python {

using host::SolutionRecord;
using namespace pybind11::literals;

namespace {

template <typename T>
py::list self_calibrated_rows(const Rows& r, const host::ModelFile* m, double time_constant_days,
                              std::optional<double> orbit_period_s, const calib::CommonRotationWeights& rule,
                              const std::array<double, kMaxHeads>& lag_s, bool learn_lag, bool learn_sun, double* q_out,
                              std::uint16_t* st_out) {
    calib::EstimatorConfig cfg;
    cfg.time_constant_days = time_constant_days;
    cfg.common_rotation = rule;
    // The lagged heads' temperatures, learnt from and corrected with, as by `ascorr correct`.
    const std::optional<host::LaggedTemperatures> lag = host::lagged_temperatures(lag_s, source_of(r));
    const host::RowSource rows = source_of(r);
    const host::SelfCalibration sc =
        host::self_calibrate<T>(kArrayRows, lag ? host::lagged_rows(rows, *lag) : rows,
                                m != nullptr ? std::optional<host::ModelFile>(*m) : std::nullopt, cfg, orbit_period_s,
                                host::kSelfCalibrationMemoryBytes, kMaxHeads, lag_s, learn_lag, learn_sun);
    const host::ModelSchedule<T> schedule(sc.history);
    // lag='auto': the lags the history's models took, as `ascorr correct --lag auto`.
    const std::optional<host::LagSchedule> learnt = learn_lag ? host::learnt_lags(sc.history, rows) : std::nullopt;
    host::EarthVelocity earth;
    SolutionRecord rec;
    for (py::ssize_t i = 0; i < r.n; ++i) {
        record_of(r, i, rec);
        if (lag) {
            lag->apply(rec);
        } else if (learnt) {
            learnt->apply(rec);
        }
        const CorrectionConfig<T> c{true, &schedule.at(rec.t)};
        put_row(host::correct_row<T>(rec, &earth, c, nullptr, schedule.sun_at(rec.t)), i, q_out, st_out);
    }
    py::list history;
    for (const host::ActiveModel& a : sc.history) {
        py::dict d;
        d["t"] = a.t;
        d["tt_us"] = a.t_us;
        d["version"] = a.version;
        d["crc32c"] = a.crc;
        d["model"] = py::cast(a.model);
        py::dict origin;  // per head present: "given", "learnt" or "kept" (head_origin)
        for (std::size_t h = 0; h < kMaxHeads; ++h) {
            if (a.model.present[h]) {
                origin[py::str(std::string(1, host::head_name(static_cast<std::uint8_t>(h))))] =
                    host::head_origin(a.version, h, a.learnt);
            }
        }
        d["origin"] = origin;
        history.append(d);
    }
    return history;
}

py::tuple self_calibrate(const py::object& t, const py::object& chu, const py::object& q, const py::object& temps,
                         const py::object& v, const py::object& flags, const py::object& confidence,
                         const py::object& model, const py::object& scalar_obj, const py::object& time_constant_obj,
                         const py::object& orbit_period_obj, const py::object& mountings, const py::object& lag_obj,
                         const py::object& sun_term) {
    const host::ModelFile* m = model_arg(model);
    // The run's lag: lag= ('auto': learnt from none), otherwise the model's, as correct --lag.
    const std::optional<std::array<double, kMaxHeads>> lag_given = lag_obj.is_none() ? std::nullopt : lags_arg(lag_obj);
    const bool learn_lag = !lag_obj.is_none() && !lag_given;
    const std::array<double, kMaxHeads> lag_s =
        lag_given ? *lag_given : (m != nullptr ? host::head_lags(*m) : std::array<double, kMaxHeads>{});
    // The rule for the rotation common to all heads, as correct --mountings M: combined.
    calib::CommonRotationWeights rule{};
    if (!mountings.is_none()) {
        const host::MountingsFile mf = mountings_arg(mountings);
        if (!mf.sigmas) {
            bad_argument("mountings",
                         "no sigma_cross, sigma_about: the rule for the rotation common to all heads weighs the heads "
                         "by their noise");
        }
        rule = pipeline::common_rotation_weights(mf.mountings);
    }
    const host::ScalarKind scalar = scalar_arg(scalar_obj);
    // sun_term='auto': learnt from none, as correct --sun-term auto.
    const bool learn_sun = choice_arg(sun_term, "sun_term", {"auto", "none"}) == "auto";
    const double time_constant = real_arg(time_constant_obj, "time_constant");
    if (!calib::time_constant_acceptable(time_constant)) {
        bad_argument("time_constant",
                     "expected days in " + host::time_constant_range() + ", got " + value_text(time_constant_obj));
    }
    std::optional<double> orbit_period;
    if (!orbit_period_obj.is_none()) {
        orbit_period = real_arg(orbit_period_obj, "orbit_period");
        if (!host::orbit_period_acceptable(*orbit_period)) {
            bad_argument("orbit_period",
                         "expected seconds in " + host::orbit_period_range() + ", got " + value_text(orbit_period_obj));
        }
    }
    if (m != nullptr) {
        try {
            host::refuse_quadratic_initial_model(*m, "the model given");
            if (learn_lag) {
                host::refuse_lag_to_learn(*m, "the model given", "lag='auto'");
            }
            host::refuse_other_lag(*m, "the model given", lag_s);
            host::refuse_sun_term(*m, "the model given", host::kSunTermNotLearnt);
        } catch (const std::runtime_error& e) {
            bad_argument("model", e.what());
        }
    }
    if (m != nullptr) {
        try {
            host::check_model_for_scalar(*m, scalar, "model");  // refused, never saturated, as by the command line
        } catch (const std::runtime_error& e) {
            bad_argument("model", std::string(e.what()) + " (scalar='" + std::string(host::scalar_name(scalar)) + "')");
        }
    }
    const Rows r = rows_of(t, chu, q, temps, v, flags, confidence);
    py::array_t<double> q_out({r.n, py::ssize_t{4}});
    py::array_t<std::uint16_t> st_out(r.n);
    py::list history;
    if (scalar == host::ScalarKind::kDouble) {
        history = self_calibrated_rows<double>(r, m, time_constant, orbit_period, rule, lag_s, learn_lag, learn_sun,
                                               q_out.mutable_data(), st_out.mutable_data());
    } else if (scalar == host::ScalarKind::kFloat) {
        history = self_calibrated_rows<float>(r, m, time_constant, orbit_period, rule, lag_s, learn_lag, learn_sun,
                                              q_out.mutable_data(), st_out.mutable_data());
    } else {
        history = self_calibrated_rows<Q30>(r, m, time_constant, orbit_period, rule, lag_s, learn_lag, learn_sun,
                                            q_out.mutable_data(), st_out.mutable_data());
    }
    return py::make_tuple(q_out, st_out, history);
}

}  // namespace

void bind_self_calibration(py::module_& mod) {
    mod.def("self_calibrate", &self_calibrate, "t"_a, "chu"_a, "q"_a, "temps"_a, "v"_a, "flags"_a = py::none(),
            "confidence"_a = py::none(), "model"_a = py::none(), "scalar"_a = "double", "time_constant"_a = 30.0,
            "orbit_period"_a = py::none(), "mountings"_a = py::none(), "lag"_a = py::none(), "sun_term"_a = "none",
            docstring(docs::kSelfCalibrate));
}

}  // namespace ascorr::python
