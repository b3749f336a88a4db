// ascorr_host/correct/correct_row.hpp: one recorded row through the core, as
// `ascorr correct` does it.
//
// The per-row code path shared by `ascorr correct` (correct_file.cpp) and the
// Python module (python/src/bind_correct.cpp): the row's inputs converted once to
// the scalar T (solution_input.hpp), with --states the on-board velocity
// service's velocity for a row without its own (states_velocity.hpp), the
// epoch pipeline's correction stage (correct_stage(), pipeline/
// solution_stage.hpp: the core and the service's bits), and the status bits
// the core cannot know (a velocity with 1 or 2 of
// its 3 components: the core saw "not available", the row gets 4 + 32; the
// service's 4, 4|512, 4|32). Compiled once, in ascorr_host, for double,
// float and Q30, so both callers run the same object code and agree bit for
// bit.
#pragma once

#include "ascorr/core/correct.hpp"
#include "ascorr/core/fixed_point.hpp"
#include "ascorr/core/quaternion.hpp"
#include "ascorr/core/sun_term.hpp"
#include "ascorr/nav/sun_direction.hpp"
#include "ascorr/pipeline/solution_stage.hpp"
#include "ascorr_host/correct/earth_velocity.hpp"
#include "ascorr_host/correct/states_velocity.hpp"
#include "ascorr_host/formats/solutions_csv.hpp"

namespace ascorr::host {

template <typename T>
struct RowCorrection {
    SolutionInput<T> in;            // what the core was given (for messages)
    StatusBits status;              // the core's bits, plus 4 + 32 for a partial velocity
    Quaternion<double> q_chu_icrf;  // corrected; the input exactly when status has kRejected
    bool from_states;               // the velocity came from the states (the row had none)
    StatusBits service;             // then the service's bits (0: a usable velocity)
    bool sun_unknown;               // the model's Sun term could not be evaluated: thermal skipped (128)
};

// What a row whose Sun term cannot be evaluated is told, after its place.
inline constexpr const char* kSunUnknownText =
    "t outside the Sun ephemeris' span (2000-2051): the model's Sun term cannot be evaluated: thermal skipped "
    "(status 128)";

// What the model's Sun term (sun, nullptr: none; core/sun_term.hpp) does to
// a row the core corrected with status core_status: nothing (the thermal
// stage did not apply, or the head has no term: present, as sun_term_of
// decides it in double), apply at s_icrf, or, where the Sun's direction is
// unknown (t outside nav/sun_direction.hpp's span, 2000-2051), skip the
// row's thermal stage with status 128 (kThermalOutOfRange: the model's angle
// outside its domain); for correct_row and stats alike.
struct RowSunTerm {
    bool apply = false;
    bool unknown = false;
    Vector3<double> s_icrf{};
};
template <typename T>
RowSunTerm row_sun_term(const SunTermModel<T>* sun, StatusBits core_status, std::uint8_t head, double t) {
    RowSunTerm s;
    if (sun == nullptr || (core_status & status::kThermalApplied) == 0U || head >= kMaxHeads || !sun->present[head]) {
        return s;
    }
    s.apply = nav::sun_direction_icrf(t, s.s_icrf);
    s.unknown = !s.apply;
    return s;
}

// correct_stage() (pipeline/solution_stage.hpp) with the contract's Sun term
// (docs/contract.md, "The Sun term"; sun nullptr: none) of head in.head at
// t, in T: where the thermal stage applied, the core's result turned by the
// term (its coefficients as the caller holds them in T, sun_term_of<T>, and ŝ
// rounded to T once); where ŝ is unknown, the stage undone (the aberration's
// result) and 128, sun_unknown set. For correct_row and replay's double
// reference alike.
template <typename T>
CorrectedSolution<T> correct_stage_with_sun(SolutionInput<T>& in, const pipeline::VelocityAnswer<T>& v,
                                            const CorrectionConfig<T>& cfg, const SunTermModel<T>* sun, double t,
                                            bool& sun_unknown);
extern template CorrectedSolution<double> correct_stage_with_sun(SolutionInput<double>&,
                                                                 const pipeline::VelocityAnswer<double>&,
                                                                 const CorrectionConfig<double>&,
                                                                 const SunTermModel<double>*, double, bool&);

// earth: used when the aberration stage is on (cfg.aberration) and the row
// has its velocity; states: nullptr without --states (one per thread: it
// keeps the service's state between rows); sun: the model's Sun term in the
// core's scalar (sun_term_of<T>, converted once per model, not per row),
// applied after the core where its thermal stage was (correct_stage_with_sun).
template <typename T>
RowCorrection<T> correct_row(const SolutionRecord& rec, EarthVelocity* earth, const CorrectionConfig<T>& cfg,
                             StatesVelocity<T>* states, const SunTermModel<T>* sun = nullptr);
extern template RowCorrection<double> correct_row(const SolutionRecord&, EarthVelocity*,
                                                  const CorrectionConfig<double>&, StatesVelocity<double>*,
                                                  const SunTermModel<double>*);
extern template RowCorrection<float> correct_row(const SolutionRecord&, EarthVelocity*, const CorrectionConfig<float>&,
                                                 StatesVelocity<float>*, const SunTermModel<float>*);
extern template RowCorrection<Q30> correct_row(const SolutionRecord&, EarthVelocity*, const CorrectionConfig<Q30>&,
                                               StatesVelocity<Q30>*, const SunTermModel<Q30>*);

}  // namespace ascorr::host
