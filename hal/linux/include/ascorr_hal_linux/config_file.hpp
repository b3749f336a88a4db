// ascorr_hal_linux/config_file.hpp: the thermistor configuration file.
//
// Format (line oriented, UTF-8; '#' starts a comment; blank lines ignored).
// Each line is a directive followed by key=value pairs, separated by spaces:
//
//   acquisition settle_us=2000 samples=9 gap_us=0 half_period_us=5 stale_s=5
//               vote_tolerance=1.0 quorum=2
//   gpio chip=gpiochip0 cs=8 clk=11 mosi=10 miso=9
//   channel name=THT00029 adc=0 role=t029 a=1.129241e-3 b=2.341077e-4 c=8.775468e-8
//           [divider=low|high] [r_fixed=10000] [levels=4096] [r_open=2e6] [r_short=100]
//           [t_min=-60] [t_max=80] [max_rate=0.5] [stuck_frames=0] [max_spread=8]
//
// (a directive is one line; it is wrapped here for reading). Units: µs, s, °C,
// °C/s, ohm, counts; a, b, c are the thermistor's Steinhart–Hart coefficients.
// role is one of monitor, chu_a … chu_d, t029, t032; at most 8 channels, at
// most 3 per role, names and ADC inputs unique. `gpio` and `acquisition` are
// optional (defaults as shown; they come from ascorr_hal/channel_defaults.hpp)
// and may appear once each. Every error is
// reported as file:line:column with the offending key or value.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "ascorr_hal/channel_config.hpp"
#include "ascorr_hal/voting.hpp"
#include "ascorr_text/input_error.hpp"

namespace ascorr::hal {

// Every refusal of the HAL's readers is a text::InputError
// (ascorr_text/input_error.hpp): "file:line:column: what".

// The wiring of the bit-banged MCP3208 (GPIO line offsets on one chip).
struct GpioWiring {
    std::string chip = "gpiochip0";
    unsigned cs = 8;
    unsigned clk = 11;
    unsigned mosi = 10;
    unsigned miso = 9;
    std::uint32_t half_period_us = 5;
};

struct HalConfig {
    AcquisitionConfig<double> acquisition{};
    GpioWiring gpio;
};

HalConfig parse_config(const std::string& file_name, std::string_view text);
HalConfig read_config(const std::string& path);

// Index of the channel called name, or -1.
int find_channel(const AcquisitionConfig<double>& c, std::string_view name) noexcept;

}  // namespace ascorr::hal
