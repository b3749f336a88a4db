// The epoch key and the consecutive-run grouper (ascorr/pipeline/epoch_key.hpp)
// on their own: the rounding of the key (a mutation to truncation, to
// round-half-even or to another unit fails here), which times have none, and
// which rows the grouper puts in one epoch.
#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <optional>
#include <vector>

#include "ascorr/pipeline/epoch_key.hpp"

namespace ascorr::test {
namespace {

using pipeline::ConsecutiveEpochs;
using pipeline::epoch_key;
using pipeline::epoch_key_of;
using pipeline::has_epoch_key;

TEST(EpochKey, MillisecondsRoundedHalfAwayFromZero) {
    EXPECT_EQ(epoch_key(0.0), 0);
    EXPECT_EQ(epoch_key(1.0), 1000);  // milliseconds, not µs or s
    // 0.0625 s = 62.5 ms exactly (1/16 in binary): halves go away from zero,
    // where truncation and round-half-even give 62.
    EXPECT_EQ(epoch_key(0.0625), 63);
    EXPECT_EQ(epoch_key(-0.0625), -63);
    EXPECT_EQ(epoch_key(0.1875), 188);  // 187.5 ms: floor and truncation give 187
    // Below and above a half millisecond: the nearest.
    EXPECT_EQ(epoch_key(1.0004), 1000);
    EXPECT_EQ(epoch_key(1.0006), 1001);
    EXPECT_EQ(epoch_key(-1.0006), -1001);
    // A large time of a real file (J2000 seconds in 2016) keeps every millisecond.
    EXPECT_EQ(epoch_key(5.0e8 + 0.123), 500000000123);
}

TEST(EpochKey, NoKeyOutsideItsRange) {
    EXPECT_TRUE(has_epoch_key(8.9e15));
    EXPECT_TRUE(has_epoch_key(-8.9e15));
    EXPECT_FALSE(has_epoch_key(pipeline::kMaxEpochTimeS));
    EXPECT_FALSE(has_epoch_key(-1e300));
    EXPECT_FALSE(has_epoch_key(std::numeric_limits<double>::quiet_NaN()));
    EXPECT_FALSE(has_epoch_key(std::numeric_limits<double>::infinity()));
    EXPECT_EQ(epoch_key_of(std::numeric_limits<double>::quiet_NaN()), std::nullopt);
    EXPECT_EQ(epoch_key_of(1e300), std::nullopt);
    EXPECT_EQ(epoch_key_of(2.0625), std::optional<std::int64_t>(2063));
    // The largest key fits in 64 bits.
    EXPECT_EQ(epoch_key(8.9e15), 8900000000000000000);
}

// The epochs of `times` as the grouper forms them: each epoch's row indices;
// a row with no key is in none.
std::vector<std::vector<int>> group(const std::vector<double>& times) {
    std::vector<std::vector<int>> out;
    std::vector<int> open;
    ConsecutiveEpochs epochs;
    for (int i = 0; i < static_cast<int>(times.size()); ++i) {
        const std::optional<std::int64_t> key = epoch_key_of(times[static_cast<std::size_t>(i)]);
        if (epochs.ends_before(key)) {
            out.push_back(open);
            open.clear();
            epochs.close();
        }
        if (key) {
            const bool opens = epochs.add(*key);
            EXPECT_EQ(opens, open.empty());
            EXPECT_EQ(epochs.key(), *key);
            open.push_back(i);
        }
    }
    if (epochs.is_open()) {
        out.push_back(open);
    }
    return out;
}

TEST(EpochGrouper, ConsecutiveRowsWithOneKey) {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    using G = std::vector<std::vector<int>>;
    EXPECT_EQ(group({}), G{});
    EXPECT_EQ(group({10.0}), (G{{0}}));
    // Within half a millisecond: one epoch; a millisecond apart: two.
    EXPECT_EQ(group({10.0, 10.0004, 9.9996, 10.001}), (G{{0, 1, 2}, {3}}));
    // The rounding decides: 10.0625 s is key 10063, with 10.063 s, not 10.062 s.
    EXPECT_EQ(group({10.062, 10.0625, 10.063}), (G{{0}, {1, 2}}));
    // The same key again after another is a new epoch (callers sort or refuse).
    EXPECT_EQ(group({1.0, 2.0, 1.0}), (G{{0}, {1}, {2}}));
    // A row with no key ends the open epoch and is in none.
    EXPECT_EQ(group({1.0, nan, 1.0, 1e300}), (G{{0}, {2}}));
    EXPECT_EQ(group({nan, nan}), G{});
}

TEST(EpochGrouper, StateOfTheOpenEpoch) {
    ConsecutiveEpochs e;
    EXPECT_FALSE(e.is_open());
    EXPECT_FALSE(e.ends_before(5));
    EXPECT_FALSE(e.ends_before(std::nullopt));
    EXPECT_TRUE(e.add(5));
    EXPECT_FALSE(e.add(5));
    EXPECT_TRUE(e.is_open());
    EXPECT_FALSE(e.ends_before(5));
    EXPECT_TRUE(e.ends_before(6));
    EXPECT_TRUE(e.ends_before(4));
    EXPECT_TRUE(e.ends_before(std::nullopt));
    e.close();
    EXPECT_FALSE(e.is_open());
    EXPECT_FALSE(e.ends_before(6));
}

}  // namespace
}  // namespace ascorr::test
