// ascorr/combine/combined_status.hpp: status bits of a combined attitude.
//
// The contract's bits ("Combined attitude", docs/contract.md), defined here
// once; every other use (the host's writer, the link, the tests) takes them
// from here. Exactly one of 1, 2 and 8 is set on every combined attitude; 4
// may come with any of them:
//   1  two or more heads were averaged;
//   2  one head only (its formal σ is large about its boresight);
//   4  a head present at the epoch was left out: not usable (the caller's
//      selection), not in the mountings, a second solution of one head, an
//      index that is no head, or inconsistent with the others (the gate,
//      combiner.hpp);
//   8  no usable head: q is the identity and carries no information.
#pragma once

#include <cstdint>

namespace ascorr::combine {

using CombinedStatus = std::uint8_t;

namespace combined_status {
inline constexpr CombinedStatus kTwoOrMoreHeads = 1U;
inline constexpr CombinedStatus kOneHead = 2U;
inline constexpr CombinedStatus kHeadLeftOut = 4U;
inline constexpr CombinedStatus kNoHead = 8U;

// Name of each bit, index = bit position, for messages and summaries.
inline constexpr int kBitCount = 4;
inline constexpr const char* kBitNames[kBitCount] = {
    "two or more heads",  // 1
    "one head",           // 2
    "head left out",      // 4
    "no usable head",     // 8
};

// True when `s` follows the rule above: exactly one of 1, 2, 8, and no
// other bit than 4.
constexpr bool status_consistent(CombinedStatus s) noexcept {
    const unsigned kind = s & (kTwoOrMoreHeads | kOneHead | kNoHead);
    const bool one_kind = kind == kTwoOrMoreHeads || kind == kOneHead || kind == kNoHead;
    return one_kind && (s & ~(kTwoOrMoreHeads | kOneHead | kHeadLeftOut | kNoHead)) == 0U;
}
}  // namespace combined_status

}  // namespace ascorr::combine
