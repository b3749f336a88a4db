// python/src/bind.hpp: what every part of the bindings shares: the checks that
// turn a Python argument into what the host library takes, with the module's
// one form of message ("argument 'NAME': expected WHAT, got REPR (TYPE)"), the
// rows of arrays as the solutions reader would have read them, and the
// docstrings (docstrings.hpp) with the heads filled in.
//
// Arrays: float64 C-contiguous inputs are used in place; other real dtypes
// (float32, integers) and non-contiguous arrays are converted once; times
// must be float64 or integers. Every argument is a py::object checked here, so
// that a wrong one raises ValueError, never pybind11's cast error
// (python/ascorr/__init__.py turns a missing or unknown argument into Python's
// own TypeError). Enumerations are the command line's names in any case; paths
// are str or os.PathLike.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "ascorr_host/analysis/iba.hpp"
#include "ascorr_host/correct/correct_row.hpp"
#include "ascorr_host/correct/scalar_kind.hpp"
#include "ascorr_host/formats/combined_csv.hpp"
#include "ascorr_host/formats/model_csv.hpp"
#include "ascorr_host/formats/mountings_csv.hpp"
#include "ascorr_host/formats/solutions_csv.hpp"

namespace ascorr::python {

namespace py = pybind11;

using Doubles = py::array_t<double, py::array::c_style | py::array::forcecast>;

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// The label of array rows in messages (InputError's "file:line:column").
inline constexpr const char* kArrayRows = "<arrays, 1-based row>";

// A docstring of docstrings.hpp with its placeholders filled in; the text
// lives as long as the module.
const char* docstring(const char* text);

// ---- the parts of the module, each adding its names (module.cpp calls them)
void bind_model(py::module_& mod);  // first: the others' signatures name ascorr.Model
void bind_formats(py::module_& mod);
void bind_correct(py::module_& mod);
void bind_self_calibration(py::module_& mod);
void bind_analysis(py::module_& mod);
void bind_combine(py::module_& mod);  // read_mountings, combine, align
void bind_interpolate(py::module_& mod);
void bind_gracefo(py::module_& mod);  // import_gracefo

// A mountings dict (read_mountings()'s) as the mountings file's reader takes
// it, with its rules and messages (ValueError naming argument 'mountings').
host::MountingsFile mountings_arg(const py::handle& obj);

// fit()'s and self_calibrate()'s lag=: 'auto' (nullopt: fit's choice, or
// learnt by the self-calibration), 'TAU' or 'X:TAU,...' as --lag
// (host::parse_lags), or a number for every head; ValueError naming 'lag'
// otherwise (bind_analysis.cpp).
std::optional<std::array<double, kMaxHeads>> lags_arg(const py::handle& lag);

// ---- arguments (arguments.cpp)

[[noreturn]] void bad_argument(const std::string& name, const std::string& what);
// A number for a message: the shortest text that reads back exactly (1e+300,
// never 300 digits), nan and inf as such.
std::string number_text(double x);
// What a Python value is, for messages: its repr (cut short) and its type.
std::string value_text(const py::handle& x);
// An enumeration's value: one of names, in any case, as on the command line
// ("names, case-insensitive"). Numbers are not names.
std::string choice_arg(const py::handle& x, const char* name, std::initializer_list<const char*> names);
// The scalar= argument: one of the host's scalar names (scalar_kind.hpp).
host::ScalarKind scalar_arg(const py::handle& x);
// True or False (Python's bool or NumPy's bool_); None and numbers are refused.
bool bool_arg(const py::handle& x, const char* name);
// A real number (int, float, NumPy real scalar); not a bool, a string or None.
double real_arg(const py::handle& x, const char* name);
// A non-negative integer (int or NumPy integer; not a bool or a float).
std::size_t count_arg(const py::handle& x, const char* name);
// A path: str or os.PathLike (pathlib.Path); bytes and the rest are refused.
std::string path_arg(const py::handle& x, const char* name);
// Heads by their letters, as the command line's --heads and --frame-heads
// (iba.hpp parse_head_letters: heads.hpp's, in its order, none twice), at
// least min and at most max of them; a str, else refused.
HeadMask heads_arg(const py::handle& x, const char* name, std::size_t min, std::size_t max);
// A time (t_from, t_to): None, or a real number that is not NaN; a NumPy
// float below 64 bits is refused (too few bits for a time since J2000).
std::optional<double> time_arg(const py::object& x, const char* name);
// An ascorr.Model or None (nullptr).
const host::ModelFile* model_arg(const py::object& model);
// obj, an ascorr.Model, as the host's model; TypeError naming `what` when it
// is none or its __init__ never ran (model_initialised: false). pickle calls
// Model.__new__ then __setstate__, and anyone may call __new__ alone: pybind11
// would then hand a method raw memory (allocated on first use, never
// constructed), so every use of a Model goes through here.
bool model_initialised(const py::handle& obj);
const host::ModelFile& model_of(const py::handle& obj, const std::string& what);

std::string shape_text(const py::array& a);
// Rows of a combined file as combine() and interpolate() return them: "t",
// "q" (m, 4), "heads", "sigma" (m, 3), "status", with covariance "cov" (m, 3).
py::dict combined_dict(const std::vector<host::AttitudeRow>& rows, bool covariance);
// Mountings as read_mountings() returns them: {"heads": "ABC", "q": (k, 4),
// "sigma_cross": (k,) or None, "sigma_about": (k,) or None}.
py::dict mountings_dict(const host::MountingsFile& m);
py::array as_numpy(const py::handle& obj);
// A real-valued array of shape (n,) (cols == 0) or (n, cols) as float64,
// C-contiguous: the same buffer when it already is, else one converted copy.
// n < 0: any length (it is then taken from this argument).
Doubles real_array(const py::handle& obj, const std::string& name, py::ssize_t n, py::ssize_t cols);
// Times (s since J2000.0): float64 or integers; float32 is refused.
Doubles time_array(const py::handle& obj, const std::string& name);
// The heads for messages: "'A'..'D'" and "0..3".
std::string head_letter_range();
std::string head_index_range();

// Integers given as an array (flags; chu as head indices), one rule with the
// solutions reader: an integer dtype, or floats that are all integral (pandas
// makes an integer column float64 when it held a missing value); every value
// within [lo, hi]. Otherwise the first row that is not, and why, in the
// reader's words (why_not_an_integer: "'0.9' ..." names the range). The dtype
// must be an integer or a float one (the caller checks).
struct Integers {
    std::vector<long long> values;
    py::ssize_t bad_row = -1;
    std::string why;
};
Integers integers_of(const py::array& a, long long lo, long long hi);

// The columns of a set of solutions, validated, as the core's caller needs them.
struct Rows {
    py::ssize_t n = 0;
    Doubles t, q, temps, v, confidence;
    std::vector<std::uint8_t> head;
    std::vector<long long> flags;
};

// The rows' columns, checked; temps, v, flags and confidence may be None (all
// missing, flags 0).
Rows rows_of(const py::handle& t, const py::handle& chu, const py::handle& q, const py::handle& temps,
             const py::handle& v, const py::handle& flags = py::none(), const py::handle& confidence = py::none());
// Row i as the solutions reader would have read it from a file holding the
// same values: NaN is "not available", as `nan` in a file.
void record_of(const Rows& r, py::ssize_t i, host::SolutionRecord& rec);
// Row i of the output arrays (q: (n, 4) w, x, y, z; status: (n,)) from a
// corrected row.
template <typename T>
void put_row(const host::RowCorrection<T>& c, py::ssize_t i, double* q_out, std::uint16_t* st_out) {
    double* q = q_out + 4 * i;
    q[0] = c.q_chu_icrf.w;
    q[1] = c.q_chu_icrf.x;
    q[2] = c.q_chu_icrf.y;
    q[3] = c.q_chu_icrf.z;
    st_out[i] = c.status;
}
// The rows as the host's analyses take a file's (for_each_solution).
host::RowSource source_of(const Rows& r);

}  // namespace ascorr::python
