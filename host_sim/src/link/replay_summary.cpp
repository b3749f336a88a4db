// `ascorr replay`'s summary: whether the target agreed with the host, in what not, and the JSON line.
#include <string>

#include "ascorr_host/link/replay.hpp"
#include "ascorr_text/c_format.hpp"

namespace ascorr::host {

bool agrees(const ReplaySummary& s) {
    return s.mismatches == 0 &&
           (!s.self_calibrate || (s.version_mismatches == 0 && s.history_mismatches == 0 && s.report_matches)) &&
           (!s.combined || s.combined_mismatches == 0);
}

std::string disagreement(const ReplaySummary& s) {
    std::string out = "replay: the target disagrees with the host: " + std::to_string(s.mismatches) + " answer(s)";
    if (s.self_calibrate) {
        out += ", " + std::to_string(s.version_mismatches) + " model version(s), " +
               std::to_string(s.history_mismatches) + " model(s), the report " +
               (s.report_matches ? "agrees" : "differs");
    }
    if (s.combined) {
        out += ", " + std::to_string(s.combined_mismatches) + " combined attitude(s)";
    }
    return out + " (the outputs are written; see the messages above)";
}

std::string to_json(const ReplaySummary& s) {
    char buf[512];
    text::c_snprintf(buf, sizeof buf,
                     "{\"frames\": %zu, \"returned\": %zu, \"mismatches\": %zu, \"max_error_arcsec\": %.6g, "
                     "\"crc_errors\": %zu, \"retries\": %zu, \"instructions_per_solution\": %.1f, \"restarts\": %zu, "
                     "\"injected_faults\": %zu",
                     s.frames, s.returned, s.mismatches, s.max_error_arcsec, s.crc_errors, s.retries,
                     s.instructions_per_solution, s.restarts, s.injected);
    std::string out = buf;
    if (s.self_calibrate) {
        text::c_snprintf(buf, sizeof buf,
                         ", \"self_calibration\": {\"models\": %zu, \"version_mismatches\": %zu, "
                         "\"history_mismatches\": %zu, \"report_matches\": %s}",
                         s.models, s.version_mismatches, s.history_mismatches, s.report_matches ? "true" : "false");
        out += buf;
    }
    if (s.combined) {
        text::c_snprintf(buf, sizeof buf,
                         ", \"combined\": {\"epochs\": %zu, \"mismatches\": %zu, \"instructions_per_epoch\": %.1f}",
                         s.combined_epochs, s.combined_mismatches, s.combination_instructions_per_epoch);
        out += buf;
    }
    return out + "}";
}

}  // namespace ascorr::host
