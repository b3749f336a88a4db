// Compile-time guard check (each kernel's guard, see vector3.hpp): naming a generic
// kernel template for Q30, which is what a call resolves to when the Q30
// overload's signature has drifted, must not compile. CTest compiles this file
// once per kernel (ASCORR_KERNEL = 0 … 15) with ASCORR_SCALAR=Q30 and expects
// "deleted function"; the control compiles every call with ASCORR_SCALAR=float,
// so a failure can only come from the guard, not from the file.
#include <cstddef>
#include <tuple>
#include <utility>

#include "ascorr/core/fixed_point.hpp"
#include "ascorr/core/sun_term.hpp"

namespace ascorr {

using S = ASCORR_SCALAR;

// What the kernels are called with.
struct Args {
    S one;
    Vector3<S> v;
    Quaternion<S> q;
    SmallRotation<S> r;
    S zero;
    SunTermModel<S> sun;
};

// One call per kernel, ASCORR_KERNEL's number its place here. Generic lambdas:
// a call is compiled only where it is made.
const auto kKernels =
    std::make_tuple([](const auto& a) { return dot<S>(a.v, a.v); },                                 // 0
                    [](const auto& a) { return squared_norm<S>(a.v); },                             // 1
                    [](const auto& a) { return cross<S>(a.v, a.v); },                               // 2
                    [](const auto& a) { return dot<S>(a.q, a.q); },                                 // 3
                    [](const auto& a) { return squared_norm<S>(a.q); },                             // 4
                    [](const auto& a) { return operator*<S>(a.q, a.q); },                           // 5
                    [](const auto& a) { return boresight<S>(a.q); },                                // 6
                    [](const auto& a) { return conjugate<S>(a.r); },                                // 7
                    [](const auto& a) { return norm_within<S>(a.q, a.one); },                       // 8
                    [](const auto& a) { return right_increment<S>(a.q, a.r); },                     // 9
                    [](const auto& a) { return add_left_increment<S>(a.q, a.r, a.q); },             // 10
                    [](const auto& a) { return renormalized_sum<S>(a.q, a.q); },                    // 11
                    [](const auto& a) { return beta_in_domain<S>(a.v); },                           // 12
                    [](const auto& a) { return aberration_rotation<S>(a.v, a.v, a.one); },          // 13
                    [](const auto& a) { return thermal_rotation<S>(a.zero, a.zero, a.zero); },      // 14
                    [](const auto& a) { return plus_sun_term_angles<S>(a.v, a.sun, 0, a.q, a.v); }  // 15
    );

// Every kernel's call (the control).
template <std::size_t... K>
void call_every_kernel(const Args& a, std::index_sequence<K...>) {
    (static_cast<void>(std::get<K>(kKernels)(a)), ...);
}

void call_kernel() {
    const S one = constant<S>(1.0);
    const S zero = constant<S>(0.0);
    const Vector3<S> v{zero, zero, one};
    const Args a{one, v, Quaternion<S>{one, zero, zero, zero}, SmallRotation<S>{zero, v}, zero, SunTermModel<S>{}};
#if defined(ASCORR_KERNEL)
    static_cast<void>(std::get<ASCORR_KERNEL>(kKernels)(a));
#else
    call_every_kernel(a, std::make_index_sequence<std::tuple_size_v<decltype(kKernels)> >{});
#endif
}

}  // namespace ascorr
