// firmware/app/combine_entry_float.cpp: the float combination, out of line.
#include "combine_entry.hpp"

namespace ascorr::app {

combine::CombinedAttitude<float> combine_float(const combine::Combiner<float>& c,
                                               const combine::HeadAttitude<float>* heads, std::uint8_t n) noexcept {
    return c.combine(heads, n);
}

}  // namespace ascorr::app
