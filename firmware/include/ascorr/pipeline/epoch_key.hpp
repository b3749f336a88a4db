// ascorr/pipeline/epoch_key.hpp: which rows form one epoch.
//
// Conventions: a row's time t is in seconds (a double, as in the files of
// docs/contract.md); its epoch key is t rounded to the nearest millisecond,
// halves away from zero (std::llround of t * 1000), a signed 64-bit count of
// milliseconds. The key exists only for |t| < kMaxEpochTimeS (NaN and
// ±infinity included in "not"): beyond it the count would not fit, and such a
// row belongs to no epoch. Rows with one key are solutions of one epoch (the
// heads' solutions of one instant agree to far better than a millisecond).
//
// Why here: the rule "consecutive rows with one key form an epoch" is used by
// the host's combination stage (analysis/combine.cpp), replay's combination
// on the target (link/replay.cpp) and the temperature histories of the Linux
// HAL (simulated_source.cpp), and the key also by the host's analyses (rows
// in any order, analysis/epochs.hpp). They must agree row for row, so the key
// and the grouping live once, on the firmware side, below all of them.
// The flight loop needs neither: its solutions carry one clock's time tag in
// µs, and EpochPipeline::begin() compares it directly.
//
// Header-only, allocation-free, no exceptions, no loops.
#pragma once

#include <cmath>
#include <cstdint>
#include <optional>

namespace ascorr::pipeline {

// |t| below this has a key: 9e15 s * 1000 < 2^63 with room for the rounding.
inline constexpr double kMaxEpochTimeS = 9.0e15;

// Whether t has an epoch key (false for NaN and ±infinity).
inline bool has_epoch_key(double t) noexcept {
    return std::abs(t) < kMaxEpochTimeS;
}

// The epoch key of t, the caller having checked has_epoch_key(t).
inline std::int64_t epoch_key(double t) noexcept {
    return static_cast<std::int64_t>(std::llround(t * 1000.0));
}

// The epoch key of t, or none (a row in no epoch).
inline std::optional<std::int64_t> epoch_key_of(double t) noexcept {
    if (!has_epoch_key(t)) {
        return std::nullopt;
    }
    return epoch_key(t);
}

// Consecutive rows with one key form an epoch. For each row, in order:
//   if (epochs.ends_before(key)) { close the caller's epoch; epochs.close(); }
//   epochs.add(*key);  // when the row has a key
// and at the end, if (epochs.is_open()), close the last one. A row with no
// key (std::nullopt) ends the open epoch and opens none. The same key again
// after another is a new epoch: the caller sorts first, or refuses.
class ConsecutiveEpochs {
public:
    // Whether the open epoch ends before a row of `key`.
    bool ends_before(std::optional<std::int64_t> key) const noexcept { return open_ && !(key && *key == key_); }
    // The row of `key` is in the open epoch; true when it opens it.
    bool add(std::int64_t key) noexcept {
        const bool opens = !open_;
        open_ = true;
        key_ = key;
        return opens;
    }
    void close() noexcept { open_ = false; }
    bool is_open() const noexcept { return open_; }
    // The open epoch's key (is_open()).
    std::int64_t key() const noexcept { return key_; }

private:
    bool open_ = false;
    std::int64_t key_ = 0;
};

}  // namespace ascorr::pipeline
