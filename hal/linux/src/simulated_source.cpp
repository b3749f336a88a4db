// Simulated acquisition from temperature histories (simulated_source.hpp).
#include "ascorr_hal_linux/simulated_source.hpp"
#include "ascorr/pipeline/epoch_key.hpp"
#include "ascorr_hal/thermistor.hpp"
#include "ascorr_text/c_format.hpp"
#include "ascorr_text/number_fields.hpp"
#include "ascorr_text/text_file.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace ascorr::hal {
namespace {

bool parse_number(std::string_view v, double& x) {
    const auto r = std::from_chars(v.data(), v.data() + v.size(), x);
    return !v.empty() && r.ec == std::errc() && r.ptr == v.data() + v.size();
}

}  // namespace

namespace {

// NAME:KIND:FROM:TO[:VALUE] split at ':'.
std::vector<std::string_view> fault_parts(std::string_view spec) {
    std::vector<std::string_view> part;
    std::size_t start = 0;
    while (true) {
        const std::size_t c = spec.find(':', start);
        part.push_back(spec.substr(start, c == std::string_view::npos ? std::string_view::npos : c - start));
        if (c == std::string_view::npos) {
            return part;
        }
        start = c + 1;
    }
}

// The fault kind named by text; throws naming the spec s.
FaultKind fault_kind(const std::string& s, std::string_view text) {
    static constexpr std::pair<const char*, FaultKind> kinds[] = {
        {"open", FaultKind::kOpen},   {"short", FaultKind::kShort},   {"bus", FaultKind::kBus},
        {"stuck", FaultKind::kStuck}, {"offset", FaultKind::kOffset}, {"noise", FaultKind::kNoise},
        {"drop", FaultKind::kDrop}};
    for (const auto& [name, kind] : kinds) {
        if (text == name) {
            return kind;
        }
    }
    throw std::invalid_argument("fault '" + s + "': unknown kind '" + std::string(text) +
                                "' (open, short, bus, stuck, offset, noise, drop)");
}

// FROM and TO: finite seconds, FROM < TO.
void fault_times(const std::string& s, std::string_view from, std::string_view to, InjectedFault& f) {
    if (!parse_number(from, f.from_s) || !parse_number(to, f.to_s) || !std::isfinite(f.from_s) ||
        !std::isfinite(f.to_s) || !(f.from_s < f.to_s)) {
        const std::string why = text::out_of_range_reason(from) + text::out_of_range_reason(to);
        throw std::invalid_argument("fault '" + s +
                                    "': " + (why.empty() ? "FROM and TO must be finite numbers with FROM < TO" : why));
    }
}

// VALUE of an offset (°C, finite and within the ±200 °C any temperature has)
// or of noise (counts, > 0: 0 or less would inject nothing, and at most 65535,
// an ADC code's range, so the simulated code stays an int); the other kinds
// take none.
void fault_value(const std::string& s, const std::vector<std::string_view>& part, InjectedFault& f) {
    const bool needs_value = f.kind == FaultKind::kOffset || f.kind == FaultKind::kNoise;
    if (needs_value != (part.size() == 5)) {
        throw std::invalid_argument("fault '" + s + "': " + (needs_value ? "needs" : "takes no") + " VALUE");
    }
    if (!needs_value) {
        return;
    }
    const std::string text(part[4]);
    if (!parse_number(part[4], f.value)) {
        const std::string why = text::out_of_range_reason(part[4]);
        throw std::invalid_argument("fault '" + s + "': " + (why.empty() ? "needs VALUE" : why));
    }
    if (f.kind == FaultKind::kOffset && !(std::fabs(f.value) <= 200.0)) {
        throw std::invalid_argument("fault '" + s +
                                    "': offset VALUE must be a finite number of degC within +-200, got '" + text + "'");
    }
    if (f.kind == FaultKind::kNoise && !(f.value > 0.0 && f.value <= 65535.0)) {
        throw std::invalid_argument("fault '" + s + "': noise VALUE must be a number of counts in (0, 65535], got '" +
                                    text + "'");
    }
}

}  // namespace

InjectedFault parse_fault(std::string_view spec, const AcquisitionConfig<double>& config) {
    const std::vector<std::string_view> part = fault_parts(spec);
    const std::string s(spec);
    if (part.size() < 4 || part.size() > 5) {
        throw std::invalid_argument("fault '" + s + "': expected NAME:KIND:FROM:TO[:VALUE]");
    }
    InjectedFault f{find_channel(config, part[0]), FaultKind::kOpen, 0.0, 0.0, 0.0};
    if (f.channel < 0) {
        throw std::invalid_argument("fault '" + s + "': no channel '" + std::string(part[0]) + "'");
    }
    f.kind = fault_kind(s, part[1]);
    fault_times(s, part[2], part[3], f);
    fault_value(s, part, f);
    return f;
}

namespace {

// The columns of a history: their indices in a row (-1: absent).
struct HistoryColumns {
    int t = -1;
    int chu = -1;
    int temperature[3] = {-1, -1, -1};  // t_chu, t_029, t_032
    std::size_t count = 0;              // fields every row has
};

// The temperature columns of a history, in HistoryColumns::temperature's order.
constexpr const char* kHistoryTemperatureNames[3] = {"t_chu", "t_029", "t_032"};

// The header line: which field is which; t, t_chu, t_029, t_032 required.
HistoryColumns history_columns(const std::string& file, const std::vector<text::Field>& header) {
    HistoryColumns cols;
    cols.count = header.size();
    for (std::size_t i = 0; i < header.size(); ++i) {
        const std::string name = text::csv::unquoted(header[i].first);  // "t" names the column t
        const int index = static_cast<int>(i);
        if (name == "t") {
            cols.t = index;
        } else if (name == "chu") {
            cols.chu = index;
        }
        for (int k = 0; k < 3; ++k) {
            if (name == kHistoryTemperatureNames[k]) {
                cols.temperature[k] = index;
            }
        }
    }
    if (cols.t < 0 || cols.temperature[0] < 0 || cols.temperature[1] < 0 || cols.temperature[2] < 0) {
        throw text::InputError(file, 1, 1, "a temperature history needs columns t, t_chu, t_029, t_032");
    }
    return cols;
}

const text::Field& field(const std::vector<text::Field>& f, int column) {
    return f[static_cast<std::size_t>(column)];
}

// The head of a row: -1 without a chu column, else its index (heads.hpp).
int history_head(const std::string& file, std::size_t line_no, const std::vector<text::Field>& f,
                 const HistoryColumns& cols) {
    if (cols.chu < 0) {
        return -1;
    }
    text::refuse_quoted(file, line_no, field(f, cols.chu), "chu");
    const auto& [v, c] = field(f, cols.chu);
    if (v.size() != 1 || head_index(v[0]) == kUnknownHead) {
        throw text::InputError(file, line_no, c, "'chu' must be " + std::string(kHeadChoices.text));
    }
    return head_index(v[0]);
}

// A temperature field: NaN when empty or nan (none), else a finite number
// not below absolute zero (a thermistor's resistance has no value there:
// resistance_from_celsius, thermistor.hpp).
double history_temperature(const std::string& file, std::size_t line_no, const text::Field& field) {
    const auto& [v, c] = field;
    double x = std::numeric_limits<double>::quiet_NaN();
    if (v.empty() || v == "nan") {
        return x;
    }
    if (!parse_number(v, x) || !std::isfinite(x)) {
        throw text::InputError(file, line_no, c,
                               text::number_refusal(v, "not a temperature: '" + std::string(v) +
                                                           "' (a finite number, or empty or nan for none)"));
    }
    if (x <= -kZeroCelsiusK) {
        throw text::InputError(file, line_no, c,
                               "not a temperature: '" + std::string(v) + "' is not above absolute zero (" +
                                   text::number_text(-kZeroCelsiusK) + " degC): no thermistor reads it");
    }
    return x;
}

// One data line of a history.
HistoryRow history_row(const std::string& file, std::size_t line_no, std::string_view line,
                       const std::vector<text::Field>& f, const HistoryColumns& cols) {
    if (f.size() != cols.count) {
        throw text::InputError(file, line_no, line.size() + 1,
                               "expected " + std::to_string(cols.count) + " fields, found " + std::to_string(f.size()));
    }
    HistoryRow r{0.0, -1, 0.0, 0.0, 0.0};
    r.line = line_no;
    text::refuse_quoted(file, line_no, field(f, cols.t), "t");
    const auto& [t_text, t_col] = field(f, cols.t);
    if (!parse_number(t_text, r.t) || !(r.t >= 0.0 && r.t <= 1.0e12)) {
        throw text::InputError(file, line_no, t_col,
                               text::number_refusal(t_text, "'t' must be a number of seconds in [0, 1e12]", "'t': "));
    }
    r.head = history_head(file, line_no, f, cols);
    double* dst[3] = {&r.t_chu, &r.t_029, &r.t_032};
    for (int k = 0; k < 3; ++k) {
        const text::Field& tf = field(f, cols.temperature[k]);
        text::refuse_quoted(file, line_no, tf, kHistoryTemperatureNames[k]);
        r.column[k] = tf.second;
        *dst[k] = history_temperature(file, line_no, tf);
    }
    return r;
}

}  // namespace

std::vector<HistoryRow> parse_history(const std::string& file, std::string_view text) {
    text::TextLines lines(file, text);
    std::string_view line;
    text::FieldSplitter splitter;
    if (!lines.next(line)) {
        throw text::InputError(file, 1, 1, "empty file (no header)");
    }
    const HistoryColumns cols = history_columns(file, splitter.split(file, lines.number(), line));
    std::vector<HistoryRow> rows;
    while (lines.next(line)) {
        if (line.empty() && lines.at_end()) {  // a blank last line
            break;
        }
        rows.push_back(history_row(file, lines.number(), line, splitter.split(file, lines.number(), line), cols));
    }
    return rows;
}

namespace {

static_assert(static_cast<int>(Role::kT029) - static_cast<int>(Role::kChuA) == kHistoryHeads,
              "one history head per chu role");

// One truth of an epoch and the row that gave it.
struct EpochValue {
    double value = std::numeric_limits<double>::quiet_NaN();
    std::size_t line = 0;
};

// Sets `slot` from a row's value, or refuses a second, different value.
void merge_value(const std::string& file, const HistoryRow& row, int k, const char* name, double v, EpochValue& slot) {
    if (std::isnan(v)) {
        return;
    }
    if (std::isnan(slot.value) || slot.value == v) {
        slot = {v, row.line};
        return;
    }
    char buf[160];
    text::c_snprintf(buf, sizeof buf, "%s = %.17g at t = %.3f s disagrees with %.17g on line %zu (the same epoch)",
                     name, v, row.t, slot.value, slot.line);
    throw text::InputError(file, row.line, row.column[k], buf);
}

// The truths of one epoch, merged from its rows.
struct EpochTruths {
    EpochValue chu[kHistoryHeads];
    EpochValue t029;
    EpochValue t032;

    void merge(const std::string& file, const HistoryRow& r) {
        for (int h = 0; h < kHistoryHeads; ++h) {
            if (r.head < 0 || r.head == h) {
                merge_value(file, r, 0, "t_chu", r.t_chu, chu[h]);
            }
        }
        merge_value(file, r, 1, "t_029", r.t_029, t029);
        merge_value(file, r, 2, "t_032", r.t_032, t032);
    }

    HistoryEpoch epoch(std::int64_t key) const {
        HistoryEpoch e{static_cast<std::uint64_t>(key) * 1000U, {}, t029.value, t032.value};
        for (int h = 0; h < kHistoryHeads; ++h) {
            e.t_chu[h] = chu[h].value;
        }
        return e;
    }
};

}  // namespace

std::vector<HistoryEpoch> history_epochs(const std::string& file_name, std::vector<HistoryRow> rows) {
    // t is within [0, 1e12] s (history_row): every row has a key.
    using pipeline::epoch_key;
    std::stable_sort(rows.begin(), rows.end(),
                     [](const HistoryRow& a, const HistoryRow& b) { return epoch_key(a.t) < epoch_key(b.t); });
    std::vector<HistoryEpoch> epochs;
    pipeline::ConsecutiveEpochs runs;
    EpochTruths truths;
    for (const HistoryRow& r : rows) {
        const std::int64_t key = epoch_key(r.t);
        if (runs.ends_before(key)) {
            epochs.push_back(truths.epoch(runs.key()));
            truths = {};
            runs.close();
        }
        runs.add(key);
        truths.merge(file_name, r);
    }
    if (runs.is_open()) {
        epochs.push_back(truths.epoch(runs.key()));
    }
    return epochs;
}

std::vector<HistoryEpoch> read_history(const std::string& path) {
    return history_epochs(path, parse_history(path, text::read_text_file(path)));
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
    }
    const int dither[3] = {0, 1, -1};
    n += dither[dither_[ch]];
    dither_[ch] = static_cast<std::uint8_t>((dither_[ch] + 1U) % 3U);
    n = n < 0 ? 0 : (n > c.divider.levels - 1 ? c.divider.levels - 1 : n);
    counts = static_cast<std::uint16_t>(n);
    frozen_[ch] = counts;
    frozen_valid_[ch] = true;
    return true;
}

SimulatedSource::SimulatedSource(const AcquisitionConfig<double>& config, std::vector<HistoryEpoch> history,
                                 std::vector<InjectedFault> faults)
    : config_(config), history_(std::move(history)), adc_(config_, clock_), source_(adc_, clock_, config_) {
    adc_.set_faults(std::move(faults));
}

bool SimulatedSource::acquire(SampleSet<double>& samples) noexcept {
    if (next_ >= history_.size()) {
        return false;
    }
    const HistoryEpoch& e = history_[next_++];
    if (e.t_us > clock_.now_us()) {
        clock_.advance_us(e.t_us - clock_.now_us());
    }
    for (std::uint8_t i = 0; i < config_.channels; ++i) {
        const Role role = config_.channel[i].role;
        double v = std::numeric_limits<double>::quiet_NaN();
        if (role == Role::kT029) {
            v = e.t_029;
        } else if (role == Role::kT032) {
            v = e.t_032;
        } else if (role != Role::kMonitor) {
            v = e.t_chu[static_cast<int>(role) - static_cast<int>(Role::kChuA)];
        }
        if (std::isfinite(v)) {
            adc_.set_truth(i, v);
        }
    }
    source_.acquire(samples);
    for (std::uint8_t i = 0; i < config_.channels; ++i) {
        if (!adc_.has_truth(i) || adc_.dropped(i)) {
            samples.channel[i] = {SampleKind::kNone, 0U, 0U, 0.0, 0U};
        }
    }
    return true;
}

}  // namespace ascorr::hal
