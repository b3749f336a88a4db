// python/src/bind_formats.cpp: read_solutions() and write_solutions(), the
// solutions and corrected files to and from arrays, through the host's reader
// (for_each_solution_row) and writer (append_solution_fields,
// write_file_atomically): the files the command line reads and writes.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "ascorr/core/status.hpp"
#include "ascorr_host/formats/atomic_file.hpp"
#include "ascorr_host/formats/csv.hpp"
#include "ascorr_text/input_error.hpp"
#include "bind.hpp"
#include "docstrings.hpp"

namespace ascorr::python {

using host::SolutionRecord;
using namespace pybind11::literals;

namespace {

// The row's vx,vy,vz, NaN where absent (a field that is not there or empty).
void append_velocity(const host::SolutionsReader& reader, const SolutionRecord& rec, std::vector<double>& v) {
    const int cols[3] = {reader.columns().vx, reader.columns().vy, reader.columns().vz};
    const double vs[3] = {rec.v_sc_kms.x, rec.v_sc_kms.y, rec.v_sc_kms.z};
    for (std::size_t j = 0; j < 3; ++j) {  // present: a field that is there and not empty or nan
        const bool there = cols[j] >= 0 && !reader.fields()[static_cast<std::size_t>(cols[j])].empty();
        v.push_back(there ? vs[j] : kNaN);
    }
}

// The row's status column (0 … 65535; InputError otherwise).
long long status_of(const std::string& path, const host::SolutionsReader& reader, const SolutionRecord& rec,
                    int status_col) {
    const auto f = reader.fields()[static_cast<std::size_t>(status_col)];
    const auto s = host::parse_integer(f);
    if (!s || *s < 0 || *s > 0xFFFF) {
        throw text::InputError(path, rec.line, static_cast<std::size_t>(f.data() - reader.fields()[0].data()) + 1,
                               "column 'status': " + host::why_not_an_integer(f, 0, 0xFFFF));
    }
    return *s;
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
    int status_col = -1;
    host::for_each_solution_row(
        path,
        [&](const host::SolutionsReader& header) {
            status_col = header.header().index(host::kStatusColumn);
            has_status = status_col >= 0;
            for (std::size_t c = 0; c < header.header().size(); ++c) {
                if (!host::is_solutions_column(header.header().names()[c])) {
                    extra_cols.push_back(c);
                    extra_names.push_back(header.header().raw_names()[c]);
                }
            }
            extra.resize(extra_cols.size());
        },
        [&](const host::SolutionsReader& reader, const SolutionRecord& rec) {
            t.push_back(rec.t);
            chu.emplace_back(rec.chu);
            chu_width = std::max(chu_width, rec.chu.size());
            q.insert(q.end(), {rec.q_chu_icrf.w, rec.q_chu_icrf.x, rec.q_chu_icrf.y, rec.q_chu_icrf.z});
            for (std::size_t j = 0; j < 3; ++j) {
                temps.push_back(rec.temperature_present[j] ? rec.temperature[j] : kNaN);
            }
            append_velocity(reader, rec, v);
            flags.push_back(rec.flags);
            conf.push_back(rec.confidence_present ? rec.confidence : kNaN);
            if (has_status) {
                st.push_back(status_of(path, reader, rec, status_col));
            }
            for (std::size_t j = 0; j < extra_cols.size(); ++j) {
                extra[j].emplace_back(reader.fields()[extra_cols[j]]);
            }
        },
        "");
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
        if (host::is_solutions_column(name)) {
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
    } catch (const text::InputError& e) {
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
    std::string out(host::kSolutionsHeader);
    for (const auto& [name, values] : extras) {
        out += ',' + name;
    }
    out += st ? "," + std::string(host::kStatusColumn) + "\n" : "\n";
    for (py::ssize_t i = 0; i < r.n; ++i) {
        const auto k = static_cast<std::size_t>(i);
        const std::string chu_text = chu_field(r, chu_a, i);
        const double* qi = r.q.data() + 4 * i;
        const double* tc = r.temps.data() + 3 * i;
        const double* vi = r.v.data() + 3 * i;
        host::SolutionValues row;
        row.t = r.t.data()[i];
        row.chu = chu_text;
        row.q_chu_icrf = {qi[0], qi[1], qi[2], qi[3]};
        row.temperature = {tc[0], tc[1], tc[2]};
        row.v_sc_kms = {vi[0], vi[1], vi[2]};
        row.flags = r.flags[k];
        row.confidence = r.confidence.data()[i];
        host::append_solution_fields(out, row);
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

}  // namespace

void bind_formats(py::module_& mod) {
    mod.def("read_solutions", &read_solutions, "path"_a, docstring(docs::kReadSolutions));
    // For from_frame() (ascorr/__init__.py): the solutions reader's refusal of
    // a column that looks like one it reads (near_miss_column), as (index,
    // message), or None.
    mod.def("_near_miss", [](const std::vector<std::string>& names) -> py::object {
        const auto miss = host::near_miss_column(names);
        return miss ? py::make_tuple(miss->column, miss->message) : py::object(py::none());
    });
    // For from_frame() (ascorr/__init__.py): a column of integers by the rule
    // of the arrays (integers_of), as (int64 values, first bad row or -1, why).
    mod.def("_integers", [](const py::array& values, long long lo, long long hi) {
        const Integers r = integers_of(values, lo, hi);
        py::array_t<std::int64_t> a(static_cast<py::ssize_t>(r.values.size()));
        std::copy(r.values.begin(), r.values.end(), a.mutable_data());
        return py::make_tuple(a, r.bad_row, r.why);
    });
    mod.def("write_solutions", &write_solutions, "path"_a, "t"_a, "chu"_a, "q"_a, "temps"_a = py::none(),
            "v"_a = py::none(), "flags"_a = py::none(), "confidence"_a = py::none(), "status"_a = py::none(),
            "extra"_a = py::none(), docstring(docs::kWriteSolutions));
}

}  // namespace ascorr::python
