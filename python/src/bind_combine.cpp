// python/src/bind_combine.cpp: read_mountings(), combine() and align(): the
// combined attitude of the bench (ascorr_host/analysis/combine.hpp, align.hpp)
// over the rows of arrays, as `ascorr combine` and `ascorr align` run them
// over a file's.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "ascorr/combine/combined_status.hpp"
#include "ascorr_host/analysis/align.hpp"
#include "ascorr_host/analysis/combine.hpp"
#include "ascorr_host/analysis/epochs.hpp"
#include "ascorr_host/formats/combined_csv.hpp"
#include "ascorr_host/formats/mountings_csv.hpp"
#include "ascorr_text/input_error.hpp"
#include "bind.hpp"
#include "docstrings.hpp"

namespace ascorr::python {

using namespace pybind11::literals;

namespace {

// The rows of arrays as the combination takes a file's: status None is a raw
// solutions file (taken as it is), else each row's status bits.
struct CombineRows {
    Rows rows;
    std::vector<StatusBits> status;  // empty: raw
};

CombineRows combine_rows(const py::object& t, const py::object& chu, const py::object& q, const py::object& status,
                         const py::object& flags, const py::object& confidence) {
    CombineRows c{rows_of(t, chu, q, py::none(), py::none(), flags, confidence), {}};
    if (status.is_none()) {
        return c;
    }
    const py::array a = as_numpy(status);
    const char kind = a.dtype().kind();
    if ((kind != 'i' && kind != 'u') || a.ndim() != 1 || a.shape(0) != c.rows.n) {
        bad_argument("status", "expected " + std::to_string(c.rows.n) + " integers 0..65535, shape (n,), got dtype " +
                                   std::string(py::str(a.dtype())) + " shape " + shape_text(a));
    }
    const auto s = py::array_t<long long, py::array::c_style | py::array::forcecast>::ensure(a);
    c.status.resize(static_cast<std::size_t>(c.rows.n));
    for (py::ssize_t i = 0; i < c.rows.n; ++i) {
        const long long v = s.data()[i];
        if (v < 0 || v > 0xFFFF) {
            bad_argument("status", "row " + std::to_string(i) + ": " + std::to_string(v) + " is not in 0..65535");
        }
        c.status[static_cast<std::size_t>(i)] = static_cast<StatusBits>(v);
    }
    return c;
}

host::CorrectedRowSource rows_source(const CombineRows& c) {
    return [&c](const std::function<void(const host::CorrectedRow&)>& fn) {
        host::SolutionRecord rec;
        for (py::ssize_t i = 0; i < c.rows.n; ++i) {
            record_of(c.rows, i, rec);
            fn(host::CorrectedRow::of(rec, c.status.empty()
                                               ? std::nullopt
                                               : std::optional<StatusBits>(c.status[static_cast<std::size_t>(i)])));
        }
    };
}

void warn(const std::string& log) {
    if (!log.empty() && PyErr_WarnEx(PyExc_UserWarning, log.c_str(), 1) != 0) {
        throw py::error_already_set();
    }
}

// The gate's arguments (None: the default by the rows' stages), checked as
// the command line's --gate-sigmas and --gate-floor.
host::GateOptions gate_arg(const py::object& sigmas, const py::object& floor) {
    host::GateOptions g;
    if (!sigmas.is_none()) {
        g.sigmas = real_arg(sigmas, "gate_sigmas");
    }
    if (!floor.is_none()) {
        g.floor_arcsec = real_arg(floor, "gate_floor");
    }
    const combine::CombinerConfig c = host::gate_config(g, true);  // the options' own values
    if (!(c.gate_sigmas >= combine::kMinGateSigmas && c.gate_sigmas <= combine::kMaxGateSigmas)) {
        bad_argument("gate_sigmas", "expected a number in [3, 100], got " + value_text(sigmas));
    }
    if (!combine::gate_config_valid(c)) {
        bad_argument("gate_floor", "expected arcsec in [1, 3600], got " + value_text(floor));
    }
    return g;
}

}  // namespace

// The mountings as Python holds them: {"heads": "ABC", "q": (k, 4),
// "sigma_cross": (k,) or None, "sigma_about": (k,) or None}, rows in the
// order of heads.
py::dict mountings_dict(const host::MountingsFile& m) {
    std::string heads;
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        if (m.mountings.head[h].present) {
            heads += kHeadLetters[h];
        }
    }
    const auto k = static_cast<py::ssize_t>(heads.size());
    py::array_t<double> q({k, py::ssize_t{4}});
    py::array_t<double> cross(k);
    py::array_t<double> about(k);
    py::ssize_t i = 0;
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        const combine::HeadMounting& hm = m.mountings.head[h];
        if (!hm.present) {
            continue;
        }
        double* row = q.mutable_data() + 4 * i;
        row[0] = hm.q_chu_crf.w;
        row[1] = hm.q_chu_crf.x;
        row[2] = hm.q_chu_crf.y;
        row[3] = hm.q_chu_crf.z;
        cross.mutable_data()[i] = hm.sigma_cross_arcsec;
        about.mutable_data()[i] = hm.sigma_about_arcsec;
        ++i;
    }
    py::dict d;
    d["heads"] = heads;
    d["q"] = q;
    d["sigma_cross"] = m.sigmas ? py::object(cross) : py::object(py::none());
    d["sigma_about"] = m.sigmas ? py::object(about) : py::object(py::none());
    return d;
}

py::dict combined_dict(const std::vector<host::AttitudeRow>& out, bool covariance) {
    const auto n = static_cast<py::ssize_t>(out.size());
    py::array_t<double> ta(n);
    py::array_t<double> qa({n, py::ssize_t{4}});
    py::array_t<double> sa({n, py::ssize_t{3}});
    py::array_t<std::uint8_t> st(n);
    py::array_t<double> ca({n, py::ssize_t{3}});
    py::list heads;
    for (py::ssize_t i = 0; i < n; ++i) {
        const host::AttitudeRow& r = out[static_cast<std::size_t>(i)];
        ta.mutable_data()[i] = r.t;
        double* qq = qa.mutable_data() + 4 * i;
        double* ss = sa.mutable_data() + 3 * i;
        qq[0] = r.has_q ? r.q_crf_icrf.w : kNaN;
        qq[1] = r.has_q ? r.q_crf_icrf.x : kNaN;
        qq[2] = r.has_q ? r.q_crf_icrf.y : kNaN;
        qq[3] = r.has_q ? r.q_crf_icrf.z : kNaN;
        double* cc = ca.mutable_data() + 3 * i;
        for (std::size_t a = 0; a < 3; ++a) {
            ss[a] = r.has_q ? r.sigma_arcsec[a] : kNaN;
            cc[a] = r.has_cov ? r.cov_arcsec2[a] : kNaN;
        }
        heads.append(host::head_letters(r.heads));
        st.mutable_data()[i] = static_cast<std::uint8_t>(r.status);
    }
    py::dict d;
    d["t"] = ta;
    d["q"] = qa;
    d["heads"] = py::module_::import("numpy").attr("array")(heads, "dtype"_a = "U" + std::to_string(kMaxHeads));
    d["sigma"] = sa;
    d["status"] = st;
    if (covariance) {
        d["cov"] = ca;
    }
    return d;
}

namespace {

// The combination of `ascorr combine`, kept in memory: its rows as the
// combined file reads back (q to 15 decimals), so the numbers are the
// command line's to the digit, with no file (and no TMPDIR) at all.
py::dict combine_arrays(const py::object& t, const py::object& chu, const py::object& q, const py::object& mountings,
                        const py::object& status, const py::object& flags, const py::object& confidence,
                        const py::object& gate_sigmas, const py::object& gate_floor, bool covariance) {
    const host::MountingsFile m = mountings_arg(mountings);
    const host::CombinedColumns columns{covariance};
    const host::GateOptions gate = gate_arg(gate_sigmas, gate_floor);
    try {
        host::refuse_unusable_mountings(m, "argument 'mountings'", gate);
    } catch (const std::runtime_error& e) {
        throw py::value_error(e.what());
    }
    const CombineRows rows = combine_rows(t, chu, q, status, flags, confidence);
    std::ostringstream log;
    std::vector<host::AttitudeRow> out;
    {
        py::gil_scoped_release unlocked;  // the rows are C++ data by now
        host::CombineStage stage(m, gate, out, kArrayRows, log, columns);
        rows_source(rows)([&stage](const host::CorrectedRow& r) { stage.add(r); });
        stage.finish();
    }
    warn(log.str());
    return combined_dict(out, covariance);
}

py::dict report_dict(const host::AlignReport& r) {
    const auto k = static_cast<py::ssize_t>(head_count(r.heads));
    py::array_t<double> rot({k, py::ssize_t{3}});
    py::array_t<double> rot_sd({k, py::ssize_t{3}});
    py::array_t<double> sc(k);
    py::array_t<double> sc_sd(k);
    py::array_t<double> sa(k);
    py::array_t<double> sa_sd(k);
    py::array_t<std::int64_t> epochs(k);
    py::ssize_t i = 0;
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        if (!has_head(r.heads, h)) {
            continue;
        }
        const host::HeadAlignment& a = r.head[h];
        for (Eigen::Index ax = 0; ax < 3; ++ax) {
            rot.mutable_data()[3 * i + ax] = a.rotation_arcsec(ax);
            rot_sd.mutable_data()[3 * i + ax] = a.rotation_sd_arcsec(ax);
        }
        sc.mutable_data()[i] = a.noise.sigma_cross_arcsec;
        sc_sd.mutable_data()[i] = a.noise.sd_cross_arcsec;
        sa.mutable_data()[i] = a.noise.sigma_about_arcsec;
        sa_sd.mutable_data()[i] = a.noise.sd_about_arcsec;
        epochs.mutable_data()[i] = static_cast<std::int64_t>(a.epochs);
        ++i;
    }
    py::dict left_out;
    for (std::size_t w = 1; w < host::kLeftOutKinds; ++w) {
        left_out[host::left_out_name(static_cast<host::LeftOut>(w))] = r.rows_left_out[w];
    }
    py::dict d;
    d["heads"] = host::head_letters(r.heads);
    d["rotation"] = rot;
    d["rotation_sd"] = rot_sd;
    d["sigma_cross"] = sc;
    d["sd_cross"] = sc_sd;
    d["sigma_about"] = sa;
    d["sd_about"] = sa_sd;
    d["epochs"] = epochs;
    d["rows"] = r.rows;
    d["rows_in_period"] = r.rows_in_period;
    d["left_out"] = left_out;
    d["period_epochs"] = r.epochs;
    d["joint_epochs"] = r.joint_epochs;
    d["single_epochs"] = r.single_epochs;
    d["noise_model"] = r.noise.model == host::NoiseModel::kEqualCross ? "equal_cross" : "per_head";
    d["noise_window"] = r.noise_window_s;
    d["dof"] = r.noise.dof;
    d["iterations"] = r.noise.iterations;
    d["passes"] = r.passes;
    d["last_update"] = r.last_update_arcsec;
    d["weighted_mean"] =
        py::make_tuple(r.weighted_mean_arcsec.x(), r.weighted_mean_arcsec.y(), r.weighted_mean_arcsec.z());
    d["text"] = host::describe(r);
    return d;
}

py::tuple align_arrays(const py::object& t, const py::object& chu, const py::object& q, const py::object& mountings,
                       const py::object& status, const py::object& flags, const py::object& confidence,
                       const py::object& t_from, const py::object& t_to, const py::object& noise_window,
                       const py::object& min_epochs, const py::object& gate_sigmas, const py::object& gate_floor) {
    const host::MountingsFile m = mountings_arg(mountings);
    host::AlignOptions opt;
    opt.in = kArrayRows;
    opt.from = time_arg(t_from, "t_from");
    opt.to = time_arg(t_to, "t_to");
    host::refuse_bad_time_range(opt.from, opt.to, "t_from", "t_to");  // as `ascorr align`: an empty period is refused
    opt.noise_window_s = real_arg(noise_window, "noise_window");
    if (!host::noise_window_valid(opt.noise_window_s)) {
        bad_argument("noise_window", "expected 0 or a window in [" + host::number_text(host::kMinNoiseWindowS) + ", " +
                                         host::number_text(host::kMaxNoiseWindowS) + "] s, got " +
                                         value_text(noise_window));
    }
    opt.gate = gate_arg(gate_sigmas, gate_floor);
    opt.min_epochs = count_arg(min_epochs, "min_epochs");
    if (opt.min_epochs < 2) {
        bad_argument("min_epochs", "expected 2 or more, got " + value_text(min_epochs));
    }
    const CombineRows rows = combine_rows(t, chu, q, status, flags, confidence);
    std::optional<host::AlignReport> r;
    {
        py::gil_scoped_release unlocked;  // the rows are C++ data by now
        r = host::align_rows(rows_source(rows), kArrayRows, m, opt);
    }
    return py::make_tuple(mountings_dict(r->aligned), report_dict(*r));
}

}  // namespace

// The dict back, checked by the mountings file's own reader (the same rules
// and messages, with the argument's name for the file's).
host::MountingsFile mountings_arg(const py::handle& obj) {
    if (!py::isinstance<py::dict>(obj)) {
        bad_argument("mountings",
                     "expected a dict {'heads', 'q', 'sigma_cross', 'sigma_about'} (read_mountings()), "
                     "got " +
                         value_text(obj));
    }
    const py::dict d = py::reinterpret_borrow<py::dict>(obj);
    for (const char* key : {"heads", "q", "sigma_cross", "sigma_about"}) {
        if (!d.contains(key)) {
            bad_argument("mountings", std::string("the dict has no '") + key + "' (as read_mountings() returns it)");
        }
    }
    const HeadMask heads = heads_arg(d["heads"], "mountings['heads']", 1, kMaxHeads);
    const auto k = static_cast<py::ssize_t>(head_count(heads));
    const Doubles q = real_array(d["q"], "mountings['q']", k, 4);
    const bool sigmas = !d["sigma_cross"].is_none() || !d["sigma_about"].is_none();
    Doubles cross;
    Doubles about;
    if (sigmas) {
        cross = real_array(d["sigma_cross"], "mountings['sigma_cross']", k, 0);
        about = real_array(d["sigma_about"], "mountings['sigma_about']", k, 0);
    }
    host::MountingsFile m;
    m.sigmas = sigmas;
    py::ssize_t i = 0;
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        if (!has_head(heads, h)) {
            continue;
        }
        combine::HeadMounting& hm = m.mountings.head[h];
        hm.present = true;
        const double* row = q.data() + 4 * i;
        hm.q_chu_crf = {row[0], row[1], row[2], row[3]};
        hm.sigma_cross_arcsec = sigmas ? cross.data()[i] : kNaN;
        hm.sigma_about_arcsec = sigmas ? about.data()[i] : kNaN;
        ++i;
    }
    // The file's text reads back to exactly these values (shortest round trip).
    try {
        return host::parse_mountings("argument 'mountings' (as a mountings file)", host::format_mountings(m));
    } catch (const text::InputError& e) {
        throw py::value_error(e.what());
    }
}

void bind_combine(py::module_& mod) {
    py::register_exception<host::AlignRefused>(mod, "AlignRefused", PyExc_ValueError).attr("__doc__") =
        docs::kAlignRefused;
    mod.def(
        "read_mountings",
        [](const py::object& path) { return mountings_dict(host::read_mountings_file(path_arg(path, "path"))); },
        "path"_a, docstring(docs::kReadMountings));
    mod.def("combine", &combine_arrays, "t"_a, "chu"_a, "q"_a, "mountings"_a, "status"_a = py::none(),
            "flags"_a = py::none(), "confidence"_a = py::none(), "gate_sigmas"_a = py::none(),
            "gate_floor"_a = py::none(), "covariance"_a = false, docstring(docs::kCombine));
    mod.def("align", &align_arrays, "t"_a, "chu"_a, "q"_a, "mountings"_a, "status"_a = py::none(),
            "flags"_a = py::none(), "confidence"_a = py::none(), "t_from"_a = py::none(), "t_to"_a = py::none(),
            "noise_window"_a = host::kDefaultNoiseWindowS, "min_epochs"_a = host::kMinAlignEpochs,
            "gate_sigmas"_a = py::none(), "gate_floor"_a = py::none(), docstring(docs::kAlign));
}

}  // namespace ascorr::python
