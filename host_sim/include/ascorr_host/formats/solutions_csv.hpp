// ascorr_host/formats/solutions_csv.hpp: reader of the solutions file (docs/contract.md).
//
// Columns are matched by name; unknown columns are ignored by the reader and
// kept verbatim by writers. Required: t, chu, qw, qx, qy, qz. Optional:
// t_chu, t_029, t_032, vx, vy, vz, flags, confidence (absent = not available).
// A field that is present but not a number is malformed (InputError with
// file:line:column); "nan" or an empty field means "not available" for
// temperatures and velocities, and a NaN quaternion is passed on for the core
// to reject.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "ascorr/core/heads.hpp"
#include "ascorr/core/quaternion.hpp"
#include "ascorr/core/vector3.hpp"
#include "ascorr_host/formats/csv.hpp"

namespace ascorr::host {

using ascorr::kUnknownHead;  // heads.hpp

// The head index of a `chu` field (one letter of kHeadLetters, ascorr/core/heads.hpp),
// kUnknownHead otherwise.
std::uint8_t head_from_name(std::string_view chu) noexcept;
char head_name(std::uint8_t head) noexcept;  // its letter, '?' for an unknown head

struct SolutionRecord {
    std::size_t line = 0;  // 1-based line in the file
    double t = 0.0;        // s since J2000.0, TT
    std::string_view chu;  // as written
    std::uint8_t head = kUnknownHead;
    Quaternion<double> q_chu_icrf{};
    std::array<double, 3> temperature{};        // t_chu, t_029, t_032 (°C)
    std::array<bool, 3> temperature_present{};  // false: empty, nan or column absent
    Vector3<double> v_sc_kms{};                 // vx, vy, vz
    int velocity_components = 0;                // how many of vx, vy, vz are present
    long long flags = 0;                        // 0 when absent
    double confidence = 0.0;                    // arcsec; 0 when absent
    bool confidence_present = false;
};

class SolutionsReader {
public:
    // Parses the header; throws InputError when a required column is missing.
    SolutionsReader(std::string file_name, std::string_view text);
    // Reads the data rows in body, a block of whole lines of the same file
    // after the header (see BlockReader); lines_before numbers them.
    SolutionsReader(const SolutionsReader& header_from, std::string_view body, std::size_t lines_before);

    // Reads the next data row into rec (empty lines are skipped and counted).
    // Returns false at the end. Throws InputError for a malformed row; the
    // reader has then moved past it, so a caller may report it and go on.
    bool next(SolutionRecord& rec);

    const Header& header() const noexcept { return header_; }
    const std::string& file_name() const noexcept { return file_; }
    // The fields of the row last returned (or last rejected), in file order.
    const std::vector<std::string_view>& fields() const noexcept { return fields_; }
    std::size_t empty_lines() const noexcept { return empty_lines_; }

    // Column indices (−1 where absent).
    struct Columns {
        int t, chu, qw, qx, qy, qz, t_chu, t_029, t_032, vx, vy, vz, flags, confidence;
    };
    const Columns& columns() const noexcept { return col_; }

private:
    [[noreturn]] void fail(std::size_t field, const std::string& what) const;
    double number(int col, const char* name) const;
    bool optional_number(int col, const char* name, double& out) const;

    std::string file_;
    LineReader lines_;
    Header header_;
    Columns col_{};
    std::vector<std::string_view> fields_;
    std::string_view line_;  // the row last read, for column numbers in messages
    std::size_t empty_lines_ = 0;
};

// Throws InputError when the header has a `status` column: the file is already
// corrected (docs/contract.md), and correcting or fitting it again would apply the
// corrections twice.
// (`stats` without a model shows a corrected file as it is, its one stage;
// `stats --model` and `plot` refuse it.)
void refuse_corrected_input(const SolutionsReader& header);
// The same check on a file's header line, read alone.
void refuse_corrected_file(const std::string& path);
// True when the file's header has a `status` column (a corrected file).
bool is_corrected_file(const std::string& path);

// Where rows come from: calls its argument for every row, in order. A file is
// [&](auto& fn) { for_each_solution(path, fn, label); }; the Python module
// passes arrays (python/src/arguments.cpp, source_of).
using RowSource = std::function<void(const std::function<void(const SolutionRecord&)>&)>;

// The rows of a vector, in its order (the vector outlives the source).
RowSource rows_in(const std::vector<SolutionRecord>& rows);

// Calls fn for every data row of the file, in file order. Throws InputError
// for a malformed row. label: shown with the progress on a terminal.
void for_each_solution(const std::string& path, const std::function<void(const SolutionRecord&)>& fn,
                       const std::string& label);

// The same reading, for a caller that needs more than the record: on_header
// is called once with the header (its columns, before any row), fn for every
// row with the reader that read it (its fields() are the row's fields as
// written). The file is read in blocks (BlockReader): memory bounded whatever
// its size. label: shown with the progress on a terminal; empty: no progress.
void for_each_solution_row(const std::string& path, const std::function<void(const SolutionsReader& header)>& on_header,
                           const std::function<void(const SolutionsReader& reader, const SolutionRecord&)>& fn,
                           const std::string& label);

// ---- Writing (docs/contract.md, "Solutions file")

// The columns of a solutions file in the order ascorr writes them (simulate,
// Python's write_solutions()); a corrected file adds kStatusColumn last.
inline constexpr std::array<std::string_view, 14> kSolutionsColumns = {
    "t", "chu", "qw", "qx", "qy", "qz", "t_chu", "t_029", "t_032", "vx", "vy", "vz", "flags", "confidence"};
inline constexpr std::string_view kStatusColumn = "status";
// Their header line, without its line end.
inline constexpr std::string_view kSolutionsHeader = "t,chu,qw,qx,qy,qz,t_chu,t_029,t_032,vx,vy,vz,flags,confidence";
// True for a column of kSolutionsColumns or kStatusColumn: one a writer
// writes from its own values (any other column is an extra one, kept as written).
bool is_solutions_column(std::string_view name) noexcept;

// A header's column that is not one ascorr reads but looks like one the header
// lacks: a misspelt `T_CHU` would leave every row without temperatures and
// nothing would name it. Looks like: the same name in another case, or, for
// the names of five letters or more (t_chu, t_029, t_032, flags, confidence,
// status), one or two letters inserted, deleted, replaced or swapped (`tchu`,
// `t_29`, `confidance`); the short names (t, chu, qw..qz, vx..vz) only by case,
// as a short extra column (`x`, `id`) is one or two edits from one of them.
// The solutions reader refuses such a header (InputError at file:1:column), and
// Python's from_frame() the same columns, with the same words.
struct NearMiss {
    std::size_t column = 0;  // index in names
    std::string_view known;  // the column it looks like
    std::string message;     // "column 'T_CHU' is not a column ascorr reads ..."
};
std::optional<NearMiss> near_miss_column(const std::vector<std::string>& names);

// One row's values, NaN where not available.
struct SolutionValues {
    double t = 0.0;
    std::string_view chu;  // written as given: one plain CSV field
    Quaternion<double> q_chu_icrf{};
    std::array<double, 3> temperature{};  // t_chu, t_029, t_032
    bool no_temperatures = false;         // a source without thermistors: empty fields, as velocities
    std::array<double, 3> v_sc_kms{};     // vx, vy, vz
    long long flags = 0;
    double confidence = 0.0;  // arcsec
};

// Appends the row's fields in kSolutionsColumns' order, without a line end
// (a caller appends its extra columns, a status and '\n'). Numbers are written
// with the fewest digits that read back exactly (std::to_chars); NaN
// temperatures as "nan" (empty with no_temperatures), NaN velocities and
// confidence as empty fields, as the contract writes "not available"; NaN time
// or quaternion components as "nan".
void append_solution_fields(std::string& out, const SolutionValues& row);

}  // namespace ascorr::host
