// python/src/bind_gracefo.cpp: import_gracefo(), GRACE-FO Level-1 star-camera
// products as arrays (ascorr_host/formats/gracefo.hpp): the numbers of the
// files `ascorr import gracefo` writes, read back.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "ascorr_host/formats/combined_csv.hpp"
#include "ascorr_host/formats/csv.hpp"
#include "ascorr_host/formats/gracefo.hpp"
#include "ascorr_text/input_error.hpp"
#include "bind.hpp"
#include "docstrings.hpp"

namespace ascorr::python {

using namespace pybind11::literals;

namespace {

std::vector<std::string> paths_arg(const py::object& x, const char* name) {
    std::vector<std::string> out;
    if (py::isinstance<py::str>(x) || py::hasattr(x, "__fspath__")) {
        out.push_back(path_arg(x, name));
        return out;
    }
    if (!py::isinstance<py::sequence>(x) || py::len(x) == 0) {
        bad_argument(name, "expected a path or a non-empty list of paths, got " + value_text(x));
    }
    for (const py::handle item : x) {
        out.push_back(path_arg(item, name));
    }
    return out;
}

std::string optional_path(const py::object& x, const char* name) {
    return x.is_none() ? std::string() : path_arg(x, name);
}

std::vector<std::string> optional_paths(const py::object& x, const char* name) {
    return x.is_none() ? std::vector<std::string>() : paths_arg(x, name);
}

template <typename T>
py::array_t<T> array_of(const std::vector<T>& v, py::ssize_t cols) {
    const auto rows = static_cast<py::ssize_t>(cols == 0 ? v.size() : v.size() / static_cast<std::size_t>(cols));
    py::array_t<T> a(cols == 0 ? std::vector<py::ssize_t>{rows} : std::vector<py::ssize_t>{rows, cols});
    std::copy(v.begin(), v.end(), a.mutable_data());
    return a;
}

py::dict import_gracefo_arrays(const py::object& sca1a, const py::object& qsa1b, const py::object& tim1b,
                               const py::object& clk1b, const py::object& sca1b, const py::object& time_offset) {
    host::GracefoOptions opt;
    opt.sca1a = paths_arg(sca1a, "sca1a");
    opt.qsa1b = path_arg(qsa1b, "qsa1b");
    opt.tim1b = optional_paths(tim1b, "tim1b");
    opt.clk1b = optional_paths(clk1b, "clk1b");
    opt.sca1b = optional_path(sca1b, "sca1b");
    opt.time_offset_s = real_arg(time_offset, "time_offset");
    if (!(std::abs(opt.time_offset_s) <= host::kMaxTimeOffsetS)) {
        bad_argument("time_offset", "expected seconds in [-10, 10], got " + value_text(time_offset));
    }
    std::vector<double> t, q, conf, ref_t, ref_q;
    std::vector<std::string> chu;
    std::vector<std::int64_t> flags;
    std::vector<std::string> extra[3];  // kGracefoColumns, as the file writes them
    host::GracefoSink sink;
    sink.solution = [&](const host::SolutionValues& v, const host::Sca1aRecord& r) {
        t.push_back(v.t);
        chu.emplace_back(v.chu);
        q.insert(q.end(), {v.q_chu_icrf.w, v.q_chu_icrf.x, v.q_chu_icrf.y, v.q_chu_icrf.z});
        flags.push_back(v.flags);
        conf.push_back(v.confidence);
        extra[0].push_back(std::to_string(r.mode));
        extra[1].push_back(std::to_string(r.quality));
        extra[2].push_back(std::to_string(r.confidence));
    };
    sink.reference = [&](double at, const Quaternion<double>& r) {
        const Quaternion<double> c = host::attitude_as_written(r);
        ref_t.push_back(at);
        ref_q.insert(ref_q.end(), {c.w, c.x, c.y, c.z});
    };
    host::GracefoSummary sum;
    host::MountingsFile m;
    {
        py::gil_scoped_release unlocked;
        m = host::import_gracefo(opt, sink, sum);
    }
    const auto n = static_cast<py::ssize_t>(t.size());
    py::dict s;
    s["t"] = array_of(t, 0);
    s["chu"] = py::module_::import("numpy").attr("array")(py::cast(chu), "dtype"_a = "U1");
    s["q"] = array_of(q, 4);
    s["temps"] = array_of(std::vector<double>(static_cast<std::size_t>(3 * n), kNaN), 3);
    s["v"] = array_of(std::vector<double>(static_cast<std::size_t>(3 * n), kNaN), 3);
    s["flags"] = array_of(flags, 0);
    s["confidence"] = array_of(conf, 0);
    py::dict ex;  // as read_solutions() gives a file's other columns: {name: (n,) str}
    const std::string names(host::kGracefoColumns);
    std::size_t from = 0;
    for (const auto& column : extra) {
        const std::size_t to = std::min(names.find(',', from), names.size());
        ex[py::str(names.substr(from, to - from))] =
            py::module_::import("numpy").attr("array")(py::cast(column), "dtype"_a = "U");
        from = to + 1;
    }
    s["extra"] = ex;
    py::dict d;
    d["satellite"] = std::string(1, sum.satellite);
    d["solutions"] = s;
    d["mountings"] = mountings_dict(m);
    if (opt.sca1b.empty()) {
        d["reference"] = py::none();
    } else {
        py::dict r;
        r["t"] = array_of(ref_t, 0);
        r["q"] = array_of(ref_q, 4);
        d["reference"] = r;
    }
    return d;
}

}  // namespace

void bind_gracefo(py::module_& mod) {
    mod.def("import_gracefo", &import_gracefo_arrays, "sca1a"_a, "qsa1b"_a, "tim1b"_a = py::none(),
            "clk1b"_a = py::none(), "sca1b"_a = py::none(), "time_offset"_a = host::kGracefoTimeOffsetS,
            docstring(docs::kImportGracefo));
}

}  // namespace ascorr::python
