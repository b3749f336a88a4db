// firmware/app/sun_entry_float.cpp: the float Sun term, out of line.
#include "sun_entry.hpp"

namespace ascorr::app {

void sun_float(const SunTermModel<float>& m, std::uint8_t head, const Vector3<float>& s_icrf,
               Quaternion<float>& q) noexcept {
    q = with_sun_term(q, sun_term_rotation(m, head, q, s_icrf));
}

}  // namespace ascorr::app
