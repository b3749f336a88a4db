#include "ascorr_host/correct/solution_input.hpp"

#include <cstdio>
#include <string>

#include "ascorr_host/correct/earth_velocity.hpp"
#include "ascorr_text/c_format.hpp"
#include "ascorr_text/number_fields.hpp"

namespace ascorr::host {

std::string velocity_problem(const SolutionRecord& rec) {
    if (rec.velocity_components != 0 && rec.velocity_components != 3) {
        return "only " + std::to_string(rec.velocity_components) + " of vx,vy,vz given";
    }
    if (rec.velocity_components == 3 && !in_ephemeris_span(rec.t)) {
        char span[80];
        text::c_snprintf(span, sizeof span, "%.4g .. %.4g", kEphemerisFirstT, kEphemerisEndT);
        // t as written (the shortest text that reads back as it), never rounded
        return "t = " + text::number_text(rec.t) + " s is outside the span of the Earth ephemeris (1900-2100, " + span +
               " s since J2000 TT; a time in ms?)";
    }
    return {};
}

}  // namespace ascorr::host
