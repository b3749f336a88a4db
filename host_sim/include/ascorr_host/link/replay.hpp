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
#pragma once

#include <cstdint>
#include <iosfwd>
#include <string>
#include <vector>

namespace ascorr::host {

struct ReplayOptions {
    std::string target;    // a replay name of ascorr_host/link/qemu_targets.hpp, loopback-float, or a serial device
    std::string firmware;  // qemu targets: the link image; empty: the one of this build tree
    std::string in;
    std::string model;
    std::string out;
    std::string states;        // --states: spacecraft states sent over the link in time order; empty: none
    bool states_gcrs = false;  // --states-frame gcrs (default itrf)
    // --max-propagation: the target's horizon is its firmware's (the velocity
    // service's default); another value is refused, not silently ignored.
    double max_propagation_s = 21600.0;
    double inject_errors = 0.0;  // fraction of frames faulted, each direction
    bool realtime = false;       // pace by the rows' t instead of as fast as the link allows
    int timeout_ms = 0;          // before a resend; 0: the target's default (serial 500, qemu 20, loopback 1)
    int max_attempts = 20;
    std::uint64_t seed = 1;
    unsigned baud = 115200;
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
};

ReplaySummary replay(const ReplayOptions& opt, std::ostream& log);
// The QEMU command line that runs a link image with UART0 on stdin/stdout.
std::vector<std::string> qemu_link_command(const std::string& machine, const std::string& image);
// The link image of this build tree for a target (a cpu of toolchain/targets.txt).
std::string default_link_firmware(const std::string& target);
std::string to_json(const ReplaySummary& s);

}  // namespace ascorr::host
