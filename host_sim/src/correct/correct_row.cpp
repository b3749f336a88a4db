#include "ascorr_host/correct/correct_row.hpp"

#include "ascorr/pipeline/solution_stage.hpp"
#include "ascorr_host/correct/solution_input.hpp"

namespace ascorr::host {

template <typename T>
CorrectedSolution<T> correct_stage_with_sun(SolutionInput<T>& in, const pipeline::VelocityAnswer<T>& v,
                                            const CorrectionConfig<T>& cfg, const SunTermModel<T>* sun, double t,
                                            bool& sun_unknown) {
    CorrectedSolution<T> c = pipeline::correct_stage(in, v, cfg);
    const RowSunTerm s = row_sun_term(sun, c.status, in.head, t);
    sun_unknown = s.unknown;
    if (s.unknown) {  // the stage skipped: the aberration's result, 128
        c = pipeline::correct_stage(in, v, CorrectionConfig<T>{cfg.aberration, nullptr});
        c.status |= status::kThermalOutOfRange;
    } else if (s.apply) {
        using S = ScalarTraits<T>;
        const Vector3<T> s_icrf{S::from_double(s.s_icrf.x), S::from_double(s.s_icrf.y), S::from_double(s.s_icrf.z)};
        c.q_chu_icrf = with_sun_term(c.q_chu_icrf, sun_term_rotation(*sun, in.head, c.q_chu_icrf, s_icrf));
    }
    return c;
}

template <typename T>
RowCorrection<T> correct_row(const SolutionRecord& rec, EarthVelocity* earth, const CorrectionConfig<T>& cfg,
                             StatesVelocity<T>* states, const SunTermModel<T>* sun) {
    RowCorrection<T> r{to_core_input<T>(rec, cfg.aberration ? earth : nullptr), 0, rec.q_chu_icrf, false, 0, false};
    r.from_states = states != nullptr && cfg.aberration && rec.velocity_components == 0;
    const pipeline::VelocityAnswer<T> v =
        r.from_states ? pipeline::from_service(states->at(rec.t)) : pipeline::given_velocity(r.in.velocity);
    r.service = v.service;
    const CorrectedSolution<T> c = correct_stage_with_sun(r.in, v, cfg, sun, rec.t, r.sun_unknown);
    // A velocity given but unusable before the core (1 or 2 of vx,vy,vz, a time
    // outside the ephemeris): the core saw "not available", the row gets 4|32.
    r.status = host_status(rec, cfg.aberration, c.status);
    if ((r.status & status::kRejected) != 0U) {
        return r;
    }
    r.q_chu_icrf = in_double(c.q_chu_icrf);
    return r;
}

template CorrectedSolution<double> correct_stage_with_sun(SolutionInput<double>&,
                                                          const pipeline::VelocityAnswer<double>&,
                                                          const CorrectionConfig<double>&, const SunTermModel<double>*,
                                                          double, bool&);
template RowCorrection<double> correct_row(const SolutionRecord&, EarthVelocity*, const CorrectionConfig<double>&,
                                           StatesVelocity<double>*, const SunTermModel<double>*);
template RowCorrection<float> correct_row(const SolutionRecord&, EarthVelocity*, const CorrectionConfig<float>&,
                                          StatesVelocity<float>*, const SunTermModel<float>*);
template RowCorrection<Q30> correct_row(const SolutionRecord&, EarthVelocity*, const CorrectionConfig<Q30>&,
                                        StatesVelocity<Q30>*, const SunTermModel<Q30>*);

}  // namespace ascorr::host
