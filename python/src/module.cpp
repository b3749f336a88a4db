// python/src/module.cpp: the compiled part of `import ascorr` (pybind11).
//
// Glue only: every number comes from the core headers (firmware/include/) and
// the host library (host_sim/, ascorr_host), the same code as the command
// line. correct() builds, per row, the SolutionRecord that the solutions
// reader would have made of the same values and runs it through
// host::correct_row(), the per-row path of `ascorr correct`, so both agree
// bit for bit in every scalar.
//
// Arrays: float64 C-contiguous inputs are used in place; other real dtypes
// (float32, integers) and non-contiguous arrays are converted once; times
// must be float64 or integers. Every argument is a py::object checked here, so
// that a wrong one raises ValueError "argument 'NAME': expected WHAT, got
// REPR (TYPE)", never pybind11's cast error (python/ascorr/__init__.py turns a
// missing or unknown argument into Python's own TypeError). Enumerations are
// the command line's names in any case; paths are str or os.PathLike.
// Per-row problems are status bits (docs/contract.md) and never an exception:
// every row comes back. The GIL is released while rows are corrected, on up to
// 8 threads.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <functional>
#include <limits>
#include <numeric>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "ascorr/core/correct.hpp"
#include "ascorr/core/fixed_point.hpp"
#include "ascorr_host/analysis/epochs.hpp"
#include "ascorr_host/analysis/fit.hpp"
#include "ascorr_host/analysis/iba.hpp"
#include "ascorr_host/analysis/stats.hpp"
#include "ascorr_host/correct/correct_file.hpp"
#include "ascorr_host/correct/correct_row.hpp"
#include "ascorr_host/correct/earth_velocity.hpp"
#include "ascorr_host/correct/self_calibration.hpp"
#include "ascorr_host/correct/states_velocity.hpp"
#include "ascorr_host/formats/atomic_file.hpp"
#include "ascorr_host/formats/csv.hpp"
#include "ascorr_host/formats/diagnostics.hpp"
#include "ascorr_host/formats/input_error.hpp"
#include "ascorr_host/formats/model_csv.hpp"
#include "ascorr_host/formats/solutions_csv.hpp"
#include "ascorr_host/formats/states_csv.hpp"

namespace py = pybind11;
using namespace pybind11::literals;

namespace ascorr::python {

using host::SolutionRecord;

namespace {

using Doubles = py::array_t<double, py::array::c_style | py::array::forcecast>;

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The label of array rows in messages (InputError's "file:line:column").
constexpr const char* kArrayRows = "<arrays, 1-based row>";

[[noreturn]] void bad_argument(const std::string& name, const std::string& what) {
    throw py::value_error("argument '" + name + "': " + what);
}

// A number for a message: the shortest text that reads back exactly (1e+300,
// never 300 digits), nan and inf as such.
std::string number_text(double x) {
    char buf[40];
    const auto r = std::to_chars(buf, buf + sizeof buf, x);
    return {buf, static_cast<std::size_t>(r.ptr - buf)};
}

// What a Python value is, for messages: its repr (cut short) and its type.
std::string value_text(const py::handle& x) {
    std::string s = py::repr(x);
    if (s.size() > 40) {
        s = s.substr(0, 37) + "...";
    }
    return s + " (" + std::string(py::str(py::type::handle_of(x).attr("__name__"))) + ")";
}

// An enumeration's value: one of names, in any case, as on the command line
// ("names, case-insensitive"). Numbers are not names.
std::string choice_arg(const py::handle& x, const char* name, std::initializer_list<const char*> names) {
    if (py::isinstance<py::str>(x)) {
        std::string s = x.cast<std::string>();
        std::transform(s.begin(), s.end(), s.begin(),
                       [](char c) { return c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c; });
        for (const char* n : names) {
            if (s == n) {
                return s;
            }
        }
    }
    std::string list;
    std::size_t k = 0;
    for (const char* n : names) {
        list += std::string(k == 0 ? "" : k + 1 == names.size() ? " or " : ", ") + "'" + n + "'";
        ++k;
    }
    bad_argument(name, "expected " + list + " (a name, in any case), got " + value_text(x));
}

// True or False (Python's bool or NumPy's bool_); None and numbers are refused.
bool bool_arg(const py::handle& x, const char* name) {
    if (py::isinstance<py::bool_>(x) || py::isinstance(x, py::module_::import("numpy").attr("bool_"))) {
        return py::cast<bool>(x);
    }
    bad_argument(name, "expected True or False, got " + value_text(x));
}

// A real number (int, float, NumPy real scalar); not a bool, a string or None.
double real_arg(const py::handle& x, const char* name) {
    const py::module_ np = py::module_::import("numpy");
    const bool real = py::isinstance<py::int_>(x) || py::isinstance<py::float_>(x) ||
                      py::isinstance(x, np.attr("integer")) || py::isinstance(x, np.attr("floating"));
    if (!real || py::isinstance<py::bool_>(x)) {
        bad_argument(name, "expected a real number, got " + value_text(x));
    }
    const double d = PyFloat_AsDouble(x.ptr());
    if (d == -1.0 && PyErr_Occurred() != nullptr) {
        PyErr_Clear();
        bad_argument(name, "expected a real number within the range of a double, got " + value_text(x));
    }
    return d;
}

// A non-negative integer (int or NumPy integer; not a bool or a float).
std::size_t count_arg(const py::handle& x, const char* name) {
    const py::module_ np = py::module_::import("numpy");
    if ((py::isinstance<py::int_>(x) || py::isinstance(x, np.attr("integer"))) && !py::isinstance<py::bool_>(x)) {
        const py::int_ i(py::reinterpret_borrow<py::object>(x));
        if (!(i < py::int_(0)) && !(i > py::int_(std::numeric_limits<long long>::max()))) {
            return static_cast<std::size_t>(i.cast<long long>());
        }
    }
    bad_argument(name, "expected a non-negative integer, got " + value_text(x));
}

// A path: str or os.PathLike (pathlib.Path); bytes and the rest are refused.
std::string path_arg(const py::handle& x, const char* name) {
    if (py::isinstance<py::str>(x) || py::hasattr(x, "__fspath__")) {
        const py::object p = py::module_::import("os").attr("fspath")(x);
        if (py::isinstance<py::str>(p)) {
            return p.cast<std::string>();
        }
    }
    bad_argument(name, "expected a path (str or os.PathLike such as pathlib.Path), got " + value_text(x));
}

std::string shape_text(const py::array& a) {
    std::string s = "(";
    for (py::ssize_t i = 0; i < a.ndim(); ++i) {
        s += (i ? ", " : "") + std::to_string(a.shape(i));
    }
    return s + (a.ndim() == 1 ? ",)" : ")");
}

py::array as_numpy(const py::handle& obj) {
    return py::module_::import("numpy").attr("asarray")(obj);
}

// A real-valued array of shape (n,) (cols == 0) or (n, cols) as float64,
// C-contiguous: the same buffer when it already is, else one converted copy.
// n < 0: any length (it is then taken from this argument).
Doubles real_array(const py::handle& obj, const std::string& name, py::ssize_t n, py::ssize_t cols) {
    if (obj.is_none()) {
        bad_argument(name, "expected an array of real numbers, got None");
    }
    const py::array a = as_numpy(obj);
    const char kind = a.dtype().kind();
    if (kind != 'f' && kind != 'i' && kind != 'u') {
        bad_argument(name, "expected real numbers, got dtype " + std::string(py::str(a.dtype())));
    }
    const bool shape_ok = cols == 0 ? a.ndim() == 1 : a.ndim() == 2 && a.shape(1) == cols;
    if (!shape_ok) {
        bad_argument(name, "expected shape " + std::string(cols == 0 ? "(n,)" : "(n, " + std::to_string(cols) + ")") +
                               ", got " + shape_text(a));
    }
    if (n >= 0 && a.shape(0) != n) {
        bad_argument(name, "expected " + std::to_string(n) + " rows (as t), got " + std::to_string(a.shape(0)));
    }
    return Doubles::ensure(a);
}

// Times (s since J2000.0): float64 or integers. float32 (and float16) are
// refused: 24 bits of mantissa hold a time of 2020 to ~32 s, so the rows
// would be matched and corrected at the wrong time.
Doubles time_array(const py::handle& obj, const std::string& name) {
    if (obj.is_none()) {
        bad_argument(name, "expected an array of float64 (or integer) times, got None");
    }
    const py::array a = as_numpy(obj);
    if (a.dtype().kind() == 'f' && a.itemsize() < 8) {
        bad_argument(name, "expected float64 (or integer) times, got dtype " + std::string(py::str(a.dtype())) +
                               ": its " + std::to_string(a.itemsize() == 4 ? 24 : 11) +
                               "-bit mantissa holds a time since J2000 to tens of seconds or worse (convert the "
                               "times from their source as float64)");
    }
    return real_array(a, name, -1, 0);
}

// Optional (n, cols) argument: None means "all missing" (NaN).
Doubles optional_real_array(const py::handle& obj, const std::string& name, py::ssize_t n, py::ssize_t cols,
                            double fill) {
    if (obj.is_none()) {
        Doubles a(cols == 0 ? std::vector<py::ssize_t>{n} : std::vector<py::ssize_t>{n, cols});
        std::fill(a.mutable_data(), a.mutable_data() + a.size(), fill);
        return a;
    }
    return real_array(obj, name, n, cols);
}

// The heads for messages and docstrings, from ascorr/heads.hpp: "'A'..'D'" and "0..3".
std::string head_letter_range() {
    return std::string("'") + kHeadLetters[0] + "'..'" + kHeadLetters[kMaxHeads - 1] + "'";
}

std::string head_index_range() {
    return "0.." + std::to_string(kMaxHeads - 1);
}

// chu: head letters (kHeadLetters; anything else is an unknown head, status 16)
// or integer head indices (below kMaxHeads; anything else: status 16), as the
// reader maps them.
std::vector<std::uint8_t> heads_of(const py::handle& obj, py::ssize_t n) {
    if (obj.is_none()) {
        bad_argument("chu", "expected (n,) strings " + head_letter_range() + " or integers " + head_index_range() +
                                ", got None");
    }
    const py::array a = as_numpy(obj);
    if (a.ndim() != 1) {
        bad_argument("chu", "expected shape (n,), got " + shape_text(a));
    }
    if (a.shape(0) != n) {
        bad_argument("chu", "expected " + std::to_string(n) + " rows (as t), got " + std::to_string(a.shape(0)));
    }
    std::vector<std::uint8_t> heads(static_cast<std::size_t>(n), host::kUnknownHead);
    const char kind = a.dtype().kind();
    if (kind == 'i' || kind == 'u') {
        const auto idx = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(a);
        const std::int64_t* p = idx.data();
        for (py::ssize_t i = 0; i < n; ++i) {
            if (p[i] >= 0 && p[i] < static_cast<std::int64_t>(kMaxHeads)) {
                heads[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(p[i]);
            }
        }
    } else if (kind == 'U' || kind == 'S') {
        // Fixed-width strings, read in place: UCS-4 code points or bytes, NUL-padded.
        const py::array c = py::array::ensure(a, py::array::c_style);
        const auto width = static_cast<std::size_t>(c.itemsize());
        const std::size_t unit = kind == 'U' ? 4 : 1;
        const auto* base = static_cast<const unsigned char*>(c.data());
        for (py::ssize_t i = 0; i < n; ++i) {
            const unsigned char* e = base + static_cast<std::size_t>(i) * width;
            std::uint32_t first = 0;  // assembled byte by byte: the elements need not be aligned
            std::uint32_t second = 0;
            if (width >= unit) {
                for (std::size_t b = 0; b < unit; ++b) {
                    first |= static_cast<std::uint32_t>(e[b]) << (8 * (kind == 'U' ? b : 0));
                }
            }
            if (width >= 2 * unit) {
                for (std::size_t b = 0; b < unit; ++b) {
                    second |= static_cast<std::uint32_t>(e[unit + b]) << (8 * (kind == 'U' ? b : 0));
                }
            }
            if (second == 0 && first < 0x80U) {
                heads[static_cast<std::size_t>(i)] = head_index(static_cast<char>(first));
            }
        }
    } else if (kind == 'O') {
        for (py::ssize_t i = 0; i < n; ++i) {
            const py::object x = a[py::int_(i)];
            if (py::isinstance<py::str>(x)) {
                heads[static_cast<std::size_t>(i)] = host::head_from_name(x.cast<std::string>());
            } else if (py::isinstance<py::int_>(x)) {
                const long long h = x.cast<long long>();
                if (h >= 0 && h < static_cast<long long>(kMaxHeads)) {
                    heads[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(h);
                }
            } else {
                bad_argument("chu", "row " + std::to_string(i) + ": expected a string or an integer, got " +
                                        std::string(py::str(x.get_type())));
            }
        }
    } else {
        bad_argument("chu", "expected strings " + head_letter_range() + " or integers " + head_index_range() +
                                ", got dtype " + std::string(py::str(a.dtype())));
    }
    return heads;
}

// The columns of a set of solutions, validated, as the core's caller needs them.
struct Rows {
    py::ssize_t n = 0;
    Doubles t, q, temps, v, confidence;
    std::vector<std::uint8_t> head;
    std::vector<long long> flags;
};

Rows rows_of(const py::handle& t, const py::handle& chu, const py::handle& q, const py::handle& temps,
             const py::handle& v, const py::handle& flags = py::none(), const py::handle& confidence = py::none()) {
    Rows r;
    r.t = time_array(t, "t");
    r.n = r.t.shape(0);
    const double* tp = r.t.data();
    // As the solutions reader: a time that is not finite makes the row
    // malformed; any finite time is a row (outside the Earth ephemeris,
    // 1900-2100, with a velocity: status 4+32, as `ascorr correct`).
    for (py::ssize_t i = 0; i < r.n; ++i) {
        if (!std::isfinite(tp[i])) {
            bad_argument("t", "row " + std::to_string(i) + ": time " + number_text(tp[i]) +
                                  " is not finite (the command line refuses such a row as malformed)");
        }
    }
    r.head = heads_of(chu, r.n);
    r.q = real_array(q, "q", r.n, 4);
    r.temps = optional_real_array(temps, "temps", r.n, 3, kNaN);
    r.v = optional_real_array(v, "v", r.n, 3, kNaN);
    r.confidence = optional_real_array(confidence, "confidence", r.n, 0, kNaN);
    r.flags.assign(static_cast<std::size_t>(r.n), 0);
    if (!flags.is_none()) {
        const py::array a = as_numpy(flags);
        const char kind = a.dtype().kind();
        if ((kind != 'i' && kind != 'u') || a.ndim() != 1 || a.shape(0) != r.n) {
            bad_argument("flags", "expected " + std::to_string(r.n) + " non-negative integers, shape (n,), got dtype " +
                                      std::string(py::str(a.dtype())) + " shape " + shape_text(a));
        }
        const auto f = py::array_t<long long, py::array::c_style | py::array::forcecast>::ensure(a);
        for (py::ssize_t i = 0; i < r.n; ++i) {
            if (f.data()[i] < 0) {
                bad_argument("flags", "row " + std::to_string(i) + ": negative flags");
            }
            r.flags[static_cast<std::size_t>(i)] = f.data()[i];
        }
    }
    return r;
}

// Row i as the solutions reader would have read it from a file holding the
// same values: NaN is "not available", as `nan` in a file.
void record_of(const Rows& r, py::ssize_t i, SolutionRecord& rec) {
    const auto k = static_cast<std::size_t>(i);
    rec.line = k + 1;
    rec.t = r.t.data()[i];
    rec.head = r.head[k];
    rec.chu = rec.head < kMaxHeads ? std::string_view(&kHeadLetters[rec.head], 1) : std::string_view("?");
    const double* q = r.q.data() + 4 * i;
    rec.q_chu_icrf = {q[0], q[1], q[2], q[3]};
    const double* tc = r.temps.data() + 3 * i;
    for (std::size_t j = 0; j < 3; ++j) {
        rec.temperature[j] = tc[j];
        rec.temperature_present[j] = !std::isnan(tc[j]);
    }
    const double* v = r.v.data() + 3 * i;
    rec.v_sc_kms = {v[0], v[1], v[2]};
    rec.velocity_components =
        static_cast<int>(!std::isnan(v[0])) + static_cast<int>(!std::isnan(v[1])) + static_cast<int>(!std::isnan(v[2]));
    rec.flags = r.flags[k];
    const double c = r.confidence.data()[i];
    rec.confidence_present = !std::isnan(c);
    rec.confidence = rec.confidence_present ? c : 0.0;
}

host::RowSource source_of(const Rows& r) {
    return [&r](const std::function<void(const SolutionRecord&)>& fn) {
        SolutionRecord rec;
        for (py::ssize_t i = 0; i < r.n; ++i) {
            record_of(r, i, rec);
            fn(rec);
        }
    };
}

std::size_t thread_count(py::ssize_t n) {
    constexpr py::ssize_t kRowsPerThread = 16384;  // below this a thread costs more than it saves
    const unsigned hw = std::thread::hardware_concurrency();
    const auto by_size = static_cast<std::size_t>(std::max<py::ssize_t>(1, n / kRowsPerThread));
    return std::clamp<std::size_t>(std::min<std::size_t>(hw == 0 ? 1 : hw, by_size), 1, 8);
}

// Runs body(begin, end) over [0, n) in contiguous pieces, one per thread.
void parallel_rows(py::ssize_t n, const std::function<void(py::ssize_t, py::ssize_t)>& body) {
    const std::size_t k = thread_count(n);
    std::vector<std::thread> threads;
    const auto piece = [&](std::size_t j) { return static_cast<py::ssize_t>(static_cast<std::size_t>(n) * j / k); };
    for (std::size_t j = 1; j < k; ++j) {
        threads.emplace_back([&, j] { body(piece(j), piece(j + 1)); });
    }
    body(0, piece(1));
    for (auto& t : threads) {
        t.join();
    }
}

template <typename T>
void correct_rows(const Rows& r, const host::ModelFile* m, bool aberration, const host::StatesFile* states,
                  double max_propagation_s, double* q_out, std::uint16_t* st_out) {
    std::optional<ThermalModel<T>> model;
    if (m != nullptr) {
        model = host::to_core<T>(*m);
    }
    const CorrectionConfig<T> cfg{aberration, model ? &*model : nullptr};
    py::gil_scoped_release unlocked;
    // The rows' velocities from the states asked in time order, as by `ascorr correct`.
    std::optional<host::StatesVelocityTable<T>> table;
    if (states != nullptr && aberration) {
        std::vector<std::int64_t> times;
        SolutionRecord rec;
        TtTime t{};
        for (py::ssize_t i = 0; i < r.n; ++i) {
            record_of(r, i, rec);
            if (rec.velocity_components == 0 && tt_from_seconds(rec.t, t)) {
                times.push_back(t.us);
            }
        }
        table.emplace(*states, host::service_config(max_propagation_s), std::move(times), thread_count(r.n));
    }
    parallel_rows(r.n, [&](py::ssize_t begin, py::ssize_t end) {
        host::EarthVelocity earth;
        std::optional<host::StatesVelocity<T>> service;  // per thread, as per chunk in `ascorr correct`
        if (states != nullptr) {
            service.emplace(*states, host::service_config(max_propagation_s), table ? &*table : nullptr);
        }
        SolutionRecord rec;
        for (py::ssize_t i = begin; i < end; ++i) {
            record_of(r, i, rec);
            const host::RowCorrection<T> c = host::correct_row(rec, &earth, cfg, service ? &*service : nullptr);
            double* q = q_out + 4 * i;
            q[0] = c.q_chu_icrf.w;
            q[1] = c.q_chu_icrf.x;
            q[2] = c.q_chu_icrf.y;
            q[3] = c.q_chu_icrf.z;
            st_out[i] = c.status;
        }
    });
}

const host::ModelFile* model_arg(const py::object& model) {
    if (model.is_none()) {
        return nullptr;
    }
    if (!py::isinstance<host::ModelFile>(model)) {
        bad_argument("model", "expected an ascorr.Model (read_model() or fit()) or None, got " +
                                  std::string(py::str(model.get_type())));
    }
    return &model.cast<const host::ModelFile&>();
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
    const std::string scalar = choice_arg(scalar_obj, "scalar", {"double", "float", "fixed"});
    const bool aberration = bool_arg(aberration_obj, "aberration");
    const std::string states_frame = choice_arg(states_frame_obj, "states_frame", {"itrf", "gcrs"});
    const double max_propagation = real_arg(max_propagation_obj, "max_propagation");
    const std::optional<host::StatesFile> sf = states_arg(states, states_frame, max_propagation);
    const host::StatesFile* s = sf ? &*sf : nullptr;
    if (scalar == "fixed" && m != nullptr) {
        try {
            host::check_fixed_point_range(*m, "model");  // refused, never saturated, as by the command line
        } catch (const std::runtime_error& e) {
            bad_argument("model", std::string(e.what()) + " (scalar='fixed')");
        }
    }
    const Rows r = rows_of(t, chu, q, temps, v);
    py::array_t<double> q_out({r.n, py::ssize_t{4}});
    py::array_t<std::uint16_t> st_out(r.n);
    double* qo = q_out.mutable_data();
    std::uint16_t* so = st_out.mutable_data();
    if (scalar == "double") {
        correct_rows<double>(r, m, aberration, s, max_propagation, qo, so);
    } else if (scalar == "float") {
        correct_rows<float>(r, m, aberration, s, max_propagation, qo, so);
    } else {
        correct_rows<Q30>(r, m, aberration, s, max_propagation, qo, so);
    }
    return py::make_tuple(q_out, st_out);
}

// ---- self-calibration (`ascorr correct --self-calibrate`)

template <typename T>
py::list self_calibrated_rows(const Rows& r, const host::ModelFile* m, double time_constant_days, double* q_out,
                              std::uint16_t* st_out) {
    calib::EstimatorConfig cfg;
    cfg.time_constant_days = time_constant_days;
    const host::SelfCalibration sc = host::self_calibrate<T>(
        kArrayRows, source_of(r), m != nullptr ? std::optional<host::ModelFile>(*m) : std::nullopt, cfg, std::nullopt);
    const host::ModelSchedule<T> schedule(sc.history);
    host::EarthVelocity earth;
    SolutionRecord rec;
    for (py::ssize_t i = 0; i < r.n; ++i) {
        record_of(r, i, rec);
        const CorrectionConfig<T> c{true, &schedule.at(rec.t)};
        const host::RowCorrection<T> row = host::correct_row<T>(rec, &earth, c, nullptr);
        double* q = q_out + 4 * i;
        q[0] = row.q_chu_icrf.w;
        q[1] = row.q_chu_icrf.x;
        q[2] = row.q_chu_icrf.y;
        q[3] = row.q_chu_icrf.z;
        st_out[i] = row.status;
    }
    py::list history;
    for (const host::ActiveModel& a : sc.history) {
        py::dict d;
        d["t"] = a.t;
        d["version"] = a.version;
        d["crc32c"] = a.crc;
        d["model"] = py::cast(a.model);
        history.append(d);
    }
    return history;
}

py::tuple self_calibrate(const py::object& t, const py::object& chu, const py::object& q, const py::object& temps,
                         const py::object& v, const py::object& flags, const py::object& confidence,
                         const py::object& model, const py::object& scalar_obj, const py::object& time_constant_obj) {
    const host::ModelFile* m = model_arg(model);
    const std::string scalar = choice_arg(scalar_obj, "scalar", {"double", "float", "fixed"});
    const double time_constant = real_arg(time_constant_obj, "time_constant");
    if (!(time_constant >= calib::kMinTimeConstantDays && time_constant <= calib::kMaxTimeConstantDays)) {
        bad_argument("time_constant", "expected days in [1, 10000], got " + value_text(time_constant_obj));
    }
    if (scalar == "fixed" && m != nullptr) {
        try {
            host::check_fixed_point_range(*m, "model");
        } catch (const std::runtime_error& e) {
            bad_argument("model", std::string(e.what()) + " (scalar='fixed')");
        }
    }
    const Rows r = rows_of(t, chu, q, temps, v, flags, confidence);
    py::array_t<double> q_out({r.n, py::ssize_t{4}});
    py::array_t<std::uint16_t> st_out(r.n);
    py::list history;
    if (scalar == "double") {
        history = self_calibrated_rows<double>(r, m, time_constant, q_out.mutable_data(), st_out.mutable_data());
    } else if (scalar == "float") {
        history = self_calibrated_rows<float>(r, m, time_constant, q_out.mutable_data(), st_out.mutable_data());
    } else {
        history = self_calibrated_rows<Q30>(r, m, time_constant, q_out.mutable_data(), st_out.mutable_data());
    }
    return py::make_tuple(q_out, st_out, history);
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
        parallel_rows(n, [&](py::ssize_t begin, py::ssize_t end) {
            host::EarthVelocity grid;
            for (py::ssize_t i = begin; i < end; ++i) {
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

py::dict iba(const py::object& t, const py::object& chu, const py::object& q) {
    const Rows r = rows_of(t, chu, q, py::none(), py::none());
    // Every pair of kMaxHeads while reading; those of the rows' heads at the end (as stats()).
    constexpr host::PairList kAllPairs = host::pairs_of(host::kAllHeads);
    host::HeadSet with_rows = 0U;
    std::array<std::vector<double>, host::kMaxPairs> pt;
    std::array<std::vector<double>, host::kMaxPairs> pv;
    // A row whose quaternion the core rejects (not finite, not unit: status 16
    // in correct()) takes no part in any IBA, as in stats(); it still counts
    // for the one-row-per-head-and-epoch rule.
    struct Boresight {
        Vector3<double> z;
        bool accepted;
    };
    host::EpochAssembler<Boresight> epochs(kArrayRows, [&](const host::Epoch<Boresight>& e) {
        for (std::size_t p = 0; p < kAllPairs.count; ++p) {
            const auto& a = e.head[kAllPairs.pair[p].first];
            const auto& b = e.head[kAllPairs.pair[p].second];
            if (a && b && a->accepted && b->accepted) {
                pt[p].push_back(e.t);
                pv[p].push_back(host::angle_arcsec(a->z, b->z));
            }
        }
    });
    std::ostringstream log;
    host::Diagnostics diag(log);
    SolutionRecord rec;
    for (py::ssize_t i = 0; i < r.n; ++i) {
        record_of(r, i, rec);
        if (rec.head < kMaxHeads) {
            with_rows |= host::head_bit(rec.head);
            SolutionInput<double> in{};
            in.q_chu_icrf = rec.q_chu_icrf;
            in.head = rec.head;
            const Rejection why = check_solution(in);
            if (why != Rejection::kNone) {
                diag.report("rejected", std::string(kArrayRows) + ":" + std::to_string(rec.line) + ": quaternion " +
                                            (why == Rejection::kQuaternionNotFinite ? "not finite" : "not unit") +
                                            ": left out of the IBA (status 16 in correct())");
            }
            epochs.add(rec.t, rec.head, rec.line, Boresight{boresight(rec.q_chu_icrf), why == Rejection::kNone});
        }
    }
    epochs.finish();
    diag.summarize();
    if (!log.str().empty() && PyErr_WarnEx(PyExc_UserWarning, log.str().c_str(), 1) != 0) {
        throw py::error_already_set();
    }
    py::dict out;
    for (std::size_t p = 0; p < kAllPairs.count; ++p) {
        const host::HeadPair& pair = kAllPairs.pair[p];
        const host::HeadSet heads = host::analysis_heads(with_rows);
        if (!host::has_head(heads, pair.first) || !host::has_head(heads, pair.second)) {
            continue;
        }
        std::vector<std::size_t> idx(pt[p].size());
        std::iota(idx.begin(), idx.end(), std::size_t{0});
        std::sort(idx.begin(), idx.end(), [&](std::size_t i, std::size_t j) { return pt[p][i] < pt[p][j]; });
        py::array_t<double> ta(static_cast<py::ssize_t>(idx.size()));
        py::array_t<double> va(static_cast<py::ssize_t>(idx.size()));
        for (std::size_t i = 0; i < idx.size(); ++i) {
            ta.mutable_data()[i] = pt[p][idx[i]];
            va.mutable_data()[i] = pv[p][idx[i]];
        }
        out[pair.name] = py::make_tuple(ta, va);
    }
    return out;
}

std::optional<double> time_arg(const py::object& x, const char* name) {
    if (x.is_none()) {
        return std::nullopt;
    }
    if (py::isinstance(x, py::module_::import("numpy").attr("floating")) &&
        x.attr("dtype").attr("itemsize").cast<int>() < 8) {
        bad_argument(name, "expected a float64 (or integer) time, got " + value_text(x) +
                               ": too few bits for a time since J2000");
    }
    const double d = real_arg(x, name);
    if (std::isnan(d)) {
        bad_argument(name, "must not be NaN");
    }
    return d;
}

py::dict stats(const py::object& t, const py::object& chu, const py::object& q, const py::object& temps,
               const py::object& v, const py::object& flags, const py::object& confidence, const py::object& model,
               const py::object& t_from, const py::object& t_to) {
    const host::ModelFile* m = model_arg(model);
    host::StatsOptions opt;
    opt.in = kArrayRows;
    opt.from = time_arg(t_from, "t_from");
    opt.to = time_arg(t_to, "t_to");
    opt.period_options = "t_from/t_to";
    host::refuse_bad_time_range(opt.from, opt.to, "t_from", "t_to");  // as `ascorr stats`: an empty period is refused
    const Rows r = rows_of(t, chu, q, temps, v, flags, confidence);
    std::optional<ThermalModel<double>> core_model;
    if (m != nullptr) {
        core_model = host::to_core<double>(*m);
    }
    std::ostringstream log;
    const host::StatsResult s = host::compute_stats(opt, source_of(r), core_model ? &*core_model : nullptr, log);
    py::dict pairs;
    for (std::size_t p = 0; p < s.pairs.count; ++p) {
        py::dict d;
        for (std::size_t st = 0; st < host::kStages; ++st) {
            const bool have = host::rms_defined(s, p, st);
            d[host::kStageNames[st]] = have ? py::object(py::float_(s.rms[p][st].rms)) : py::object(py::none());
            d[(std::string(host::kStageNames[st]) + "_smoothed").c_str()] =
                have ? py::object(py::float_(s.rms[p][st].rms_smoothed)) : py::object(py::none());
        }
        d["n"] = s.n[p];
        pairs[s.pairs.pair[p].name] = d;
    }
    py::dict out;
    out["pairs"] = pairs;
    out["rows"] = s.rows;
    out["clean_rows"] = s.clean_rows;
    out["table"] = host::stats_table(s);
    out["messages"] = log.str();
    return out;
}

// The value after "--terms " or "--holdout " at text[i], as a keyword's:
// "='linear'", "=0"; empty (and i unchanged) when none follows.
std::string keyword_value(const std::string& name, const std::string& text, std::size_t& i) {
    if ((name != "terms" && name != "holdout") || i >= text.size() || text[i] != ' ') {
        return {};
    }
    std::size_t v = i + 1;
    while (v < text.size() &&
           ((text[v] >= 'a' && text[v] <= 'z') || (text[v] >= '0' && text[v] <= '9') || text[v] == '.')) {
        ++v;
    }
    const std::string value = text.substr(i + 1, v - i - 1);
    if (name == "terms" && (value == "linear" || value == "quadratic")) {
        i = v;
        return "='" + value + "'";
    }
    if (name == "holdout" && !value.empty() && value[0] >= '0' && value[0] <= '9') {
        i = v;
        return "=" + value;
    }
    return {};
}

// The host's fit names its settings as the command line's options; from
// Python they are fit()'s keywords: "--min-temperature-range" is
// "min_temperature_range", "--from" "t_from", "--terms linear" "terms='linear'".
std::string as_keywords(const std::string& text) {
    std::string out;
    for (std::size_t i = 0; i < text.size();) {
        if (text.compare(i, 2, "--") != 0 || i + 2 >= text.size() || text[i + 2] < 'a' || text[i + 2] > 'z') {
            out += text[i++];
            continue;
        }
        std::size_t e = i + 2;
        while (e < text.size() && ((text[e] >= 'a' && text[e] <= 'z') || text[e] == '-')) {
            ++e;
        }
        std::string name = text.substr(i + 2, e - i - 2);
        i = e;
        if (name == "from" || name == "to") {
            name = "t_" + name;
        }
        std::replace(name.begin(), name.end(), '-', '_');
        out += name + keyword_value(name, text, i);
    }
    return out;
}

py::tuple fit(const py::object& t, const py::object& chu, const py::object& q, const py::object& temps,
              const py::object& v, const py::object& flags, const py::object& confidence, const py::object& t_from,
              const py::object& t_to, const py::object& min_days, const py::object& min_orbits,
              const py::object& max_condition, const py::object& orbit_period, const py::object& terms,
              const py::object& holdout, const py::object& min_temperature_range) {
    host::FitOptions opt;
    opt.in = kArrayRows;
    opt.from = time_arg(t_from, "t_from");
    opt.to = time_arg(t_to, "t_to");
    opt.min_span_days = real_arg(min_days, "min_days");
    opt.min_orbits = count_arg(min_orbits, "min_orbits");
    opt.max_condition = real_arg(max_condition, "max_condition");
    if (!orbit_period.is_none()) {
        opt.orbit_period_s = real_arg(orbit_period, "orbit_period");
    }
    opt.terms = choice_arg(terms, "terms", {"linear", "quadratic"}) == "linear" ? host::Terms::kLinear
                                                                                : host::Terms::kQuadratic;
    opt.holdout = real_arg(holdout, "holdout");
    opt.min_temperature_range_c = real_arg(min_temperature_range, "min_temperature_range");
    const Rows r = rows_of(t, chu, q, temps, v, flags, confidence);
    const host::FitReport rep = [&] {
        try {
            return host::fit_model(opt, source_of(r));
        } catch (const host::FitRefused& e) {
            throw host::FitRefused(as_keywords(e.what()));
        }
    }();
    py::dict d;
    d["t_first"] = rep.t_first;
    d["t_last"] = rep.t_last;
    d["orbit_period_s"] = rep.orbit_period_s;
    d["rows"] = rep.rows;
    py::dict dropped;
    for (std::size_t k = 0; k < host::kDropKinds; ++k) {
        dropped[host::drop_name(static_cast<host::Drop>(k))] = rep.dropped[k];
    }
    d["dropped"] = dropped;
    d["epochs"] = rep.epochs;
    d["orbits_used"] = rep.orbits_used;
    d["orbits_left_out"] = rep.orbits_left_out;
    d["singular_values"] = rep.singular_values;
    d["condition"] = rep.condition;
    // A row per head fitted (d["heads"], in heads.hpp's order), a column per axis.
    const host::HeadList heads = host::heads_of(rep.heads);
    const auto n_heads = static_cast<py::ssize_t>(heads.count);
    py::array_t<double> res({n_heads, py::ssize_t{3}});
    py::array_t<double> sig({n_heads, py::ssize_t{3}});
    for (std::size_t i = 0; i < heads.count; ++i) {
        for (std::size_t a = 0; a < 3; ++a) {
            res.mutable_data()[3 * i + a] = rep.head[heads.head[i]].residual_rms[a];
            sig.mutable_data()[3 * i + a] = rep.head[heads.head[i]].signal_rms[a];
        }
    }
    d["heads"] = host::head_letters(rep.heads);
    d["residual_rms"] = res;
    d["signal_rms"] = sig;
    d["terms"] = host::terms_name(rep.terms);
    d["text"] = as_keywords(host::describe(rep));
    return py::make_tuple(py::cast(rep.model), d);
}

// ---- files <-> arrays

// The columns write_solutions() writes itself, in its order; any other column
// of a file is an extra column, kept as written.
constexpr std::array<const char*, 15> kSolutionsColumns = {
    "t", "chu", "qw", "qx", "qy", "qz", "t_chu", "t_029", "t_032", "vx", "vy", "vz", "flags", "confidence", "status"};

bool known_column(std::string_view name) {
    return std::find(kSolutionsColumns.begin(), kSolutionsColumns.end(), name) != kSolutionsColumns.end();
}

py::dict read_solutions(const py::object& path_obj) {
    const std::string path = path_arg(path_obj, "path");
    std::vector<double> t, q, temps, v, conf;
    std::vector<std::string> chu;
    std::vector<long long> flags, st;
    std::size_t chu_width = 1;
    bool has_status = false;
    std::vector<std::size_t> extra_cols;          // other columns, in file order
    std::vector<std::string> extra_names;         // as written in the header
    std::vector<std::vector<std::string>> extra;  // their fields as written
    {
        host::BlockReader blocks(path);
        std::string_view block;
        if (!blocks.next(block)) {
            throw host::InputError(path, 1, 1, "empty file: expected a header line");
        }
        const std::size_t nl = block.find('\n');
        const host::SolutionsReader header(path, block.substr(0, nl));
        const int status_col = header.header().index("status");
        has_status = status_col >= 0;
        for (std::size_t c = 0; c < header.header().size(); ++c) {
            if (!known_column(header.header().names()[c])) {
                extra_cols.push_back(c);
                extra_names.push_back(header.header().raw_names()[c]);
            }
        }
        extra.resize(extra_cols.size());
        block = nl == std::string_view::npos ? std::string_view() : block.substr(nl + 1);
        std::size_t lines_before = 1;
        SolutionRecord rec;
        for (;;) {
            host::SolutionsReader reader(header, block, lines_before);
            while (reader.next(rec)) {
                t.push_back(rec.t);
                chu.emplace_back(rec.chu);
                chu_width = std::max(chu_width, rec.chu.size());
                q.insert(q.end(), {rec.q_chu_icrf.w, rec.q_chu_icrf.x, rec.q_chu_icrf.y, rec.q_chu_icrf.z});
                for (std::size_t j = 0; j < 3; ++j) {
                    temps.push_back(rec.temperature_present[j] ? rec.temperature[j] : kNaN);
                }
                const int cols[3] = {header.columns().vx, header.columns().vy, header.columns().vz};
                const double vs[3] = {rec.v_sc_kms.x, rec.v_sc_kms.y, rec.v_sc_kms.z};
                for (std::size_t j = 0; j < 3; ++j) {  // present: a field that is there and not empty or nan
                    const bool there = cols[j] >= 0 && !reader.fields()[static_cast<std::size_t>(cols[j])].empty();
                    v.push_back(there ? vs[j] : kNaN);
                }
                flags.push_back(rec.flags);
                conf.push_back(rec.confidence_present ? rec.confidence : kNaN);
                if (has_status) {
                    const auto f = reader.fields()[static_cast<std::size_t>(status_col)];
                    const auto s = host::parse_integer(f);
                    if (!s || *s < 0 || *s > 0xFFFF) {
                        throw host::InputError(path, rec.line,
                                               static_cast<std::size_t>(f.data() - reader.fields()[0].data()) + 1,
                                               "column 'status': " + host::why_not_an_integer(f, 0, 0xFFFF));
                    }
                    st.push_back(*s);
                }
                for (std::size_t j = 0; j < extra_cols.size(); ++j) {
                    extra[j].emplace_back(reader.fields()[extra_cols[j]]);
                }
            }
            if (!blocks.next(block)) {
                break;
            }
            lines_before = blocks.lines_before();
        }
    }
    const auto n = static_cast<py::ssize_t>(t.size());
    const auto arr = [](const std::vector<double>& x, py::ssize_t rows, py::ssize_t cols) {
        py::array_t<double> a(cols == 0 ? std::vector<py::ssize_t>{rows} : std::vector<py::ssize_t>{rows, cols});
        std::copy(x.begin(), x.end(), a.mutable_data());
        return a;
    };
    py::dict d;
    d["t"] = arr(t, n, 0);
    d["chu"] = py::module_::import("numpy").attr("array")(py::cast(chu), "dtype"_a = "U" + std::to_string(chu_width));
    d["q"] = arr(q, n, 4);
    d["temps"] = arr(temps, n, 3);
    d["v"] = arr(v, n, 3);
    py::array_t<std::int64_t> fa(n);
    std::copy(flags.begin(), flags.end(), fa.mutable_data());
    d["flags"] = fa;
    d["confidence"] = arr(conf, n, 0);
    if (has_status) {
        py::array_t<std::uint16_t> sa(n);
        std::transform(st.begin(), st.end(), sa.mutable_data(),
                       [](long long x) { return static_cast<std::uint16_t>(x); });
        d["status"] = sa;
    }
    py::dict ex;  // {name as written: (n,) str, the fields as written}
    for (std::size_t j = 0; j < extra_cols.size(); ++j) {
        ex[py::str(extra_names[j])] = py::module_::import("numpy").attr("array")(py::cast(extra[j]), "dtype"_a = "U");
    }
    d["extra"] = ex;
    return d;
}

void append_number(std::string& out, double x) {
    if (std::isnan(x)) {
        out += "nan";
        return;
    }
    char buf[40];
    const auto r = std::to_chars(buf, buf + sizeof buf, x);  // shortest text that reads back exactly
    out.append(buf, static_cast<std::size_t>(r.ptr - buf));
}

// The extra columns of write_solutions(): {name: (n,) values}, each value
// written as its str(), verbatim; a name or value that would not read back
// as one CSV field is refused.
std::vector<std::pair<std::string, std::vector<std::string>>> extra_columns(const py::object& extra, py::ssize_t n) {
    std::vector<std::pair<std::string, std::vector<std::string>>> cols;
    if (extra.is_none()) {
        return cols;
    }
    if (!py::isinstance<py::dict>(extra)) {
        bad_argument("extra", "expected a dict {column name: (n,) values} or None, got " + value_text(extra));
    }
    std::vector<std::string_view> fields;
    const auto one_field = [&](const std::string& x) {
        return x.find_first_of(std::string("\n\r\0", 3)) == std::string::npos &&
               host::split_fields(x, fields) == host::kSplitOk && fields.size() == 1;
    };
    for (const auto& item : extra.cast<py::dict>()) {
        if (!py::isinstance<py::str>(item.first)) {
            bad_argument("extra", "column names are strings, got " + value_text(item.first));
        }
        const std::string name = item.first.cast<std::string>();
        if (known_column(name)) {
            bad_argument("extra", "column '" + name + "' is written from write_solutions()'s own argument");
        }
        if (!one_field(name)) {
            bad_argument("extra", "column name '" + name +
                                      "' is not one CSV field (a comma or quote needs RFC 4180 quotes; no line break)");
        }
        const py::array a = as_numpy(item.second);
        if (a.ndim() != 1 || a.shape(0) != n) {
            bad_argument("extra", "column '" + name + "': expected shape (" + std::to_string(n) + ",) (as t), got " +
                                      shape_text(a));
        }
        std::vector<std::string> values = a.attr("astype")("str").attr("tolist")().cast<std::vector<std::string>>();
        for (std::size_t i = 0; i < values.size(); ++i) {
            if (!one_field(values[i])) {
                bad_argument("extra", "column '" + name + "', row " + std::to_string(i) + ": '" + values[i] +
                                          "' is not one CSV field (a comma or quote needs RFC 4180 quotes; no line "
                                          "break)");
            }
        }
        cols.emplace_back(name, std::move(values));
    }
    return cols;
}

// The text as read_solutions() reads it, before anything is written: a row it
// would refuse is refused here, naming the row and the column.
void check_reads_back(const std::string& text) {
    static const std::string kName = "<write_solutions>";
    try {
        const std::size_t nl = text.find('\n');
        const host::SolutionsReader header(kName, std::string_view(text).substr(0, nl));
        host::SolutionsReader reader(header, std::string_view(text).substr(nl + 1), 1);
        SolutionRecord rec;
        while (reader.next(rec)) {
        }
    } catch (const host::InputError& e) {
        const std::string what = e.what();
        const std::string why = what.substr(std::min(what.size(), what.find(": ") + 2));
        throw py::value_error(
            "write_solutions: " + (e.line() <= 1 ? std::string("header") : "row " + std::to_string(e.line() - 2)) +
            ", character " + std::to_string(e.column()) + ": " + why +
            " (read_solutions() would refuse it; nothing written)");
    }
}

// write_solutions()'s status: integers in [0, 65535] that follow the rules of
// docs/contract.md, section 4, and 16 for a row whose chu is no camera head
// (what correct() gives it).
using Statuses = py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>;
Statuses status_arg(const py::object& status, const Rows& r) {
    const py::array a = as_numpy(status);
    const char kind = a.dtype().kind();
    if ((kind != 'i' && kind != 'u') || a.ndim() != 1 || a.shape(0) != r.n) {
        bad_argument("status", "expected " + std::to_string(r.n) + " integers, shape (n,), got dtype " +
                                   std::string(py::str(a.dtype())) + " shape " + shape_text(a));
    }
    // uint64 beyond int64 would wrap in the conversion: refused as out of range first.
    if (kind == 'u' && a.size() > 0 && py::int_(a.attr("max")()) > py::int_(0xFFFF)) {
        const auto i =
            py::module_::import("numpy").attr("flatnonzero")(a.attr("__gt__")(0xFFFF))[py::int_(0)].cast<py::ssize_t>();
        bad_argument("status", "row " + std::to_string(i) + ": " + std::string(py::str(a[py::int_(i)])) +
                                   " is out of range: a status is an integer in [0, 65535] (docs/contract.md, "
                                   "section 4)");
    }
    Statuses st = Statuses::ensure(a);
    for (py::ssize_t i = 0; i < r.n; ++i) {
        const std::int64_t x = st.data()[i];
        if (x < 0 || x > 0xFFFF) {
            bad_argument("status", "row " + std::to_string(i) + ": " + std::to_string(x) +
                                       " is out of range: a status is an integer in [0, 65535] (docs/contract.md, "
                                       "section 4)");
        }
        if (!status::status_consistent(static_cast<StatusBits>(x))) {
            bad_argument("status", "row " + std::to_string(i) + ": " + std::to_string(x) +
                                       " is not a status correct() gives: bits that never come together "
                                       "(docs/contract.md, section 4)");
        }
        if (r.head[static_cast<std::size_t>(i)] >= kMaxHeads && x != status::kRejected) {
            bad_argument("chu", "row " + std::to_string(i) + ": not a camera head (" + std::string(kHeadChoices.text) +
                                    ") with status " + std::to_string(x) +
                                    ": correct() gives such a row status 16 (rejected)");
        }
    }
    return st;
}

// Row i's chu as written: the head letter, or the text given for an unknown
// head (bytes as Latin-1), which must be one unquoted CSV field.
std::string chu_field(const Rows& r, const py::array& chu, py::ssize_t i) {
    const std::uint8_t head = r.head[static_cast<std::size_t>(i)];
    if (head < kMaxHeads) {
        return std::string(1, host::head_name(head));
    }
    const py::object x = chu[py::int_(i)];
    std::string name = chu.dtype().kind() == 'S' ? py::str(x.attr("decode")("latin-1")) : py::str(x);
    if (name.find_first_of(std::string(",\n\r\"\0", 5)) != std::string::npos) {
        bad_argument("chu", "row " + std::to_string(i) + ": '" + name + "' cannot be written to a CSV field");
    }
    return name;
}

void write_solutions(const py::object& path_obj, const py::object& t, const py::object& chu, const py::object& q,
                     const py::object& temps, const py::object& v, const py::object& flags,
                     const py::object& confidence, const py::object& status, const py::object& extra) {
    const std::string path = path_arg(path_obj, "path");
    const Rows r = rows_of(t, chu, q, temps, v, flags, confidence);
    std::optional<Statuses> st;
    if (!status.is_none()) {
        st = status_arg(status, r);
    }
    const auto extras = extra_columns(extra, r.n);
    const py::array chu_a = as_numpy(chu);
    std::string out = "t,chu,qw,qx,qy,qz,t_chu,t_029,t_032,vx,vy,vz,flags,confidence";
    for (const auto& [name, values] : extras) {
        out += ',' + name;
    }
    out += st ? ",status\n" : "\n";
    for (py::ssize_t i = 0; i < r.n; ++i) {
        const auto k = static_cast<std::size_t>(i);
        append_number(out, r.t.data()[i]);
        out += ',';
        out += chu_field(r, chu_a, i);
        for (int j = 0; j < 4; ++j) {
            out += ',';
            append_number(out, r.q.data()[4 * i + j]);
        }
        for (int j = 0; j < 3; ++j) {
            out += ',';
            append_number(out, r.temps.data()[3 * i + j]);
        }
        for (int j = 0; j < 3; ++j) {
            out += ',';
            const double x = r.v.data()[3 * i + j];
            if (!std::isnan(x)) {  // docs/contract.md: empty when not available
                append_number(out, x);
            }
        }
        out += ',' + std::to_string(r.flags[k]) + ',';
        if (!std::isnan(r.confidence.data()[i])) {
            append_number(out, r.confidence.data()[i]);
        }
        for (const auto& [name, values] : extras) {
            out += ',' + values[k];
        }
        if (st) {
            out += ',' + std::to_string(st->data()[i]);
        }
        out += '\n';
    }
    check_reads_back(out);
    host::write_file_atomically(path, out);
}

// ---- Model

py::array_t<double> model_coefficients(const host::ModelFile& m) {
    py::array_t<double> a({py::ssize_t{kMaxHeads}, py::ssize_t{3}, py::ssize_t{7}});
    double* p = a.mutable_data();
    for (std::size_t h = 0; h < kMaxHeads; ++h) {
        for (std::size_t ax = 0; ax < 3; ++ax) {
            for (std::size_t c = 0; c < 7; ++c) {
                *p++ = m.coefficients[h][ax][c];
            }
        }
    }
    return a;
}

host::ModelFile model_from(const py::object& coefficients, const py::object& heads) {
    const py::array a = as_numpy(coefficients);
    const char kind = a.dtype().kind();
    if (kind != 'f' && kind != 'i' && kind != 'u') {
        bad_argument("coefficients", "expected real numbers, got dtype " + std::string(py::str(a.dtype())));
    }
    if (a.ndim() != 3 || a.shape(0) != py::ssize_t{kMaxHeads} || a.shape(1) != 3 ||
        (a.shape(2) != 4 && a.shape(2) != 7)) {
        bad_argument("coefficients", "expected shape (" + std::to_string(kMaxHeads) + ", 3, 4) or (" +
                                         std::to_string(kMaxHeads) + ", 3, 7) (head " + head_letter_range() +
                                         ", axis alpha/beta/gamma, c0 c1 c2 c3 [c1_2 c2_2 c3_2]), got " +
                                         shape_text(a));
    }
    const Doubles c = Doubles::ensure(a);
    const auto k = static_cast<std::size_t>(a.shape(2));
    host::ModelFile m;
    for (std::size_t h = 0; h < kMaxHeads; ++h) {
        for (std::size_t ax = 0; ax < 3; ++ax) {
            for (std::size_t j = 0; j < k; ++j) {
                const double x = c.data()[(h * 3 + ax) * k + j];
                if (!std::isfinite(x)) {
                    bad_argument("coefficients", std::string("head ") + head_letter(static_cast<std::uint8_t>(h)) +
                                                     " " + host::kAxisNames[ax] + " " + host::kCoefficientNames[j] +
                                                     " is not finite");
                }
                m.coefficients[h][ax][j] = x;
                m.quadratic = m.quadratic || (j >= 4 && x != 0.0);
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
    return a.present == b.present && a.coefficients == b.coefficients && a.quadratic == b.quadratic;
}

// Pickling: (coefficients (heads, 3, 7), heads, quadratic), rebuilt by Model().
py::tuple model_state(const host::ModelFile& m) {
    return py::make_tuple(model_coefficients(m), model_heads(m), m.quadratic);
}

host::ModelFile model_from_state(const py::tuple& state) {
    if (state.size() != 3) {
        throw py::value_error("ascorr.Model: a pickled state is (coefficients, heads, quadratic)");
    }
    host::ModelFile m = model_from(state[0], state[1]);
    m.quadratic = state[2].cast<bool>();
    return m;
}

}  // namespace

}  // namespace ascorr::python

PYBIND11_MODULE(_ascorr, mod) {
    using namespace ascorr;
    using namespace ascorr::python;
    mod.doc() = "Compiled part of the ascorr package (see help(ascorr)).";

    // Malformed input and refused fits are ValueErrors; other failures of the
    // host library (a file that cannot be written, a model beyond the fixed-point
    // formats) are std::runtime_error, hence RuntimeError.
    py::register_exception<host::InputError>(mod, "InputError", PyExc_ValueError).attr("__doc__") =
        "A malformed input file or rows (a ValueError); the message starts with file:line:column.";
    py::register_exception<host::FitRefused>(mod, "FitRefused", PyExc_ValueError).attr("__doc__") =
        "fit() refused the data: period too short, too few orbits or an ill-conditioned design (a ValueError).";

    // The heads (ascorr/heads.hpp), for Python and for the docstrings below.
    mod.attr("HEADS") = py::str(kHeadLetters);
    const std::string n_heads = std::to_string(kMaxHeads);
    static const std::string model_doc =
        R"doc(A thermal model: per head and axis, angles in arcsec linear (and
optionally quadratic) in T_CHU, T029 - T_CHU and T032 - T_CHU (docs/contract.md, "Model file").

Model(coefficients, heads=")doc" +
        std::string(kHeadLetters) + "\"): coefficients of shape (" + n_heads + ", 3, 4) or (" + n_heads +
        ", 3, 7),\nindexed [head " + head_letter_range() +
        R"doc(][axis alpha, beta, gamma][c0, c1, c2, c3, c1_2, c2_2, c3_2],
in arcsec, arcsec/degC and arcsec/degC^2; heads: the heads that have
coefficients (a head not listed gets status 256 in correct()).)doc";
    static const std::string coefficients_doc = "Coefficients, float64 (" + n_heads + ", 3, 7): [head " +
                                                head_letter_range() +
                                                "][alpha, beta, gamma][c0, c1, c2, c3, c1_2, c2_2, c3_2], arcsec "
                                                "(a copy).";
    py::class_<host::ModelFile>(mod, "Model", model_doc.c_str())
        .def(py::init(&model_from), "coefficients"_a, "heads"_a = py::none())
        .def_property_readonly("coefficients", &model_coefficients, coefficients_doc.c_str())
        .def_property_readonly("heads", &model_heads, "The heads with coefficients, e.g. 'ABC'.")
        .def_property_readonly(
            "quadratic", [](const host::ModelFile& m) { return m.quadratic; },
            "True when the model has (and its file will carry) the quadratic columns.")
        .def(
            "write",
            [](const host::ModelFile& m, const py::object& path) { host::write_model_file(path_arg(path, "path"), m); },
            "path"_a,
            "Write the model file (docs/contract.md), atomically: the whole file or nothing. path: str or "
            "os.PathLike.")
        .def("to_csv", &host::format_model, "The model file's text.")
        .def(
            "__eq__",
            [](const host::ModelFile& m, const py::object& other) -> py::object {
                if (!py::isinstance<host::ModelFile>(other)) {
                    return py::reinterpret_borrow<py::object>(Py_NotImplemented);
                }
                return py::bool_(models_equal(m, other.cast<const host::ModelFile&>()));
            },
            py::is_operator(), "Equal when both would write the same model file (heads, coefficients, columns).")
        .def(py::pickle(&model_state, &model_from_state))
        .def("__repr__", [](const host::ModelFile& m) {
            return "<ascorr.Model heads='" + model_heads(m) + "'" + (m.quadratic ? " quadratic" : "") + ">";
        });

    mod.def(
        "read_model", [](const py::object& path) { return host::read_model_file(path_arg(path, "path")); }, "path"_a,
        R"doc(Read a model file (docs/contract.md, "Model file"). A malformed file raises ascorr.InputError
(a ValueError) with file:line:column, as the command line reports it.)doc");

    static const std::string correct_doc =
        R"doc(Correct solutions: aberration, then the thermal model; the numbers and status bits of
`ascorr correct` on the same rows, bit for bit, in every scalar.

t: float64 (n,), s since J2000.0 TT. chu: (n,) strings )doc" +
        head_letter_range() + " or head indices\n" + head_index_range() +
        R"doc(. q: (n, 4) q_chu_icrf (w, x, y, z). temps: (n, 3) t_chu, t_029, t_032 in
degC, NaN where missing. v: (n, 3) spacecraft velocity, km/s GCRS, NaN where
missing. temps and v may be None (all missing). model: an ascorr.Model, or None
for no thermal stage. scalar: 'double', 'float' or 'fixed' (the core's Q30).
aberration: True or False (False skips the aberration stage; None is refused).
states: the path (str or os.PathLike) of a states file
(t,x,y,z,vx,vy,vz; `ascorr correct --states`): a row without its own velocity
(all three NaN) gets the on-board velocity service's, propagated from the
latest state at or before it (status 4 before the first state, 4+512 beyond
max_propagation seconds, 4+32 off a plausible orbit); states_frame 'itrf' (GNSS)
or 'gcrs' (uplinked). States the service refuses are reported as a warning.
The names of scalar and states_frame are those of the command line, in any
case ('GCRS' is 'gcrs'); numbers are not names.

Returns (q_corrected float64 (n, 4), status uint16 (n,)). Every row comes back;
a row that cannot be corrected keeps its quaternion exactly and says why in its
status bits (1 aberration, 2 thermal, 4 no velocity, 8 temperatures missing,
16 rejected, 32 velocity unusable, 64 temperature unusable, 128 model angle
beyond 1 deg, 256 no model for the head). A time outside the Earth ephemeris
(1900-2100, e.g. 1e300 s or a time in ms) is a row like any other: with a
velocity it gets 4+32, as on the command line. Raises ValueError naming the
argument and what it accepts for a wrong shape, dtype or value, or a time that
is not finite (the command line refuses such a row as malformed).)doc";
    mod.def("correct", &correct, "t"_a, "chu"_a, "q"_a, "temps"_a, "v"_a, "model"_a = py::none(), "scalar"_a = "double",
            "aberration"_a = true, "states"_a = py::none(), "states_frame"_a = "itrf",
            "max_propagation"_a = host::CorrectOptions{}.max_propagation_s, correct_doc.c_str());

    mod.def("self_calibrate", &self_calibrate, "t"_a, "chu"_a, "q"_a, "temps"_a, "v"_a, "flags"_a = py::none(),
            "confidence"_a = py::none(), "model"_a = py::none(), "scalar"_a = "double", "time_constant"_a = 30.0,
            R"doc(Correct with a thermal model the on-board estimator learns from the rows themselves, as
`ascorr correct --self-calibrate`: causally in time order (any row order), from the
epochs `fit` would select (flags: integers (n,) or None; confidence: (n,) arcsec or
None), after the aberration stage, in `scalar`, starting from `model` (version 0)
or from none (rows before the first adopted model get status 256).
time_constant: the estimator's forgetting in days. Returns (q_corrected float64
(n, 4), status uint16 (n,), history), history a list of {"t", "version", "crc32c",
"model"} for every model that became active, in time order.)doc");

    mod.def("earth_velocity", &earth_velocity, "t"_a, "exact"_a = false,
            R"doc(The Earth's barycentric velocity (ICRF axes, km/s) and heliocentric distance (au) at t
(s since J2000.0 TT), from ERFA's eraEpv00: as the correction uses it (Chebyshev
series of degree 15 on 16-day segments, within 5e-9 km/s and 5e-12 au of
eraEpv00), or with exact=True (True or False) a direct call for each t.
eraEpv00 spans 1900-2100: outside it (and for NaN) the row is NaN, velocity and
distance (the correction then has no velocity: status 4+32).
Returns (v float64 (n, 3), sun_distance_au float64 (n,)).)doc");

    mod.def("iba", &iba, "t"_a, "chu"_a, "q"_a,
            R"doc(Inter-boresight angles: for each pair 'A-B', 'A-C', 'B-C', the angle in arcsec between the
two heads' boresights at every epoch (t to the millisecond) where both have a row.
Returns {pair: (t float64 (m,), iba float64 (m,))}, sorted by t. A row whose
quaternion the core rejects (not finite or not unit, status 16 in correct(),
a zero quaternion included) takes part in no IBA, as in stats(); a UserWarning
names such rows. A second row of one head at one epoch raises ascorr.InputError.)doc");

    mod.def("stats", &stats, "t"_a, "chu"_a, "q"_a, "temps"_a, "v"_a, "flags"_a = py::none(),
            "confidence"_a = py::none(), "model"_a = py::none(), "t_from"_a = py::none(), "t_to"_a = py::none(),
            R"doc(IBA statistics as `ascorr stats`: per pair and stage (original, aberration, thermal), the
IBA RMS about the mean over the clean epochs (flags 0, confidence <= 5 or missing,
temperatures and velocity present and accepted), and after 200 s smoothing.
flags: integers (n,) or None (0); confidence: (n,) arcsec, NaN or None when
missing; t_from, t_to: the period (inclusive).
Returns {"pairs": {pair: {"original", "aberration", "thermal", "<stage>_smoothed"
(arcsec; None with fewer than two clean epochs, or thermal without a model, as
null in `ascorr stats --json`), "n"}}, "rows", "clean_rows", "table" (the command's text),
"messages" (rows left out, one line each)}.)doc");

    mod.def("fit", &fit, "t"_a, "chu"_a, "q"_a, "temps"_a, "v"_a, "flags"_a = py::none(), "confidence"_a = py::none(),
            "t_from"_a = py::none(), "t_to"_a = py::none(), "min_days"_a = host::kDefaultMinSpanDays,
            "min_orbits"_a = host::kDefaultMinOrbits, "max_condition"_a = host::kDefaultMaxCondition,
            "orbit_period"_a = py::none(), "terms"_a = "linear", "holdout"_a = host::kDefaultHoldout,
            "min_temperature_range"_a = host::kDefaultMinTemperatureRange,
            R"doc(Fit the thermal model as `ascorr fit` (the paper's procedure; see the README), with its
defaults and checks. terms: 'linear' or 'quadratic' (also c1_2, c2_2, c3_2; any
case, as --terms); holdout: the fraction of the period (its end) held out for the
model-selection report, 0..0.5; min_temperature_range: the smallest range (degC)
of each regressor for quadratic terms. Returns (model, report): model an
ascorr.Model (model.write(path) writes the model file), report a dict (rows,
dropped, epochs, orbits_used, condition, singular_values, terms, heads (the
letters of the heads fitted: A, B, C and any other with rows), residual_rms and
signal_rms (len(heads), 3) arcsec [head][alpha, beta, gamma], text).
Raises ascorr.FitRefused (a ValueError) when the data cannot determine the model
(period shorter than min_days, fewer than min_orbits orbits, condition number
above max_condition, too small a temperature range for quadratic terms) or a
setting is out of its range; its text, and the report's, name the settings as
this function's keywords (min_temperature_range, not --min-temperature-range).)doc");

    mod.def("read_solutions", &read_solutions, "path"_a,
            R"doc(Read a solutions file, or a corrected file, into arrays: {"t", "chu" (strings as written),
"q" (n, 4), "temps" (n, 3), "v" (n, 3) (NaN where not available), "flags" (0 when
absent), "confidence" (NaN when absent)} plus "status" for a corrected file, and "extra":
{column name as written: (n,) str, the fields as written} for every other column
(kept, as `ascorr correct` keeps them). The keys are write_solutions()'s argument
names: write_solutions(path2, **read_solutions(path1)) writes every column.
path: str or os.PathLike. Malformed rows raise ascorr.InputError with
file:line:column, as the command line.)doc");

    mod.def("write_solutions", &write_solutions, "path"_a, "t"_a, "chu"_a, "q"_a, "temps"_a = py::none(),
            "v"_a = py::none(), "flags"_a = py::none(), "confidence"_a = py::none(), "status"_a = py::none(),
            "extra"_a = py::none(),
            R"doc(Write a solutions file (or, with status, a corrected file) from arrays, as the command
line writes its outputs: atomically (a temporary file renamed over the output,
whose permission bits and symbolic links are kept; on an error the existing file
is left as it was). path: str or os.PathLike. Columns: t, chu, qw..qz, t_chu,
t_029, t_032, vx, vy, vz, flags, confidence, then extra's columns in its order
({name: (n,) values}, each value written as str(value), verbatim; what read_solutions()
returned), then status. Numbers are written with the fewest digits that read
back exactly; NaN temperatures as 'nan', NaN velocities and confidences as empty
fields. Nothing is written that read_solutions() would refuse: a status outside
0..65535 or with bits correct() never sets together, a row whose chu is not a
camera head with a status other than 16, a value that is not one CSV field raise
ValueError naming the argument (or column) and the row.)doc");
}
