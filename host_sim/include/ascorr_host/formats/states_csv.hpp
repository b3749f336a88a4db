// ascorr_host/formats/states_csv.hpp: the states file (docs/contract.md, "States file").
//
// Header t,x,y,z,vx,vy,vz (by name, unknown columns ignored), one row per
// spacecraft state in increasing time: TT seconds since J2000, km, km/s, in
// the frame the caller names (itrf: a GNSS receiver's; gcrs: an uplinked
// state vector). One row is a valid file.
//
// Malformed input (missing column, empty file, no rows, a field that is not a
// number, a truncated row or extra fields, a non-finite or out-of-range time)
// throws InputError with file:line:column. A well-formed state that the
// on-board service refuses (non-finite or implausible position or velocity,
// time going backwards, a duplicate time: velocity_service.hpp) is reported
// through Diagnostics with file:line and its verdict, and counted; the others
// are kept. The verdicts are the on-board code's, applied in file order, so
// the host keeps exactly the states a DPU given the same feed keeps.
//
// With skip_bad (--skip-bad), a malformed data row is reported through
// Diagnostics with file:line:column and counted instead (the header stays
// required). A file in which no state is accepted (every row refused or
// skipped) gives the velocity of no row: it throws InputError naming the counts.
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "ascorr/nav/velocity_service.hpp"
#include "ascorr_host/formats/diagnostics.hpp"

namespace ascorr::host {

struct StateRecord {
    std::size_t line;
    TtTime t;
    Vector3<double> r_km;
    Vector3<double> v_kms;
};

struct StatesFile {
    std::string path;
    StateFrame frame = StateFrame::kItrf;
    std::vector<StateRecord> accepted;  // in increasing time
    StateCounts counts{};               // the on-board verdicts, file order
    std::size_t malformed = 0;          // rows skipped (skip_bad only)

    std::size_t refused() const noexcept {
        return static_cast<std::size_t>(counts.not_finite) + counts.implausible + counts.time_backwards +
               counts.duplicate_time;
    }
};

StatesFile read_states_file(const std::string& path, StateFrame frame, Diagnostics& diag, bool skip_bad = false);

// "non-finite position or velocity", ... for messages.
const char* describe(StateVerdict v) noexcept;

}  // namespace ascorr::host
