// firmware/app/calib_idle_fixed.cpp: the estimator's idle-time part (Q30 estimator), out of line.
#include "calib_entry.hpp"

namespace ascorr::app {

bool calib_step_fixed(FlightEstimator<Q30>& e) noexcept {
    return e.step();
}

}  // namespace ascorr::app
