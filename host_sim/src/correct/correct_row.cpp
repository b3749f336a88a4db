#include "ascorr_host/correct/correct_row.hpp"

#include <type_traits>

#include "ascorr/nav/sun_direction.hpp"
#include "ascorr/pipeline/solution_stage.hpp"
#include "ascorr_host/correct/solution_input.hpp"

namespace ascorr::host {

RowSunTerm row_sun_term(const SunTermModel<double>* sun, StatusBits core_status, std::uint8_t head, double t) {
    RowSunTerm s;
    if (sun == nullptr || (core_status & status::kThermalApplied) == 0U || !has_sun_term(*sun, head)) {
        return s;
    }
    s.apply = nav::sun_direction_icrf(t, s.s_icrf);
    s.unknown = !s.apply;
    return s;
}

namespace {

// The Sun term of `head` in the core's scalar T, as its per-solution path
// holds it (each coefficient and ŝ rounded to T once), applied in T to the
// core's result (core/sun_term.hpp; float and Q30: the targets' scalars).
template <typename T>
Quaternion<T> with_sun_term_in(const Quaternion<T>& q, const SunTermModel<double>& sun, std::uint8_t head,
                               const Vector3<double>& s_icrf) {
    using S = ScalarTraits<T>;
    SunTermModel<T> m{};
    m.present[head] = sun.present[head];
    for (std::size_t a = 0; a < kModelAxes; ++a) {
        for (std::size_t c = 0; c < kSunComponents; ++c) {
            m.coefficient[head][a][c] = S::from_double(sun.coefficient[head][a][c]);
        }
    }
    const Vector3<T> s{S::from_double(s_icrf.x), S::from_double(s_icrf.y), S::from_double(s_icrf.z)};
    return with_sun_term(q, sun_term_rotation(m, head, q, s));
}

}  // namespace

template <typename T>
CorrectedSolution<T> correct_stage_with_sun(SolutionInput<T>& in, const pipeline::VelocityAnswer<T>& v,
                                            const CorrectionConfig<T>& cfg, const SunTermModel<double>* sun, double t,
                                            bool& sun_unknown) {
    CorrectedSolution<T> c = pipeline::correct_stage(in, v, cfg);
    const RowSunTerm s = row_sun_term(sun, c.status, in.head, t);
    sun_unknown = s.unknown;
    if (s.unknown) {  // the stage skipped: the aberration's result, 128
        c = pipeline::correct_stage(in, v, CorrectionConfig<T>{cfg.aberration, nullptr});
        c.status |= status::kThermalOutOfRange;
    } else if (s.apply) {
        if constexpr (std::is_same_v<T, double>) {
            c.q_chu_icrf = with_sun_term(c.q_chu_icrf, sun_term_rotation(*sun, in.head, c.q_chu_icrf, s.s_icrf));
        } else {
            c.q_chu_icrf = with_sun_term_in(c.q_chu_icrf, *sun, in.head, s.s_icrf);
        }
    }
    return c;
}

template <typename T>
RowCorrection<T> correct_row(const SolutionRecord& rec, EarthVelocity* earth, const CorrectionConfig<T>& cfg,
                             StatesVelocity<T>* states, const SunTermModel<double>* sun) {
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
                                          StatesVelocity<float>*, const SunTermModel<double>*);
template RowCorrection<Q30> correct_row(const SolutionRecord&, EarthVelocity*, const CorrectionConfig<Q30>&,
                                        StatesVelocity<Q30>*, const SunTermModel<double>*);

}  // namespace ascorr::host
