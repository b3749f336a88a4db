// firmware/app/velocity_entry_fixed.cpp: the Q30 velocity query (velocity_entry.hpp).
#include "velocity_entry.hpp"

namespace ascorr::app {

ServiceVelocity<Q30> velocity_query_fixed(const VelocityService<Q30>& service, TtTime t) noexcept {
    return service.velocity_at(t);
}

}  // namespace ascorr::app
