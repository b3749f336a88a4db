// firmware/app/sun_learner_entry.cpp: the Sun-term learner, out of line.
#include "sun_learner_entry.hpp"

namespace ascorr::app {

bool sun_learner_take(calib::SunLearner& learner, std::int64_t t_us,
                      const Quaternion<double> (&q_chu_icrf)[calib::kFrameHeads]) noexcept {
    return learner.take(t_us, q_chu_icrf);
}

bool sun_learner_step(calib::SunLearner& learner) noexcept {
    return learner.step();
}

}  // namespace ascorr::app
