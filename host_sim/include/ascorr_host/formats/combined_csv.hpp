// ascorr_host/formats/combined_csv.hpp: attitude files of the bench (docs/contract.md, "Combined attitude").
//
// Two files of one attitude per epoch, q = q_crf_icrf (v_crf = R(q) v_icrf,
// qw >= 0):
//  - the combined file, `t,qw,qx,qy,qz,heads,sigma_x,sigma_y,sigma_z,status`
//    (`ascorr combine`, `correct --combined`);
//    and with `--covariance` the columns `cov_xy,cov_xz,cov_yz` after them
//    (arcsec²: the off-diagonal of the formal covariance whose diagonal's
//    roots are the sigmas);
//  - the attitude file, `t,qw,qx,qy,qz` (`simulate`'s true attitude of the
//    CRF, OUT.attitude.csv), the combined file's first five columns.
// Numbers as the corrected file writes them: q with 15 decimals (2e-10
// arcsec); t and the sigmas in the shortest text that reads back exactly
// (t the earliest of the epoch's rows', to the bit); an epoch without a usable
// head has empty q, heads and sigmas.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "ascorr/core/heads.hpp"
#include "ascorr/core/quaternion.hpp"

namespace ascorr::host {

inline constexpr std::string_view kAttitudeHeader = "t,qw,qx,qy,qz";
inline constexpr std::string_view kCombinedHeader = "t,qw,qx,qy,qz,heads,sigma_x,sigma_y,sigma_z,status";
inline constexpr std::string_view kCovarianceColumns = "cov_xy,cov_xz,cov_yz";

// The optional columns of a combined file.
struct CombinedColumns {
    bool covariance = false;  // cov_xy,cov_xz,cov_yz
};
// The header line (no line end) of a combined file with these columns.
std::string combined_header(CombinedColumns c);

// One row of either file. `heads` is a mask (bit h: head h of heads.hpp);
// without q (no usable head) heads is 0 and sigma is not written.
struct AttitudeRow {
    std::size_t line = 0;  // 1-based, when read
    double t = 0.0;
    bool has_q = false;
    Quaternion<double> q_crf_icrf{};
    HeadMask heads = 0;
    std::array<double, 3> sigma_arcsec{};  // about CRF x, y, z
    unsigned status = 0;
    bool has_cov = false;                 // read: the file has the columns and the row a q
    std::array<double, 3> cov_arcsec2{};  // xy, xz, yz (arcsec²)
};

// Appends `t,qw,qx,qy,qz\n` (the attitude file's row).
void append_attitude_row(std::string& out, double t, const Quaternion<double>& q_crf_icrf);
// q_crf_icrf as append_attitude_row writes it and a reader reads it back
// (canonical, each component rounded to the file's decimals), for a caller
// that hands the attitude over without the file.
Quaternion<double> attitude_as_written(const Quaternion<double>& q_crf_icrf);
// Appends the combined file's row (with its line end); the covariance
// columns when c has them (empty without q, as the sigmas).
void append_combined_row(std::string& out, const AttitudeRow& row, CombinedColumns c = {});
// The rows of `text` (append_combined_row's with c, no header) as a reader of
// the combined file reads them (q to 15 decimals), appended to rows: a
// combination kept in memory gives the file's numbers to the digit. name and
// first_line: for messages, the line of rows' first element (the rows of
// arrays: 1-based rows).
void read_combined_rows(std::string_view text, std::vector<AttitudeRow>& rows, CombinedColumns c = {},
                        const std::string& name = "combined rows", std::size_t first_line = 2);

// Reads an attitude or a combined file (told apart by the header:
// combined()), row by row in file order, in blocks (bounded memory). Throws
// InputError (file:line:column) for a malformed row: a header that is
// neither, q neither four numbers nor four empty fields, a non-unit q, heads
// not letters of heads.hpp in order, a status not an integer in [0, 255],
// covariance columns not all three, not finite, or not a covariance with the
// row's sigmas (|cov_ab| > sigma_a sigma_b). In an attitude file every row has q.
class AttitudeReader {
public:
    explicit AttitudeReader(const std::string& path);
    ~AttitudeReader();
    AttitudeReader(const AttitudeReader&) = delete;
    AttitudeReader& operator=(const AttitudeReader&) = delete;
    bool combined() const noexcept;
    // The optional columns the file has (cov_xy, cov_xz, cov_yz).
    CombinedColumns columns() const noexcept;
    // The next row; false at the end.
    bool next(AttitudeRow& row);

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

// An attitude file read as the truth (stats --combined, plot --combined,
// --truth-attitude): a combined file is refused (file:1:1), and so is a row
// not after the one before it by epoch (file:line:1, naming both lines): one
// rule for every reader of a truth.
class TruthReader {
public:
    explicit TruthReader(const std::string& path);
    // The next row, checked; false at the end.
    bool next(AttitudeRow& row);

private:
    std::string path_;
    AttitudeReader reader_;
    bool any_ = false;
    std::int64_t last_key_ = 0;
    std::size_t last_line_ = 0;
};

}  // namespace ascorr::host
