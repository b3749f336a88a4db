// firmware/app/combine_entry_fixed.cpp: the fixed-point combination, out of line.
#include "combine_entry.hpp"

namespace ascorr::app {

combine::CombinedAttitude<Q30> combine_fixed(const combine::Combiner<Q30>& c, const combine::HeadAttitude<Q30>* heads,
                                             std::uint8_t n) noexcept {
    return c.combine(heads, n);
}

}  // namespace ascorr::app
