// The scripted libgpiod double (gpiod_double.hpp).
#include "gpiod_double.hpp"

#include <gpiod.hpp>
#include <map>
#include <stdexcept>
#include <system_error>

struct gpiod_chip {
    int unused;
};
struct gpiod_line {
    unsigned offset;
};

namespace gpiod_double {
namespace {

struct State {
    Script script;
    std::vector<Call> calls;
    std::vector<Conversion> conversions;
    std::vector<std::string> errors;
    std::map<unsigned, int> levels;
    std::map<unsigned, int> request_type;  // offset → line_request type
    std::vector<gpiod_line> lines = std::vector<gpiod_line>(64);
    gpiod_chip chip{0};
    // MCP3208 model.
    bool active = false;   // CS low
    bool started = false;  // start bit seen
    unsigned n = 0;        // rising clocks since the start bit
    unsigned command = 0;
    unsigned dout = 1;
    std::uint16_t value = 0;
    std::map<unsigned, unsigned> per_channel;
};

State& st() {
    static State s;
    return s;
}

int lvl(unsigned o) {
    const auto it = st().levels.find(o);
    return it == st().levels.end() ? -1 : it->second;
}

void finish_conversion() {
    State& s = st();
    if (s.started && !s.conversions.empty() && s.n < 19) {
        s.errors.push_back("CS raised after " + std::to_string(s.n) + " clocks, before B0");
    }
    s.active = false;
    s.started = false;
    s.dout = 1;
}

void on_edge(unsigned offset, int old_level, int new_level) {
    State& s = st();
    const Script& sc = s.script;
    if (offset == sc.cs) {
        if (old_level == 1 && new_level == 0) {
            if (lvl(sc.clk) != 0) {
                s.errors.push_back("CS fell with CLK high (mode 0,0 needs CLK idle low)");
            }
            s.active = true;
            s.started = false;
            s.n = 0;
            s.command = 0;
            s.dout = 1;
        } else if (old_level == 0 && new_level == 1) {
            finish_conversion();
        }
        return;
    }
    if (offset == sc.mosi && s.active && lvl(sc.clk) == 1) {
        s.errors.push_back("DIN changed while CLK high");
    }
    if (offset != sc.clk || !s.active) {
        return;
    }
    if (old_level == 0 && new_level == 1) {  // rising: latch DIN
        const int din = lvl(sc.mosi);
        if (!s.started) {
            if (din == 1) {
                s.started = true;
                s.n = 1;
                s.command = 1;
            }
        } else {
            ++s.n;
            if (s.n <= 5) {
                s.command = (s.command << 1U) | (din == 1 ? 1U : 0U);
            }
            if (s.n == 5) {
                const unsigned ch = s.command & 7U;
                const unsigned idx = s.per_channel[ch]++;
                s.value = static_cast<std::uint16_t>(sc.counts(ch, idx) & 0x0FFFU);
                s.conversions.push_back({true, ((s.command >> 3U) & 1U) != 0U, ch, 5, s.value, 0});
            }
        }
        if (s.started && !s.conversions.empty() && s.n > 5) {
            s.conversions.back().rising_clocks = s.n;
        }
    } else if (old_level == 1 && new_level == 0 && s.started) {  // falling: shift DOUT
        if (s.n == 6) {
            s.dout = 0;  // null bit
        } else if (s.n >= 7 && s.n <= 18) {
            s.dout = (static_cast<unsigned>(s.value) >> (18U - s.n)) & 1U;
        } else if (s.n > 18) {
            s.dout = 0;
        }
    }
}

[[noreturn]] void fail(const std::string& what) {
    throw std::system_error(std::make_error_code(std::errc::io_error), what);
}

}  // namespace

void reset(Script script) {
    st() = State{};
    st().script = std::move(script);
}
const std::vector<Call>& calls() {
    return st().calls;
}
const std::vector<Conversion>& conversions() {
    return st().conversions;
}
const std::vector<std::string>& protocol_errors() {
    return st().errors;
}
int level(unsigned offset) {
    return lvl(offset);
}
bool requested(unsigned offset) {
    return st().request_type.count(offset) != 0U;
}

}  // namespace gpiod_double

// ---- the libgpiod C++ symbols the backend uses -------------------------------
namespace gpiod {

using gpiod_double::Call;
using gpiod_double::st;

chip::chip(::gpiod_chip* c) : _m_chip(c, [](::gpiod_chip*) {}) {}

chip::chip(const ::std::string& device, int how) {
    open(device, how);
}

void chip::open(const ::std::string& device, int) {
    st().calls.push_back({Call::kOpen, 0, 0, 0, device});
    if (device != st().script.chip) {
        throw std::system_error(std::make_error_code(std::errc::no_such_file_or_directory), "no chip " + device);
    }
    _m_chip = ::std::shared_ptr<::gpiod_chip>(&st().chip, [](::gpiod_chip*) {});
}

line chip::get_line(unsigned int offset) const {
    st().calls.push_back({Call::kGetLine, offset, 0, 0, ""});
    if (!_m_chip || offset >= st().script.num_lines || offset >= st().lines.size()) {
        throw std::out_of_range("line offset greater than the number of lines");  // as libgpiod 1.6 does
    }
    st().lines[offset].offset = offset;
    return line(&st().lines[offset], *this);
}

line::line() : _m_line(nullptr), _m_chip() {}

line::line(::gpiod_line* l, const chip& owner) : _m_line(l), _m_chip(owner) {}

void line::request(const line_request& config, int default_val) const {
    const unsigned o = _m_line->offset;
    st().calls.push_back({Call::kRequest, o, default_val, config.request_type, config.consumer});
    if (st().request_type.count(o) != 0U) {
        throw std::system_error(std::make_error_code(std::errc::device_or_resource_busy), "line busy");
    }
    st().request_type[o] = config.request_type;
    if (config.request_type == line_request::DIRECTION_OUTPUT) {
        const int old = gpiod_double::lvl(o);
        st().levels[o] = default_val;
        gpiod_double::on_edge(o, old < 0 ? 1 - default_val : old, default_val);
    }
}

void line::release() const {
    const unsigned o = _m_line->offset;
    st().calls.push_back({Call::kRelease, o, 0, 0, ""});
    st().request_type.erase(o);
}

bool line::is_requested() const {
    return _m_line != nullptr && st().request_type.count(_m_line->offset) != 0U;
}

void line::set_value(int val) const {
    const unsigned o = _m_line->offset;
    st().calls.push_back({Call::kSet, o, val, 0, ""});
    const auto it = st().request_type.find(o);
    if (it == st().request_type.end() || it->second != line_request::DIRECTION_OUTPUT) {
        st().errors.push_back("set_value on line " + std::to_string(o) + " not requested as output");
        throw std::system_error(std::make_error_code(std::errc::operation_not_permitted), "not an output");
    }
    if (st().script.failing_outputs.count(o) != 0U) {
        gpiod_double::fail("scripted I/O error on line " + std::to_string(o));
    }
    const int old = gpiod_double::lvl(o);
    st().levels[o] = val;
    if (old != val) {
        gpiod_double::on_edge(o, old, val);
    }
}

int line::get_value() const {
    const unsigned o = _m_line->offset;
    const auto it = st().request_type.find(o);
    if (it == st().request_type.end()) {
        st().errors.push_back("get_value on unrequested line " + std::to_string(o));
        throw std::system_error(std::make_error_code(std::errc::operation_not_permitted), "not requested");
    }
    int v = 1;  // pulled up
    if (o == st().script.miso && st().script.device_present && st().active) {
        v = static_cast<int>(st().dout);
        if (gpiod_double::lvl(st().script.clk) != 1 && !st().conversions.empty()) {
            ++st().conversions.back().miso_reads_clk_low;
        }
    } else if (o != st().script.miso) {
        v = gpiod_double::lvl(o) < 0 ? 0 : gpiod_double::lvl(o);
    }
    st().calls.push_back({Call::kGet, o, v, 0, ""});
    return v;
}

}  // namespace gpiod
