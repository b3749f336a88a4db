// Compile-time guard check (each kernel's guard, see vector3.hpp): naming a generic
// kernel template for Q30, which is what a call resolves to when the Q30
// overload's signature has drifted, must not compile. CTest compiles this file
// once per kernel (ASCORR_KERNEL = 0 … 14) with ASCORR_SCALAR=Q30 and expects
// "deleted function"; the control compiles every call with ASCORR_SCALAR=float,
// so a failure can only come from the guard, not from the file.
#include "ascorr/core/fixed_point.hpp"

namespace ascorr {

using S = ASCORR_SCALAR;

void call_kernel() {
    const S one = constant<S>(1.0);
    const S zero = constant<S>(0.0);
    const Vector3<S> v{zero, zero, one};
    const Quaternion<S> q{one, zero, zero, zero};
    const SmallRotation<S> r{zero, v};
    static_cast<void>(v);
    static_cast<void>(q);
    static_cast<void>(r);
#if ASCORR_KERNEL == 0 || !defined(ASCORR_KERNEL)
    static_cast<void>(dot<S>(v, v));
#endif
#if ASCORR_KERNEL == 1 || !defined(ASCORR_KERNEL)
    static_cast<void>(squared_norm<S>(v));
#endif
#if ASCORR_KERNEL == 2 || !defined(ASCORR_KERNEL)
    static_cast<void>(cross<S>(v, v));
#endif
#if ASCORR_KERNEL == 3 || !defined(ASCORR_KERNEL)
    static_cast<void>(dot<S>(q, q));
#endif
#if ASCORR_KERNEL == 4 || !defined(ASCORR_KERNEL)
    static_cast<void>(squared_norm<S>(q));
#endif
#if ASCORR_KERNEL == 5 || !defined(ASCORR_KERNEL)
    static_cast<void>(operator*<S>(q, q));
#endif
#if ASCORR_KERNEL == 6 || !defined(ASCORR_KERNEL)
    static_cast<void>(boresight<S>(q));
#endif
#if ASCORR_KERNEL == 7 || !defined(ASCORR_KERNEL)
    static_cast<void>(conjugate<S>(r));
#endif
#if ASCORR_KERNEL == 8 || !defined(ASCORR_KERNEL)
    static_cast<void>(norm_within<S>(q, one));
#endif
#if ASCORR_KERNEL == 9 || !defined(ASCORR_KERNEL)
    static_cast<void>(right_increment<S>(q, r));
#endif
#if ASCORR_KERNEL == 10 || !defined(ASCORR_KERNEL)
    static_cast<void>(add_left_increment<S>(q, r, q));
#endif
#if ASCORR_KERNEL == 11 || !defined(ASCORR_KERNEL)
    static_cast<void>(renormalized_sum<S>(q, q));
#endif
#if ASCORR_KERNEL == 12 || !defined(ASCORR_KERNEL)
    static_cast<void>(beta_in_domain<S>(v));
#endif
#if ASCORR_KERNEL == 13 || !defined(ASCORR_KERNEL)
    static_cast<void>(aberration_rotation<S>(v, v, one));
#endif
#if ASCORR_KERNEL == 14 || !defined(ASCORR_KERNEL)
    static_cast<void>(thermal_rotation<S>(zero, zero, zero));
#endif
}

}  // namespace ascorr
