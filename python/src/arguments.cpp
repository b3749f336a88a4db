// python/src/arguments.cpp: the argument checks of bind.hpp, and the
// docstrings' placeholders.
#include <algorithm>
#include <charconv>
#include <cmath>
#include <list>
#include <string>
#include <string_view>
#include <vector>

#include "ascorr/core/heads.hpp"
#include "ascorr_host/formats/csv.hpp"
#include "ascorr_host/formats/model_csv.hpp"
#include "bind.hpp"

namespace ascorr::python {

using host::SolutionRecord;

const char* docstring(const char* text) {
    static std::list<std::string> kept;  // stable addresses: pybind11 may keep the pointer
    std::string s(text);
    const auto fill = [&s](std::string_view key, const std::string& value) {
        for (std::size_t at = s.find(key); at != std::string::npos; at = s.find(key, at + value.size())) {
            s.replace(at, key.size(), value);
        }
    };
    fill("@HEADS@", std::string(kHeadLetters));
    fill("@N_HEADS@", std::to_string(kMaxHeads));
    fill("@HEAD_LETTERS@", head_letter_range());
    fill("@HEAD_INDICES@", head_index_range());
    fill("@N_TERMS@", std::to_string(kModelTerms));
    fill("@N_LINEAR_TERMS@", std::to_string(kLinearModelTerms));
    fill("@TERMS@", host::coefficient_columns(0, kModelTerms, ", "));
    fill("@QUADRATIC_TERMS@", host::coefficient_columns(kLinearModelTerms, kModelTerms, ", "));
    return kept.emplace_back(std::move(s)).c_str();
}

[[noreturn]] void bad_argument(const std::string& name, const std::string& what) {
    throw py::value_error("argument '" + name + "': " + what);
}

std::string number_text(double x) {
    char buf[40];
    const auto r = std::to_chars(buf, buf + sizeof buf, x);
    return {buf, static_cast<std::size_t>(r.ptr - buf)};
}

std::string value_text(const py::handle& x) {
    std::string s = py::repr(x);
    if (s.size() > 40) {
        s = s.substr(0, 37) + "...";
    }
    return s + " (" + std::string(py::str(py::type::handle_of(x).attr("__name__"))) + ")";
}

namespace {
// One of names, in any case; numbers are not names.
std::string choice(const py::handle& x, const char* name, const std::vector<std::string_view>& names) {
    if (py::isinstance<py::str>(x)) {
        std::string s = x.cast<std::string>();
        std::transform(s.begin(), s.end(), s.begin(),
                       [](char c) { return c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c; });
        for (const std::string_view n : names) {
            if (s == n) {
                return s;
            }
        }
    }
    std::string list;
    std::size_t k = 0;
    for (const std::string_view n : names) {
        list += std::string(k == 0 ? "" : k + 1 == names.size() ? " or " : ", ") + "'" + std::string(n) + "'";
        ++k;
    }
    bad_argument(name, "expected " + list + " (a name, in any case), got " + value_text(x));
}
}  // namespace

std::string choice_arg(const py::handle& x, const char* name, std::initializer_list<const char*> names) {
    return choice(x, name, std::vector<std::string_view>(names.begin(), names.end()));
}

host::ScalarKind scalar_arg(const py::handle& x) {
    std::vector<std::string_view> names;
    for (const host::ScalarName& n : host::kScalarNames) {
        names.push_back(n.name);
    }
    return *host::scalar_from_name(choice(x, "scalar", names));
}

HeadMask heads_arg(const py::handle& x, const char* name, std::size_t min, std::size_t max) {
    const std::optional<HeadMask> set =
        py::isinstance<py::str>(x) ? host::parse_head_letters(x.cast<std::string>()) : std::nullopt;
    const std::size_t n = set ? head_count(*set) : 0U;
    if (!set || n < min || n > max) {
        const std::string count = min == max ? std::to_string(min) : std::to_string(min) + " or more";
        bad_argument(name, "expected " + count + " of the heads " + kHeadLetters +
                               " as a string of their letters, in that order, none twice; got " + value_text(x));
    }
    return *set;
}

bool bool_arg(const py::handle& x, const char* name) {
    if (py::isinstance<py::bool_>(x) || py::isinstance(x, py::module_::import("numpy").attr("bool_"))) {
        return py::cast<bool>(x);
    }
    bad_argument(name, "expected True or False, got " + value_text(x));
}

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

std::string path_arg(const py::handle& x, const char* name) {
    if (py::isinstance<py::str>(x) || py::hasattr(x, "__fspath__")) {
        const py::object p = py::module_::import("os").attr("fspath")(x);
        if (py::isinstance<py::str>(p)) {
            std::string path = p.cast<std::string>();
            if (path.empty()) {
                bad_argument(name, "an empty path names no file");  // as the command line's options
            }
            return path;
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

std::string head_letter_range() {
    return std::string("'") + kHeadLetters[0] + "'..'" + kHeadLetters[kMaxHeads - 1] + "'";
}

std::string head_index_range() {
    return "0.." + std::to_string(kMaxHeads - 1);
}

namespace {

// Marks row i of out as the first that is no integer in [lo, hi]; text is the
// value as the reader would have read it.
void refuse_integer(Integers& out, std::size_t i, const std::string& text, long long lo, long long hi) {
    out.bad_row = static_cast<py::ssize_t>(i);
    out.why = host::why_not_an_integer(text, lo, hi);
}

void integral_floats(const py::array& a, long long lo, long long hi, Integers& out) {
    const auto x = Doubles::ensure(a);
    for (std::size_t i = 0; i < out.values.size(); ++i) {
        const double v = x.data()[i];
        const bool integral = std::isfinite(v) && std::floor(v) == v;
        if (!integral || v >= 0x1p63 || v < -0x1p63) {  // 2^63: the first double beyond long long
            char buf[400];                              // an integral double in full: at most 309 digits
            const auto r = integral ? std::to_chars(buf, buf + sizeof buf, v, std::chars_format::fixed, 0)
                                    : std::to_chars(buf, buf + sizeof buf, v);
            return refuse_integer(out, i, std::string(buf, r.ptr), lo, hi);
        }
        out.values[i] = static_cast<long long>(v);
        if (out.values[i] < lo || out.values[i] > hi) {
            return refuse_integer(out, i, std::to_string(out.values[i]), lo, hi);
        }
    }
}

void integers(const py::array& a, long long lo, long long hi, Integers& out) {
    if (a.dtype().kind() == 'u' && a.itemsize() >= 8) {  // beyond long long it would wrap to a negative number
        const auto x = py::array_t<std::uint64_t, py::array::c_style | py::array::forcecast>::ensure(a);
        for (std::size_t i = 0; i < out.values.size(); ++i) {
            if (x.data()[i] > static_cast<std::uint64_t>(std::numeric_limits<long long>::max())) {
                return refuse_integer(out, i, std::to_string(x.data()[i]), lo, hi);
            }
        }
    }
    const auto x = py::array_t<long long, py::array::c_style | py::array::forcecast>::ensure(a);
    for (std::size_t i = 0; i < out.values.size(); ++i) {
        out.values[i] = x.data()[i];
        if (out.values[i] < lo || out.values[i] > hi) {
            return refuse_integer(out, i, std::to_string(out.values[i]), lo, hi);
        }
    }
}

}  // namespace

Integers integers_of(const py::array& a, long long lo, long long hi) {
    Integers out;
    out.values.assign(static_cast<std::size_t>(a.size()), 0);
    if (a.dtype().kind() == 'f') {
        integral_floats(a, lo, hi, out);
    } else {
        integers(a, lo, hi, out);
    }
    return out;
}

namespace {

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

// The head of an integer index (below kMaxHeads), kUnknownHead otherwise.
std::uint8_t head_of_index(long long h) {
    return h >= 0 && h < static_cast<long long>(kMaxHeads) ? static_cast<std::uint8_t>(h) : host::kUnknownHead;
}

// chu as numbers: integer head indices.
void heads_of_indices(const py::array& a, py::ssize_t n, std::vector<std::uint8_t>& heads) {
    const Integers idx = integers_of(a, std::numeric_limits<long long>::min(), std::numeric_limits<long long>::max());
    if (idx.bad_row >= 0) {
        bad_argument("chu", "row " + std::to_string(idx.bad_row) + ": " + idx.why + " (a head index)");
    }
    for (py::ssize_t i = 0; i < n; ++i) {
        heads[static_cast<std::size_t>(i)] = head_of_index(idx.values[static_cast<std::size_t>(i)]);
    }
}

// The code point of a fixed-width string's character k (UCS-4 when unit is
// 4, a byte when 1), 0 past the width; assembled byte by byte: the elements
// need not be aligned.
std::uint32_t code_point(const unsigned char* e, std::size_t width, std::size_t unit, std::size_t k) {
    std::uint32_t c = 0;
    if (width >= (k + 1) * unit) {
        for (std::size_t b = 0; b < unit; ++b) {
            c |= static_cast<std::uint32_t>(e[k * unit + b]) << (8 * (unit == 4 ? b : 0));
        }
    }
    return c;
}

// chu as fixed-width strings, read in place: UCS-4 code points or bytes, NUL-padded.
void heads_of_strings(const py::array& a, py::ssize_t n, std::vector<std::uint8_t>& heads) {
    const py::array c = py::array::ensure(a, py::array::c_style);
    const auto width = static_cast<std::size_t>(c.itemsize());
    const std::size_t unit = a.dtype().kind() == 'U' ? 4 : 1;
    const auto* base = static_cast<const unsigned char*>(c.data());
    for (py::ssize_t i = 0; i < n; ++i) {
        const unsigned char* e = base + static_cast<std::size_t>(i) * width;
        const std::uint32_t first = code_point(e, width, unit, 0);
        const std::uint32_t second = code_point(e, width, unit, 1);
        if (second == 0 && first < 0x80U) {
            heads[static_cast<std::size_t>(i)] = head_index(static_cast<char>(first));
        }
    }
}

// chu as Python objects: str head names or int indices.
void heads_of_objects(const py::array& a, py::ssize_t n, std::vector<std::uint8_t>& heads) {
    for (py::ssize_t i = 0; i < n; ++i) {
        const py::object x = a[py::int_(i)];
        if (py::isinstance<py::str>(x)) {
            heads[static_cast<std::size_t>(i)] = host::head_from_name(x.cast<std::string>());
        } else if (py::isinstance<py::int_>(x)) {
            heads[static_cast<std::size_t>(i)] = head_of_index(x.cast<long long>());
        } else {
            bad_argument("chu", "row " + std::to_string(i) + ": expected a string or an integer, got " +
                                    std::string(py::str(x.get_type())));
        }
    }
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
    if (kind == 'i' || kind == 'u' || kind == 'f') {
        heads_of_indices(a, n, heads);
    } else if (kind == 'U' || kind == 'S') {
        heads_of_strings(a, n, heads);
    } else if (kind == 'O') {
        heads_of_objects(a, n, heads);
    } else {
        bad_argument("chu", "expected strings " + head_letter_range() + " or integers " + head_index_range() +
                                ", got dtype " + std::string(py::str(a.dtype())));
    }
    return heads;
}

}  // namespace

Rows rows_of(const py::handle& t, const py::handle& chu, const py::handle& q, const py::handle& temps,
             const py::handle& v, const py::handle& flags, const py::handle& confidence) {
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
        if ((kind != 'i' && kind != 'u' && kind != 'f') || a.ndim() != 1 || a.shape(0) != r.n) {
            bad_argument("flags", "expected " + std::to_string(r.n) + " non-negative integers, shape (n,), got dtype " +
                                      std::string(py::str(a.dtype())) + " shape " + shape_text(a));
        }
        Integers f = integers_of(a, 0, std::numeric_limits<long long>::max());
        if (f.bad_row >= 0) {
            bad_argument("flags", "row " + std::to_string(f.bad_row) + ": " + f.why);
        }
        r.flags = std::move(f.values);
    }
    return r;
}

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

bool model_initialised(const py::handle& obj) {
    return py::isinstance<host::ModelFile>(obj) &&
           reinterpret_cast<py::detail::instance*>(obj.ptr())->get_value_and_holder().holder_constructed();
}

const host::ModelFile& model_of(const py::handle& obj, const std::string& what) {
    if (!py::isinstance<host::ModelFile>(obj)) {
        throw py::type_error(what + ": expected an ascorr.Model, got " + value_text(obj));
    }
    if (!model_initialised(obj)) {
        throw py::type_error(what +
                             ": an ascorr.Model that was never initialised (Model.__new__ without __init__); make "
                             "models with read_model(), fit() or Model(coefficients)");
    }
    return obj.cast<const host::ModelFile&>();
}

const host::ModelFile* model_arg(const py::object& model) {
    if (model.is_none()) {
        return nullptr;
    }
    if (!py::isinstance<host::ModelFile>(model)) {
        bad_argument("model", "expected an ascorr.Model (read_model() or fit()) or None, got " +
                                  std::string(py::str(model.get_type())));
    }
    return &model_of(model, "argument 'model'");
}

}  // namespace ascorr::python
