// ascorr_hal/mcp3208.hpp: one MCP3208 conversion, bit-banged over four pins.
//
// Conventions (Microchip MCP3204/3208 data sheet, SPI mode 0,0):
//  - Pins: CS (active low, idle high), CLK (idle low), MOSI → DIN, DOUT → MISO.
//  - The device latches DIN on each rising CLK edge and shifts DOUT out on
//    falling edges. A conversion is 19 clocks after CS falls:
//      clocks 1–5: start bit (1), SGL/DIFF (1 = single ended), D2, D1, D0;
//      clock 6:    sample period ends (DOUT still undefined, read and ignored);
//      clock 7:    null bit, must read 0;
//      clocks 8–19: B11 … B0, most significant first.
//    We read DOUT while CLK is high (after the falling edge that shifted it).
//  - A null bit of 1 means no device is driving DOUT (open line, pulled up, or
//    unpowered ADC): the conversion fails with a bus fault, never a value.
//  - Freestanding: the pins are an interface (BitBangPins); the firmware
//    implements it on its GPIO registers, the Linux backend with libgpiod.
//    The loop is bounded (19 clocks); no heap, no exceptions.
#pragma once

#include <cstdint>
#include "interface.hpp"

#include "clock.hpp"

namespace ascorr::hal {

// Four GPIO lines. Every call returns false when the line could not be driven
// or read (the conversion then fails with a bus fault).
class BitBangPins : private Interface {
public:
    virtual ~BitBangPins() = default;
    virtual bool set_cs(bool level) noexcept = 0;
    virtual bool set_clk(bool level) noexcept = 0;
    virtual bool set_mosi(bool level) noexcept = 0;
    virtual bool get_miso(bool& level) noexcept = 0;
};

// One ADC that converts a channel into counts: the device interface the
// sampler uses (a MCP3208, a replayed or simulated ADC).
class AdcPort : private Interface {
public:
    virtual ~AdcPort() = default;
    // false: the conversion failed (bus fault); counts is then unspecified.
    virtual bool convert(std::uint8_t channel, std::uint16_t& counts) noexcept = 0;
};

class Mcp3208 final : public AdcPort {
public:
    static constexpr std::uint8_t kChannels = 8;
    static constexpr std::uint16_t kLevels = 4096;
    static constexpr int kClocksPerConversion = 19;

    // half_period_us: CLK high and low time (0 for as fast as the pins go;
    // the MCP3208 needs ≥ 0.5 µs at 2.7 V, and a clock ≥ 10 kHz so that the
    // sample-and-hold does not droop: keep half_period_us ≤ 50).
    Mcp3208(BitBangPins& pins, Clock& clock, std::uint32_t half_period_us) noexcept
        : pins_(pins), clock_(clock), half_us_(half_period_us) {}

    bool convert(std::uint8_t channel, std::uint16_t& counts) noexcept override {
        if (channel >= kChannels) {
            return false;
        }
        bool ok = pins_.set_clk(false) && pins_.set_cs(false);
        const unsigned command = 0x18U | channel;  // 1 1 D2 D1 D0: start, single-ended, channel
        unsigned value = 0;
        bool null_bit = true;
        for (int clk = 1; ok && clk <= kClocksPerConversion; ++clk) {
            ok = pins_.set_clk(false);
            if (ok && clk <= 5) {
                ok = pins_.set_mosi(((command >> static_cast<unsigned>(5 - clk)) & 1U) != 0U);
            }
            wait();
            ok = ok && pins_.set_clk(true);
            bool bit = false;
            if (ok && clk >= 7) {
                ok = pins_.get_miso(bit);
            }
            if (clk == 7) {
                null_bit = bit;
            } else if (clk >= 8) {
                value = (value << 1U) | (bit ? 1U : 0U);
            }
            wait();
        }
        // Always release the bus, even after a failed line operation.
        const bool clk_low = pins_.set_clk(false);
        const bool mosi_low = pins_.set_mosi(false);
        const bool deselected = pins_.set_cs(true);
        const bool released = clk_low && mosi_low && deselected;
        counts = static_cast<std::uint16_t>(value & 0x0FFFU);
        return ok && released && !null_bit;
    }

private:
    void wait() noexcept {
        if (half_us_ != 0U) {
            clock_.wait_us(half_us_);
        }
    }

    BitBangPins& pins_;
    Clock& clock_;
    std::uint32_t half_us_;
};

}  // namespace ascorr::hal
