#include "ascorr_host/formats/gracefo.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string_view>

#include "ascorr/core/heads.hpp"
#include "ascorr/core/scalar_traits.hpp"
#include "ascorr_host/formats/combined_csv.hpp"
#include "ascorr_host/formats/csv.hpp"
#include "ascorr_text/c_format.hpp"
#include "ascorr_text/input_error.hpp"

namespace ascorr::host {

namespace {

constexpr std::string_view kYamlEnd = "# End of YAML header";
constexpr std::string_view kFixedEnd = "END OF HEADER";

// One record of a Level-1 file: its whitespace-separated fields.
struct Record {
    const std::string* file;
    std::size_t line;
    std::vector<std::string_view> field;
    std::vector<std::size_t> start;  // 0-based column of each field

    [[noreturn]] void fail(std::size_t i, const std::string& what) const {
        throw text::InputError(*file, line, (i < start.size() ? start[i] : 0) + 1, what);
    }
    long long integer(std::size_t i, const char* name, long long lo, long long hi) const {
        const auto v = parse_integer(field[i]);
        if (!v || *v < lo || *v > hi) {
            fail(i, std::string(name) + ": " + why_not_an_integer(field[i], lo, hi));
        }
        return *v;
    }
    double number(std::size_t i, const char* name) const {
        const auto v = parse_double(field[i]);
        if (!v || !std::isfinite(*v)) {
            fail(i, std::string(name) + ": " +
                        (v ? "a finite number, got " + number_text(*v) : why_not_a_number(field[i])));
        }
        return *v;
    }
    // Eight binary digits, bit 0 rightmost.
    std::uint8_t flag_byte(std::size_t i, const char* name) const {
        const std::string_view f = field[i];
        unsigned v = 0;
        bool ok = f.size() == 8;
        for (const char c : f) {
            ok = ok && (c == '0' || c == '1');
            v = (v << 1U) | (c == '1' ? 1U : 0U);
        }
        if (!ok) {
            fail(i,
                 std::string(name) + ": expected eight binary digits (bit 0 rightmost), got '" + std::string(f) + "'");
        }
        return static_cast<std::uint8_t>(v);
    }
    char satellite(std::size_t i) const {
        if (field[i] != "C" && field[i] != "D") {
            fail(i, "GRACEFO_id: expected C or D, got '" + std::string(field[i]) + "'");
        }
        return field[i][0];
    }
    Quaternion<double> quaternion(std::size_t i) const {
        const Quaternion<double> q{number(i, "qw"), number(i + 1, "qx"), number(i + 2, "qy"), number(i + 3, "qz")};
        if (!norm_within(q, ScalarTraits<double>::unit_norm_tolerance)) {
            fail(i, "the quaternion is not unit (|q|^2 = " + number_text(squared_norm(q)) + ")");
        }
        return q;
    }
};

void split_whitespace(std::string_view line, Record& r) {
    r.field.clear();
    r.start.clear();
    std::size_t i = 0;
    while (i < line.size()) {
        while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) {
            ++i;
        }
        const std::size_t b = i;
        while (i < line.size() && line[i] != ' ' && line[i] != '\t') {
            ++i;
        }
        if (i > b) {
            r.field.push_back(line.substr(b, i - b));
            r.start.push_back(b);
        }
    }
}

bool header_end(std::string_view line) {
    while (!line.empty() && (line.back() == ' ' || line.back() == '\r')) {
        line.remove_suffix(1);
    }
    return line == kYamlEnd || line.substr(0, kFixedEnd.size()) == kFixedEnd;
}

// Every record of a Level-1 file with `fields` fields, in file order, in
// blocks, until fn returns false.
void for_each_record(const std::string& path, std::size_t fields, const char* product,
                     const std::function<bool(const Record&)>& fn) {
    BlockReader blocks(path);
    std::string_view block;
    bool in_header = true;
    Record r{&path, 0, {}, {}};
    while (blocks.next(block)) {
        LineReader lines(block, blocks.lines_before());
        std::string_view line;
        while (lines.next(line)) {
            if (in_header) {
                in_header = !header_end(line);
                continue;
            }
            if (!line.empty() && line.back() == '\r') {
                line.remove_suffix(1);
            }
            r.line = lines.line_number();
            split_whitespace(line, r);
            if (r.field.empty()) {
                continue;
            }
            if (r.field.size() != fields) {  // at the first extra field, or the line's end
                throw text::InputError(path, r.line, (r.field.size() > fields ? r.start[fields] : line.size()) + 1,
                                       std::string("expected ") + std::to_string(fields) + " fields of a " + product +
                                           " record, found " + std::to_string(r.field.size()));
            }
            if (!fn(r)) {
                return;
            }
        }
    }
    if (in_header) {
        throw text::InputError::whole_file(path, text::input_name(path) + ": no end of a GRACE-FO Level-1 header ('" +
                                                     std::string(kYamlEnd) + "' or '" + std::string(kFixedEnd) +
                                                     "'): is it a " + product + " file?");
    }
}

Sca1aRecord sca1a_record(const Record& r) {
    Sca1aRecord s;
    s.line = r.line;
    s.obc_s = r.integer(0, "rcvtime_intg", 0, 4000000000LL);
    s.obc_us = r.integer(1, "rcvtime_frac", 0, 999999);
    s.satellite = r.satellite(2);
    s.head = static_cast<std::uint8_t>(r.integer(3, "sca_id (1, 2 or 3)", 1, 3) - 1);
    s.q_icrf_chu = r.quaternion(5);
    r.integer(9, "nlocks", 0, 1000000);
    r.integer(10, "nstars", 0, 1000000);
    s.confidence = static_cast<int>(r.integer(11, "sca_confid", 0, 255));
    s.mode = r.flag_byte(14, "sca_mode");
    s.quality = r.flag_byte(15, "qualflg");
    return s;
}

// qualflg bit 0 is read inverted from sca_mode's: JPL's GRACE Level-1 format
// (GRACEiolib.h: qualflg bit 0, "valid flag", set when invalid) and GROOPS
// (graceL1a2StarCamera drops records with it set) read it so, and every
// record of the public sample has it clear while sca_mode calls it valid; the
// files' YAML header repeats sca_mode's description for qualflg.
long long flags_of(const Sca1aRecord& s) {
    long long f = 0;
    if ((s.mode & 1U) == 0U || (s.quality & 1U) != 0U) {
        f |= kGracefoInvalid;
    }
    if (((s.mode | s.quality) & 4U) != 0U) {
        f |= kGracefoTimeTagShift;
    }
    if (((s.mode | s.quality) & 8U) != 0U) {
        f |= kGracefoFalseStars;
    }
    if ((s.mode & 64U) == 0U) {
        f |= kGracefoNotCorrected;
    }
    return f;
}

void same_satellite(char want, char got, const Record& r, std::size_t i) {
    if (want != 0 && got != want) {
        r.fail(i, std::string("a record of GRACE ") + got + " among those of GRACE " + want +
                      ": import one satellite at a time");
    }
}

MountingsFile read_qsa1b(const std::string& path, char& satellite) {
    MountingsFile m;
    for_each_record(path, 9, "QSA1B", [&](const Record& r) {
        const char sat = r.satellite(1);
        same_satellite(satellite, sat, r, 1);
        satellite = sat;
        const auto h = static_cast<std::uint8_t>(r.integer(2, "sca_id (1, 2 or 3)", 1, 3) - 1);
        if (m.mountings.head[h].present) {
            r.fail(2, "a second mounting of head " + std::string(1, head_name(h)) + " (the first on line " +
                          std::to_string(m.line[h]) + ")");
        }
        m.mountings.head[h].present = true;
        m.mountings.head[h].q_chu_crf = r.quaternion(3);
        m.mountings.head[h].sigma_cross_arcsec = std::nan("");
        m.mountings.head[h].sigma_about_arcsec = std::nan("");
        m.line[h] = r.line;
        return true;
    });
    if (satellite == 0) {
        throw text::InputError::whole_file(path, text::input_name(path) + ": no QSA1B record");
    }
    return m;
}

// The first record's OBC time of an SCA1A file (for the files' order).
double first_obc(const std::string& path) {
    double t = -1.0;
    for_each_record(path, 16, "SCA1A", [&t](const Record& r) {
        const Sca1aRecord s = sca1a_record(r);
        t = static_cast<double>(s.obc_s) + 1e-6 * static_cast<double>(s.obc_us);
        return false;  // the first record is enough
    });
    return t;
}

}  // namespace

namespace {

// One clock record: at the product's own time, the offset to add.
struct ClockPoint {
    double at;
    double offset;
    std::uint8_t flags;
};

// A TIM1B record's mapping, or none: bit 3 "Receiver Time mapping not
// defined", bit 6 "Unable to compute Receiver Time mapping" (the file's header).
constexpr std::uint8_t kTimNoMapping = 8U | 64U;

std::vector<ClockPoint> clock_points(const std::string& path, const char* product, bool tim, char satellite) {
    std::vector<ClockPoint> points;
    double last = -1e300;
    for_each_record(path, 8, product, [&](const Record& r) {
        same_satellite(satellite, r.satellite(1), r, 1);
        ClockPoint p{};
        if (tim) {
            const long long obc = r.integer(0, "obctime", 0, 4000000000LL);
            const long long rcv = r.integer(3, "rcvtime_intg", 0, 4000000000LL);
            const long long ns = r.integer(4, "rcvtime_frac", 0, 999999999);
            p = {static_cast<double>(obc), static_cast<double>(rcv - obc) + 1e-9 * static_cast<double>(ns),
                 r.flag_byte(7, "qualflg")};
        } else {
            p = {r.number(0, "rcv_time"), r.number(3, "eps_time"), r.flag_byte(7, "qualflg")};
        }
        if (p.at < last) {  // a repeat is an arc's end and the next one's start
            r.fail(0, "the time goes back from the record before");
        }
        last = p.at;
        if (!tim || (p.flags & kTimNoMapping) == 0U) {
            points.push_back(p);
        }
        return true;
    });
    return points;
}

}  // namespace

GracefoClock::GracefoClock(const std::vector<std::string>& tim1b, const std::vector<std::string>& clk1b,
                           char satellite) {
    const auto load = [satellite](const std::vector<std::string>& paths, const char* product, bool tim) {
        std::vector<ClockPoint> all;
        for (const std::string& path : paths) {
            const std::vector<ClockPoint> p = clock_points(path, product, tim, satellite);
            all.insert(all.end(), p.begin(), p.end());
        }
        std::stable_sort(all.begin(), all.end(), [](const ClockPoint& a, const ClockPoint& b) { return a.at < b.at; });
        if (all.size() < 2 || all.front().at == all.back().at) {
            throw text::InputError::whole_file(
                paths.front(), std::string(product) + ": " + std::to_string(all.size()) + " usable records in " +
                                   text::input_name(paths.front()) + (paths.size() > 1 ? " and the others" : "") +
                                   ": a clock product needs two or more at different times (with a defined "
                                   "mapping)");
        }
        Table t;
        t.name = text::input_name(paths.front()) +
                 (paths.size() > 1 ? " and the other " + std::string(product) + " files" : "");
        std::vector<double> steps;
        for (std::size_t i = 0; i < all.size(); ++i) {
            t.at.push_back(all[i].at);
            t.offset.push_back(all[i].offset);
            if (i > 0 && all[i].at > all[i - 1].at) {  // repeats (arcs' ends, a file twice) are no spacing
                steps.push_back(all[i].at - all[i - 1].at);
            }
        }
        std::nth_element(steps.begin(), steps.begin() + static_cast<long>(steps.size() / 2), steps.end());
        t.max_step = 2.0 * steps[steps.size() / 2];
        // CLK1B: bit 1 "extrapolation not valid BEFORE", bit 0 "not valid AFTER" the record.
        t.before_first = tim || (all.front().flags & 2U) == 0U;
        t.after_last = tim || (all.back().flags & 1U) == 0U;
        return t;
    };
    if (!tim1b.empty()) {
        tim_ = load(tim1b, "TIM1B", true);
    }
    if (!clk1b.empty()) {
        clk_ = load(clk1b, "CLK1B", false);
    }
}

double GracefoClock::offset_at(const Table& t, double x, const std::string& file, std::size_t line) {
    const auto hi = std::lower_bound(t.at.begin(), t.at.end(), x);
    const auto i = static_cast<std::size_t>(hi - t.at.begin());
    if (i < t.at.size() && t.at[i] == x) {
        return t.offset[i];
    }
    // Within two records' spacing of the first or the last: its offset (a
    // day's product starts seconds after midnight; the offsets vary by ns),
    // unless the record says its value is not valid beyond it.
    if (i == 0 && t.before_first && t.at.front() - x <= t.max_step) {
        return t.offset.front();
    }
    if (i == t.at.size() && t.after_last && x - t.at.back() <= t.max_step) {
        return t.offset.back();
    }
    if (i == 0 || i == t.at.size() || t.at[i] - t.at[i - 1] > t.max_step) {
        char buf[200];
        text::c_snprintf(buf, sizeof buf, "%.6f", x);
        throw text::InputError(file, line, 1,
                               "the time " + std::string(buf) + " s is not covered by " + t.name +
                                   " (outside its records, or in a gap between them)");
    }
    const double u = (x - t.at[i - 1]) / (t.at[i] - t.at[i - 1]);
    return t.offset[i - 1] + u * (t.offset[i] - t.offset[i - 1]);
}

double GracefoClock::gps_time(std::int64_t obc_s, std::int64_t obc_us, const std::string& file,
                              std::size_t line) const {
    double t = static_cast<double>(obc_s) + 1e-6 * static_cast<double>(obc_us);
    if (tim_) {
        t += offset_at(*tim_, t, file, line);
    }
    if (clk_) {
        t += offset_at(*clk_, t, file, line);
    }
    return t;
}

std::string describe(const GracefoSummary& s) {
    char buf[300];
    text::c_snprintf(buf, sizeof buf,
                     "GRACE %c: %zu star-camera records (%zu not clean), t %.3f to %.3f s TT; %zu reference records",
                     s.satellite, s.records, s.not_clean, s.first_t, s.last_t, s.reference);
    std::string out = buf;
    if (!s.tim1b || !s.clk1b) {  // the OBC and receiver clocks are off GPS by up to tens of ms
        out += std::string("; without ") + (s.tim1b ? "" : "TIM1B (OBC time taken as receiver time)") +
               (!s.tim1b && !s.clk1b ? " and " : "") + (s.clk1b ? "" : "CLK1B (receiver time taken as GPS time)");
    }
    return out;
}

MountingsFile import_gracefo(const GracefoOptions& opt, const GracefoSink& sink, GracefoSummary& sum) {
    char satellite = 0;
    MountingsFile m = read_qsa1b(opt.qsa1b, satellite);
    sum.satellite = satellite;
    sum.tim1b = !opt.tim1b.empty();
    sum.clk1b = !opt.clk1b.empty();
    const GracefoClock clock(opt.tim1b, opt.clk1b, satellite);
    std::vector<std::pair<double, std::string>> files;
    for (const std::string& f : opt.sca1a) {
        files.emplace_back(first_obc(f), f);
    }
    std::stable_sort(files.begin(), files.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    std::int64_t last_us = -1;  // OBC time of the record before, µs
    for (const auto& [first, path] : files) {
        for_each_record(path, 16, "SCA1A", [&, &path = path](const Record& r) {
            const Sca1aRecord s = sca1a_record(r);
            same_satellite(satellite, s.satellite, r, 2);
            const std::int64_t us = s.obc_s * 1000000 + s.obc_us;
            if (us < last_us) {
                r.fail(0,
                       "the time goes back from the record before (files are taken in the order of their first "
                       "records)");
            }
            last_us = us;
            SolutionValues v;
            v.t = clock.gps_time(s.obc_s, s.obc_us, path, s.line) + kTtMinusGpsS + opt.time_offset_s;
            v.chu = std::string_view(&kHeadLetters[s.head], 1);
            v.q_chu_icrf = conjugate(s.q_icrf_chu);
            v.temperature = {std::nan(""), std::nan(""), std::nan("")};
            v.no_temperatures = true;  // written empty (docs/contract.md, "Real flight data")
            v.v_sc_kms = {std::nan(""), std::nan(""), std::nan("")};
            v.flags = flags_of(s);
            v.confidence = std::nan("");  // no misfit in arcsec: sca_confid is a code (kGracefoColumns)
            sum.not_clean += v.flags != 0 ? 1U : 0U;
            sum.first_t = sum.records == 0 ? v.t : sum.first_t;
            sum.last_t = v.t;
            ++sum.records;
            sink.solution(v, s);
            return true;
        });
    }
    if (!opt.sca1b.empty()) {
        double last = -1e300;
        for_each_record(opt.sca1b, 9, "SCA1B", [&](const Record& r) {
            same_satellite(satellite, r.satellite(1), r, 1);
            const double t = r.number(0, "gps_time") + kTtMinusGpsS;
            if (!(t > last)) {
                r.fail(0, "the time goes back (or repeats) from the record before");
            }
            last = t;
            ++sum.reference;
            sink.reference(t, conjugate(r.quaternion(3)));
            return true;
        });
    }
    return m;
}

std::vector<NamedPath> gracefo_inputs(const GracefoOptions& opt) {
    std::vector<NamedPath> in;
    for (const std::string& f : opt.sca1a) {
        in.push_back({"--sca1a", f});
    }
    in.push_back({"--qsa1b", opt.qsa1b});
    for (const std::string& f : opt.tim1b) {
        in.push_back({"--tim1b", f});
    }
    for (const std::string& f : opt.clk1b) {
        in.push_back({"--clk1b", f});
    }
    if (!opt.sca1b.empty()) {
        in.push_back({"--sca1b", opt.sca1b});
    }
    return in;
}

std::vector<NamedPath> gracefo_outputs(const GracefoOptions& opt) {
    std::vector<NamedPath> out{{"--out", opt.out}, {"--mountings", opt.mountings}};
    if (!opt.reference.empty()) {
        out.push_back({"--reference", opt.reference});
    }
    return out;
}

GracefoSummary import_gracefo_files(const GracefoOptions& opt, OutputSet& outputs) {
    refuse_output_over_input(gracefo_inputs(opt), gracefo_outputs(opt));
    std::string solutions = std::string(kSolutionsHeader) + "," + std::string(kGracefoColumns) + "\n";
    std::string reference = std::string(kAttitudeHeader) + "\n";
    AtomicFile& out = outputs["--out"];
    GracefoSink sink;
    sink.solution = [&](const SolutionValues& v, const Sca1aRecord& r) {
        append_solution_fields(solutions, v);
        for (const int x : {int{r.mode}, int{r.quality}, r.confidence}) {
            solutions += ',' + std::to_string(x);
        }
        solutions += '\n';
        if (solutions.size() > (1U << 20)) {
            out.write(solutions);
            solutions.clear();
        }
    };
    sink.reference = [&](double t, const Quaternion<double>& q) { append_attitude_row(reference, t, q); };
    GracefoSummary sum;
    const MountingsFile m = import_gracefo(opt, sink, sum);
    out.write(solutions);
    outputs["--mountings"].write(format_mountings(m));
    if (!opt.reference.empty()) {
        outputs["--reference"].write(reference);
    }
    return sum;
}

}  // namespace ascorr::host
