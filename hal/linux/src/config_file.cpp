// The thermistor configuration file (config_file.hpp).
#include "ascorr_hal_linux/config_file.hpp"

#include "ascorr_hal/channel_defaults.hpp"
#include "ascorr_text/c_format.hpp"
#include "ascorr_text/text_file.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <utility>
#include <vector>

namespace ascorr::hal {
namespace {

struct Token {
    std::string_view key;
    std::string_view value;
    std::size_t key_col;
    std::size_t value_col;
};

class LineParser {
public:
    LineParser(const std::string& file, std::size_t line) : file_(file), line_(line) {}

    [[noreturn]] void fail(std::size_t col, const std::string& what) const {
        throw text::InputError(file_, line_, col, what);
    }

    double number(const Token& t) const {
        double v = 0.0;
        const char* b = t.value.data();
        const char* e = b + t.value.size();
        const auto r = std::from_chars(b, e, v);
        if (t.value.empty() || r.ec != std::errc() || r.ptr != e || !std::isfinite(v)) {
            fail(t.value_col, "'" + std::string(t.key) + "': " +
                                  text::number_refusal(t.value, "not a finite number: '" + std::string(t.value) + "'"));
        }
        return v;
    }

    double positive(const Token& t) const {
        const double v = number(t);
        if (!(v > 0.0)) {
            fail(t.value_col, "'" + std::string(t.key) + "' must be > 0");
        }
        return v;
    }

    unsigned long long integer(const Token& t, unsigned long long lo, unsigned long long hi) const {
        unsigned long long v = 0;
        const char* b = t.value.data();
        const char* e = b + t.value.size();
        const auto r = std::from_chars(b, e, v);
        if (t.value.empty() || r.ec != std::errc() || r.ptr != e || v < lo || v > hi) {
            fail(t.value_col, "'" + std::string(t.key) + "': expected an integer in [" + std::to_string(lo) + ", " +
                                  std::to_string(hi) + "], got '" + std::string(t.value) + "'");
        }
        return v;
    }

private:
    const std::string& file_;
    std::size_t line_;
};

}  // namespace

int find_channel(const AcquisitionConfig<double>& c, std::string_view name) noexcept {
    for (std::uint8_t i = 0; i < c.channels; ++i) {
        if (name == c.channel[i].name) {
            return i;
        }
    }
    return -1;
}

namespace {

// One directive line split into its directive word and key=value tokens
// (columns 1-based); a malformed or repeated key is an error at its column.
struct DirectiveLine {
    std::string_view directive;
    std::size_t directive_col = 0;
    std::vector<Token> tokens;
};

void split_line(std::string_view line, const LineParser& p, DirectiveLine& out) {
    const std::size_t hash = line.find('#');
    if (hash != std::string_view::npos) {
        line = line.substr(0, hash);
    }
    out.directive = {};
    out.directive_col = 0;
    out.tokens.clear();
    std::size_t i = 0;
    while (i < line.size()) {
        if (line[i] == ' ' || line[i] == '\t') {
            ++i;
            continue;
        }
        const std::size_t start = i;
        while (i < line.size() && line[i] != ' ' && line[i] != '\t') {
            ++i;
        }
        const std::string_view word = line.substr(start, i - start);
        if (out.directive.empty()) {
            out.directive = word;
            out.directive_col = start + 1;
            continue;
        }
        const std::size_t eq = word.find('=');
        if (eq == std::string_view::npos || eq == 0) {
            p.fail(start + 1, "expected key=value, got '" + std::string(word) + "'");
        }
        for (const Token& t : out.tokens) {
            if (t.key == word.substr(0, eq)) {
                p.fail(start + 1, "duplicate key '" + std::string(t.key) + "'");
            }
        }
        out.tokens.push_back({word.substr(0, eq), word.substr(eq + 1), start + 1, start + eq + 2});
    }
}

void parse_acquisition(const DirectiveLine& d, const LineParser& p, HalConfig& cfg) {
    AcquisitionConfig<double>& a = cfg.acquisition;
    for (const Token& t : d.tokens) {
        if (t.key == "settle_us") {
            a.sampler.settle_us = static_cast<std::uint32_t>(p.integer(t, 0, 10000000));
        } else if (t.key == "samples") {
            a.sampler.samples = static_cast<std::uint8_t>(p.integer(t, 1, kMaxSamples));
        } else if (t.key == "gap_us") {
            a.sampler.gap_us = static_cast<std::uint32_t>(p.integer(t, 0, 10000000));
        } else if (t.key == "half_period_us") {
            cfg.gpio.half_period_us = static_cast<std::uint32_t>(p.integer(t, 0, 50));
        } else if (t.key == "stale_s") {
            a.stale_us = static_cast<std::uint64_t>(std::llround(p.positive(t) * 1e6));
        } else if (t.key == "vote_tolerance") {
            a.vote_tolerance = p.positive(t);
        } else if (t.key == "quorum") {
            a.quorum = static_cast<std::uint8_t>(p.integer(t, 1, kMaxVoters));
        } else {
            p.fail(t.key_col, "unknown acquisition key '" + std::string(t.key) + "'");
        }
    }
}

void parse_gpio(const DirectiveLine& d, const LineParser& p, GpioWiring& gpio) {
    for (const Token& t : d.tokens) {
        if (t.key == "chip") {
            if (t.value.empty()) {
                p.fail(t.value_col, "'chip' is empty");
            }
            gpio.chip = std::string(t.value);
        } else if (t.key == "cs") {
            gpio.cs = static_cast<unsigned>(p.integer(t, 0, 1023));
        } else if (t.key == "clk") {
            gpio.clk = static_cast<unsigned>(p.integer(t, 0, 1023));
        } else if (t.key == "mosi") {
            gpio.mosi = static_cast<unsigned>(p.integer(t, 0, 1023));
        } else if (t.key == "miso") {
            gpio.miso = static_cast<unsigned>(p.integer(t, 0, 1023));
        } else {
            p.fail(t.key_col, "unknown gpio key '" + std::string(t.key) + "'");
        }
    }
    const unsigned lines[4] = {gpio.cs, gpio.clk, gpio.mosi, gpio.miso};
    for (int x = 0; x < 4; ++x) {
        for (int y = x + 1; y < 4; ++y) {
            if (lines[x] == lines[y]) {
                p.fail(d.directive_col, "gpio: two signals on line " + std::to_string(lines[x]));
            }
        }
    }
}

// The keys a channel line must have, as they are seen.
struct RequiredChannelKeys {
    bool name = false, adc = false, role = false, a = false, b = false, c = false;
    const char* first_missing() const noexcept {
        return !name ? "name" : !adc ? "adc" : !role ? "role" : !a ? "a" : !b ? "b" : !c ? "c" : nullptr;
    }
};

void parse_channel_name(const Token& t, const LineParser& p, const AcquisitionConfig<double>& a,
                        ChannelConfig<double>& c) {
    if (t.value.empty() || t.value.size() >= kNameLength) {
        p.fail(t.value_col, "'name' must have 1 to " + std::to_string(kNameLength - 1) + " characters");
    }
    for (char ch : t.value) {
        if (!(std::isalnum(static_cast<unsigned char>(ch)) || ch == '_')) {
            p.fail(t.value_col, "'name' may hold letters, digits and '_' only");
        }
    }
    if (find_channel(a, t.value) >= 0) {
        p.fail(t.value_col, "channel '" + std::string(t.value) + "' defined twice");
    }
    std::memcpy(c.name, t.value.data(), t.value.size());
    c.name[t.value.size()] = '\0';
}

void parse_channel_adc(const Token& t, const LineParser& p, const AcquisitionConfig<double>& a,
                       ChannelConfig<double>& c) {
    c.adc_channel = static_cast<std::uint8_t>(p.integer(t, 0, 7));
    for (std::uint8_t k = 0; k < a.channels; ++k) {
        if (a.channel[k].adc_channel == c.adc_channel) {
            p.fail(t.value_col,
                   "ADC input " + std::to_string(c.adc_channel) + " already used by '" + a.channel[k].name + "'");
        }
    }
}

// "monitor, chu_a, …, t032", from kRoleNames.
std::string role_list() {
    std::string s;
    for (std::uint8_t r = 0; r < kRoleCount; ++r) {
        s += (r == 0 ? "" : ", ") + std::string(kRoleNames[r]);
    }
    return s;
}

void parse_channel_role(const Token& t, const LineParser& p, const AcquisitionConfig<double>& a,
                        ChannelConfig<double>& c) {
    bool found = false;
    for (std::uint8_t r = 0; r < kRoleCount; ++r) {
        if (t.value == kRoleNames[r]) {
            c.role = static_cast<Role>(r);
            found = true;
        }
    }
    if (!found) {
        p.fail(t.value_col, "unknown role '" + std::string(t.value) + "' (" + role_list() + ")");
    }
    std::uint8_t same = 0;
    for (std::uint8_t k = 0; k < a.channels; ++k) {
        same = static_cast<std::uint8_t>(same + (a.channel[k].role == c.role ? 1 : 0));
    }
    if (c.role != Role::kMonitor && same >= kMaxVoters) {
        p.fail(t.value_col, "more than 3 channels with role '" + std::string(t.value) + "'");
    }
}

// The optional keys of a channel line: its divider, limits and checks.
void parse_channel_option(const Token& t, const LineParser& p, ChannelConfig<double>& c) {
    if (t.key == "divider") {
        if (t.value != "low" && t.value != "high") {
            p.fail(t.value_col, "'divider' is low or high");
        }
        c.divider.thermistor_low = t.value == "low";
    } else if (t.key == "r_fixed") {
        c.divider.r_fixed = p.positive(t);
    } else if (t.key == "levels") {
        c.divider.levels = static_cast<std::uint16_t>(p.integer(t, 2, 65535));
    } else if (t.key == "r_open") {
        c.r_open = p.positive(t);
    } else if (t.key == "r_short") {
        c.r_short = p.number(t);
    } else if (t.key == "t_min") {
        c.t_min = p.number(t);
    } else if (t.key == "t_max") {
        c.t_max = p.number(t);
    } else if (t.key == "max_rate") {
        c.max_rate = p.number(t);
        if (c.max_rate < 0.0) {
            p.fail(t.value_col, "'max_rate' must be >= 0");
        }
    } else if (t.key == "stuck_frames") {
        c.stuck_frames = static_cast<std::uint16_t>(p.integer(t, 0, 65535));
    } else if (t.key == "max_spread") {
        c.max_spread = static_cast<std::uint16_t>(p.integer(t, 0, 65535));
    } else {
        p.fail(t.key_col, "unknown channel key '" + std::string(t.key) + "'");
    }
}

// The Steinhart–Hart curve must be an NTC's (check_curve) on every
// resistance the channel converts: between r_short and r_open, and within
// what the divider's codes 1 … levels − 1 can give.
void check_channel_curve(const DirectiveLine& d, const LineParser& p, const ChannelConfig<double>& c) {
    const auto top = static_cast<std::uint16_t>(c.divider.levels - 1U);  // levels >= 2
    const std::uint16_t one = 1U;
    const double code_lo = resistance_from_counts(c.divider, c.divider.thermistor_low ? one : top);
    const double code_hi = resistance_from_counts(c.divider, c.divider.thermistor_low ? top : one);
    const double r_lo = std::max(c.r_short > 0.0 ? c.r_short : 0.0, code_lo);
    const double r_hi = std::min(c.r_open, code_hi);
    if (!(r_lo < r_hi)) {
        return;  // no resistance is converted: every reading is open or short
    }
    const CurveCheck<double> k = check_curve(c.sh, r_lo, r_hi);
    if (k.ok) {
        return;
    }
    char buf[320];
    if (k.no_temperature) {
        text::c_snprintf(buf, sizeof buf,
                         "channel '%s': the Steinhart-Hart coefficients give no temperature (1/T <= 0) at R = %.6g ohm "
                         "(the channel converts %.6g ... %.6g ohm)",
                         c.name, k.r_from, r_lo, r_hi);
    } else {
        text::c_snprintf(buf, sizeof buf,
                         "channel '%s': the Steinhart-Hart coefficients are not monotonic (T does not fall as R rises) "
                         "for R in [%.6g, %.6g] ohm (T %.6g ... %.6g degC); the channel converts %.6g ... %.6g ohm",
                         c.name, k.r_from, k.r_to, celsius_from_resistance(c.sh, k.r_from),
                         celsius_from_resistance(c.sh, k.r_to), r_lo, r_hi);
    }
    p.fail(d.directive_col, buf);
}

// Checks that need the whole channel line: the required keys and the ranges.
void check_channel(const DirectiveLine& d, const LineParser& p, const RequiredChannelKeys& seen,
                   const ChannelConfig<double>& c) {
    if (const char* missing = seen.first_missing()) {
        p.fail(d.directive_col, std::string("channel: missing '") + missing + "'");
    }
    const std::string name(c.name);
    if (!(c.t_min < c.t_max)) {
        p.fail(d.directive_col, "channel '" + name + "': t_min must be below t_max");
    }
    if (!(c.r_short < c.r_open)) {
        p.fail(d.directive_col, "channel '" + name + "': r_short must be below r_open");
    }
    if (!(std::fabs(c.t_min) <= 200.0 && std::fabs(c.t_max) <= 200.0)) {
        p.fail(d.directive_col, "channel '" + name + "': t_min, t_max must be within ±200 °C");
    }
    check_channel_curve(d, p, c);
}

void parse_channel(const DirectiveLine& d, const LineParser& p, AcquisitionConfig<double>& a) {
    if (a.channels >= kMaxChannels) {
        p.fail(d.directive_col, "more than " + std::to_string(kMaxChannels) + " channels");
    }
    ChannelConfig<double> c = default_channel<double>();  // channel_defaults.hpp
    RequiredChannelKeys seen;
    for (const Token& t : d.tokens) {
        if (t.key == "name") {
            parse_channel_name(t, p, a, c);
            seen.name = true;
        } else if (t.key == "adc") {
            parse_channel_adc(t, p, a, c);
            seen.adc = true;
        } else if (t.key == "role") {
            parse_channel_role(t, p, a, c);
            seen.role = true;
        } else if (t.key == "a") {
            c.sh.a = p.number(t);
            seen.a = true;
        } else if (t.key == "b") {
            c.sh.b = p.number(t);
            seen.b = true;
        } else if (t.key == "c") {
            c.sh.c = p.number(t);
            seen.c = true;
        } else {
            parse_channel_option(t, p, c);
        }
    }
    check_channel(d, p, seen, c);
    a.channel[a.channels++] = c;
}

}  // namespace

HalConfig parse_config(const std::string& file_name, std::string_view text) {
    HalConfig cfg;
    cfg.acquisition = default_acquisition<double>();  // channel_defaults.hpp
    AcquisitionConfig<double>& a = cfg.acquisition;
    bool seen_acq = false;
    bool seen_gpio = false;
    text::TextLines lines(file_name, text);
    std::string_view line;
    DirectiveLine d;
    while (lines.next(line)) {
        const LineParser p(file_name, lines.number());
        split_line(line, p, d);
        if (d.directive.empty()) {
            continue;
        }
        if (d.directive == "acquisition") {
            if (std::exchange(seen_acq, true)) {
                p.fail(d.directive_col, "a second 'acquisition' line");
            }
            parse_acquisition(d, p, cfg);
        } else if (d.directive == "gpio") {
            if (std::exchange(seen_gpio, true)) {
                p.fail(d.directive_col, "a second 'gpio' line");
            }
            parse_gpio(d, p, cfg.gpio);
        } else if (d.directive == "channel") {
            parse_channel(d, p, a);
        } else {
            p.fail(d.directive_col,
                   "unknown directive '" + std::string(d.directive) + "' (acquisition, gpio, channel)");
        }
    }
    if (a.channels == 0U) {
        throw text::InputError(file_name, lines.end_line(), 1, "no 'channel' line");
    }
    return cfg;
}

HalConfig read_config(const std::string& path) {
    return parse_config(path, text::read_text_file(path));
}

}  // namespace ascorr::hal
