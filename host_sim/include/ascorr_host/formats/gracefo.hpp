// ascorr_host/formats/gracefo.hpp: GRACE Follow-On Level-1 star-camera
// products in this contract's files (`ascorr import gracefo`, Python
// import_gracefo(); docs/contract.md, "Real flight data").
//
// The products (NASA/JPL, GRACE-FO Level-1 Data Product User Handbook, JPL
// D-56935; the variables' own descriptions in each file's YAML header) are
// ASCII: a header ending in `# End of YAML header` (or, in older files, a
// fixed header ending in `END OF HEADER`), then one record per line,
// whitespace-separated. Times are seconds past 2000-01-01 12:00:00 (OBC time,
// receiver time or GPS time as the product says). Flag bytes are written as
// eight binary digits, bit 0 rightmost.
//  - SCA1A, 16 fields: rcvtime_intg rcvtime_frac(µs) GRACEFO_id sca_id
//    sca_desig qw qx qy qz nlocks nstars sca_confid null null sca_mode qualflg.
//    The quaternion rotates the camera frame (SCF) into inertial; the time is
//    the OBC time at which the record was received.
//  - QSA1B, 9 fields: time GRACEFO_id sca_id qw qx qy qz qual flags: the
//    heads' mountings, the quaternion q_chu_crf as ascorr takes it (the CRF
//    being the satellite's science reference frame, SRF).
//  - TIM1B, 8 fields: obctime GRACEFO_id TS_suppid rcvtime_intg
//    rcvtime_frac(ns) first_icu final_icu qualflg: OBC time to receiver time.
//  - CLK1B, 8 fields: rcv_time GRACEFO_id clock_id eps_time eps_err eps_drift
//    drift_err qualflg: GPS time = receiver time + eps_time.
//  - SCA1B, 9 fields: gps_time GRACEFO_id sca_config qw qx qy qz qual_rss
//    qualflg: JPL's combined attitude (with the gyros); the quaternion rotates
//    the SRF into inertial.
// Quaternion conventions were checked on the public sample (the three heads
// agree to their stale mountings, 30-140″, only this way; docs/ground.md).
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "ascorr/core/quaternion.hpp"
#include "ascorr_host/formats/atomic_file.hpp"
#include "ascorr_host/formats/mountings_csv.hpp"
#include "ascorr_host/formats/solutions_csv.hpp"

namespace ascorr::host {

// TT − GPS time (s): TAI − GPS 19 s, TT − TAI 32.184 s.
inline constexpr double kTtMinusGpsS = 51.184;
// The default --time-offset for GRACE-FO SCA1A (s): none. On the public
// sample a latency is not observable (the combined attitude against SCA1B at
// its own epochs is flat over ±1 s: docs/figures/gracefo-jpl.json; the
// −0.28 s an earlier comparison found was interpolation averaging two epochs'
// noise): tools/gracefo/calibrate_time_offset.py, docs/ground.md "Real
// flight data".
inline constexpr double kGracefoTimeOffsetS = 0.0;
inline constexpr double kMaxTimeOffsetS = 10.0;  // --time-offset in [-10, 10]

// The solutions file's flags of an imported record (the contract's bits):
inline constexpr long long kGracefoInvalid = 4;       // sca_mode bit 0 clear, or qualflg bit 0 set
inline constexpr long long kGracefoFalseStars = 2;    // sca_mode or qualflg bit 3: non-stellar object
inline constexpr long long kGracefoNotCorrected = 8;  // sca_mode bit 6 clear: aberration not corrected on board
// sca_mode or qualflg bit 2, "add 1/4 of star camera integration period to
// rcv_time": the integration period is in no product, so the record's time
// cannot be made right; it is kept, not clean.
inline constexpr long long kGracefoTimeTagShift = 16;
// The solutions file's columns after the contract's: the record's quality
// fields as they are (sca_mode and qualflg as integers 0-255, sca_confid,
// the tracker's own 0-255 code, not a misfit in arcsec: `confidence` is
// empty, so that a record the product calls valid is clean).
inline constexpr std::string_view kGracefoColumns = "sca_mode,qualflg,sca_confid";

struct Sca1aRecord {
    std::size_t line = 0;
    std::int64_t obc_s = 0;           // rcvtime_intg
    std::int64_t obc_us = 0;          // rcvtime_frac
    char satellite = 0;               // 'C' or 'D'
    std::uint8_t head = 0;            // sca_id − 1
    Quaternion<double> q_icrf_chu{};  // as written: SCF into inertial
    int confidence = 0;               // sca_confid
    std::uint8_t mode = 0;            // sca_mode
    std::uint8_t quality = 0;         // qualflg
};

// OBC time → GPS time: TIM1B (OBC → receiver time) and CLK1B (receiver →
// GPS), each linear between its records; without a product, no change.
class GracefoClock {
public:
    // tim1b, clk1b: the products' files (several days: merged in time
    // order), or none; satellite: the SCA1A files'. TIM1B records without a
    // mapping (qualflg bit 3 or 6) are not used. InputError for a bad record,
    // or fewer than two usable records.
    GracefoClock(const std::vector<std::string>& tim1b, const std::vector<std::string>& clk1b, char satellite);
    // GPS time of OBC time obc_s + obc_us µs; within two records' usual
    // spacing before the first or after the last record, that record's
    // offset. Throws InputError naming the SCA1A record (file, line) when a
    // product does not cover it (further out, or in a gap of more than two
    // records' spacing).
    double gps_time(std::int64_t obc_s, std::int64_t obc_us, const std::string& file, std::size_t line) const;

private:
    struct Table {
        std::string name;            // for messages
        std::vector<double> at;      // the product's own time (OBC, receiver)
        std::vector<double> offset;  // to add (s)
        double max_step = 0.0;       // the records' usual spacing × 2
        bool before_first = true;    // the first record's offset holds before it (CLK1B: qualflg bit 1 clear)
        bool after_last = true;      // the last record's offset holds after it (CLK1B: qualflg bit 0 clear)
    };
    static double offset_at(const Table& t, double x, const std::string& file, std::size_t line);
    std::optional<Table> tim_;
    std::optional<Table> clk_;
};

struct GracefoOptions {
    std::vector<std::string> sca1a;
    std::string qsa1b;
    std::vector<std::string> tim1b;  // none: OBC time taken as receiver time
    std::vector<std::string> clk1b;  // none: receiver time taken as GPS time (an extension)
    std::string sca1b;               // empty: no reference
    std::string out;                 // solutions file
    std::string mountings;           // mountings file
    std::string reference;           // attitude file of SCA1B, with sca1b
    double time_offset_s = kGracefoTimeOffsetS;
};

struct GracefoSummary {
    char satellite = 0;
    std::size_t records = 0;    // SCA1A records written
    std::size_t not_clean = 0;  // of them with flags != 0
    bool tim1b = false;         // the clock products used
    bool clk1b = false;
    std::size_t reference = 0;  // SCA1B records
    double first_t = 0.0;       // TT of the first and last record
    double last_t = 0.0;
};
std::string describe(const GracefoSummary& s);

// What an import produces, row by row (the CLI writes files, Python arrays).
struct GracefoSink {
    std::function<void(const SolutionValues&, const Sca1aRecord&)> solution;
    std::function<void(double t, const Quaternion<double>& q_crf_icrf)> reference;  // with sca1b
};

// The import: mountings from QSA1B, then every SCA1A record (the files in
// the order of their first records) and every SCA1B record to the sink.
// InputError (file:line:column) for a malformed record, a time that goes back
// (within a file or from one file to the next), files of two satellites, or a
// clock product that does not cover a record.
MountingsFile import_gracefo(const GracefoOptions& opt, const GracefoSink& sink, GracefoSummary& summary);

// `ascorr import gracefo`: the files of opt into outputs (opened from
// gracefo_outputs, committed by the caller).
GracefoSummary import_gracefo_files(const GracefoOptions& opt, OutputSet& outputs);
std::vector<NamedPath> gracefo_inputs(const GracefoOptions& opt);
std::vector<NamedPath> gracefo_outputs(const GracefoOptions& opt);

}  // namespace ascorr::host
