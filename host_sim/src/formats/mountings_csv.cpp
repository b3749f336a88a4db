#include "ascorr_host/formats/mountings_csv.hpp"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "ascorr/core/quaternion.hpp"
#include "ascorr_host/formats/atomic_file.hpp"
#include "ascorr_host/formats/csv.hpp"
#include "ascorr_host/formats/solutions_csv.hpp"
#include "ascorr_text/c_format.hpp"
#include "ascorr_text/input_error.hpp"

namespace ascorr::host {

namespace {

constexpr const char* kQuaternionNames[4] = {"qw", "qx", "qy", "qz"};
constexpr const char* kSigmaNames[2] = {"sigma_cross", "sigma_about"};
constexpr const char* kHeaderText = "chu,qw,qx,qy,qz and optionally sigma_cross,sigma_about";

struct Columns {
    int chu = -1;
    int q[4] = {-1, -1, -1, -1};
    int sigma[2] = {-1, -1};
};

Columns columns_of(const Header& header, const std::string& file) {
    Columns c;
    c.chu = header.index("chu");
    for (std::size_t i = 0; i < 4; ++i) {
        c.q[i] = header.index(kQuaternionNames[i]);
    }
    for (std::size_t i = 0; i < 2; ++i) {
        c.sigma[i] = header.index(kSigmaNames[i]);
    }
    if (c.chu < 0 || c.q[0] < 0 || c.q[1] < 0 || c.q[2] < 0 || c.q[3] < 0) {
        throw text::InputError(file, 1, 1, std::string("the mountings header must have ") + kHeaderText);
    }
    // A misspelt column (sigma_acros) is never dropped silently.
    std::size_t column = 1;
    for (const std::string& name : header.names()) {
        bool known = name == "chu";
        for (const char* q : kQuaternionNames) {
            known = known || name == q;
        }
        for (const char* s : kSigmaNames) {
            known = known || name == s;
        }
        if (!known) {
            throw text::InputError(file, 1, column,
                                   "unknown column '" + name + "' (a mountings file has " + kHeaderText + ")");
        }
        column += name.size() + 1;
    }
    if ((c.sigma[0] < 0) != (c.sigma[1] < 0)) {
        throw text::InputError(file, 1, 1,
                               std::string("the header has ") + (c.sigma[0] < 0 ? kSigmaNames[1] : kSigmaNames[0]) +
                                   " without " + (c.sigma[0] < 0 ? kSigmaNames[0] : kSigmaNames[1]) +
                                   ": a head's noise is both or neither");
    }
    return c;
}

// One data row, split, with where its fields start.
struct Row {
    const std::string& file;
    std::size_t line;
    const std::vector<std::string_view>& fields;
    const std::vector<std::size_t>& starts;
    [[noreturn]] void fail(int col, const std::string& what) const {
        throw text::InputError(file, line, starts[static_cast<std::size_t>(col)] + 1, what);
    }
    std::string_view field(int col) const { return fields[static_cast<std::size_t>(col)]; }
};

// A finite number in column `col` named `name`.
double finite_number(const Row& r, int col, const char* name) {
    const std::string_view f = r.field(col);
    if (f.empty()) {
        r.fail(col, std::string("column '") + name + "' is empty: expected a finite number");
    }
    const auto x = parse_double(f);
    if (!x) {
        r.fail(col, std::string("column '") + name + "': " + why_not_a_number(f));
    }
    if (!std::isfinite(*x)) {
        r.fail(col, std::string("column '") + name + "': expected a finite number, got '" + std::string(f) + "'");
    }
    return *x;
}

Quaternion<double> quaternion_of(const Row& r, const Columns& c, char head) {
    double q[4];
    for (std::size_t i = 0; i < 4; ++i) {
        q[i] = finite_number(r, c.q[i], kQuaternionNames[i]);
    }
    const Quaternion<double> out{q[0], q[1], q[2], q[3]};
    const double n2 = squared_norm(out);
    if (!(std::fabs(n2 - 1.0) <= combine::kMountingNormTolerance)) {
        char what[200];
        text::c_snprintf(what, sizeof what,
                         "the mounting of CHU %c is %s (|q|^2 = %.9g, tolerance %.1g): q_chu_crf is a unit quaternion",
                         head, n2 == 0.0 ? "zero" : "not unit", n2, combine::kMountingNormTolerance);
        r.fail(c.q[0], what);
    }
    return out;
}

// Whether the row gives its sigmas; both, or neither (empty fields).
bool row_has_sigmas(const Row& r, const Columns& c) {
    if (c.sigma[0] < 0) {
        return false;
    }
    const bool cross = !r.field(c.sigma[0]).empty();
    const bool about = !r.field(c.sigma[1]).empty();
    if (cross != about) {
        r.fail(cross ? c.sigma[1] : c.sigma[0], std::string("column '") + (cross ? kSigmaNames[1] : kSigmaNames[0]) +
                                                    "' is empty while '" + (cross ? kSigmaNames[0] : kSigmaNames[1]) +
                                                    "' is given: a head's noise is both or neither");
    }
    return cross;
}

double sigma_of(const Row& r, int col, const char* name) {
    const double s = finite_number(r, col, name);
    if (!(s >= combine::kMinSigmaArcsec && s <= combine::kMaxSigmaArcsec)) {
        char range[96];
        text::c_snprintf(range, sizeof range, ": a head's noise is a positive number of arcsec, in [%g, %g]",
                         combine::kMinSigmaArcsec, combine::kMaxSigmaArcsec);
        r.fail(col, std::string("column '") + name + "' = " + number_text(s) + range);
    }
    return s;
}

void append_number(std::string& out, double x) {
    char buf[40];
    const auto r = std::to_chars(buf, buf + sizeof buf, x);  // the shortest text that reads back exactly
    out.append(buf, static_cast<std::size_t>(r.ptr - buf));
}

// The row's head: named, known and not given by an earlier row.
std::uint8_t head_of_row(const Row& r, const Columns& c, const MountingsFile& m) {
    const std::string_view chu = r.field(c.chu);
    if (chu.empty()) {
        r.fail(c.chu, "the head is missing: chu must be " + std::string(kHeadChoices.text));
    }
    const std::uint8_t head = head_from_name(chu);
    if (head == kUnknownHead) {
        r.fail(c.chu, "chu must be " + std::string(kHeadChoices.text) + ", got '" + std::string(chu) + "'");
    }
    if (m.line[head] != 0) {
        r.fail(c.chu, std::string("second row for CHU ") + head_name(head) + " (the first is on line " +
                          std::to_string(m.line[head]) + ")");
    }
    return head;
}

}  // namespace

MountingsFile parse_mountings(const std::string& file_name, std::string_view text) {
    if (text.empty()) {
        throw text::InputError(file_name, 1, 1,
                               std::string("empty mountings file: expected the header ") + kHeaderText);
    }
    LineReader lines(text);
    std::string_view line;
    lines.next(line);
    const Header header(line, file_name);
    const Columns c = columns_of(header, file_name);

    MountingsFile m;
    for (combine::HeadMounting& h : m.mountings.head) {
        h.sigma_cross_arcsec = std::numeric_limits<double>::quiet_NaN();
        h.sigma_about_arcsec = std::numeric_limits<double>::quiet_NaN();
    }
    std::vector<std::string_view> fields;
    std::vector<std::size_t> starts;
    std::size_t first_line = 0;  // the first row's: the one the others' sigmas agree with
    while (lines.next(line)) {
        if (line.empty()) {
            continue;
        }
        const std::size_t n = lines.line_number();
        split_row(line, header.size(), file_name, n, fields, starts);
        const Row r{file_name, n, fields, starts};
        const std::uint8_t head = head_of_row(r, c, m);
        combine::HeadMounting& h = m.mountings.head[head];
        h.q_chu_crf = quaternion_of(r, c, head_name(head));
        const bool sigmas = row_has_sigmas(r, c);
        if (first_line == 0) {
            first_line = n;
            m.sigmas = sigmas;
        } else if (sigmas != m.sigmas) {
            r.fail(c.sigma[0], std::string("sigmas on some rows only: this row ") + (sigmas ? "gives" : "has no") +
                                   " sigma_cross,sigma_about, line " + std::to_string(first_line) +
                                   (sigmas ? " has none" : " gives them") +
                                   " (every head's, or none: then they are "
                                   "estimated from the data)");
        }
        if (sigmas) {
            h.sigma_cross_arcsec = sigma_of(r, c.sigma[0], kSigmaNames[0]);
            h.sigma_about_arcsec = sigma_of(r, c.sigma[1], kSigmaNames[1]);
        }
        h.present = true;
        m.line[head] = n;
    }
    if (first_line == 0) {
        throw text::InputError(file_name, lines.line_number(), 1, "the mountings file has no head rows");
    }
    return m;
}

MountingsFile read_mountings_file(const std::string& path) {
    return parse_mountings(path, read_text_file(path));
}

std::string format_mountings(const MountingsFile& m) {
    std::string out = m.sigmas ? "chu,qw,qx,qy,qz,sigma_cross,sigma_about\n" : "chu,qw,qx,qy,qz\n";
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        const combine::HeadMounting& hm = m.mountings.head[h];
        if (!hm.present) {
            continue;
        }
        out += head_name(h);
        for (const double x : {hm.q_chu_crf.w, hm.q_chu_crf.x, hm.q_chu_crf.y, hm.q_chu_crf.z}) {
            out += ',';
            append_number(out, x);
        }
        if (m.sigmas) {
            for (const double x : {hm.sigma_cross_arcsec, hm.sigma_about_arcsec}) {
                out += ',';
                append_number(out, x);
            }
        }
        out += '\n';
    }
    return out;
}

void write_mountings_file(const std::string& path, const MountingsFile& m) {
    write_file_atomically(path, format_mountings(m));
}

}  // namespace ascorr::host
