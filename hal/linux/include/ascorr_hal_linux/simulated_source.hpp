// ascorr_hal_linux/simulated_source.hpp: sample sets from temperature histories,
// through a simulated MCP3208, with injectable faults.
//
// History: CSV with columns t (s), t_chu, t_029, t_032 and optionally chu
// (A–D); other columns are ignored, so a solutions file (docs/contract.md) is a
// history. A row with chu = X sets the truth of the chu_x channels; without a
// chu column t_chu sets every chu channel. t_029 and t_032 set every member of
// their triplet. Empty/nan keeps the previous truth; a channel without truth
// yet is not sampled.
// Epochs: the rows whose t agree to the millisecond (as docs/contract.md §5
// matches the rows of the heads) are one epoch, in any row order (the rows
// are sorted by t, stably); rows of one epoch must not disagree (two values of
// one head's t_chu, of t_029 or of t_032: InputError at the later row).
// Each epoch becomes one sample set at its t (µs = the millisecond key · 1000),
// with every head's truth of that epoch: the truth goes through the inverse
// Steinhart–Hart and the divider into counts (SimulatedAdc), and the sample set
// is acquired by the same AdcSampleSetSource as on hardware (settle, samples,
// median) on a ManualClock, so the whole conversion path runs. Between epochs
// the truth holds. A sample set takes channels · (settle + (samples − 1) · gap) µs
// of that clock; an epoch closer than that to the previous one is acquired
// when the previous sample set ends, as the hardware would.
// (One sample set per row, as before, sampled the heads of one epoch a few ms
// apart: a one-count step between them read as a rate of several °C/s.)
// Faults (--inject NAME:KIND:FROM:TO[:VALUE], times in the history's seconds,
// active for FROM ≤ t < TO):
//   open, short   the thermistor at R = ∞ or 0
//   bus           the ADC does not answer on that input (conversion fails)
//   stuck         the counts frozen at their value when the fault began
//   offset        VALUE °C added to the truth (a drifting or spiking member)
//   noise         ±VALUE counts of pseudo-random noise on every conversion
//   drop          no sample at all (the reading ages and turns stale)
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include "ascorr_hal/clock.hpp"
#include "ascorr_hal/mcp3208.hpp"
#include "ascorr_hal/sample_set.hpp"
#include "config_file.hpp"

namespace ascorr::hal {

enum class FaultKind : std::uint8_t { kOpen, kShort, kBus, kStuck, kOffset, kNoise, kDrop };

struct InjectedFault {
    int channel;  // index in the configuration
    FaultKind kind;
    double from_s;
    double to_s;
    double value;
};

// "NAME:KIND:FROM:TO[:VALUE]"; throws std::invalid_argument naming the part.
InjectedFault parse_fault(std::string_view spec, const AcquisitionConfig<double>& config);

struct HistoryRow {
    double t;
    int head;  // -1: applies to every head
    double t_chu;
    double t_029;
    double t_032;
    std::size_t line = 0;                  // in the file, for messages (0: not from a file)
    std::size_t column[3] = {0U, 0U, 0U};  // of t_chu, t_029, t_032
};
std::vector<HistoryRow> parse_history(const std::string& file_name, std::string_view text);

inline constexpr int kHistoryHeads = kMaxHeads;  // the chu roles (channel_config.hpp, heads.hpp)

// One epoch of a history: the truths its rows give (NaN: none, the previous
// truth holds).
struct HistoryEpoch {
    std::uint64_t t_us;  // the millisecond key · 1000
    double t_chu[kHistoryHeads];
    double t_029;
    double t_032;
};
// Rows → epochs in time order (see the top); InputError at the first row
// that disagrees with an earlier row of its epoch.
std::vector<HistoryEpoch> history_epochs(const std::string& file_name, std::vector<HistoryRow> rows);
// parse_history + history_epochs of a file.
std::vector<HistoryEpoch> read_history(const std::string& path);

// An MCP3208 whose inputs are set from temperatures. Like a real converter,
// its conversions of a steady input differ by an LSB: each channel's
// conversions cycle through the offsets 0, +1, −1 counts (clamped to the
// range), so that a median of a multiple of three samples is the input's
// counts and their spread is not 0 (a noise-free converter would trip the
// stuck check, channel_check.hpp, on every steady channel). An injected
// stuck fault holds one value: spread 0.
class SimulatedAdc final : public AdcPort {
public:
    SimulatedAdc(const AcquisitionConfig<double>& config, Clock& clock) : config_(config), clock_(clock) {}
    void set_truth(int channel, double celsius) { truth_[channel] = celsius; }
    bool has_truth(int channel) const { return truth_[channel] == truth_[channel]; }
    void set_faults(std::vector<InjectedFault> faults) { faults_ = std::move(faults); }
    bool dropped(int channel) const;
    bool convert(std::uint8_t adc_channel, std::uint16_t& counts) noexcept override;

private:
    bool active(const InjectedFault& f) const noexcept;
    const AcquisitionConfig<double>& config_;
    Clock& clock_;
    double truth_[kMaxChannels] = {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN(),
                                   std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN(),
                                   std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN(),
                                   std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()};
    std::vector<InjectedFault> faults_;
    bool frozen_valid_[kMaxChannels] = {};
    std::uint16_t frozen_[kMaxChannels] = {};
    std::uint32_t lcg_ = 12345U;
    std::uint8_t dither_[kMaxChannels] = {};  // each channel's next offset: 0, +1, −1
};

class SimulatedSource final : public SampleSetSource<double> {
public:
    SimulatedSource(const AcquisitionConfig<double>& config, std::vector<HistoryEpoch> history,
                    std::vector<InjectedFault> faults);
    SimulatedSource(const SimulatedSource&) = delete;  // members refer to each other
    SimulatedSource& operator=(const SimulatedSource&) = delete;
    bool acquire(SampleSet<double>& samples) noexcept override;

private:
    AcquisitionConfig<double> config_;
    std::vector<HistoryEpoch> history_;
    std::size_t next_ = 0;
    ManualClock clock_;
    SimulatedAdc adc_;
    AdcSampleSetSource<double> source_;
};

}  // namespace ascorr::hal
