// ascorr/core/heads.hpp: the camera heads (CHUs) one DPU serves, and their letters.
//
// Conventions: a head is an index 0 … kMaxHeads − 1 and a letter, index i ↔
// kHeadLetters[i] (0 = A, 1 = B, 2 = C, 3 = D). This header is the one place
// that says how many heads there are and what they are called: the core's
// tables (thermal.hpp), the link protocol, the HAL's roles (static_asserted),
// the host's file formats and messages, the Python module (ascorr.HEADS) and
// the tests take them from here; the documentation's statements of them are
// checked by the test Heads.* (tests/test_facts.cpp). Adding a head: append its
// letter to kHeadLetters (DEVELOPERS.md, "Add a head").
#pragma once

#include <cstdint>

namespace ascorr {

inline constexpr char kHeadLetters[] = "ABCD";  // index → letter; NUL-terminated
inline constexpr std::uint8_t kMaxHeads = sizeof(kHeadLetters) - 1;

// Not a head: what head_index() returns for anything else, and what a reader
// stores for a head it does not know (the core rejects it, status 16).
inline constexpr std::uint8_t kUnknownHead = 0xFF;
static_assert(kMaxHeads > 0 && kMaxHeads < kUnknownHead, "head indices fit in a byte, below kUnknownHead");

// A set of heads: bit h is head h. The one head-set type of the flight code
// and the ground's (combine/, calib/, the host's analyses).
using HeadMask = std::uint8_t;
static_assert(kMaxHeads <= 8, "a HeadMask holds one bit per head");

constexpr HeadMask head_bit(std::uint8_t head) noexcept {
    return static_cast<HeadMask>(1U << head);
}

// The heads whose flag is set (flag[h] for h < kMaxHeads: a model's present
// heads, as bool[] or std::array<bool>).
template <typename Flags>
constexpr HeadMask heads_where(const Flags& flag) noexcept {
    HeadMask s = 0U;
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        s = static_cast<HeadMask>(s | (flag[h] ? head_bit(h) : 0U));
    }
    return s;
}

// Bit i of a mask (a HeadMask, or a mask of an epoch's candidates).
constexpr bool in_mask(std::uint8_t mask, std::uint8_t i) noexcept {
    return ((static_cast<unsigned>(mask) >> i) & 1U) != 0U;
}

constexpr bool has_head(HeadMask s, std::uint8_t head) noexcept {
    return in_mask(s, head);
}

// Number of heads in a mask (bounded: kMaxHeads bits).
constexpr std::uint8_t head_count(HeadMask s) noexcept {
    std::uint8_t n = 0;
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        n = static_cast<std::uint8_t>(n + (in_mask(s, h) ? 1U : 0U));
    }
    return n;
}

// The letter of head `head`, '?' for an index ≥ kMaxHeads.
constexpr char head_letter(std::uint8_t head) noexcept {
    return head < kMaxHeads ? kHeadLetters[head] : '?';
}

// The index of the head lettered `letter` (upper case only), kUnknownHead for
// any other character. At most kMaxHeads comparisons.
constexpr std::uint8_t head_index(char letter) noexcept {
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        if (kHeadLetters[h] == letter) {
            return h;
        }
    }
    return kUnknownHead;
}

// The heads for a message, "A, B, C or D", built from kHeadLetters.
struct HeadChoices {
    char text[4 * kMaxHeads + 1];  // n letters, n − 2 ", ", one " or ", NUL
};

constexpr HeadChoices head_choices() noexcept {
    HeadChoices c{};
    std::uint8_t n = 0;
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        const char* sep = h == 0 ? "" : h + 1 == kMaxHeads ? " or " : ", ";
        for (; *sep != '\0'; ++sep) {
            c.text[n++] = *sep;
        }
        c.text[n++] = kHeadLetters[h];
    }
    return c;
}

inline constexpr HeadChoices kHeadChoices = head_choices();

}  // namespace ascorr
