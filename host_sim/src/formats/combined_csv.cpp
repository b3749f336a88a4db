#include "ascorr_host/formats/combined_csv.hpp"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <string_view>
#include <vector>

#include "ascorr/combine/combined_status.hpp"
#include "ascorr/core/heads.hpp"
#include "ascorr/core/scalar_traits.hpp"
#include "ascorr/pipeline/epoch_key.hpp"
#include "ascorr_host/formats/csv.hpp"
#include "ascorr_text/input_error.hpp"

namespace ascorr::host {

namespace {

void append_shortest(std::string& out, double x) {
    char buf[40];
    const auto r = std::to_chars(buf, buf + sizeof buf, x);  // the shortest text that reads back exactly
    out.append(buf, static_cast<std::size_t>(r.ptr - buf));
}

void append_quaternion(std::string& out, const Quaternion<double>& q) {
    char num[64];
    for (const double c : {q.w, q.x, q.y, q.z}) {
        out += ',';
        const char* end = format_fixed(num, num + sizeof num, c, 15);
        out.append(num, static_cast<std::size_t>(end - num));
    }
}

// The columns of either file; heads..status -1 in an attitude file.
struct Columns {
    int t = -1;
    int q[4] = {-1, -1, -1, -1};
    int heads = -1;
    int sigma[3] = {-1, -1, -1};
    int status = -1;
    int cov[3] = {-1, -1, -1};  // all or none (columns_of)
};

Columns columns_of(const Header& h, const std::string& file, bool& combined) {
    Columns c;
    c.t = h.index("t");
    c.q[0] = h.index("qw");
    c.q[1] = h.index("qx");
    c.q[2] = h.index("qy");
    c.q[3] = h.index("qz");
    c.heads = h.index("heads");
    c.sigma[0] = h.index("sigma_x");
    c.sigma[1] = h.index("sigma_y");
    c.sigma[2] = h.index("sigma_z");
    c.status = h.index("status");
    c.cov[0] = h.index("cov_xy");
    c.cov[1] = h.index("cov_xz");
    c.cov[2] = h.index("cov_yz");
    const bool attitude = c.t >= 0 && c.q[0] >= 0 && c.q[1] >= 0 && c.q[2] >= 0 && c.q[3] >= 0;
    combined = attitude && c.heads >= 0 && c.sigma[0] >= 0 && c.sigma[1] >= 0 && c.sigma[2] >= 0 && c.status >= 0;
    if (!attitude) {
        throw text::InputError(file, 1, 1,
                               "expected the header of an attitude file (" + std::string(kAttitudeHeader) +
                                   ") or of a combined file (" + std::string(kCombinedHeader) + ")");
    }
    const int covs = int(c.cov[0] >= 0) + int(c.cov[1] >= 0) + int(c.cov[2] >= 0);
    if (covs != 0 && (covs != 3 || !combined)) {
        throw text::InputError(file, 1, 1,
                               "the covariance columns (" + std::string(kCovarianceColumns) +
                                   ") are all three or none, and only in a combined file");
    }
    return c;
}

class RowParser {
public:
    RowParser(std::string file, const Columns& c, bool combined) : file_(std::move(file)), c_(c), combined_(combined) {}

    AttitudeRow parse(std::string_view line, std::size_t n) {
        AttitudeRow row;
        row.line = n;
        line_ = n;
        if (const std::size_t bad = split_fields(line, fields_, starts_); bad != kSplitOk) {
            throw text::InputError(file_, n, bad + 1, why_split_failed(line, bad));
        }
        row.t = number(c_.t, "t");
        if (!std::isfinite(row.t)) {
            fail(c_.t, "'t' must be a finite time");
        }
        const int empty_q = int(field(c_.q[0]).empty()) + int(field(c_.q[1]).empty()) + int(field(c_.q[2]).empty()) +
                            int(field(c_.q[3]).empty());
        row.has_q = empty_q == 0;
        if (!row.has_q && (empty_q != 4 || !combined_)) {
            fail(c_.q[0], combined_ ? "qw,qx,qy,qz: four numbers, or four empty fields (no usable head)"
                                    : "qw,qx,qy,qz: an attitude file has a quaternion on every row");
        }
        if (row.has_q) {
            row.q_crf_icrf = {number(c_.q[0], "qw"), number(c_.q[1], "qx"), number(c_.q[2], "qy"),
                              number(c_.q[3], "qz")};
            if (!norm_within(row.q_crf_icrf, ScalarTraits<double>::unit_norm_tolerance)) {
                fail(c_.q[0], "q_crf_icrf is not a unit quaternion");
            }
        }
        if (combined_) {
            parse_combined(row);
        }
        return row;
    }

private:
    void parse_combined(AttitudeRow& row) {
        const std::string_view heads = field(c_.heads);
        std::uint8_t last = 0;
        for (std::size_t i = 0; i < heads.size(); ++i) {
            const std::uint8_t h = head_index(heads[i]);
            if (h == kUnknownHead || (i > 0 && h <= last)) {
                fail(c_.heads, "heads must be letters of " + std::string(kHeadLetters) + ", in that order, got '" +
                                   std::string(heads) + "'");
            }
            row.heads |= head_bit(h);
            last = h;
        }
        if (row.has_q != (row.heads != 0U)) {
            fail(c_.heads, "heads and q: both given, or both empty");
        }
        for (std::size_t a = 0; a < 3; ++a) {
            static constexpr const char* kNames[3] = {"sigma_x", "sigma_y", "sigma_z"};
            row.sigma_arcsec[a] = row.has_q ? number(c_.sigma[a], kNames[a]) : std::nan("");
        }
        const std::string_view st = field(c_.status);
        const auto v = parse_integer(st);
        if (!v || *v < 0 || *v > 255) {
            fail(c_.status, "column 'status': " + why_not_an_integer(st, 0, 255));
        }
        row.status = static_cast<unsigned>(*v);
        refuse_impossible(row);
        if (c_.cov[0] >= 0) {
            parse_covariance(row);
        }
    }

    // cov_xy, cov_xz, cov_yz: empty without q, else numbers that with the
    // sigmas can be a covariance (|cov_ab| <= sigma_a sigma_b, to rounding).
    void parse_covariance(AttitudeRow& row) const {
        static constexpr const char* kNames[3] = {"cov_xy", "cov_xz", "cov_yz"};
        static constexpr int kAxes[3][2] = {{0, 1}, {0, 2}, {1, 2}};
        for (std::size_t k = 0; k < 3; ++k) {
            if (!row.has_q) {
                if (!field(c_.cov[k]).empty()) {
                    fail(c_.cov[k], std::string("column '") + kNames[k] + "': empty on a row without q");
                }
                continue;
            }
            const double c = number(c_.cov[k], kNames[k]);
            const double product = row.sigma_arcsec[static_cast<std::size_t>(kAxes[k][0])] *
                                   row.sigma_arcsec[static_cast<std::size_t>(kAxes[k][1])];
            if (!(std::fabs(c) <= product * (1.0 + 1e-12))) {  // the written sigmas' rounding
                fail(c_.cov[k],
                     std::string("column '") + kNames[k] + "': " + number_text(c) +
                         " arcsec^2 is no covariance with the row's sigmas (|cov| <= " + number_text(product) + ")");
            }
            row.cov_arcsec2[k] = c;
        }
        row.has_cov = row.has_q;
    }

    // A row the combination cannot have written: a status against the rule
    // (combine/combined_status.hpp), heads that contradict it, a sigma that is
    // not a positive finite number.
    void refuse_impossible(const AttitudeRow& row) const {
        namespace cs = combine::combined_status;
        const auto st = static_cast<combine::CombinedStatus>(row.status);
        if (!cs::status_consistent(st)) {
            fail(c_.status, "column 'status': " + std::to_string(row.status) +
                                " is no combined status (exactly one of 1, 2 and 8, with or without 4)");
        }
        const unsigned n = head_count(row.heads);
        const unsigned kind = static_cast<unsigned>(st) & (cs::kTwoOrMoreHeads | cs::kOneHead | cs::kNoHead);
        const unsigned expected = static_cast<unsigned>(n == 0U   ? cs::kNoHead
                                                        : n == 1U ? cs::kOneHead
                                                                  : cs::kTwoOrMoreHeads);
        if (kind != expected) {
            fail(c_.status, "column 'status': " + std::to_string(row.status) + " contradicts the row's " +
                                std::to_string(n) + (n == 1U ? " head" : " heads"));
        }
        for (std::size_t a = 0; row.has_q && a < 3; ++a) {
            static constexpr const char* kNames[3] = {"sigma_x", "sigma_y", "sigma_z"};
            if (!(row.sigma_arcsec[a] > 0.0) || !std::isfinite(row.sigma_arcsec[a])) {
                fail(c_.sigma[a], std::string("column '") + kNames[a] + "': a formal sigma is a positive finite " +
                                      "number of arcsec, got " + number_text(row.sigma_arcsec[a]));
            }
        }
    }

    std::string_view field(int col) const {
        const auto i = static_cast<std::size_t>(col);
        if (i >= fields_.size()) {
            throw text::InputError(
                file_, line_, starts_.back() + 1,
                "expected at least " + std::to_string(i + 1) + " fields, found " + std::to_string(fields_.size()));
        }
        return fields_[i];
    }
    double number(int col, const char* name) const {
        const std::string_view f = field(col);
        const auto x = parse_double(f);
        if (!x) {
            fail(col, std::string("column '") + name + "': " + why_not_a_number(f));
        }
        return *x;
    }
    [[noreturn]] void fail(int col, const std::string& what) const {
        const auto i = static_cast<std::size_t>(col);
        throw text::InputError(file_, line_, (i < starts_.size() ? starts_[i] : 0) + 1, what);
    }

    std::string file_;
    Columns c_;
    bool combined_;
    std::size_t line_ = 0;
    std::vector<std::string_view> fields_;
    std::vector<std::size_t> starts_;
};

}  // namespace

void append_attitude_row(std::string& out, double t, const Quaternion<double>& q_crf_icrf) {
    append_shortest(out, t);
    append_quaternion(out, canonical(q_crf_icrf));
    out += '\n';
}

Quaternion<double> attitude_as_written(const Quaternion<double>& q_crf_icrf) {
    std::string line;
    append_quaternion(line, canonical(q_crf_icrf));  // ",w,x,y,z": the fields a reader splits
    std::vector<std::string_view> f;
    split_fields(line, f);
    return {*parse_double(f[1]), *parse_double(f[2]), *parse_double(f[3]), *parse_double(f[4])};
}

std::string combined_header(CombinedColumns c) {
    std::string h(kCombinedHeader);
    if (c.covariance) {
        h += ',';
        h += kCovarianceColumns;
    }
    return h;
}

void append_combined_row(std::string& out, const AttitudeRow& row, CombinedColumns c) {
    append_shortest(out, row.t);
    if (row.has_q) {
        append_quaternion(out, canonical(row.q_crf_icrf));
    } else {
        out += ",,,,";
    }
    out += ',';
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        if (has_head(row.heads, h)) {
            out += head_letter(h);
        }
    }
    for (const double s : row.sigma_arcsec) {
        out += ',';
        if (row.has_q) {
            append_shortest(out, s);
        }
    }
    out += ',';
    out += std::to_string(row.status);
    for (std::size_t k = 0; c.covariance && k < 3; ++k) {
        out += ',';
        if (row.has_q) {
            append_shortest(out, row.cov_arcsec2[k]);
        }
    }
    out += '\n';
}

struct AttitudeReader::Impl {
    explicit Impl(const std::string& p) : path(p), blocks(p) {
        if (!blocks.next(block)) {
            throw text::InputError(path, 1, 1, "empty file: expected a header line");
        }
        const std::size_t nl = block.find('\n');
        std::string_view header_line = block.substr(0, nl);
        if (!header_line.empty() && header_line.back() == '\r') {
            header_line.remove_suffix(1);
        }
        const Header header(header_line, path);
        columns = columns_of(header, path, combined);
        parser = std::make_unique<RowParser>(path, columns, combined);
        block = nl == std::string_view::npos ? std::string_view() : block.substr(nl + 1);
        lines = LineReader(block, 1);
    }
    bool next(AttitudeRow& row) {
        for (;;) {
            std::string_view line;
            while (lines.next(line)) {
                if (!line.empty()) {
                    row = parser->parse(line, lines.line_number());
                    return true;
                }
            }
            if (!blocks.next(block)) {
                return false;
            }
            lines = LineReader(block, blocks.lines_before());
        }
    }
    std::string path;
    BlockReader blocks;
    std::string_view block;
    LineReader lines{std::string_view()};
    Columns columns;
    bool combined = false;
    std::unique_ptr<RowParser> parser;
};

AttitudeReader::AttitudeReader(const std::string& path) : impl_(std::make_unique<Impl>(path)) {}
AttitudeReader::~AttitudeReader() = default;
bool AttitudeReader::combined() const noexcept {
    return impl_->combined;
}
CombinedColumns AttitudeReader::columns() const noexcept {
    return {impl_->columns.cov[0] >= 0};
}
bool AttitudeReader::next(AttitudeRow& row) {
    return impl_->next(row);
}

TruthReader::TruthReader(const std::string& path) : path_(path), reader_(path) {
    if (reader_.combined()) {
        throw text::InputError(path, 1, 1, "the truth is an attitude file (t,qw,qx,qy,qz), not a combined file");
    }
}

bool TruthReader::next(AttitudeRow& row) {
    if (!reader_.next(row)) {
        return false;
    }
    if (!(std::abs(row.t) < pipeline::kMaxEpochTimeS)) {
        throw text::InputError(path_, row.line, 1,
                               "t = " + number_text(row.t) + " s has no millisecond key: no epoch to compare");
    }
    const std::int64_t key = pipeline::epoch_key(row.t);
    if (any_ && key <= last_key_) {
        throw text::InputError(path_, row.line, 1,
                               "the truth's rows must be in time order, one per epoch (line " +
                                   std::to_string(last_line_) + " is at or after this one)");
    }
    any_ = true;
    last_key_ = key;
    last_line_ = row.line;
    return true;
}

void read_combined_rows(std::string_view text, std::vector<AttitudeRow>& rows, CombinedColumns cols,
                        const std::string& name, std::size_t first_line) {
    bool combined = false;
    const std::string header = combined_header(cols);
    const Columns c = columns_of(Header(header, name), name, combined);
    RowParser parser(name, c, combined);
    std::size_t n = first_line + rows.size();  // rows appended: the lines go on
    while (!text.empty()) {
        const std::size_t end = text.find('\n');
        const std::string_view line = text.substr(0, end);
        rows.push_back(parser.parse(line, n++));
        text.remove_prefix(end == std::string_view::npos ? text.size() : end + 1U);
    }
}

}  // namespace ascorr::host
