// ascorr_link/wire.hpp: the link's payload encoding (little-endian).
//
// A "word" is one scalar of the target's type in its 32-bit wire form
// (WireTraits), so host and target exchange exactly the values the core
// computes with: a float target gets IEEE binary32 bit patterns, a
// fixed-point target its raw Q integers. Writer and Reader put and take
// fields; a Reader never reads past its payload (each read says whether the
// field was there), and done() says whether it was all read.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>

#include "ascorr/core/fixed_point.hpp"
#include "ascorr/core/model_coefficients.hpp"
#include "frame.hpp"

namespace ascorr::link {
// 32-bit wire form of a scalar type. kKind identifies the representation in
// HELLO, so that a host never talks float to a fixed-point target.
template <typename U>
struct WireTraits;

template <>
struct WireTraits<float> {
    static constexpr std::uint8_t kKind = 1;  // IEEE 754 binary32
    static std::uint32_t encode(float x) noexcept {
        std::uint32_t w = 0;
        std::memcpy(&w, &x, sizeof w);
        return w;
    }
    static float decode(std::uint32_t w) noexcept {
        float x = 0.0F;
        std::memcpy(&x, &w, sizeof x);
        return x;
    }
};

// Fixed-point types travel as their raw two's-complement integers, so the
// target computes with exactly the values the host's fixed-point core uses.
template <typename U>
struct RawWire {
    static std::uint32_t encode(U x) noexcept {
        std::uint32_t w = 0;
        std::memcpy(&w, &x.raw, sizeof w);
        return w;
    }
    static U decode(std::uint32_t w) noexcept {
        U x{};
        std::memcpy(&x.raw, &w, sizeof w);
        return x;
    }
};
template <>
struct WireTraits<Q30> : RawWire<Q30> {
    static constexpr std::uint8_t kKind = 2;  // Q30 core (fixed_point.hpp)
};
template <>
struct WireTraits<QCelsius> : RawWire<QCelsius> {};
template <>
struct WireTraits<QCoefficient> : RawWire<QCoefficient> {};
template <>
struct WireTraits<QQuadraticCoefficient> : RawWire<QQuadraticCoefficient> {};

// ---- encoding helpers
class Writer {
public:
    explicit Writer(std::uint8_t* p) noexcept : p_(p) {}
    void u8(std::uint8_t v) noexcept { p_[n_++] = v; }
    void u16(std::uint16_t v) noexcept {
        put_u16(p_ + n_, v);
        n_ += 2;
    }
    void u32(std::uint32_t v) noexcept {
        put_u32(p_ + n_, v);
        n_ += 4;
    }
    template <typename U>
    void word(const U& v) noexcept {
        u32(WireTraits<U>::encode(v));
    }
    void u64(std::uint64_t v) noexcept {
        u32(static_cast<std::uint32_t>(v));
        u32(static_cast<std::uint32_t>(v >> 32));
    }
    void f64(double x) noexcept {
        std::uint64_t v = 0;
        std::memcpy(&v, &x, sizeof v);
        u64(v);
    }
    std::size_t size() const noexcept { return n_; }

private:
    std::uint8_t* p_;
    std::size_t n_ = 0;
};

class Reader {
public:
    Reader(const std::uint8_t* p, std::size_t n) noexcept : p_(p), n_(n) {}
    bool u8(std::uint8_t& v) noexcept {
        if (i_ + 1 > n_) {
            return false;
        }
        v = p_[i_++];
        return true;
    }
    bool u16(std::uint16_t& v) noexcept {
        if (i_ + 2 > n_) {
            return false;
        }
        v = get_u16(p_ + i_);
        i_ += 2;
        return true;
    }
    bool u32(std::uint32_t& v) noexcept {
        if (i_ + 4 > n_) {
            return false;
        }
        v = get_u32(p_ + i_);
        i_ += 4;
        return true;
    }
    template <typename U>
    bool word(U& v) noexcept {
        std::uint32_t w = 0;
        if (!u32(w)) {
            return false;
        }
        v = WireTraits<U>::decode(w);
        return true;
    }
    bool u64(std::uint64_t& v) noexcept {
        std::uint32_t lo = 0;
        std::uint32_t hi = 0;
        if (!(u32(lo) && u32(hi))) {
            return false;
        }
        v = (std::uint64_t{hi} << 32) | lo;
        return true;
    }
    bool f64(double& x) noexcept {
        std::uint64_t v = 0;
        if (!u64(v)) {
            return false;
        }
        std::memcpy(&x, &v, sizeof x);
        return true;
    }
    bool i64(std::int64_t& x) noexcept {
        std::uint64_t v = 0;
        if (!u64(v)) {
            return false;
        }
        std::memcpy(&x, &v, sizeof x);
        return true;
    }
    bool done() const noexcept { return i_ == n_; }

private:
    const std::uint8_t* p_;
    std::size_t n_;
    std::size_t i_ = 0;
};

// One head's linear coefficients (α, β, γ × c0..c3) as 12 IEEE binary64;
// `acceptable` judges each one read.
using LinearCoefficients = double[kModelAxes][kLinearModelTerms];
inline void put_linear(Writer& w, const LinearCoefficients& c) noexcept {
    for (const auto& axis : c) {
        for (const double x : axis) {
            w.f64(x);
        }
    }
}
template <typename Acceptable>
bool get_linear(Reader& r, LinearCoefficients& c, Acceptable acceptable) noexcept {
    for (auto& axis : c) {
        for (double& x : axis) {
            if (!r.f64(x) || !acceptable(x)) {
                return false;
            }
        }
    }
    return true;
}

}  // namespace ascorr::link
