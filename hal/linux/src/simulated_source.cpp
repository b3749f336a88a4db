// Simulated acquisition from temperature histories (simulated_source.hpp).
#include "ascorr_hal_linux/simulated_source.hpp"
#include "text_lines.hpp"

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace ascorr::hal {
namespace {

bool parse_number(std::string_view v, double& x) {
    const auto r = std::from_chars(v.data(), v.data() + v.size(), x);
    return !v.empty() && r.ec == std::errc() && r.ptr == v.data() + v.size();
}

}  // namespace

InjectedFault parse_fault(std::string_view spec, const AcquisitionConfig<double>& config) {
    std::vector<std::string_view> part;
    std::size_t start = 0;
    while (true) {
        const std::size_t c = spec.find(':', start);
        part.push_back(spec.substr(start, c == std::string_view::npos ? std::string_view::npos : c - start));
        if (c == std::string_view::npos) {
            break;
        }
        start = c + 1;
    }
    const std::string s(spec);
    if (part.size() < 4 || part.size() > 5) {
        throw std::invalid_argument("fault '" + s + "': expected NAME:KIND:FROM:TO[:VALUE]");
    }
    InjectedFault f{find_channel(config, part[0]), FaultKind::kOpen, 0.0, 0.0, 0.0};
    if (f.channel < 0) {
        throw std::invalid_argument("fault '" + s + "': no channel '" + std::string(part[0]) + "'");
    }
    static constexpr std::pair<const char*, FaultKind> kinds[] = {
        {"open", FaultKind::kOpen},   {"short", FaultKind::kShort},   {"bus", FaultKind::kBus},
        {"stuck", FaultKind::kStuck}, {"offset", FaultKind::kOffset}, {"noise", FaultKind::kNoise},
        {"drop", FaultKind::kDrop}};
    bool found = false;
    for (const auto& [name, kind] : kinds) {
        if (part[1] == name) {
            f.kind = kind;
            found = true;
        }
    }
    if (!found) {
        throw std::invalid_argument("fault '" + s + "': unknown kind '" + std::string(part[1]) +
                                    "' (open, short, bus, stuck, offset, noise, drop)");
    }
    if (!parse_number(part[2], f.from_s) || !parse_number(part[3], f.to_s) || !(f.from_s < f.to_s)) {
        throw std::invalid_argument("fault '" + s + "': FROM and TO must be numbers with FROM < TO");
    }
    const bool needs_value = f.kind == FaultKind::kOffset || f.kind == FaultKind::kNoise;
    if (needs_value != (part.size() == 5) || (needs_value && !parse_number(part[4], f.value))) {
        throw std::invalid_argument("fault '" + s + "': " + (needs_value ? "needs" : "takes no") + " VALUE");
    }
    return f;
}

std::vector<HistoryRow> parse_history(const std::string& file, std::string_view text) {
    std::vector<HistoryRow> rows;
    int col_t = -1, col_chu = -1, col_t1 = -1, col_t2 = -1, col_t3 = -1;
    std::size_t ncols = 0;
    linux_detail::TextLines lines(text);
    std::string_view line;
    std::vector<linux_detail::Field> f;
    while (lines.next(line)) {
        const std::size_t line_no = lines.number();
        linux_detail::split_fields(line, f);
        if (line_no == 1) {
            for (std::size_t i = 0; i < f.size(); ++i) {
                const std::string_view n = f[i].first;
                int* slot = n == "t"       ? &col_t
                            : n == "chu"   ? &col_chu
                            : n == "t_chu" ? &col_t1
                            : n == "t_029" ? &col_t2
                            : n == "t_032" ? &col_t3
                                           : nullptr;
                if (slot != nullptr) {
                    *slot = static_cast<int>(i);
                }
            }
            if (col_t < 0 || col_t1 < 0 || col_t2 < 0 || col_t3 < 0) {
                throw ConfigError(file, 1, 1, "a temperature history needs columns t, t_chu, t_029, t_032");
            }
            ncols = f.size();
            continue;
        }
        if (line.empty() && lines.at_end()) {  // a blank last line
            break;
        }
        if (f.size() != ncols) {
            throw ConfigError(file, line_no, line.size() + 1,
                              "expected " + std::to_string(ncols) + " fields, found " + std::to_string(f.size()));
        }
        HistoryRow r{0.0, -1, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN(),
                     std::numeric_limits<double>::quiet_NaN()};
        if (!parse_number(f[static_cast<std::size_t>(col_t)].first, r.t) || !std::isfinite(r.t) || r.t < 0.0) {
            throw ConfigError(file, line_no, f[static_cast<std::size_t>(col_t)].second, "'t' must be seconds >= 0");
        }
        if (col_chu >= 0) {
            const auto& [v, c] = f[static_cast<std::size_t>(col_chu)];
            if (v.size() != 1 || head_index(v[0]) == kUnknownHead) {
                throw ConfigError(file, line_no, c, "'chu' must be " + std::string(kHeadChoices.text));
            }
            r.head = head_index(v[0]);
        }
        double* dst[3] = {&r.t_chu, &r.t_029, &r.t_032};
        const int cols[3] = {col_t1, col_t2, col_t3};
        for (int k = 0; k < 3; ++k) {
            const auto& [v, c] = f[static_cast<std::size_t>(cols[k])];
            if (v.empty() || v == "nan") {
                continue;
            }
            if (!parse_number(v, *dst[k])) {
                throw ConfigError(file, line_no, c, "not a temperature: '" + std::string(v) + "'");
            }
        }
        rows.push_back(r);
    }
    if (lines.number() == 0) {
        throw ConfigError(file, 1, 1, "empty file (no header)");
    }
    return rows;
}

std::vector<HistoryRow> read_history(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        throw ConfigError(path, 0, 0, std::string("cannot open: ") + std::strerror(errno));
    }
    std::ostringstream ss;
    ss << in.rdbuf();
    return parse_history(path, ss.str());
}

bool SimulatedAdc::active(const InjectedFault& f) const noexcept {
    const double t = static_cast<double>(clock_.now_us()) * 1e-6;
    return t >= f.from_s && t < f.to_s;
}

bool SimulatedAdc::dropped(int channel) const {
    for (const InjectedFault& f : faults_) {
        if (f.channel == channel && f.kind == FaultKind::kDrop && active(f)) {
            return true;
        }
    }
    return false;
}

bool SimulatedAdc::convert(std::uint8_t adc_channel, std::uint16_t& counts) noexcept {
    int ch = -1;
    for (std::uint8_t i = 0; i < config_.channels; ++i) {
        if (config_.channel[i].adc_channel == adc_channel) {
            ch = i;
        }
    }
    if (ch < 0 || !has_truth(ch)) {
        return false;  // nothing wired to this input: DOUT floats high
    }
    const ChannelConfig<double>& c = config_.channel[ch];
    double t = truth_[ch];
    double r = 0.0;
    bool open = false, shorted = false, stuck = false;
    double noise = 0.0;
    for (const InjectedFault& f : faults_) {
        if (f.channel != ch || !active(f)) {
            continue;
        }
        switch (f.kind) {
            case FaultKind::kBus:
                return false;
            case FaultKind::kOpen:
                open = true;
                break;
            case FaultKind::kShort:
                shorted = true;
                break;
            case FaultKind::kStuck:
                stuck = true;
                break;
            case FaultKind::kOffset:
                t += f.value;
                break;
            case FaultKind::kNoise:
                noise = f.value;
                break;
            case FaultKind::kDrop:
                break;
        }
    }
    if (stuck && frozen_valid_[ch]) {
        counts = frozen_[ch];
        return true;
    }
    r = open ? std::numeric_limits<double>::infinity() : shorted ? 0.0 : resistance_from_celsius(c.sh, t);
    int n = counts_from_resistance(c.divider, r);
    if (noise > 0.0) {
        lcg_ = lcg_ * 1664525U + 1013904223U;
        const double u = static_cast<double>(lcg_ >> 8) / static_cast<double>(1U << 24);  // [0, 1)
        n += static_cast<int>(std::lround((2.0 * u - 1.0) * noise));
        n = n < 0 ? 0 : (n > c.divider.levels - 1 ? c.divider.levels - 1 : n);
    }
    counts = static_cast<std::uint16_t>(n);
    frozen_[ch] = counts;
    frozen_valid_[ch] = true;
    return true;
}

SimulatedSource::SimulatedSource(const AcquisitionConfig<double>& config, std::vector<HistoryRow> history,
                                 std::vector<InjectedFault> faults)
    : config_(config), history_(std::move(history)), adc_(config_, clock_), source_(adc_, clock_, config_) {
    adc_.set_faults(std::move(faults));
}

bool SimulatedSource::acquire(Frame<double>& frame) noexcept {
    if (next_ >= history_.size()) {
        return false;
    }
    const HistoryRow& row = history_[next_++];
    const std::uint64_t t_us = static_cast<std::uint64_t>(std::llround(row.t * 1e6));
    if (t_us > clock_.now_us()) {
        clock_.advance_us(t_us - clock_.now_us());
    }
    for (std::uint8_t i = 0; i < config_.channels; ++i) {
        const Role role = config_.channel[i].role;
        double v = std::numeric_limits<double>::quiet_NaN();
        if (role == Role::kT029) {
            v = row.t_029;
        } else if (role == Role::kT032) {
            v = row.t_032;
        } else if (role != Role::kMonitor && (row.head < 0 || chu_role(static_cast<std::uint8_t>(row.head)) == role)) {
            v = row.t_chu;
        }
        if (std::isfinite(v)) {
            adc_.set_truth(i, v);
        }
    }
    source_.acquire(frame);
    for (std::uint8_t i = 0; i < config_.channels; ++i) {
        if (!adc_.has_truth(i) || adc_.dropped(i)) {
            frame.channel[i] = {SampleKind::kNone, 0U, 0U, 0.0, 0U};
        }
    }
    return true;
}

}  // namespace ascorr::hal
