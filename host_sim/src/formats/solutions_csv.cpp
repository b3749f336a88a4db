#include "ascorr_host/formats/solutions_csv.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <system_error>
#include <vector>

#include "ascorr_host/formats/csv.hpp"
#include "ascorr_host/formats/progress.hpp"
#include "ascorr_text/input_error.hpp"
#include "ascorr_text/input_name.hpp"

namespace ascorr::host {

namespace {
std::string_view header_line_of(std::string_view text, const std::string& file) {
    if (text.empty()) {
        throw text::InputError(file, 1, 1, "empty file: expected a header line");
    }
    const std::size_t end = text.find('\n');
    std::string_view line = text.substr(0, end);
    if (!line.empty() && line.back() == '\r') {
        line.remove_suffix(1);
    }
    return line;
}
}  // namespace

std::uint8_t head_from_name(std::string_view chu) noexcept {
    return chu.size() == 1 ? head_index(chu[0]) : kUnknownHead;
}

char head_name(std::uint8_t head) noexcept {
    return head_letter(head);
}

SolutionsReader::SolutionsReader(std::string file_name, std::string_view text)
    : file_(std::move(file_name)), lines_(text), header_(header_line_of(text, file_), file_) {
    std::string_view header_line;
    lines_.next(header_line);
    if (const auto miss = near_miss_column(header_.names())) {
        throw text::InputError(file_, 1, header_.column_of(miss->column), miss->message);
    }
    const auto need = [&](const char* name) {
        const int i = header_.index(name);
        if (i < 0) {
            throw text::InputError(file_, 1, 1,
                                   std::string("required column '") + name + "' is missing from the header");
        }
        return i;
    };
    col_.t = need("t");
    col_.chu = need("chu");
    col_.qw = need("qw");
    col_.qx = need("qx");
    col_.qy = need("qy");
    col_.qz = need("qz");
    col_.t_chu = header_.index("t_chu");
    col_.t_029 = header_.index("t_029");
    col_.t_032 = header_.index("t_032");
    col_.vx = header_.index("vx");
    col_.vy = header_.index("vy");
    col_.vz = header_.index("vz");
    col_.flags = header_.index("flags");
    col_.confidence = header_.index("confidence");
}

SolutionsReader::SolutionsReader(const SolutionsReader& header_from, std::string_view body, std::size_t lines_before)
    : file_(header_from.file_), lines_(body, lines_before), header_(header_from.header_), col_(header_from.col_) {}

void SolutionsReader::fail(std::size_t field, const std::string& what) const {
    const std::size_t column =
        field < fields_.size() ? static_cast<std::size_t>(fields_[field].data() - line_.data()) + 1 : 1;
    throw text::InputError(file_, lines_.line_number(), column, what);
}

double SolutionsReader::number(int col, const char* name) const {
    const auto f = fields_[static_cast<std::size_t>(col)];
    const auto x = parse_double(f);
    if (!x) {
        fail(static_cast<std::size_t>(col), std::string("column '") + name + "': " + why_not_a_number(f));
    }
    return *x;
}

bool SolutionsReader::optional_number(int col, const char* name, double& out) const {
    if (col < 0) {
        return false;
    }
    const auto f = fields_[static_cast<std::size_t>(col)];
    if (f.empty()) {
        return false;
    }
    out = number(col, name);
    return !std::isnan(out);
}

bool SolutionsReader::next(SolutionRecord& rec) {
    std::string_view line;
    for (;;) {
        if (!lines_.next(line)) {
            return false;
        }
        if (!line.empty()) {
            break;
        }
        ++empty_lines_;
    }
    line_ = line;
    if (const std::size_t bad = split_fields(line, fields_); bad != kSplitOk) {
        throw text::InputError(file_, lines_.line_number(), bad + 1, why_split_failed(line, bad));
    }
    if (fields_.size() != header_.size()) {
        fail(fields_.size() - 1, "expected " + std::to_string(header_.size()) + " fields as in the header, found " +
                                     std::to_string(fields_.size()) +
                                     (fields_.size() < header_.size() ? " (truncated row?)" : ""));
    }
    rec.line = lines_.line_number();
    rec.t = number(col_.t, "t");
    if (!std::isfinite(rec.t)) {
        fail(static_cast<std::size_t>(col_.t), "column 't': time must be finite");
    }
    rec.chu = fields_[static_cast<std::size_t>(col_.chu)];
    if (!rec.chu.empty() && rec.chu[0] == '"') {
        fail(static_cast<std::size_t>(col_.chu),
             "column 'chu': " + std::string(rec.chu) + " is a quoted field in a column ascorr reads: write " +
                 kHeadChoices.text + " without quotes (docs/contract.md, section 3)");
    }
    rec.head = head_from_name(rec.chu);
    rec.q_chu_icrf = {number(col_.qw, "qw"), number(col_.qx, "qx"), number(col_.qy, "qy"), number(col_.qz, "qz")};
    rec.temperature_present[0] = optional_number(col_.t_chu, "t_chu", rec.temperature[0]);
    rec.temperature_present[1] = optional_number(col_.t_029, "t_029", rec.temperature[1]);
    rec.temperature_present[2] = optional_number(col_.t_032, "t_032", rec.temperature[2]);
    rec.velocity_components = static_cast<int>(optional_number(col_.vx, "vx", rec.v_sc_kms.x)) +
                              static_cast<int>(optional_number(col_.vy, "vy", rec.v_sc_kms.y)) +
                              static_cast<int>(optional_number(col_.vz, "vz", rec.v_sc_kms.z));
    rec.flags = 0;
    if (col_.flags >= 0 && !fields_[static_cast<std::size_t>(col_.flags)].empty()) {
        const auto f = fields_[static_cast<std::size_t>(col_.flags)];
        const auto v = parse_integer(f);
        if (!v || *v < 0) {
            fail(static_cast<std::size_t>(col_.flags),
                 "column 'flags': " + why_not_an_integer(f, 0, std::numeric_limits<long long>::max()));
        }
        rec.flags = *v;
    }
    rec.confidence = 0.0;
    rec.confidence_present = optional_number(col_.confidence, "confidence", rec.confidence);
    return true;
}

void refuse_corrected_input(const SolutionsReader& header) {
    const int col = header.header().index("status");
    if (col >= 0) {
        throw text::InputError(
            header.file_name(), 1, header.header().column_of(static_cast<std::size_t>(col)),
            "column 'status': this file is already corrected (it has the status column of a corrected "
            "file); give the raw solutions file, so that no correction is applied twice");
    }
}

bool is_corrected_file(const std::string& path) {
    BlockReader blocks(path, 4096);
    std::string_view block;
    return blocks.next(block) && SolutionsReader(path, block.substr(0, block.find('\n'))).header().index("status") >= 0;
}

void refuse_corrected_file(const std::string& path) {
    BlockReader blocks(path, 4096);
    std::string_view block;
    if (blocks.next(block)) {
        refuse_corrected_input(SolutionsReader(path, block.substr(0, block.find('\n'))));
    }
}

RowSource rows_in(const std::vector<SolutionRecord>& rows) {
    return [&rows](const std::function<void(const SolutionRecord&)>& fn) {
        for (const SolutionRecord& r : rows) {
            fn(r);
        }
    };
}

void for_each_solution(const std::string& path, const std::function<void(const SolutionRecord&)>& fn,
                       const std::string& label) {
    for_each_solution_row(
        path, [](const SolutionsReader&) {}, [&fn](const SolutionsReader&, const SolutionRecord& rec) { fn(rec); },
        label);
}

void for_each_solution_row(const std::string& path, const std::function<void(const SolutionsReader& header)>& on_header,
                           const std::function<void(const SolutionsReader& reader, const SolutionRecord&)>& fn,
                           const std::string& label) {
    std::error_code ec;
    const auto size = std::filesystem::file_size(path, ec);
    BlockReader blocks(path);
    std::string_view block;
    if (!blocks.next(block)) {
        throw text::InputError(path, 1, 1, "empty file: expected a header line");
    }
    const std::size_t nl = block.find('\n');
    const SolutionsReader header(path, block.substr(0, nl));
    on_header(header);
    block = nl == std::string_view::npos ? std::string_view() : block.substr(nl + 1);
    std::size_t lines_before = 1;
    double done_bytes = static_cast<double>(nl == std::string_view::npos ? 0 : nl + 1);
    std::optional<Progress> progress;
    if (!label.empty()) {
        progress.emplace(label + ": reading " + text::input_name(path));
    }
    SolutionRecord rec;
    for (;;) {
        SolutionsReader reader(header, block, lines_before);
        while (reader.next(rec)) {
            fn(reader, rec);
        }
        done_bytes += static_cast<double>(block.size());
        if (progress && !ec && size > 0) {
            progress->update(done_bytes / static_cast<double>(size));
        }
        if (!blocks.next(block)) {
            break;
        }
        lines_before = blocks.lines_before();
    }
}

bool is_solutions_column(std::string_view name) noexcept {
    return name == kStatusColumn ||
           std::find(kSolutionsColumns.begin(), kSolutionsColumns.end(), name) != kSolutionsColumns.end();
}

namespace {
std::string lower_case(std::string_view s) {
    std::string out(s);
    for (char& c : out) {
        c = c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c;
    }
    return out;
}

// The optimal-string-alignment distance (insertions, deletions, replacements
// and swaps of neighbours), stopped at limit + 1: header names are short.
std::size_t edit_distance(std::string_view a, std::string_view b, std::size_t limit) {
    const std::size_t n = a.size();
    const std::size_t m = b.size();
    if ((n > m ? n - m : m - n) > limit) {
        return limit + 1;
    }
    std::vector<std::vector<std::size_t>> d(n + 1, std::vector<std::size_t>(m + 1, 0));
    for (std::size_t i = 0; i <= n; ++i) {
        d[i][0] = i;
    }
    for (std::size_t j = 0; j <= m; ++j) {
        d[0][j] = j;
    }
    for (std::size_t i = 1; i <= n; ++i) {
        for (std::size_t j = 1; j <= m; ++j) {
            const std::size_t cost = a[i - 1] == b[j - 1] ? 0 : 1;
            d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + cost});
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) {
                d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
            }
        }
    }
    return std::min(d[n][m], limit + 1);
}

// Whether name looks like the known column (near_miss_column's rule).
bool looks_like(const std::string& lower_name, std::string_view known) {
    constexpr std::size_t kLongName = 5;  // t_chu and longer: one or two edits
    if (lower_name == known) {
        return true;
    }
    return known.size() >= kLongName && edit_distance(lower_name, known, 2) <= 2;
}
}  // namespace

std::optional<NearMiss> near_miss_column(const std::vector<std::string>& names) {
    std::vector<std::string_view> known(kSolutionsColumns.begin(), kSolutionsColumns.end());
    known.push_back(kStatusColumn);
    const auto in_header = [&](std::string_view k) { return std::find(names.begin(), names.end(), k) != names.end(); };
    for (std::size_t i = 0; i < names.size(); ++i) {
        if (is_solutions_column(names[i])) {
            continue;
        }
        const std::string lower = lower_case(names[i]);
        for (const std::string_view k : known) {
            if (!in_header(k) && looks_like(lower, k)) {
                return NearMiss{i, k,
                                "column '" + names[i] + "' is not a column ascorr reads, but looks like '" +
                                    std::string(k) + "', which the header lacks (column names are case-sensitive, " +
                                    "docs/contract.md, section 3): rename it '" + std::string(k) +
                                    "', or give it a name unlike the columns ascorr reads"};
            }
        }
    }
    return std::nullopt;
}

namespace {
void append_number(std::string& out, double x) {
    if (std::isnan(x)) {
        out += "nan";
        return;
    }
    char buf[40];
    const auto r = std::to_chars(buf, buf + sizeof buf, x);  // the shortest text that reads back exactly
    out.append(buf, static_cast<std::size_t>(r.ptr - buf));
}

void append_optional(std::string& out, double x) {  // empty when not available
    if (!std::isnan(x)) {
        append_number(out, x);
    }
}
}  // namespace

void append_solution_fields(std::string& out, const SolutionValues& row) {
    append_number(out, row.t);
    out += ',';
    out += row.chu;
    for (const double c : {row.q_chu_icrf.w, row.q_chu_icrf.x, row.q_chu_icrf.y, row.q_chu_icrf.z}) {
        out += ',';
        append_number(out, c);
    }
    for (const double c : row.temperature) {
        out += ',';
        if (!row.no_temperatures) {
            append_number(out, c);
        }
    }
    for (const double c : row.v_sc_kms) {
        out += ',';
        append_optional(out, c);
    }
    out += ',';
    out += std::to_string(row.flags);
    out += ',';
    append_optional(out, row.confidence);
}

}  // namespace ascorr::host
