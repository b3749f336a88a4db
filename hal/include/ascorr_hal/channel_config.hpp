// ascorr_hal/channel_config.hpp: what the acquisition knows about each channel.
//
// Conventions:
//  - Up to kMaxChannels channels (the eight inputs of one MCP3208). Each has a
//    role: the CHU temperature of a head (T1), a member of the THT00029 triplet
//    (T2: THT00029/57/87), of the THT00032 triplet (T3: THT00032/60/90), or a
//    monitor channel that is read and checked but feeds no correction.
//  - Channels with the same role are voted together (voting.hpp); a role with
//    one channel uses it directly.
//  - Units: ohm, °C, °C/s, microseconds, ADC counts. A limit of 0 disables
//    the rate (max_rate) and stuck (stuck_frames) checks.
//  - Plain aggregates, no heap: the firmware can keep the configuration in a
//    constant table; the host fills it from a file (config_file.hpp).
#pragma once

#include <cstdint>

#include "ascorr/core/heads.hpp"
#include "sampler.hpp"
#include "thermistor.hpp"

namespace ascorr::hal {

inline constexpr std::uint8_t kMaxChannels = 8;
inline constexpr std::uint8_t kNameLength = 16;  // including the terminating NUL

enum class Role : std::uint8_t { kMonitor = 0, kChuA, kChuB, kChuC, kChuD, kT029, kT032 };
inline constexpr std::uint8_t kRoleCount = static_cast<std::uint8_t>(static_cast<std::uint8_t>(Role::kT032) + 1U);
inline constexpr const char* kRoleNames[] = {"monitor", "chu_a", "chu_b", "chu_c", "chu_d", "t029", "t032"};
static_assert(sizeof(kRoleNames) / sizeof(kRoleNames[0]) == kRoleCount, "one name per role");
// One CHU role per head of ascorr/core/heads.hpp, in head order, named chu_<letter>
// (Heads.HalRolesAreOnePerHeadNamedByItsLetter in tests/test_facts.cpp checks the
// names): a head added there needs its role here.
static_assert(static_cast<std::uint8_t>(Role::kT029) == static_cast<std::uint8_t>(Role::kChuA) + ascorr::kMaxHeads,
              "one Role::kChu<letter> per head of ascorr/core/heads.hpp");

constexpr Role chu_role(std::uint8_t head) noexcept {
    return static_cast<Role>(static_cast<std::uint8_t>(Role::kChuA) + head);
}

template <typename T>
struct ChannelConfig {
    char name[kNameLength];  // e.g. "THT00029"
    Role role;
    std::uint8_t adc_channel;  // 0 … 7
    Divider<T> divider;
    SteinhartHart<T> sh;
    T r_open;   // ohm: at or above, kOpen
    T r_short;  // ohm: at or below, kShort
    T t_min;    // °C: outside [t_min, t_max], kOutOfRange
    T t_max;
    T max_rate;                  // °C/s, 0: no rate check
    std::uint16_t stuck_frames;  // identical raw values in a row for kStuck, 0: no check
    std::uint16_t max_spread;    // counts: inner-half spread above this, kNoisy
};

template <typename T>
struct AcquisitionConfig {
    ChannelConfig<T> channel[kMaxChannels];
    std::uint8_t channels;  // how many of channel[] are used
    SamplerSettings sampler;
    std::uint64_t stale_us;  // a reading older than this is withheld (kStale)
    T vote_tolerance;        // °C: a member farther than this from the median is outvoted
    std::uint8_t quorum;     // agreeing valid members a voted value needs (1 … 3)
};

}  // namespace ascorr::hal
