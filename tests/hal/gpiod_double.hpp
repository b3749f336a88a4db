// tests/hal/gpiod_double.hpp: a scripted libgpiod (v1 C++ API) for tests.
//
// gpiod_double.cpp defines the gpiod::chip and gpiod::line members that the
// backend (hal/linux/src/gpiod_backend.cpp) uses, so a test linked with it
// instead of libgpiodcxx talks to this double at the libgpiod API boundary.
// The double plays a GPIO chip with an MCP3208 wired to it (offsets from the
// script): it tracks every line level, decodes the SPI bit stream the way the
// ADC would (commands latched on rising CLK edges while CS is low, DOUT
// shifted on falling edges: null bit after clock 6, B11…B0 after clocks
// 7…18), serves the scripted counts, and records every call and every
// protocol violation it can see.
#pragma once

#include <cstdint>
#include <functional>
#include <set>
#include <string>
#include <vector>

namespace gpiod_double {

struct Script {
    std::string chip = "gpiochip0";
    unsigned num_lines = 32;
    unsigned cs = 8, clk = 11, mosi = 10, miso = 9;
    // Counts served for (channel, index of the conversion on that channel).
    std::function<std::uint16_t(unsigned channel, unsigned index)> counts = [](unsigned, unsigned) {
        return std::uint16_t{2048};
    };
    bool device_present = true;          // false: DOUT floats high (pull-up)
    std::set<unsigned> failing_outputs;  // set_value on these offsets throws std::system_error
};

struct Call {
    enum Kind { kOpen, kGetLine, kRequest, kSet, kGet, kRelease } kind;
    unsigned offset;
    int value;             // kSet: level, kGet: level returned, kRequest: default value
    int request_type;      // kRequest
    std::string consumer;  // kRequest; kOpen: device name
};

struct Conversion {
    bool start;
    bool single_ended;
    unsigned channel;
    unsigned rising_clocks;       // while CS was low, counted from the start bit
    std::uint16_t served;         // counts the device shifted out
    unsigned miso_reads_clk_low;  // DOUT read while CLK was low (a protocol error)
};

void reset(Script script);
const std::vector<Call>& calls();
const std::vector<Conversion>& conversions();
const std::vector<std::string>& protocol_errors();
int level(unsigned offset);  // -1: never driven
bool requested(unsigned offset);

}  // namespace gpiod_double
