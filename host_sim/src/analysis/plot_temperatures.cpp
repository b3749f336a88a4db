#include <cmath>
#include <fstream>
#include <map>
#include <stdexcept>

#include "ascorr_host/analysis/epochs.hpp"
#include "ascorr_host/analysis/plot.hpp"

namespace ascorr::host {

namespace {

// Sums of one bin: T_CHU of each head (by index), T029, T032 and their counts.
constexpr std::size_t kSeries = kMaxHeads + 2U;
struct TemperatureBin {
    double sum_t = 0.0;
    std::size_t rows = 0;
    std::array<double, kSeries> sum{};
    std::array<std::size_t, kSeries> n{};
};

}  // namespace

std::size_t write_temperature_series(const std::string& in, const std::string& path, double bin_s,
                                     std::optional<double> from, std::optional<double> to, double time_offset) {
    std::map<long long, TemperatureBin> bins;
    for_each_solution(
        in,
        [&](const SolutionRecord& rec) {
            if ((from && rec.t < *from) || (to && rec.t > *to) || rec.head >= kMaxHeads) {
                return;
            }
            TemperatureBin& b = bins[static_cast<long long>(std::floor(rec.t / bin_s))];
            b.sum_t += rec.t;
            ++b.rows;
            const auto add = [&](std::size_t i, std::size_t column) {
                if (rec.temperature_present[column] && std::isfinite(rec.temperature[column])) {
                    b.sum[i] += rec.temperature[column];
                    ++b.n[i];
                }
            };
            add(rec.head, 0);
            add(kMaxHeads, 1);
            add(kMaxHeads + 1U, 2);
        },
        "plot");
    std::ofstream f(path);
    f.precision(12);
    for (const auto& kv : bins) {
        const TemperatureBin& b = kv.second;
        f << b.sum_t / static_cast<double>(b.rows) + time_offset;
        for (std::size_t i = 0; i < kSeries; ++i) {
            f << ' ';
            if (b.n[i] > 0) {
                f << b.sum[i] / static_cast<double>(b.n[i]);
            } else {
                f << "NaN";  // a gap: gnuplot breaks the line
            }
        }
        f << '\n';
    }
    if (!f) {
        throw std::runtime_error("cannot write plot data " + path);
    }
    return bins.size();
}

}  // namespace ascorr::host
