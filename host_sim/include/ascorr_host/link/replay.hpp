// ascorr_host/link/replay.hpp: the `ascorr replay` job (hardware in the loop).
//
// Streams a recorded solutions file to a target over the link: the model once,
// then per row the velocity and the head's temperatures (when they change) and
// the solution. Every returned solution is compared with the host core in the
// same scalar type (bit for bit) and with the double reference (in arcsec),
// and written in the corrected-file format. With states, the accepted states
// (states_csv.hpp: the on-board checks) go to the target before the first
// solution at or after their time, and rows without their own velocity ask the
// target to compute it; the host mirrors the target's service in the same
// scalar (and in double for the reference) with the same states in the same order.
//
// With self_calibrate the target runs its estimator on the solutions (link
// CALIB_START; each solution says whether it is clean and whether its t is
// one the on-board clock holds), starting from the model if one is given,
// otherwise from none. The host runs the same estimator over the file
// (self_calibration.hpp, the run of `ascorr correct --self-calibrate` in the
// target's scalar) and compares, for each solution, the answer and the model
// version used; for each model the target adopts, its coefficients, CRC and
// time (CALIB_MODEL); and at the end the estimator's report. The target's
// model history is written to model_history, when given.
//
// With mountings and combined the target also combines each epoch (rows whose
// t agree to the millisecond) into the bench's attitude (MOUNTING_LOAD, then
// COMBINE_REQUEST after each epoch's last solution: the epoch pipeline's stage
// 6); the host runs the same pipeline beside it and compares each combined
// attitude bit for bit; the combined file (docs/contract.md) is the target's,
// with the formal σ of the host's tables (they depend on the head set only).
#pragma once

#include <array>
#include <cstdint>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "ascorr_host/analysis/combine.hpp"
#include "ascorr_host/formats/atomic_file.hpp"

namespace ascorr::host {

// The in-process targets: the firmware's link server in float (the M4F's
// scalar) or Q30 (the M3's), behind a loopback, for tests.
inline constexpr const char* kLoopbackFloat = "loopback-float";
inline constexpr const char* kLoopbackFixed = "loopback-fixed";

struct ReplayOptions {
    std::string target;  // a replay name of ascorr_host/link/qemu_targets.hpp, kLoopbackFloat/Fixed, or a serial device
    std::string firmware;  // qemu targets: the link image; empty: the one of this build tree
    std::string in;
    std::string model;
    std::string out;
    std::string states;        // --states: spacecraft states sent over the link in time order; empty: none
    bool states_gcrs = false;  // --states-frame gcrs (default itrf)
    // --max-propagation: the target's velocity service's horizon (SERVICE_CONFIG);
    // nullopt: its firmware's (21600 s).
    std::optional<double> max_propagation_s;
    bool self_calibrate = false;           // --self-calibrate
    std::string model_history;             // --model-history: the target's models; empty: not written
    double time_constant_days = 30;        // --time-constant (calib::EstimatorConfig's default)
    std::optional<double> orbit_period_s;  // --orbit-period; nullopt: from the rows' speeds
    std::string mountings;                 // --mountings: with --combined, the combiner's (sigmas given)
    std::string combined;                  // --combined: the target's combined attitude per epoch; empty: none
    GateOptions gate;                      // --gate-sigmas, --gate-floor: the target combiner's gate
    double inject_errors = 0.0;            // fraction of frames faulted, each direction
    bool realtime = false;                 // pace by the rows' t instead of as fast as the link allows
    int timeout_ms = 0;                    // before a resend; 0: the target's default (serial 500, qemu 20, loopback 1)
    int max_attempts = 20;
    std::uint64_t seed = 1;
    unsigned baud = 115200;
    // --lag (self-calibration only): the lags the target's estimator learns
    // with (CALIB_START's); nullopt: the model's lag_s, or none.
    std::optional<std::array<double, kMaxHeads>> lag_s;
    // --sun-term auto (self-calibration only): the target learns the Sun
    // term beside its estimator (CALIB_START's sun_term), and the host's run
    // with the target's thinning (calib::kSunLearnOnBoardIntervalUs).
    bool sun_auto = false;
};

struct ReplaySummary {
    std::size_t frames = 0;         // solutions sent
    std::size_t returned = 0;       // corrected solutions accepted
    std::size_t mismatches = 0;     // differ from the host core in the same scalar type
    double max_error_arcsec = 0.0;  // against the double reference, over rows both correct
    std::size_t crc_errors = 0;     // corrupted frames detected, both directions
    std::size_t retries = 0;
    double instructions_per_solution = 0.0;  // mean over solutions with both stages applied
    std::size_t restarts = 0;
    std::size_t injected = 0;
    // --self-calibrate: what the target's estimator did, against the host's.
    bool self_calibrate = false;
    std::size_t models = 0;              // models the target made active (its history's versions)
    std::size_t version_mismatches = 0;  // solutions corrected with another model version than the host's
    std::size_t history_mismatches = 0;  // models differing from the host's (coefficients, CRC, time) or missing
    bool report_matches = false;         // the final report equals the host's, field for field
    // --combined: the target's combined attitudes against the host's.
    bool combined = false;
    std::size_t combined_epochs = 0;                // rows of the combined file
    std::size_t combined_mismatches = 0;            // epochs whose combination differs from the host's
    double combination_instructions_per_epoch = 0;  // mean over epochs of two or more heads
    // The target's stack at the end (STACK_REPORT): the most bytes used since
    // its boot, of its size; 0, 0: the target does not measure it, or (a
    // firmware from before the message) does not report it.
    std::uint32_t target_stack_bytes = 0;
    std::uint32_t target_stack_size = 0;
};

// The command's files (atomic_file.hpp's OutputSet): its inputs, and its
// outputs by option: "--out", and "--model-history" with self_calibrate.
std::vector<NamedPath> replay_inputs(const ReplayOptions& opt);
std::vector<NamedPath> replay_outputs(const ReplayOptions& opt);

// Writes into outputs (opened from replay_outputs, committed by the caller).
ReplaySummary replay(const ReplayOptions& opt, OutputSet& outputs, std::ostream& log);
// The same with its own OutputSet, committed at the end.
ReplaySummary replay(const ReplayOptions& opt, std::ostream& log);
// The same over a transport already open (a link a caller set up, a test
// double); opt.target only names it in messages. The target's HELLO says its
// scalar; timeout_ms 0 means 500.
class Transport;
ReplaySummary replay_over(const ReplayOptions& opt, Transport& transport, std::ostream& log);
// The QEMU command line that runs a link image with UART0 on stdin/stdout.
std::vector<std::string> qemu_link_command(const std::string& machine, const std::string& image);
// The link image of this build tree for a target (a cpu of toolchain/targets.txt).
std::string default_link_firmware(const std::string& target);
std::string to_json(const ReplaySummary& s);
// Whether the target agreed with the host in everything compared (answers;
// with self-calibration, model versions, models and the report); and, if not,
// one line saying in what.
bool agrees(const ReplaySummary& s);
std::string disagreement(const ReplaySummary& s);

}  // namespace ascorr::host
