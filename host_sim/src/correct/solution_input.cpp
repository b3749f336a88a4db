#include "ascorr_host/correct/solution_input.hpp"

#include <cstdio>

#include "ascorr_host/correct/earth_velocity.hpp"
#include "ascorr_text/c_format.hpp"

namespace ascorr::host {

std::string velocity_problem(const SolutionRecord& rec) {
    if (rec.velocity_components != 0 && rec.velocity_components != 3) {
        return "only " + std::to_string(rec.velocity_components) + " of vx,vy,vz given";
    }
    if (rec.velocity_components == 3 && !in_ephemeris_span(rec.t)) {
        char buf[200];
        text::c_snprintf(buf, sizeof buf,
                         "t = %.17g s is outside the span of the Earth ephemeris (1900-2100, %.4g .. %.4g s since "
                         "J2000 TT; a time in ms?)",
                         rec.t, kEphemerisFirstT, kEphemerisEndT);
        return buf;
    }
    return {};
}

}  // namespace ascorr::host
