// firmware/app/velocity_entry.hpp: the velocity service's per-solution query,
// compiled once per scalar as an out-of-line entry.
//
// Conventions: velocity_at() of velocity_service.hpp, instantiated for one
// scalar in its own translation unit (velocity_entry_fixed.cpp,
// velocity_entry_float.cpp), next to the core's entry (core_entry.hpp), so
// that the per-solution path (query + correction) is two objects whose
// symbols the no-soft-float check inspects: the service's double part
// (push_state, advance) lives in the application, outside them.
#pragma once

#include "ascorr/nav/velocity_service.hpp"

namespace ascorr::app {

ServiceVelocity<Q30> velocity_query_fixed(const VelocityService<Q30>& service, TtTime t) noexcept;
ServiceVelocity<float> velocity_query_float(const VelocityService<float>& service, TtTime t) noexcept;

inline ServiceVelocity<Q30> velocity_query(const VelocityService<Q30>& service, TtTime t) noexcept {
    return velocity_query_fixed(service, t);
}
inline ServiceVelocity<float> velocity_query(const VelocityService<float>& service, TtTime t) noexcept {
    return velocity_query_float(service, t);
}

}  // namespace ascorr::app
