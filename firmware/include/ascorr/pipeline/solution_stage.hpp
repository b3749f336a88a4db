// ascorr/pipeline/solution_stage.hpp: one solution through the velocity,
// correction and status stages.
//
// Conventions: the velocity stage's answer (VelocityAnswer) is either the
// velocity that came with the solution (given_velocity: a velocity update on
// the link, a row's own vx,vy,vz) or the on-board velocity service's for the
// solution's time (from_service: velocity_service.hpp); the correction stage
// is correct_solution() (core/correct.hpp) or a caller's out-of-line entry of
// it; the status stage adds the service's bits (with_service_status: 512
// stale, 32 invalid) when the service was asked. Every caller that corrects a
// solution (the flight loop, the link server, `ascorr correct`, the
// self-calibration run, replay's host side) goes through correct_stage(), so
// they agree bit for bit.
#pragma once

#include "../core/correct.hpp"
#include "../nav/velocity_service.hpp"

namespace ascorr::pipeline {

// What the velocity stage gave one solution.
template <typename T>
struct VelocityAnswer {
    ObserverVelocity<T> velocity;
    StatusBits service;  // the service's bits (4, 4|512, 4|32); 0 when not asked
    bool from_service;   // the service was asked: its bits join the status
};

// The velocity that came with the solution.
template <typename T>
constexpr VelocityAnswer<T> given_velocity(const ObserverVelocity<T>& v) noexcept {
    return {v, 0U, false};
}

// The service's velocity for the solution's time.
template <typename T>
constexpr VelocityAnswer<T> from_service(const ServiceVelocity<T>& v) noexcept {
    return {v.velocity, v.status, true};
}

// The library's correction stage, inline.
struct InlineCorrect {
    template <typename T>
    CorrectedSolution<T> operator()(const SolutionInput<T>& in, const CorrectionConfig<T>& cfg) const noexcept {
        return correct_solution(in, cfg);
    }
};

// Stage 2 into the core's input.
template <typename T>
constexpr void take_velocity(SolutionInput<T>& in, const VelocityAnswer<T>& v) noexcept {
    in.velocity = v.velocity;
}

// Stage 4: the service's bits join the core's when the service was asked.
template <typename T>
constexpr StatusBits status_stage(StatusBits core, const VelocityAnswer<T>& v, bool aberration) noexcept {
    return with_service_status(core, v.service, v.from_service && aberration);
}

// Stages 2–4: the velocity into the input, the correction, the status. `in`
// keeps the velocity the core was given (callers explain it).
template <typename T, typename Correct = InlineCorrect>
CorrectedSolution<T> correct_stage(SolutionInput<T>& in, const VelocityAnswer<T>& v, const CorrectionConfig<T>& cfg,
                                   const Correct& correct = Correct{}) noexcept {
    take_velocity(in, v);
    CorrectedSolution<T> c = correct(in, cfg);
    c.status = status_stage(c.status, v, cfg.aberration);
    return c;
}

}  // namespace ascorr::pipeline
