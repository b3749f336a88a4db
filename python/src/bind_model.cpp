// python/src/bind_model.cpp: ascorr.Model (the host's ModelFile) and
// read_model(): the model file of docs/contract.md, read and written by the
// host's model_csv.hpp.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <string_view>

#include "ascorr_host/formats/model_csv.hpp"
#include "bind.hpp"
#include "docstrings.hpp"

namespace ascorr::python {

using namespace pybind11::literals;

namespace {

// Numbers per head, axis and K columns (the terms' or the Sun term's) as a
// (heads, 3, K) array, a copy.
template <std::size_t K>
py::array_t<double> per_head_and_axis(const std::array<std::array<std::array<double, K>, kModelAxes>, kMaxHeads>& x) {
    py::array_t<double> a({py::ssize_t{kMaxHeads}, py::ssize_t{kModelAxes}, static_cast<py::ssize_t>(K)});
    double* p = a.mutable_data();
    for (std::size_t h = 0; h < kMaxHeads; ++h) {
        for (std::size_t ax = 0; ax < kModelAxes; ++ax) {
            for (std::size_t c = 0; c < K; ++c) {
                *p++ = x[h][ax][c];
            }
        }
    }
    return a;
}

py::array_t<double> model_coefficients(const host::ModelFile& m) {
    return per_head_and_axis(m.coefficients);
}

// lag_s: None (no head lags) or @N_HEADS@ numbers, each 0 or a lag the model file takes.
void lags_into(const py::object& lag_s, host::ModelFile& m) {
    if (lag_s.is_none()) {
        return;
    }
    const py::array a = as_numpy(lag_s);
    const char kind = a.dtype().kind();
    if ((kind != 'f' && kind != 'i' && kind != 'u') || a.ndim() != 1 || a.shape(0) != py::ssize_t{kMaxHeads}) {
        bad_argument("lag_s", "expected " + std::to_string(kMaxHeads) + " real numbers (head " + head_letter_range() +
                                  ") or None, got " + shape_text(a) + " of dtype " + std::string(py::str(a.dtype())));
    }
    const Doubles d = Doubles::ensure(a);
    for (std::size_t h = 0; h < kMaxHeads; ++h) {
        if (!host::lag_acceptable(d.data()[h])) {
            bad_argument("lag_s", std::string("head ") + head_letter(static_cast<std::uint8_t>(h)) + "'s " +
                                      number_text(d.data()[h]) + " is not " + host::lag_range_text());
        }
        if (!m.present[h] && d.data()[h] != 0.0) {
            bad_argument("lag_s", std::string("head ") + head_letter(static_cast<std::uint8_t>(h)) +
                                      " has no coefficients (heads): its lag must be 0, got " +
                                      number_text(d.data()[h]));
        }
        m.lag_s[h] = d.data()[h];
    }
}

// sun: None (no Sun term) or (@N_HEADS@, 3, 3) arcsec, each axis within the core's domain.
void sun_into(const py::object& sun, host::ModelFile& m) {
    if (sun.is_none()) {
        return;
    }
    const py::array a = as_numpy(sun);
    const char kind = a.dtype().kind();
    if ((kind != 'f' && kind != 'i' && kind != 'u') || a.ndim() != 3 || a.shape(0) != py::ssize_t{kMaxHeads} ||
        a.shape(1) != py::ssize_t{kModelAxes} || a.shape(2) != py::ssize_t{kSunComponents}) {
        bad_argument("sun", "expected real numbers of shape (" + std::to_string(kMaxHeads) +
                                ", 3, 3) (head, axis alpha/beta/gamma, x/y/z) or None, got " + shape_text(a) +
                                " of dtype " + std::string(py::str(a.dtype())));
    }
    const Doubles d = Doubles::ensure(a);
    for (std::size_t h = 0; h < kMaxHeads; ++h) {
        for (std::size_t ax = 0; ax < kModelAxes; ++ax) {
            std::array<double, kSunComponents>& s = m.sun[h][ax];
            for (std::size_t c = 0; c < kSunComponents; ++c) {
                s[c] = d.data()[(h * kModelAxes + ax) * kSunComponents + c];
            }
            const std::string why = host::sun_axis_problem(s);
            const std::string where =
                std::string("head ") + head_letter(static_cast<std::uint8_t>(h)) + " " + host::kAxisNames[ax] + ": ";
            if (!why.empty()) {
                bad_argument("sun", where + why);
            }
            if (!m.present[h] && (s[0] != 0.0 || s[1] != 0.0 || s[2] != 0.0)) {
                bad_argument("sun", where + "the head has no coefficients (heads): its Sun term must be 0");
            }
        }
    }
}

py::array_t<double> model_sun(const host::ModelFile& m) {
    return per_head_and_axis(m.sun);
}

host::ModelFile model_from(const py::object& coefficients, const py::object& heads, const py::object& lag_s,
                           const py::object& sun) {
    const py::array a = as_numpy(coefficients);
    const char kind = a.dtype().kind();
    if (kind != 'f' && kind != 'i' && kind != 'u') {
        bad_argument("coefficients", "expected real numbers, got dtype " + std::string(py::str(a.dtype())));
    }
    if (a.ndim() != 3 || a.shape(0) != py::ssize_t{kMaxHeads} || a.shape(1) != py::ssize_t{kModelAxes} ||
        (a.shape(2) != py::ssize_t{kLinearModelTerms} && a.shape(2) != py::ssize_t{kModelTerms})) {
        const std::string axes = ", " + std::to_string(kModelAxes) + ", ";
        bad_argument("coefficients",
                     "expected shape (" + std::to_string(kMaxHeads) + axes + std::to_string(kLinearModelTerms) +
                         ") or (" + std::to_string(kMaxHeads) + axes + std::to_string(kModelTerms) + ") (head " +
                         head_letter_range() + ", axis alpha/beta/gamma, " +
                         host::coefficient_columns(0, kLinearModelTerms, " ") + " [" +
                         host::coefficient_columns(kLinearModelTerms, kModelTerms, " ") + "]), got " + shape_text(a));
    }
    const Doubles c = Doubles::ensure(a);
    const auto k = static_cast<std::size_t>(a.shape(2));
    host::ModelFile m;
    for (std::size_t h = 0; h < kMaxHeads; ++h) {
        for (std::size_t ax = 0; ax < kModelAxes; ++ax) {
            for (std::size_t j = 0; j < k; ++j) {
                const double x = c.data()[(h * kModelAxes + ax) * k + j];
                if (!std::isfinite(x)) {
                    bad_argument("coefficients", std::string("head ") + head_letter(static_cast<std::uint8_t>(h)) +
                                                     " " + host::kAxisNames[ax] + " " + host::kCoefficientNames[j] +
                                                     " is not finite");
                }
                m.coefficients[h][ax][j] = x;
                m.quadratic = m.quadratic || (j >= kLinearModelTerms && x != 0.0);
            }
        }
    }
    if (!heads.is_none() && !py::isinstance<py::str>(heads)) {
        bad_argument("heads", "expected a string of head letters (" + std::string(kHeadChoices.text) +
                                  ") or None, got " + value_text(heads));
    }
    const std::string names = heads.is_none() ? std::string(kHeadLetters) : heads.cast<std::string>();
    for (const char ch : names) {
        const std::uint8_t h = host::head_from_name(std::string_view(&ch, 1));
        if (h == host::kUnknownHead) {
            bad_argument("heads", std::string("'") + ch + "' is not a camera head (" + kHeadChoices.text + ")");
        }
        m.present[h] = true;
    }
    lags_into(lag_s, m);
    sun_into(sun, m);
    return m;
}

std::string model_heads(const host::ModelFile& m) {
    std::string s;
    for (std::size_t h = 0; h < kMaxHeads; ++h) {
        if (m.present[h]) {
            s += host::head_name(static_cast<std::uint8_t>(h));
        }
    }
    return s;
}

// Two models are equal when they would write the same model file: the same
// heads, coefficients and columns (where they were read from is no part of it).
bool models_equal(const host::ModelFile& a, const host::ModelFile& b) {
    return a.present == b.present && a.coefficients == b.coefficients && a.quadratic == b.quadratic &&
           host::common_rotation_name(a.common_rotation) == host::common_rotation_name(b.common_rotation) &&
           host::format_model(a) == host::format_model(b);  // the lags as written
}

py::array_t<double> model_lags(const host::ModelFile& m) {
    py::array_t<double> a(py::ssize_t{kMaxHeads});
    for (std::size_t h = 0; h < kMaxHeads; ++h) {
        a.mutable_data()[h] = m.lag_s[h];
    }
    return a;
}

// Pickling: (coefficients (heads, 3, 7), heads, quadratic, common_rotation,
// lag_s, sun), rebuilt by Model(); a state of three (pickled before the rule
// had a name) is the rule 'smallest', one of four (before the lag) has no
// lag, one of five (before the Sun term) no Sun term.
py::tuple model_state(const host::ModelFile& m) {
    return py::make_tuple(model_coefficients(m), model_heads(m), m.quadratic,
                          host::common_rotation_name(m.common_rotation), model_lags(m), model_sun(m));
}

host::ModelFile model_from_state(const py::tuple& state) {
    if (state.size() < 3 || state.size() > 6) {
        throw py::value_error(
            "ascorr.Model: a pickled state is (coefficients, heads, quadratic, common_rotation, lag_s, sun)");
    }
    const py::object lag_s = state.size() >= 5 ? py::object(state[4]) : py::object(py::none());
    const py::object sun = state.size() == 6 ? py::object(state[5]) : py::object(py::none());
    host::ModelFile m = model_from(state[0], state[1], lag_s, sun);
    m.quadratic = state[2].cast<bool>();
    if (state.size() >= 4) {
        const std::optional<host::CommonRotationId> rule =
            host::common_rotation_named(py::str(state[3]).cast<std::string>());
        if (!rule) {
            throw py::value_error("ascorr.Model: a pickled state's common_rotation must be " +
                                  host::common_rotation_choices());
        }
        m.common_rotation = *rule;
    }
    return m;
}

// What a Model's methods call themselves in messages.
constexpr const char* kSelf = "ascorr.Model";

}  // namespace

void bind_model(py::module_& mod) {
    py::class_<host::ModelFile>(mod, "Model", docstring(docs::kModel))
        .def(py::init(&model_from), "coefficients"_a, "heads"_a = py::none(), "lag_s"_a = py::none(),
             "sun"_a = py::none())
        .def_property_readonly(
            "coefficients", [](const py::object& self) { return model_coefficients(model_of(self, kSelf)); },
            docstring(docs::kModelCoefficients))
        .def_property_readonly(
            "heads", [](const py::object& self) { return model_heads(model_of(self, kSelf)); },
            docstring(docs::kModelHeads))
        .def_property_readonly(
            "quadratic", [](const py::object& self) { return model_of(self, kSelf).quadratic; },
            docstring(docs::kModelQuadratic))
        .def_property_readonly(
            "common_rotation",
            [](const py::object& self) { return host::common_rotation_name(model_of(self, kSelf).common_rotation); },
            docstring(docs::kModelCommonRotation))
        .def_property_readonly(
            "lag_s", [](const py::object& self) { return model_lags(model_of(self, kSelf)); },
            docstring(docs::kModelLag))
        .def_property_readonly(
            "sun", [](const py::object& self) { return model_sun(model_of(self, kSelf)); }, docstring(docs::kModelSun))
        .def(
            "write",
            [](const py::object& self, const py::object& path) {
                const host::ModelFile& m = model_of(self, kSelf);
                host::write_model_file(path_arg(path, "path"), m);
            },
            "path"_a, docstring(docs::kModelWrite))
        .def(
            "to_csv", [](const py::object& self) { return host::format_model(model_of(self, kSelf)); },
            docstring(docs::kModelToCsv))
        .def(
            "__eq__",
            [](const py::object& self, const py::object& other) -> py::object {
                if (!py::isinstance<host::ModelFile>(other)) {
                    return py::reinterpret_borrow<py::object>(Py_NotImplemented);
                }
                return py::bool_(models_equal(model_of(self, kSelf), model_of(other, kSelf)));
            },
            py::is_operator(), docstring(docs::kModelEq))
        .def(py::pickle([](const py::object& self) { return model_state(model_of(self, kSelf)); }, &model_from_state))
        .def("__repr__", [](const py::object& self) {
            if (!model_initialised(self)) {
                return std::string("<ascorr.Model, not initialised>");
            }
            const host::ModelFile& m = self.cast<const host::ModelFile&>();
            return "<ascorr.Model heads='" + model_heads(m) + "'" + (m.quadratic ? " quadratic" : "") +
                   (host::has_lag(m) ? " lagged" : "") + (host::has_sun_term(m) ? " with a Sun term" : "") + ">";
        });

    mod.def(
        "read_model", [](const py::object& path) { return host::read_model_file(path_arg(path, "path")); }, "path"_a,
        docstring(docs::kReadModel));
}

}  // namespace ascorr::python
