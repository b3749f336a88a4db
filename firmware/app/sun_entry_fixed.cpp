// firmware/app/sun_entry_fixed.cpp: the fixed Sun term, out of line.
#include "sun_entry.hpp"

namespace ascorr::app {

void sun_fixed(const SunTermModel<Q30>& m, std::uint8_t head, const Vector3<Q30>& s_icrf, Quaternion<Q30>& q) noexcept {
    q = with_sun_term(q, sun_term_rotation(m, head, q, s_icrf));
}

}  // namespace ascorr::app
