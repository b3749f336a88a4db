// firmware/app/velocity_entry_float.cpp: the float velocity query (velocity_entry.hpp).
#include "velocity_entry.hpp"

namespace ascorr::app {

ServiceVelocity<float> velocity_query_float(const VelocityService<float>& service, TtTime t) noexcept {
    return service.velocity_at(t);
}

}  // namespace ascorr::app
