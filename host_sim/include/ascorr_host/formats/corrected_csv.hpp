// ascorr_host/formats/corrected_csv.hpp: writer of the corrected file (docs/contract.md).
//
// Every field of the input row verbatim except qw,qx,qy,qz (15 decimals), plus
// a `status` column (or the existing one, overwritten). A rejected row keeps
// its quaternion text exactly as read.
#pragma once

#include <array>
#include <optional>
#include <string>

#include "ascorr/core/quaternion.hpp"
#include "ascorr/core/status.hpp"
#include "ascorr_host/formats/solutions_csv.hpp"

namespace ascorr::host {

class RowWriter {
public:
    explicit RowWriter(const SolutionsReader& header);

    std::string header_line() const;

    // Appends the row last read by `reader` (which must share this header);
    // without q, the quaternion fields are copied as read.
    void row(const SolutionsReader& reader, const std::optional<Quaternion<double>>& q, StatusBits st,
             std::string& buf) const;

private:
    const SolutionsReader& header_;
    std::array<int, 4> q_cols_{};
    int status_col_ = -1;
};

// q as the corrected file holds it (15 decimals, read back): what `combine`
// reads from a corrected file, so that `correct --combined` combines the same numbers.
Quaternion<double> as_written(const Quaternion<double>& q) noexcept;

}  // namespace ascorr::host
