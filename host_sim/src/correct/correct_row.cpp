#include "ascorr_host/correct/correct_row.hpp"

#include "ascorr/pipeline/solution_stage.hpp"
#include "ascorr_host/correct/solution_input.hpp"

namespace ascorr::host {

template <typename T>
RowCorrection<T> correct_row(const SolutionRecord& rec, EarthVelocity* earth, const CorrectionConfig<T>& cfg,
                             StatesVelocity<T>* states) {
    RowCorrection<T> r{to_core_input<T>(rec, cfg.aberration ? earth : nullptr), 0, rec.q_chu_icrf, false, 0};
    r.from_states = states != nullptr && cfg.aberration && rec.velocity_components == 0;
    const pipeline::VelocityAnswer<T> v =
        r.from_states ? pipeline::from_service(states->at(rec.t)) : pipeline::given_velocity(r.in.velocity);
    r.service = v.service;
    const CorrectedSolution<T> c = pipeline::correct_stage(r.in, v, cfg);
    // A velocity given but unusable before the core (1 or 2 of vx,vy,vz, a time
    // outside the ephemeris): the core saw "not available", the row gets 4|32.
    r.status = host_status(rec, cfg.aberration, c.status);
    if ((r.status & status::kRejected) == 0U) {
        const auto d = [](const T& x) { return ScalarTraits<T>::to_double(x); };
        r.q_chu_icrf = {d(c.q_chu_icrf.w), d(c.q_chu_icrf.x), d(c.q_chu_icrf.y), d(c.q_chu_icrf.z)};
    }
    return r;
}

template RowCorrection<double> correct_row(const SolutionRecord&, EarthVelocity*, const CorrectionConfig<double>&,
                                           StatesVelocity<double>*);
template RowCorrection<float> correct_row(const SolutionRecord&, EarthVelocity*, const CorrectionConfig<float>&,
                                          StatesVelocity<float>*);
template RowCorrection<Q30> correct_row(const SolutionRecord&, EarthVelocity*, const CorrectionConfig<Q30>&,
                                        StatesVelocity<Q30>*);

}  // namespace ascorr::host
