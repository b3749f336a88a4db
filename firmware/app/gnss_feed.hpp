// firmware/app/gnss_feed.hpp: the simulated GNSS receiver of the flight application.
//
// Conventions: states are ITRF position (km) and velocity (km/s) with a TT
// time tag (tt_time.hpp), as a receiver delivers them at about 1 Hz. QEMU's
// boards have no receiver, so the feed replays the recorded orbit in flash
// (recorded_orbit.hpp, generated with ERFA's full ITRS/GCRS transformation):
// poll() hands out, in table order, each state whose time has come. The
// table's order is the receiver's, not necessarily increasing: the velocity
// service refuses a state that goes back in time (and counts it).
#pragma once

#include <cstddef>
#include <cstdint>

#include "ascorr/core/vector3.hpp"
#include "ascorr/nav/tt_time.hpp"
#include "recorded_orbit.hpp"

namespace ascorr::app {

struct GnssState {
    TtTime t;
    Vector3<double> r_itrf_km;
    Vector3<double> v_itrf_kms;
};

class GnssFeed {
public:
    // The next state due at `now` (its time ≤ now, or earlier in the table than one that is); false if none.
    bool poll(TtTime now, GnssState& out) noexcept {
        constexpr std::size_t n = sizeof kRecordedOrbit / sizeof kRecordedOrbit[0];
        if (next_ >= n) {
            return false;
        }
        const RecordedState& s = kRecordedOrbit[next_];
        if (s.t_tt_us > now.us && (next_ == 0U || s.t_tt_us > kRecordedOrbit[next_ - 1U].t_tt_us)) {
            return false;  // not yet received
        }
        out = {{s.t_tt_us},
               {s.r_itrf_km[0], s.r_itrf_km[1], s.r_itrf_km[2]},
               {s.v_itrf_kms[0], s.v_itrf_kms[1], s.v_itrf_kms[2]}};
        ++next_;
        return true;
    }

private:
    std::size_t next_ = 0U;
};

}  // namespace ascorr::app
