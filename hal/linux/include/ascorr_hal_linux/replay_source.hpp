// ascorr_hal_linux/replay_source.hpp: sample sets from a recorded file.
//
// Format: CSV, one header line, no quoting, LF or CRLF. Column `t` (seconds,
// ≥ 0, any origin: the HAL clock of the replay is t·10⁶ µs) and, per
// recorded channel, either `NAME` (°C, already converted) or `NAME.counts`
// (raw ADC counts, an integer 0 … levels−1, converted by the HAL like a live
// reading), NAME as in the configuration. An empty field or `nan` means no
// sample of that channel in that row (the HAL keeps the previous reading
// until it turns stale). Channels without a column are never sampled.
// Rows need not be evenly spaced; a time that does not advance is not a
// format error, the checks flag it (kStale). Malformed input, an unknown
// channel, or a channel recorded twice → InputError at file:line:column.
#pragma once

#include <cstddef>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "ascorr_hal/sample_set.hpp"
#include "config_file.hpp"

namespace ascorr::hal {

class ReplaySource final : public SampleSetSource<double> {
public:
    ReplaySource(const std::string& file_name, std::string_view text, const AcquisitionConfig<double>& config);
    // A source is a device (hal/interface.hpp): not copied nor moved, so it
    // comes on the heap.
    static std::unique_ptr<ReplaySource> from_file(const std::string& path, const AcquisitionConfig<double>& config);

    bool acquire(SampleSet<double>& samples) noexcept override;
    std::size_t sample_sets() const noexcept { return sample_sets_.size(); }

private:
    std::vector<SampleSet<double>> sample_sets_;
    std::size_t next_ = 0;
};

}  // namespace ascorr::hal
