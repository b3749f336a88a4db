// ascorr/core/compiler.hpp: what the core asks of the compiler, checked at compile time.
//
// The core is C++17. Its fixed-point formats (q_formats.hpp, fx.hpp), which
// the headers with a Q30 kernel beside the generic version (vector3.hpp,
// quaternion.hpp, aberration.hpp, thermal.hpp) include, also need:
//  - GCC ≥ 9 or Clang ≥ 9: __builtin_add_overflow / __builtin_sub_overflow
//    (saturating Q30 sums), __builtin_is_constant_evaluated (constant folding
//    of the register barrier), GNU inline asm (that barrier, fx::unshared) and
//    [[gnu::always_inline]];
//  - two's-complement integers whose right shift of a negative value is
//    arithmetic (rounds towards −∞): every Q-format rounding relies on it. C++17
//    leaves it implementation-defined; GCC and Clang define it so on every
//    target, and the static_asserts below refuse any compiler that does not.
#pragma once

#include <cstdint>

#if !defined(__GNUC__) && !defined(__clang__)
#error "ascorr's fixed-point core needs GCC >= 9 or Clang >= 9 (builtins, GNU inline asm); see ascorr/core/compiler.hpp"
#elif defined(__clang__)
#if __clang_major__ < 9
#error "ascorr's fixed-point core needs Clang >= 9 (__builtin_is_constant_evaluated)"
#endif
#elif __GNUC__ < 9
#error "ascorr's fixed-point core needs GCC >= 9 (__builtin_is_constant_evaluated)"
#endif

namespace ascorr::compiler_check {
static_assert(static_cast<std::int32_t>(-3) >> 1 == -2, "right shift of a negative int32 must be arithmetic");
static_assert(static_cast<std::int64_t>(-3) >> 1 == -2, "right shift of a negative int64 must be arithmetic");
static_assert(static_cast<std::int32_t>(0xFFFFFFFFU) == -1, "two's-complement conversion to int32 required");
static_assert(static_cast<std::int64_t>(0xFFFFFFFFFFFFFFFFULL) == -1, "two's-complement conversion to int64 required");
}  // namespace ascorr::compiler_check
