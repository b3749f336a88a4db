// ascorr_hal_linux/gpiod_backend.hpp: the MCP3208 on a Linux board, through
// libgpiod 1.6 (Debian 12, C++ binding gpiod.hpp, v1 API).
//
// Wiring (offsets on one gpiochip, from the configuration's `gpio` line):
//   CS   → MCP3208 pin 10 (CS/SHDN), output, requested high (idle: deselected)
//   CLK  → pin 13 (CLK),             output, requested low  (SPI mode 0,0)
//   MOSI → pin 11 (DIN),             output, requested low
//   MISO ← pin 12 (DOUT),            input, with the board's pull-up (or a
//          10 kΩ to 3.3 V) so that an absent ADC reads 1 and fails the
//          null-bit check (kBus) instead of reading 0 counts.
//   VDD and VREF at 3.3 V, which also supplies the dividers (ratiometric);
//   CH0…CH7 to the divider midpoints, each with 100 nF to AGND (the settle
//   time covers its RC constant).
// All four lines are requested by the constructor with consumer "ascorr" and
// released by the destructor. Every libgpiod error during a conversion is a
// bus fault on that channel (the pin calls return false), never an exception
// out of acquire(); opening the chip or requesting a line that does not
// exist throws std::system_error with the chip and offset named.
#pragma once

#include <chrono>
#include <cstdint>
#include <memory>
#include <string>

#include "ascorr_hal/clock.hpp"
#include "ascorr_hal/mcp3208.hpp"
#include "ascorr_hal/sample_set.hpp"
#include "config_file.hpp"

namespace ascorr::hal {

// std::chrono::steady_clock, with nanosleep-based waits.
class SteadyClock final : public Clock {
public:
    std::uint64_t now_us() noexcept override;
    void wait_us(std::uint32_t us) noexcept override;
};

class GpiodPins final : public BitBangPins {
public:
    explicit GpiodPins(const GpioWiring& wiring);
    ~GpiodPins() override;
    GpiodPins(const GpiodPins&) = delete;
    GpiodPins& operator=(const GpiodPins&) = delete;

    bool set_cs(bool level) noexcept override;
    bool set_clk(bool level) noexcept override;
    bool set_mosi(bool level) noexcept override;
    bool get_miso(bool& level) noexcept override;

private:
    struct Lines;
    std::unique_ptr<Lines> lines_;
};

// The whole Linux backend: pins, MCP3208, sampler, on the given clock.
class GpiodSampleSetSource final : public SampleSetSource<double> {
public:
    GpiodSampleSetSource(const HalConfig& config, Clock& clock);
    bool acquire(SampleSet<double>& samples) noexcept override { return source_.acquire(samples); }

private:
    HalConfig config_;
    GpiodPins pins_;
    Mcp3208 adc_;
    AdcSampleSetSource<double> source_;
};

}  // namespace ascorr::hal
