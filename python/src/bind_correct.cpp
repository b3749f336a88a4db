// python/src/bind_correct.cpp: correct() and earth_velocity(). correct()
// builds, per row, the SolutionRecord that the solutions reader would have made
// of the same values and runs it through host::correct_row(), the per-row path
// of `ascorr correct`, so both agree bit for bit in every scalar. Per-row
// problems are status bits (docs/contract.md), never an exception: every row
// comes back. The GIL is released while rows are corrected, on the host's
// workers (workers.hpp).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstdint>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "ascorr/core/correct.hpp"
#include "ascorr/core/fixed_point.hpp"
#include "ascorr_host/correct/correct_file.hpp"
#include "ascorr_host/correct/correct_row.hpp"
#include "ascorr_host/correct/earth_velocity.hpp"
#include "ascorr_host/correct/lagged_temperatures.hpp"
#include "ascorr_host/correct/states_velocity.hpp"
#include "ascorr_host/correct/workers.hpp"
#include "ascorr_host/formats/diagnostics.hpp"
#include "ascorr_host/formats/states_csv.hpp"
#include "bind.hpp"
#include "docstrings.hpp"

namespace ascorr::python {

using host::SolutionRecord;
using namespace pybind11::literals;

namespace {

// Below this many rows per thread a thread costs more than it saves.
constexpr std::size_t kRowsPerThread = 16384;

// The rows' velocities from the states asked in time order, as by `ascorr correct`.
template <typename T>
host::StatesVelocityTable<T> velocity_table(const Rows& r, const host::StatesFile& states, double max_propagation_s) {
    std::vector<std::int64_t> times;
    SolutionRecord rec;
    TtTime t{};
    for (py::ssize_t i = 0; i < r.n; ++i) {
        record_of(r, i, rec);
        if (rec.velocity_components == 0 && tt_from_seconds(rec.t, t)) {
            times.push_back(t.us);
        }
    }
    return host::StatesVelocityTable<T>(states, host::service_config(max_propagation_s), std::move(times),
                                        host::worker_count(static_cast<std::size_t>(r.n), kRowsPerThread));
}

template <typename T>
void correct_rows(const Rows& r, const host::ModelFile* m, bool aberration, const host::StatesFile* states,
                  double max_propagation_s, double* q_out, std::uint16_t* st_out) {
    std::optional<ThermalModel<T>> model;
    if (m != nullptr) {
        model = host::to_core<T>(*m);
    }
    // In the core's scalar (host::correct_row).
    const std::optional<SunTermModel<T>> sun = host::sun_term_if_any<T>(m);
    const CorrectionConfig<T> cfg{aberration, model ? &*model : nullptr};
    const SunTermModel<T>* sun_term = sun ? &*sun : nullptr;
    py::gil_scoped_release unlocked;
    const std::optional<host::StatesVelocityTable<T>> table = states != nullptr && aberration
                                                                  ? velocity_table<T>(r, *states, max_propagation_s)
                                                                  : std::optional<host::StatesVelocityTable<T>>{};
    // A lagged model's heads: their temperatures through the lag, as by `ascorr correct`.
    const std::optional<host::LaggedTemperatures> lag =
        m != nullptr ? host::lagged_temperatures(host::head_lags(*m), source_of(r)) : std::nullopt;
    const auto n = static_cast<std::size_t>(r.n);
    host::for_each_piece(n, host::worker_count(n, kRowsPerThread), [&](std::size_t begin, std::size_t end) {
        host::EarthVelocity earth;
        std::optional<host::StatesVelocity<T>> service;  // per thread, as per chunk in `ascorr correct`
        if (states != nullptr) {
            service.emplace(*states, host::service_config(max_propagation_s), table ? &*table : nullptr);
        }
        SolutionRecord rec;
        for (auto i = static_cast<py::ssize_t>(begin); i < static_cast<py::ssize_t>(end); ++i) {
            record_of(r, i, rec);
            if (lag && cfg.thermal != nullptr) {
                lag->apply(rec);
            }
            put_row(host::correct_row(rec, &earth, cfg, service ? &*service : nullptr, sun_term), i, q_out, st_out);
        }
    });
}

// The states file of `ascorr correct --states`, read as it reads it; the
// states the on-board service refuses are reported as a Python warning.
std::optional<host::StatesFile> states_arg(const py::object& states, const std::string& frame,
                                           double max_propagation_s) {
    if (!host::max_propagation_acceptable(max_propagation_s)) {
        bad_argument("max_propagation",
                     std::string(host::kMaxPropagationRule) + ", got " + number_text(max_propagation_s));
    }
    if (states.is_none()) {
        return std::nullopt;
    }
    if (!py::isinstance<py::str>(states) && !py::hasattr(states, "__fspath__")) {
        bad_argument("states",
                     "expected the path of a states file (t,x,y,z,vx,vy,vz; str or os.PathLike) or None, got " +
                         value_text(states));
    }
    const std::string path = path_arg(states, "states");
    std::ostringstream log;
    host::Diagnostics diag(log);
    std::optional<host::StatesFile> f =
        host::read_states_file(path, frame == "gcrs" ? StateFrame::kGcrs : StateFrame::kItrf, diag);
    diag.summarize();
    if (!log.str().empty()) {
        if (PyErr_WarnEx(PyExc_UserWarning, log.str().c_str(), 1) != 0) {
            throw py::error_already_set();
        }
    }
    return f;
}

py::tuple correct(const py::object& t, const py::object& chu, const py::object& q, const py::object& temps,
                  const py::object& v, const py::object& model, const py::object& scalar_obj,
                  const py::object& aberration_obj, const py::object& states, const py::object& states_frame_obj,
                  const py::object& max_propagation_obj) {
    const host::ModelFile* m = model_arg(model);
    const host::ScalarKind scalar = scalar_arg(scalar_obj);
    const bool aberration = bool_arg(aberration_obj, "aberration");
    const std::string states_frame = choice_arg(states_frame_obj, "states_frame", {"itrf", "gcrs"});
    const double max_propagation = real_arg(max_propagation_obj, "max_propagation");
    const std::optional<host::StatesFile> sf = states_arg(states, states_frame, max_propagation);
    const host::StatesFile* s = sf ? &*sf : nullptr;
    if (m != nullptr) {
        try {
            host::check_model_for_scalar(*m, scalar, "model");  // refused, never saturated, as by the command line
        } catch (const std::runtime_error& e) {
            bad_argument("model", std::string(e.what()) + " (scalar='" + std::string(host::scalar_name(scalar)) + "')");
        }
    }
    const Rows r = rows_of(t, chu, q, temps, v);
    py::array_t<double> q_out({r.n, py::ssize_t{4}});
    py::array_t<std::uint16_t> st_out(r.n);
    double* qo = q_out.mutable_data();
    std::uint16_t* so = st_out.mutable_data();
    if (scalar == host::ScalarKind::kDouble) {
        correct_rows<double>(r, m, aberration, s, max_propagation, qo, so);
    } else if (scalar == host::ScalarKind::kFloat) {
        correct_rows<float>(r, m, aberration, s, max_propagation, qo, so);
    } else {
        correct_rows<Q30>(r, m, aberration, s, max_propagation, qo, so);
    }
    return py::make_tuple(q_out, st_out);
}

py::tuple earth_velocity(const py::object& t_obj, const py::object& exact_obj) {
    const Doubles t = time_array(t_obj, "t");
    const bool exact = bool_arg(exact_obj, "exact");
    const py::ssize_t n = t.shape(0);
    py::array_t<double> v({n, py::ssize_t{3}});
    py::array_t<double> d(n);
    double* vp = v.mutable_data();
    double* dp = d.mutable_data();
    const double* tp = t.data();
    {
        py::gil_scoped_release unlocked;
        const auto rows = static_cast<std::size_t>(n);
        host::for_each_piece(rows, host::worker_count(rows, kRowsPerThread), [&](std::size_t begin, std::size_t end) {
            host::EarthVelocity grid;
            for (std::size_t i = begin; i < end; ++i) {
                // Outside the ephemeris (1900-2100, NaN included): NaN, as the
                // correction then has no velocity (status 4+32).
                const bool inside = host::in_ephemeris_span(tp[i]);
                const host::EarthState s = !inside ? host::EarthState{}
                                           : exact ? host::earth_state_exact(tp[i])
                                                   : grid.at(tp[i]);
                vp[3 * i] = inside ? s.v_bary_kms.x : kNaN;
                vp[3 * i + 1] = inside ? s.v_bary_kms.y : kNaN;
                vp[3 * i + 2] = inside ? s.v_bary_kms.z : kNaN;
                dp[i] = inside ? s.sun_distance_au : kNaN;
            }
        });
    }
    return py::make_tuple(v, d);
}

}  // namespace

void bind_correct(py::module_& mod) {
    mod.def("correct", &correct, "t"_a, "chu"_a, "q"_a, "temps"_a, "v"_a, "model"_a = py::none(), "scalar"_a = "double",
            "aberration"_a = true, "states"_a = py::none(), "states_frame"_a = "itrf",
            "max_propagation"_a = host::CorrectOptions{}.max_propagation_s, docstring(docs::kCorrect));
    mod.def("earth_velocity", &earth_velocity, "t"_a, "exact"_a = false, docstring(docs::kEarthVelocity));
}

}  // namespace ascorr::python
