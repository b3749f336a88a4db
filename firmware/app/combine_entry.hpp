// firmware/app/combine_entry.hpp: the combined attitude (ascorr/combine/) compiled
// once per scalar for the DPU, as out-of-line entry points.
//
// Conventions: each entry is Combiner<T>::combine() instantiated for one
// scalar in its own translation unit (combine_entry_fixed.cpp,
// combine_entry_float.cpp), so that its flash and worst-case stack are
// measured alone (toolchain/run-target-bench). The combiner's tables are the
// caller's (built once, from the mountings, in double).
#pragma once

#include <cstdint>

#include "ascorr/combine/combiner.hpp"
#include "ascorr/core/fixed_point.hpp"

namespace ascorr::app {

combine::CombinedAttitude<Q30> combine_fixed(const combine::Combiner<Q30>& c, const combine::HeadAttitude<Q30>* heads,
                                             std::uint8_t n) noexcept;
combine::CombinedAttitude<float> combine_float(const combine::Combiner<float>& c,
                                               const combine::HeadAttitude<float>* heads, std::uint8_t n) noexcept;

// The entry for scalar T, for code templated on it.
inline combine::CombinedAttitude<Q30> combine_epoch(const combine::Combiner<Q30>& c,
                                                    const combine::HeadAttitude<Q30>* heads, std::uint8_t n) noexcept {
    return combine_fixed(c, heads, n);
}
inline combine::CombinedAttitude<float> combine_epoch(const combine::Combiner<float>& c,
                                                      const combine::HeadAttitude<float>* heads,
                                                      std::uint8_t n) noexcept {
    return combine_float(c, heads, n);
}

}  // namespace ascorr::app
