#include "ascorr_host/analysis/plot.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "ascorr/core/rotation_vector.hpp"
#include "ascorr_host/analysis/combined_stats.hpp"
#include "ascorr_host/analysis/epochs.hpp"
#include "ascorr_host/analysis/stats.hpp"
#include "ascorr_host/formats/atomic_file.hpp"
#include "ascorr_host/formats/combined_csv.hpp"
#include "ascorr_host/formats/csv.hpp"
#include "ascorr_text/c_format.hpp"
#include "ascorr_text/input_name.hpp"

extern char** environ;

namespace ascorr::host {

namespace {

// J2000.0 (TT) as Unix time: 2000-01-01T11:58:55.816 UTC. Plot labels only.
constexpr double kJ2000Unix = 946727935.816;

int run_gnuplot(const std::string& exe, const std::string& script, const std::string& log_path) {
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, STDOUT_FILENO, log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
    posix_spawn_file_actions_adddup2(&fa, STDOUT_FILENO, STDERR_FILENO);
    std::vector<char*> argv{const_cast<char*>(exe.c_str()), const_cast<char*>(script.c_str()), nullptr};
    pid_t pid = 0;
    int slot = -1;
    {
        // Started and registered with the cleanup signals held: a signal in
        // between still finds gnuplot to kill (gnuplot runs with our mask).
        const CleanupSignalsHeld held;
        posix_spawnattr_t attr;
        posix_spawnattr_init(&attr);
        posix_spawnattr_setsigmask(&attr, &held.previous());
        posix_spawnattr_setflags(&attr, POSIX_SPAWN_SETSIGMASK);
        const int rc = posix_spawnp(&pid, exe.c_str(), &fa, &attr, argv.data(), environ);
        posix_spawnattr_destroy(&attr);
        posix_spawn_file_actions_destroy(&fa);
        if (rc != 0) {
            return -1;
        }
        slot = cleanup_register_child(pid);  // killed, should a signal end us
    }
    int st = 0;
    const pid_t waited = waitpid(pid, &st, 0);
    cleanup_release(slot);
    if (waited != pid) {
        return -1;
    }
    return WIFEXITED(st) ? WEXITSTATUS(st) : -1;
}

// The plot's working folder. Removed with its files on return, on an
// exception and on a signal: the folder and every file name used in it are in
// the signal-cleanup table (atomic_file.hpp) while it exists.
class TempDir {
public:
    TempDir() {
        std::string tmpl = (std::filesystem::temp_directory_path() / "ascorr-plot-XXXXXX").string();
        if (::mkdtemp(tmpl.data()) == nullptr) {
            throw std::runtime_error("cannot create a temporary directory for the plot");
        }
        path_ = tmpl;
        slots_.push_back(cleanup_register_folder(tmpl));
    }
    ~TempDir() {
        std::error_code ec;
        std::filesystem::remove_all(path_, ec);
        release();
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;
    const std::filesystem::path& path() const { return path_; }
    // A file in the folder, registered for removal on a signal.
    std::filesystem::path file(const std::string& name) {
        const std::filesystem::path p = path_ / name;
        for (const auto& known : files_) {
            if (known == p) {
                return p;
            }
        }
        slots_.push_back(cleanup_register_file(p.string()));
        files_.push_back(p);
        return p;
    }

private:
    void release() noexcept {
        for (const int s : slots_) {
            cleanup_release(s);
        }
        slots_.clear();
    }
    std::filesystem::path path_;
    std::vector<std::filesystem::path> files_;
    std::vector<int> slots_;
};

std::string read_all(const std::filesystem::path& p) {
    std::ifstream f(p, std::ios::binary);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
}

// Means over kPlotBinS bins of each stage's IBA about its mean.
void write_binned(std::ofstream& f, const PairSeries& s, const double (&mean)[kStages]) {
    std::size_t i = 0;
    while (i < s.t.size()) {
        const double bin = std::floor(s.t[i] / kPlotBinS);
        double sum_t = 0.0;
        double sum[kStages] = {};
        std::size_t n = 0;
        for (; i < s.t.size() && std::floor(s.t[i] / kPlotBinS) == bin; ++i, ++n) {
            sum_t += s.t[i] - s.t[0];
            for (std::size_t k = 0; k < kStages; ++k) {
                sum[k] += s.iba[k][i] - mean[k];
            }
        }
        const double dn = static_cast<double>(n);
        f.precision(12);
        f << s.t[0] + sum_t / dn + kJ2000Unix;
        for (std::size_t k = 0; k < kStages; ++k) {
            f << ' ' << sum[k] / dn;
        }
        f << '\n';
    }
}

// Each epoch's running mean over kSmoothingWindowS (|t_j − t_i| ≤ half of it,
// as rms_about_mean) of each stage's IBA about its mean.
void write_smoothed(std::ofstream& f, const PairSeries& s, const double (&mean)[kStages]) {
    f.precision(12);
    std::size_t lo = 0;
    std::size_t hi = 0;
    double sum[kStages] = {};
    const double half = 0.5 * kSmoothingWindowS;
    for (std::size_t i = 0; i < s.t.size(); ++i) {
        while (hi < s.t.size() && s.t[hi] <= s.t[i] + half) {
            for (std::size_t k = 0; k < kStages; ++k) {
                sum[k] += s.iba[k][hi] - mean[k];
            }
            ++hi;
        }
        while (s.t[lo] < s.t[i] - half) {
            for (std::size_t k = 0; k < kStages; ++k) {
                sum[k] -= s.iba[k][lo] - mean[k];
            }
            ++lo;
        }
        f << s.t[i] + kJ2000Unix;
        for (std::size_t k = 0; k < kStages; ++k) {
            f << ' ' << sum[k] / static_cast<double>(hi - lo);
        }
        f << '\n';
    }
}

// Text for a single-quoted gnuplot string ('' is one quote).
std::string gnuplot_quoted(const std::string& text) {
    std::string out;
    for (const char c : text) {
        out += c;
        if (c == '\'') {
            out += '\'';
        }
    }
    return out;
}

void check_window(const PlotOptions& opt) {
    if (!(opt.window_from && opt.window_to)) {
        throw std::runtime_error("a plot window needs both --window-from and --window-to");
    }
    if (!(std::isfinite(*opt.window_from) && std::isfinite(*opt.window_to) && *opt.window_from < *opt.window_to)) {
        throw std::runtime_error("the plot window is empty: --window-from " + number_text(*opt.window_from) +
                                 " is not before --window-to " + number_text(*opt.window_to));
    }
}

// A pair without clean epochs gets an empty panel that says why
// (compute_stats has logged it); with none at all there is nothing to plot.
void refuse_nothing_to_plot(const PlotOptions& opt, const StatsResult& st, bool window, std::ostream& log) {
    const PairList& pairs = st.pairs;  // a panel per pair of the file's heads
    std::string why_nothing;
    bool any_epoch = false;
    for (std::size_t p = 0; p < pairs.count; ++p) {
        why_nothing += std::string(p ? "\n" : "") + "no clean epoch for pair " + pairs.pair[p].name +
                       (window ? " in the window" : "") + ": " + st.no_epochs_reason[p];
        any_epoch = any_epoch || st.n[p] != 0;
    }
    if (!any_epoch) {
        throw std::runtime_error(text::input_name(opt.in) + ": nothing to plot:\n" + why_nothing);
    }
    for (std::size_t p = 0; p < pairs.count; ++p) {
        if (st.n[p] == 0) {
            log << text::input_name(opt.in) << ": pair " << pairs.pair[p].name
                << ": no clean epochs: " << st.no_epochs_reason[p] << '\n';
        }
    }
}

// Each pair's series about its means into pair<p>.dat (smoothed in a window,
// binned otherwise); t_lo and t_hi widened to the series' times.
void write_pair_data(const StatsResult& st, TempDir& dir, bool window, double& t_lo, double& t_hi) {
    for (std::size_t p = 0; p < st.pairs.count; ++p) {
        const PairSeries& s = st.series[p];
        if (s.t.empty()) {
            continue;
        }
        t_lo = std::min(t_lo, s.t.front());
        t_hi = std::max(t_hi, s.t.back());
        double mean[kStages] = {};
        for (std::size_t k = 0; k < kStages; ++k) {
            for (double v : s.iba[k]) {
                mean[k] += v;
            }
            mean[k] /= static_cast<double>(s.t.size());
        }
        std::ofstream f(dir.file(("pair" + std::to_string(p) + ".dat")));
        if (window) {
            write_smoothed(f, s, mean);
        } else {
            write_binned(f, s, mean);
        }
        if (!f) {
            throw std::runtime_error("cannot write plot data in " + dir.path().string());
        }
    }
}

// What the IBA plot's gnuplot script draws.
struct IbaScript {
    const PlotOptions& opt;
    const StatsResult& st;
    TempDir& dir;
    const std::filesystem::path& png;
    const std::filesystem::path& temps;
    bool window;
    std::size_t rows;
    double t_lo;
    double t_hi;
};

void write_script_head(std::ostream& g, const IbaScript& s, const char* terminal) {
    const PlotOptions& opt = s.opt;
    g << "set terminal " << terminal << " size " << opt.width << "," << opt.width * 2 / 7 * static_cast<int>(s.rows)
      << (opt.width < 1000 ? " font ',8'" : "") << "\n";
    g << "set output '" << s.png.string() << "'\nset termoption noenhanced\n";
    if (s.window) {
        g << "set multiplot layout " << s.rows << ",1 title 'Inter-boresight angles, " << kSmoothingWindowS
          << " s running means (RMS of the IBA and of its running mean in the legend)'\n";
    } else {
        g << "set multiplot layout " << s.rows << ",1 title 'Inter-boresight angles, " << kPlotBinS / 60.0
          << "-minute means (RMS of the unbinned IBA in the legend)'\n";
    }
    g << "set xdata time\nset timefmt '%s'\nset format x \"" << (s.window ? "%m-%d\\n%H:%M" : "%Y-%m")
      << "\"\nset grid\nset key outside right top\nset datafile missing 'NaN'\n";
    g << "set xrange ['" << s.t_lo + kJ2000Unix << "':'" << s.t_hi + kJ2000Unix << "']\n";
    g << "set lmargin 10\nset rmargin 42\n";  // the panels' time axes aligned
    g << "set ylabel 'IBA - mean (arcsec)'\n";
    if (opt.period_from && opt.period_to) {
        g.precision(12);
        g << "set object 1 rect from " << *opt.period_from + kJ2000Unix << ", graph 0 to "
          << *opt.period_to + kJ2000Unix << ", graph 1 fc rgb '#e6e6e6' fs solid 1.0 noborder behind\n";
        g << "set label 1 'modelling period' at " << *opt.period_from + kJ2000Unix << ", graph 0.95 offset 1,0 front\n";
    }
}

// Pair p's panel: its stages' series, or an empty panel with the reason.
void write_pair_panel(std::ostream& g, const IbaScript& s, std::size_t p) {
    const StatsResult& st = s.st;
    const char* colours[kStages] = {"#1f77b4", "#d62728", "#2ca02c"};
    if (st.n[p] == 0) {  // an empty panel with the reason in it
        g << "set title 'pair " << st.pairs.pair[p].name << ": no clean epochs'\n";
        g << "set label 99 '" << gnuplot_quoted(st.no_epochs_reason[p])
          << "' at graph 0.5, graph 0.5 center\nset yrange [-1:1]\nplot 2 notitle\n";
        g << "unset label 99\nset autoscale y\n";
        return;
    }
    g << "set title 'pair " << st.pairs.pair[p].name << " (" << st.n[p] << " clean epochs)'\n";
    g << "plot ";
    for (std::size_t k = 0; k < kStages; ++k) {
        if (k == 2 && !st.thermal) {
            break;
        }
        char t[96];
        if (s.window) {
            text::c_snprintf(t, sizeof t, "%s, RMS %.2f\" (200 s: %.2f\")", kStageNames[k], st.rms[p][k].rms,
                             st.rms[p][k].rms_smoothed);
        } else {
            text::c_snprintf(t, sizeof t, "%s, RMS %.2f\"", kStageNames[k], st.rms[p][k].rms);
        }
        g << (k ? ", " : "") << "'" << (s.dir.file(("pair" + std::to_string(p) + ".dat"))).string()
          << "' using 1:" << k + 2
          << (st.series[p].t.front() < st.series[p].t.back() ? " with lines" : " with points pt 7")
          << " lw 1.5 lc rgb '" << colours[k] << "' title '" << t << "'";
    }
    g << '\n';
}

// The two temperature panels: T_CHU of each head, the boom thermistors.
void write_temperature_panels(std::ostream& g, const IbaScript& s) {
    const std::string f = "'" + s.temps.string() + "'";
    g << "set ylabel 'temperature (degC)'\n";
    g << "set title 'T_CHU (T1) of each head'\n";
    const HeadList heads = heads_of(s.st.heads);  // columns: t, T_CHU by head index, T029, T032
    g << "plot ";
    for (std::size_t i = 0; i < heads.count; ++i) {
        g << (i ? ", " : "") << f << " using 1:" << 2 + heads.head[i] << " with lines lw 1.5 title 'T_CHU "
          << head_name(heads.head[i]) << "'";
    }
    g << "\nset title 'boom thermistors: THT00029 (T2, OB-boom interface) and THT00032 (T3, on the OB)'\n";
    g << "plot " << f << " using 1:" << 2 + kMaxHeads << " with lines lw 1.5 title 'T029', " << f
      << " using 1:" << 3 + kMaxHeads << " with lines lw 1.5 title 'T032'\n";
}

// The gnuplot script plot.gp for `terminal`.
void write_iba_script(const IbaScript& s, const char* terminal) {
    std::ofstream g(s.dir.file("plot.gp"));
    g.precision(12);
    write_script_head(g, s, terminal);
    for (std::size_t p = 0; p < s.st.pairs.count; ++p) {
        write_pair_panel(g, s, p);
    }
    if (s.opt.temperatures) {
        write_temperature_panels(g, s);
    }
    g << "unset multiplot\n";
}

}  // namespace

void plot_iba(const PlotOptions& opt, std::ostream& log) {
    OutputSet outputs({{"--out", opt.out}}, {{"--in", opt.in}, {"--model", opt.model}});
    plot_iba(opt, outputs, log);
    outputs.commit();
}

void plot_iba(const PlotOptions& opt, OutputSet& outputs, std::ostream& log) {
    refuse_output_over_input({{"--in", opt.in}, {"--model", opt.model}}, {{"--out", opt.out}});
    refuse_bad_time_range(opt.period_from, opt.period_to);
    StatsOptions so;
    so.in = opt.in;
    so.model = opt.model;
    so.keep_series = true;
    so.log_empty_pairs = false;  // said once, below
    if (!(opt.width >= 400 && opt.width <= 4000)) {
        throw std::runtime_error("--width must be in [400, 4000] pixels, got " + std::to_string(opt.width));
    }
    const bool window = opt.window_from.has_value() || opt.window_to.has_value();
    if (window) {
        check_window(opt);
        so.from = opt.window_from;
        so.to = opt.window_to;
        so.period_options = "--window-from/--window-to";
    }
    const StatsResult st = compute_stats(so, log);
    refuse_nothing_to_plot(opt, st, window, log);

    TempDir dir;
    double t_lo = std::numeric_limits<double>::infinity();
    double t_hi = -std::numeric_limits<double>::infinity();
    write_pair_data(st, dir, window, t_lo, t_hi);

    // A single epoch (or several at one time) is drawn as a point on a time
    // axis one smoothing window wide: gnuplot cannot scale an empty x range.
    const bool one_time = !(t_hi > t_lo);
    if (one_time) {
        t_lo -= kSmoothingWindowS / 2.0;
        t_hi += kSmoothingWindowS / 2.0;
    }

    const std::filesystem::path temps = dir.file("temperatures.dat");
    if (opt.temperatures) {
        write_temperature_series(opt.in, temps.string(), window ? kSmoothingWindowS : kPlotBinS, so.from, so.to,
                                 kJ2000Unix);
    }
    const std::size_t rows = st.pairs.count + (opt.temperatures ? 2 : 0);

    const std::filesystem::path png = dir.file("plot.png");
    const IbaScript script{opt, st, dir, png, temps, window, rows, t_lo, t_hi};
    const std::string gp_log = (dir.file("gnuplot.log")).string();
    write_iba_script(script, "pngcairo");
    int rc = run_gnuplot(opt.gnuplot, (dir.file("plot.gp")).string(), gp_log);
    if (rc == -1) {
        throw std::runtime_error("cannot run '" + opt.gnuplot + "' (Debian package gnuplot-nox)");
    }
    if (rc != 0 || !std::filesystem::exists(png)) {
        write_iba_script(script, "png");  // a gnuplot built without cairo
        rc = run_gnuplot(opt.gnuplot, (dir.file("plot.gp")).string(), gp_log);
    }
    if (rc != 0 || !std::filesystem::exists(png)) {
        throw std::runtime_error("gnuplot failed (exit " + std::to_string(rc) + "):\n" + read_all(gp_log));
    }
    // Whole or absent, through links, into streams (OutputSet).
    outputs["--out"].write(read_all(png));
}

namespace {

// Runs the script `write_script(terminal)` wrote into dir, pngcairo first, then
// png (a gnuplot built without cairo); the PNG into out (committed by the caller).
template <typename WriteScript>
void draw(TempDir& dir, const std::string& gnuplot, const std::filesystem::path& png, AtomicFile& out,
          const WriteScript& write_script) {
    const std::string gp_log = (dir.file("gnuplot.log")).string();
    write_script("pngcairo");
    int rc = run_gnuplot(gnuplot, (dir.file("plot.gp")).string(), gp_log);
    if (rc == -1) {
        throw std::runtime_error("cannot run '" + gnuplot + "' (Debian package gnuplot-nox)");
    }
    if (rc != 0 || !std::filesystem::exists(png)) {
        write_script("png");
        rc = run_gnuplot(gnuplot, (dir.file("plot.gp")).string(), gp_log);
    }
    if (rc != 0 || !std::filesystem::exists(png)) {
        throw std::runtime_error("gnuplot failed (exit " + std::to_string(rc) + "):\n" + read_all(gp_log));
    }
    out.write(read_all(png));
}

void refuse_bad_window(const CombinedPlotOptions& opt) {
    if (!(opt.from < opt.to)) {
        throw std::runtime_error("the plot window is empty: --window-from " + number_text(opt.from) +
                                 " is not before --window-to " + number_text(opt.to));
    }
    if (!(opt.width >= 400 && opt.width <= 4000)) {
        throw std::runtime_error("--width must be in [400, 4000] pixels, got " + std::to_string(opt.width));
    }
}

// Whether a combined row is drawn: in the window, with an attitude.
bool drawn(const CombinedPlotOptions& opt, const AttitudeRow& row) {
    return row.t >= opt.from && row.t <= opt.to && row.has_q;
}

double max_abs(const std::array<double, 3>& e) {
    double m = 0.0;
    for (const double v : e) {
        m = std::max(m, std::fabs(v));
    }
    return m;
}

// The truth of the window, by epoch key (a few days: a few thousand rows).
std::map<std::int64_t, Quaternion<double>> truth_in_window(const CombinedPlotOptions& opt) {
    std::map<std::int64_t, Quaternion<double>> truth;
    TruthReader r(opt.truth);  // stats --combined's rules for a truth
    AttitudeRow row;
    while (r.next(row)) {
        if (row.t >= opt.from && row.t <= opt.to) {
            truth[epoch_key(row.t)] = row.q_crf_icrf;
        }
    }
    return truth;
}

}  // namespace

void plot_combined(const CombinedPlotOptions& opt, std::ostream& log) {
    OutputSet outputs({{"--out", opt.out}}, {{"--combined", opt.combined}, {"--truth-attitude", opt.truth}});
    plot_combined(opt, outputs, log);
    outputs.commit();
}

void plot_combined(const CombinedPlotOptions& opt, OutputSet& outputs, std::ostream& log) {
    refuse_output_over_input({{"--combined", opt.combined}, {"--truth-attitude", opt.truth}}, {{"--out", opt.out}});
    refuse_bad_window(opt);
    const std::map<std::int64_t, Quaternion<double>> truth = truth_in_window(opt);
    TempDir dir;
    const std::filesystem::path data = dir.file("combined.dat");
    std::ofstream f(data);
    f.precision(12);
    std::map<HeadMask, std::size_t> sets;  // head set -> epochs in the window
    HeadMask full = 0;
    double y_max = 0.0;
    std::size_t without_truth = 0;
    double step = std::numeric_limits<double>::infinity();  // the shading's box width
    double t_previous = std::nan("");
    AttitudeReader r(opt.combined);
    if (!r.combined()) {
        throw text::InputError(opt.combined, 1, 1, "expected a combined file (t,qw,qx,qy,qz,heads,...)");
    }
    AttitudeRow row;
    while (r.next(row)) {
        if (!drawn(opt, row)) {
            continue;
        }
        const auto it = truth.find(epoch_key(row.t));
        if (it == truth.end()) {
            ++without_truth;
            continue;
        }
        const Vector3<double> v = rotation_vector_arcsec(row.q_crf_icrf, it->second);
        const std::array<double, 3> e{v.x, v.y, v.z};
        step = row.t > t_previous ? std::min(step, row.t - t_previous) : step;
        t_previous = row.t;
        f << row.t + kJ2000Unix << ' ' << e[0] << ' ' << e[1] << ' ' << e[2] << ' ' << unsigned{row.heads} << '\n';
        ++sets[row.heads];
        full = head_count(row.heads) > head_count(full) ? row.heads : full;
        y_max = std::max(y_max, max_abs(e));
    }
    f.close();
    if (sets.empty()) {
        throw std::runtime_error(text::input_name(opt.combined) +
                                 ": nothing to plot: no combined epoch with a truth row in the window");
    }
    if (without_truth != 0) {
        log << text::input_name(opt.combined) << ": " << without_truth << " epochs without a truth row, not drawn\n";
    }
    y_max = std::max(1.0, std::ceil(y_max * 1.05));
    const double half = std::isfinite(step) ? step / 2.0 : 30.0;
    const std::filesystem::path png = dir.file("plot.png");
    const auto write_script = [&](const char* terminal) {
        std::ofstream g(dir.file("plot.gp"));
        g.precision(12);
        // Three panels of at least 280 pixels; a narrow figure in a smaller font.
        const bool narrow = opt.width < 1000;
        g << "set terminal " << terminal << " size " << opt.width << "," << std::max(opt.width * 6 / 7, 840)
          << (narrow ? " font ',8'" : "") << "\n";
        g << "set output '" << png.string() << "'\nset termoption noenhanced\n";
        g << "set multiplot layout 3,1 title 'Combined attitude minus truth, coloured by head set (grey: not "
          << head_set_name(full) << ")'\n";
        g << "set xdata time\nset timefmt '%s'\nset format x \"%m-%d\\n%H:%M\"\nset grid\n";
        g << "set key outside right top vertical maxrows " << sets.size() << " samplen 1\n";
        g << "set xrange ['" << opt.from + kJ2000Unix << "':'" << opt.to + kJ2000Unix << "']\n";
        g << "set yrange [" << -y_max << ":" << y_max << "]\nset lmargin 10\nset rmargin " << (narrow ? 16 : 24)
          << "\n";
        g << "set style fill solid 0.5 noborder\n";
        const char* axes[3] = {"x", "y", "z"};
        for (int a = 0; a < 3; ++a) {
            g << "set title 'about CRF " << axes[a] << "'\nset ylabel 'error (arcsec)'\n";
            // The shading: a box per epoch without the full set, the epoch's step wide.
            g << "plot '" << data.string() << "' using 1:(0):($1-" << half << "):($1+" << half
              << "):($5 != " << unsigned{full} << " ? " << -y_max << " : 1/0):($5 != " << unsigned{full} << " ? "
              << y_max << " : 1/0) with boxxyerror lc rgb '#d0d0d0' notitle";
            for (const auto& [set, n] : sets) {
                g << ", '" << data.string() << "' using 1:($5 == " << unsigned{set} << " ? $" << 2 + a
                  << " : 1/0) with points pt 7 ps 0.3 title '" << head_set_name(set) << " (" << n << ")'";
            }
            g << "\n";
        }
        g << "unset multiplot\n";
    };
    draw(dir, opt.gnuplot, png, outputs["--out"], write_script);
}

}  // namespace ascorr::host
