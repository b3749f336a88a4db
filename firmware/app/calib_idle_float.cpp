// firmware/app/calib_idle_float.cpp: the estimator's idle-time part (float estimator), out of line.
#include "calib_entry.hpp"

namespace ascorr::app {

bool calib_step_float(FlightEstimator<float>& e) noexcept {
    return e.step();
}

}  // namespace ascorr::app
