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
#include <stdexcept>
#include <string>
#include <string_view>

#include "ascorr_hal/channel_config.hpp"
#include "ascorr_hal/voting.hpp"
#include "ascorr_text/input_name.hpp"

namespace ascorr::hal {

// A refused input file: "file:line:column: what". Lines and columns count
// from 1; 0 means none, and is never printed: "file:line: what" without a
// column, "file: what" for the whole file (e.g. "cannot open FILE: reason",
// whole_file()).
class ConfigError : public std::runtime_error {
public:
    ConfigError(const std::string& file, std::size_t line, std::size_t column, const std::string& what)
        : std::runtime_error(where(file, line, column) + what), line_(line), column_(column) {}
    // An error about the whole file, whose message names it itself.
    static ConfigError whole_file(const std::string& message) { return ConfigError(message); }
    std::size_t line() const noexcept { return line_; }
    std::size_t column() const noexcept { return column_; }

private:
    explicit ConfigError(const std::string& message) : std::runtime_error(message), line_(0), column_(0) {}
    static std::string where(const std::string& file, std::size_t line, std::size_t column) {
        if (line == 0U) {
            return text::input_name(file) + ": ";
        }
        return text::input_name(file) + ":" + std::to_string(line) +
               (column == 0U ? "" : ":" + std::to_string(column)) + ": ";
    }
    std::size_t line_;
    std::size_t column_;
};

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
