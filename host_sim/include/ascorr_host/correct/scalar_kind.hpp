// ascorr_host/correct/scalar_kind.hpp: which scalar the core is instantiated
// with, the one name for it on the host: `ascorr correct --scalar`, the boards
// of `ascorr replay` (qemu_targets.hpp) and the tests. A kind, not the type:
// the firmware's type is firmware/app/app_scalar.hpp's Scalar, and a target
// reports its kind in the link's HELLO (scalar_kind, ascorr_link/messages.hpp's
// WireTraits<T>::kKind).
#pragma once

namespace ascorr::host {

enum class ScalarKind { kDouble, kFloat, kFixed };  // double, float, Q30

}  // namespace ascorr::host
