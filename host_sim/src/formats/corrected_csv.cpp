#include "ascorr_host/formats/corrected_csv.hpp"

#include <charconv>

#include "ascorr_host/formats/csv.hpp"

namespace ascorr::host {

namespace {
void append_status(StatusBits st, std::string& buf) {
    char num[8];
    const auto r = std::to_chars(num, num + sizeof num, static_cast<unsigned>(st));
    buf.append(num, static_cast<std::size_t>(r.ptr - num));
}
}  // namespace

RowWriter::RowWriter(const SolutionsReader& header) : header_(header) {
    const auto& c = header.columns();
    q_cols_ = {c.qw, c.qx, c.qy, c.qz};
    status_col_ = header.header().index("status");
}

std::string RowWriter::header_line() const {
    std::string h;
    const auto& names = header_.header().raw_names();
    for (std::size_t i = 0; i < names.size(); ++i) {
        h += (i == 0 ? "" : ",");
        h += names[i];
    }
    h += status_col_ < 0 ? ",status\n" : "\n";
    return h;
}

void RowWriter::row(const SolutionsReader& reader, const std::optional<Quaternion<double>>& q, StatusBits st,
                    std::string& buf) const {
    const auto& fields = reader.fields();
    char num[64];
    for (std::size_t i = 0; i < fields.size(); ++i) {
        if (i != 0) {
            buf += ',';
        }
        const int col = static_cast<int>(i);
        if (col == status_col_) {
            append_status(st, buf);
        } else if (q && (col == q_cols_[0] || col == q_cols_[1] || col == q_cols_[2] || col == q_cols_[3])) {
            const double v = col == q_cols_[0] ? q->w : col == q_cols_[1] ? q->x : col == q_cols_[2] ? q->y : q->z;
            const char* end = format_fixed(num, num + sizeof num, v, 15);
            buf.append(num, static_cast<std::size_t>(end - num));
        } else {
            buf.append(fields[i]);
        }
    }
    if (status_col_ < 0) {
        buf += ',';
        append_status(st, buf);
    }
    buf += '\n';
}

Quaternion<double> as_written(const Quaternion<double>& q) noexcept {
    const auto round_trip = [](double x) {
        char num[64];
        const char* end = format_fixed(num, num + sizeof num, x, 15);
        return parse_double(std::string_view(num, static_cast<std::size_t>(end - num))).value_or(x);
    };
    return {round_trip(q.w), round_trip(q.x), round_trip(q.y), round_trip(q.z)};
}

}  // namespace ascorr::host
