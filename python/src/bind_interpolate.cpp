// python/src/bind_interpolate.cpp: interpolate(), the combined attitude at
// given times (ascorr_host/analysis/interpolate.hpp), as `ascorr interpolate`
// computes it from a combined file.
//
// The combined rows come as combine() returns them; they are written as the
// combined file's text and read back by its reader, so that a row the file
// reader would refuse is refused here too, with the same words (at
// "<arrays, 1-based row>:ROW:COLUMN"), and the numbers are the file's.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "ascorr/core/heads.hpp"
#include "ascorr/pipeline/epoch_key.hpp"
#include "ascorr_host/analysis/interpolate.hpp"
#include "ascorr_host/formats/combined_csv.hpp"
#include "ascorr_host/formats/csv.hpp"
#include "ascorr_text/input_error.hpp"
#include "bind.hpp"
#include "docstrings.hpp"

namespace ascorr::python {

using namespace pybind11::literals;

namespace {

py::object key_of(const py::dict& d, const char* key) {
    if (!d.contains(key)) {
        bad_argument("combined", std::string("expected a dict as combine() returns, without key '") + key + "'");
    }
    return d[key];
}

void append_number(std::string& out, double x) {
    if (std::isfinite(x)) {
        out += host::number_text(x);
    }
}

// combined['heads']: n strings of head letters (the reader checks their order).
std::vector<std::string> head_sets(const py::object& x, py::ssize_t n) {
    const std::string what = "expected " + std::to_string(n) + " strings of the letters " + kHeadLetters;
    if (py::isinstance<py::str>(x) || !py::isinstance<py::sequence>(py::object(as_numpy(x).attr("tolist")()))) {
        bad_argument("combined['heads']", what + ", got " + value_text(x));
    }
    const py::list items = as_numpy(x).attr("tolist")();
    if (static_cast<py::ssize_t>(items.size()) != n) {
        bad_argument("combined['heads']", what + ", got " + std::to_string(items.size()));
    }
    std::vector<std::string> out;
    for (const py::handle item : items) {
        const bool text = py::isinstance<py::str>(item);
        const std::string h = text ? item.cast<std::string>() : std::string();
        if (!text || h.find_first_not_of(kHeadLetters) != std::string::npos) {
            bad_argument("combined['heads']", what + ": row " + std::to_string(out.size() + 1) + " is " +
                                                  value_text(py::reinterpret_borrow<py::object>(item)));
        }
        out.push_back(h);
    }
    return out;
}

// The rows of combine()'s dict as the combined file's text (no header).
std::string combined_text(const py::dict& d, bool covariance) {
    const Doubles t = time_array(key_of(d, "t"), "combined['t']");
    const py::ssize_t n = t.shape(0);
    const Doubles q = real_array(key_of(d, "q"), "combined['q']", n, 4);
    const Doubles sigma = real_array(key_of(d, "sigma"), "combined['sigma']", n, 3);
    const py::array status = as_numpy(key_of(d, "status"));
    const Integers st = integers_of(status, 0, 255);
    if (st.bad_row >= 0 || status.ndim() != 1 || status.shape(0) != n) {
        bad_argument("combined['status']", "expected " + std::to_string(n) + " integers 0..255, shape (n,)" +
                                               (st.bad_row >= 0 ? ": row " + std::to_string(st.bad_row) + ": " + st.why
                                                                : ", got " + shape_text(status)));
    }
    const std::vector<std::string> heads = head_sets(key_of(d, "heads"), n);
    const Doubles cov = covariance ? real_array(key_of(d, "cov"), "combined['cov']", n, 3) : Doubles();
    std::string text;
    for (py::ssize_t i = 0; i < n; ++i) {
        text += host::number_text(t.data()[i]);
        for (int k = 0; k < 4; ++k) {
            text += ',';
            append_number(text, q.data()[4 * i + k]);
        }
        text += ',';
        text += heads[static_cast<std::size_t>(i)];
        for (int k = 0; k < 3; ++k) {
            text += ',';
            append_number(text, sigma.data()[3 * i + k]);
        }
        text += ',' + std::to_string(st.values[static_cast<std::size_t>(i)]);
        for (int k = 0; covariance && k < 3; ++k) {
            text += ',';
            append_number(text, cov.data()[3 * i + k]);
        }
        text += '\n';
    }
    return text;
}

std::vector<host::AttitudeRow> combined_rows(const py::dict& d, bool covariance) {
    const std::string text = combined_text(d, covariance);
    std::vector<host::AttitudeRow> rows;
    try {
        host::read_combined_rows(text, rows, {covariance}, kArrayRows, 1);
    } catch (const text::InputError& e) {
        throw py::value_error(std::string("argument 'combined': ") + e.what());
    }
    for (std::size_t i = 1; i < rows.size(); ++i) {
        if (!(rows[i].t > rows[i - 1].t)) {
            bad_argument("combined", "rows must be in time order: row " + std::to_string(i + 1) + " is not after row " +
                                         std::to_string(i));
        }
    }
    return rows;
}

py::dict interpolate_arrays(const py::object& combined, const py::object& at, const py::object& max_gap) {
    if (!py::isinstance<py::dict>(combined)) {
        bad_argument("combined", "expected a dict as combine() returns, got " + value_text(combined));
    }
    const py::dict d = combined;
    const bool covariance = d.contains("cov");
    const double gap = real_arg(max_gap, "max_gap");
    if (!(gap >= host::kMinMaxGapS && gap <= host::kMaxMaxGapS)) {
        bad_argument("max_gap", "expected seconds in [0.001, 1e6], got " + value_text(max_gap));
    }
    const std::vector<host::AttitudeRow> rows = combined_rows(d, covariance);
    const Doubles times = time_array(at, "at");
    std::vector<double> at_times(times.data(), times.data() + times.shape(0));
    for (std::size_t i = 0; i < at_times.size(); ++i) {
        if (!(std::abs(at_times[i]) < pipeline::kMaxEpochTimeS)) {
            bad_argument("at", "row " + std::to_string(i + 1) + ": " + host::number_text(at_times[i]) +
                                   " s is no time of an epoch");
        }
    }
    std::vector<host::AttitudeRow> out;
    {
        py::gil_scoped_release unlocked;
        host::Interpolator interp(std::move(at_times), gap, covariance);
        for (const host::AttitudeRow& r : rows) {
            interp.add(r);
        }
        std::string text;
        for (const host::AttitudeRow& r : interp.finish()) {
            host::append_combined_row(text, r, {covariance});
        }
        host::read_combined_rows(text, out, {covariance});  // the file's numbers (q to 15 decimals)
    }
    return combined_dict(out, covariance);
}

}  // namespace

void bind_interpolate(py::module_& mod) {
    mod.def("interpolate", &interpolate_arrays, "combined"_a, "at"_a, "max_gap"_a = host::kDefaultMaxGapS,
            docstring(docs::kInterpolate));
}

}  // namespace ascorr::python
