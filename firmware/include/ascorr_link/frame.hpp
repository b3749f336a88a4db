// ascorr_link/frame.hpp: framing of link messages (see firmware/link-protocol.md).
//
// Raw frame, little-endian:
//   [0] version (kProtocolVersion)  [1] message type  [2..3] sequence number
//   [4..5] payload length L         [6..6+L) payload  [6+L..10+L) CRC-32C of [0..6+L)
// On the wire: COBS(raw frame) then 0x00. The decoder takes one byte at a
// time, holds at most kMaxEncoded bytes, and classifies every frame it ends:
// a good frame, or exactly one error (overlong, bad COBS, bad length, bad CRC,
// bad version). Nothing allocates; every loop is bounded by kMaxEncoded.
//
// Names: link::Frame is a framed protocol message, the only meaning of
// "frame" in ascorr_link/ (a state's ITRF/GCRS is its reference_frame,
// messages.hpp). Elsewhere "frame" is a reference frame (q_chu_icrf,
// StateFrame); the HAL's acquisition of every channel is a SampleSet.
#pragma once

#include <cstddef>
#include <cstdint>

#include "cobs.hpp"
#include "crc32c.hpp"

namespace ascorr::link {

// 2: STATE_UPDATE, time-tagged SOLUTION_IN; 3: self-calibration; 4: the
// solutions' calibration use and model version, CALIB_MODEL, SERVICE_CONFIG.
inline constexpr std::uint8_t kProtocolVersion = 5;
inline constexpr std::size_t kHeaderBytes = 6;
inline constexpr std::size_t kCrcBytes = 4;
inline constexpr std::size_t kMaxPayload = 120;
inline constexpr std::size_t kMaxRaw = kHeaderBytes + kMaxPayload + kCrcBytes;
inline constexpr std::size_t kMaxEncoded = cobs_max_encoded(kMaxRaw);
inline constexpr std::size_t kMaxWire = kMaxEncoded + 1;  // with the delimiter

// Little-endian field access, bounds checked by the callers' length checks.
constexpr void put_u16(std::uint8_t* p, std::uint16_t v) noexcept {
    p[0] = static_cast<std::uint8_t>(v & 0xFFU);
    p[1] = static_cast<std::uint8_t>(v >> 8);
}
constexpr void put_u32(std::uint8_t* p, std::uint32_t v) noexcept {
    for (int i = 0; i < 4; ++i) {
        p[i] = static_cast<std::uint8_t>((v >> (8 * i)) & 0xFFU);
    }
}
constexpr std::uint16_t get_u16(const std::uint8_t* p) noexcept {
    return static_cast<std::uint16_t>(p[0] | (p[1] << 8));
}
constexpr std::uint32_t get_u32(const std::uint8_t* p) noexcept {
    return static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
           (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
}

// Builds the wire bytes (COBS + delimiter) of one frame into out (capacity
// cap, kMaxWire is always enough). Returns the wire size, 0 if the payload is
// longer than kMaxPayload or cap is too small.
constexpr std::size_t encode_frame(std::uint8_t type, std::uint16_t seq, const std::uint8_t* payload, std::size_t n,
                                   std::uint8_t* out, std::size_t cap) noexcept {
    if (n > kMaxPayload) {
        return 0;
    }
    std::uint8_t raw[kMaxRaw] = {};
    raw[0] = kProtocolVersion;
    raw[1] = type;
    put_u16(raw + 2, seq);
    put_u16(raw + 4, static_cast<std::uint16_t>(n));
    for (std::size_t i = 0; i < n; ++i) {
        raw[kHeaderBytes + i] = payload[i];
    }
    put_u32(raw + kHeaderBytes + n, crc32c(raw, kHeaderBytes + n));
    const std::size_t enc = cobs_encode(raw, kHeaderBytes + n + kCrcBytes, out, cap == 0 ? 0 : cap - 1);
    if (enc == 0) {
        return 0;
    }
    out[enc] = 0U;
    return enc + 1;
}

enum class FrameError : std::uint8_t {
    kNone = 0,
    kOverlong,    // more than kMaxEncoded bytes before a delimiter
    kBadCobs,     // not a valid COBS encoding
    kBadLength,   // shorter than a header + CRC, or length field disagrees
    kBadCrc,      // CRC-32C mismatch
    kBadVersion,  // another protocol version
};

inline const char* to_string(FrameError e) noexcept {
    switch (e) {
        case FrameError::kNone:
            return "none";
        case FrameError::kOverlong:
            return "overlong frame";
        case FrameError::kBadCobs:
            return "bad COBS encoding";
        case FrameError::kBadLength:
            return "bad length";
        case FrameError::kBadCrc:
            return "bad CRC";
        case FrameError::kBadVersion:
            return "bad protocol version";
    }
    return "?";
}

struct Frame {
    std::uint8_t type;
    std::uint16_t seq;
    const std::uint8_t* payload;  // valid until the next push()
    std::size_t length;
};

// Byte-at-a-time frame decoder.
class FrameDecoder {
public:
    enum class Event : std::uint8_t { kNone, kFrame, kError };

    // Feeds one byte. kFrame: frame() is valid; kError: error() says why.
    Event push(std::uint8_t b) noexcept {
        if (b != 0U) {
            if (n_ < kMaxEncoded) {
                buf_[n_++] = b;
            } else {
                overlong_ = true;  // keep discarding until the delimiter
            }
            return Event::kNone;
        }
        const std::size_t n = n_;
        const bool overlong = overlong_;
        n_ = 0;
        overlong_ = false;
        if (n == 0 && !overlong) {
            return Event::kNone;  // idle delimiters resynchronise, they are not frames
        }
        return finish(n, overlong);
    }

    const Frame& frame() const noexcept { return frame_; }
    FrameError error() const noexcept { return error_; }

private:
    Event fail(FrameError e) noexcept {
        error_ = e;
        return Event::kError;
    }

    Event finish(std::size_t n, bool overlong) noexcept {
        if (overlong) {
            return fail(FrameError::kOverlong);
        }
        const std::size_t raw_n = cobs_decode(buf_, n, raw_, kMaxRaw);
        if (raw_n == 0) {
            return fail(FrameError::kBadCobs);
        }
        if (raw_n < kHeaderBytes + kCrcBytes || get_u16(raw_ + 4) != raw_n - kHeaderBytes - kCrcBytes) {
            return fail(FrameError::kBadLength);
        }
        const std::size_t len = raw_n - kHeaderBytes - kCrcBytes;
        if (crc32c(raw_, kHeaderBytes + len) != get_u32(raw_ + kHeaderBytes + len)) {
            return fail(FrameError::kBadCrc);
        }
        if (raw_[0] != kProtocolVersion) {
            return fail(FrameError::kBadVersion);
        }
        frame_ = {raw_[1], get_u16(raw_ + 2), raw_ + kHeaderBytes, len};
        error_ = FrameError::kNone;
        return Event::kFrame;
    }

    std::uint8_t buf_[kMaxEncoded] = {};
    std::uint8_t raw_[kMaxRaw] = {};
    std::size_t n_ = 0;
    bool overlong_ = false;
    Frame frame_{};
    FrameError error_ = FrameError::kNone;
};

}  // namespace ascorr::link
