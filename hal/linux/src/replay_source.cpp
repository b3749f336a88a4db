// Replay of recorded temperatures or counts (replay_source.hpp).
#include "ascorr_hal_linux/replay_source.hpp"

#include <charconv>
#include <cmath>
#include <memory>

#include "ascorr_text/text_file.hpp"

namespace ascorr::hal {
namespace {

struct Column {
    int channel;  // -1: the time column
    bool counts;
    std::string name;  // as the header names it, unquoted
};

// The header's columns: "t" once, then configured channels ("<name>" in
// degC or "<name>.counts"), each once.
std::vector<Column> header_columns(const std::string& file, std::size_t line_no, const std::vector<text::Field>& fields,
                                   const AcquisitionConfig<double>& config) {
    std::vector<Column> columns;
    bool have_t = false;
    bool used[kMaxChannels] = {};
    for (const auto& [raw, col] : fields) {
        const std::string name = text::csv::unquoted(raw);  // "t" names the column t
        if (name == "t") {
            if (have_t) {
                throw text::InputError(file, line_no, col, "column 't' appears twice");
            }
            have_t = true;
            columns.push_back({-1, false, name});
            continue;
        }
        const bool counts = name.size() > 7 && name.substr(name.size() - 7) == ".counts";
        const std::string_view ch = std::string_view(name).substr(0, counts ? name.size() - 7 : name.size());
        const int idx = find_channel(config, ch);
        if (idx < 0) {
            throw text::InputError(file, line_no, col, "column '" + name + "' names no configured channel");
        }
        if (used[idx]) {
            throw text::InputError(file, line_no, col, "channel '" + std::string(ch) + "' recorded twice");
        }
        used[idx] = true;
        columns.push_back({idx, counts, name});
    }
    if (!have_t) {
        throw text::InputError(file, line_no, 1, "no column 't'");
    }
    return columns;
}

// The t field in µs (seconds in [0, 1e12]).
std::uint64_t read_time_us(const std::string& file, std::size_t line_no, std::string_view v, std::size_t col) {
    const char* b = v.data();
    const char* e = b + v.size();
    double t = 0.0;
    const auto r = std::from_chars(b, e, t);
    if (v.empty() || r.ec != std::errc() || r.ptr != e || !std::isfinite(t) || t < 0.0 || t > 1.0e12) {
        throw text::InputError(file, line_no, col,
                               text::number_refusal(v, "'t' must be a number of seconds in [0, 1e12]", "'t': "));
    }
    return static_cast<std::uint64_t>(std::llround(t * 1e6));
}

// A channel's field (not empty, not "nan") as counts or degC.
ChannelSample<double> read_sample(const std::string& file, std::size_t line_no, std::string_view v, std::size_t col,
                                  const Column& c, const AcquisitionConfig<double>& config) {
    const char* b = v.data();
    const char* e = b + v.size();
    if (c.counts) {
        unsigned long n = 0;
        const auto r = std::from_chars(b, e, n);
        const unsigned long top = config.channel[c.channel].divider.levels - 1UL;
        if (r.ec != std::errc() || r.ptr != e || n > top) {
            throw text::InputError(file, line_no, col, "counts must be an integer in [0, " + std::to_string(top) + "]");
        }
        return {SampleKind::kCounts, static_cast<std::uint16_t>(n), 0U, 0.0, 0U};
    }
    double x = 0.0;
    const auto r = std::from_chars(b, e, x);
    if (r.ec != std::errc() || r.ptr != e) {
        throw text::InputError(file, line_no, col,
                               text::number_refusal(v, "not a temperature: '" + std::string(v) + "'"));
    }
    return {SampleKind::kCelsius, 0U, 0U, x, 0U};
}

}  // namespace

ReplaySource::ReplaySource(const std::string& file, std::string_view text, const AcquisitionConfig<double>& config) {
    std::vector<Column> columns;
    text::TextLines lines(file, text);
    std::string_view line;
    text::FieldSplitter splitter;
    bool header = true;
    while (lines.next(line)) {
        const std::size_t line_no = lines.number();
        const std::vector<text::Field>& fields = splitter.split(file, line_no, line);
        if (header) {
            header = false;
            columns = header_columns(file, line_no, fields, config);
            continue;
        }
        if (line.empty() && lines.at_end()) {  // a blank last line
            break;
        }
        if (fields.size() != columns.size()) {
            throw text::InputError(
                file, line_no, line.size() + 1,
                "expected " + std::to_string(columns.size()) + " fields, found " + std::to_string(fields.size()));
        }
        SampleSet<double> f{};
        for (std::size_t i = 0; i < columns.size(); ++i) {
            const auto& [v, col] = fields[i];
            const Column& c = columns[i];
            text::refuse_quoted(file, line_no, fields[i], c.name);  // every column is read
            if (c.channel < 0) {
                f.t_us = read_time_us(file, line_no, v, col);
            } else if (!v.empty() && v != "nan") {  // else kNone
                f.channel[c.channel] = read_sample(file, line_no, v, col, c, config);
            }
        }
        sample_sets_.push_back(f);
    }
    if (header) {
        throw text::InputError(file, 1, 1, "empty file (no header)");
    }
}

std::unique_ptr<ReplaySource> ReplaySource::from_file(const std::string& path,
                                                      const AcquisitionConfig<double>& config) {
    return std::make_unique<ReplaySource>(path, text::read_text_file(path), config);
}

bool ReplaySource::acquire(SampleSet<double>& samples) noexcept {
    if (next_ >= sample_sets_.size()) {
        return false;
    }
    samples = sample_sets_[next_++];
    return true;
}

}  // namespace ascorr::hal
