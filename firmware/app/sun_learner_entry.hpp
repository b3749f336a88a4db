// firmware/app/sun_learner_entry.hpp: the self-calibration's Sun-term learner
// (ascorr/calib/sun_learner.hpp) compiled once for the DPU, out of line.
//
// Conventions: as SunLearner::take and step (TT µs since J2000; the frame
// heads' q_chu_icrf as the active polynomial corrected them; double,
// software floating point on both targets). In its own translation unit
// (sun_learner_entry.cpp) so that its instructions per fed cycle and per idle
// step (bench/target_bench.cpp) and its stack (-fstack-usage) are measured
// alone. In the flight image: flight_cycle.hpp's learner.
#pragma once

#include <cstdint>

#include "ascorr/calib/sun_learner.hpp"

namespace ascorr::app {

bool sun_learner_take(calib::SunLearner& learner, std::int64_t t_us,
                      const Quaternion<double> (&q_chu_icrf)[calib::kFrameHeads]) noexcept;
bool sun_learner_step(calib::SunLearner& learner) noexcept;

}  // namespace ascorr::app
