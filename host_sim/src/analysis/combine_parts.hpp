// The parts of `ascorr combine` (ascorr_host/analysis/combine.hpp) its sources
// share; private to the analysis library: combine.cpp (rows to epochs to the
// combined file), combine_reports.cpp (the messages of the rows left out) and
// combine_steps.cpp (the steps when heads drop out, HeadSetStep).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "ascorr/combine/combiner.hpp"
#include "ascorr/combine/usable.hpp"
#include "ascorr/core/heads.hpp"
#include "ascorr/core/quaternion.hpp"
#include "ascorr_host/analysis/combine.hpp"
#include "ascorr_host/formats/diagnostics.hpp"

namespace ascorr::host::detail {

// A row as kept between reading and combining (48 bytes, 56 with its key): whether it is
// usable is decided when it is read, from what needs no other row.
struct Kept {
    double t;
    Quaternion<double> q;
    std::uint32_t line;  // (a file of 4e9 lines is beyond any recording)
    std::uint8_t head;
    LeftOut why;
    std::uint8_t stages;  // status & (1|2) of a corrected row; 0 for a raw one
    bool unit;            // RowFacts::unit, tested once, when read
};

// The messages of the rows left out, through the run's Diagnostics (each
// kind counted, the first ones shown), each naming file:line.
class LeftOutReports {
public:
    // file: the input's name, held by the caller for the reports' life.
    LeftOutReports(Diagnostics& diag, const std::string& file) : diag_(diag), file_(file) {}
    // A row whose t has no millisecond key.
    void no_epoch(std::size_t line, double t);
    // Step 2's reasons of an epoch's rows (sorted by head and line; `why`
    // by row): a second row of a head, a stage missing from the epoch's `stages`.
    void epoch(const std::vector<Kept>& rows, const std::vector<LeftOut>& why, StatusBits stages);
    // The row's own reason, when it is one the combination's run names:
    // not in the mountings, not a head, not unit, inconsistent.
    void row(const Kept& k);

private:
    std::string where(std::size_t line) const;
    Diagnostics& diag_;
    const std::string& file_;
};

// The steps of the combined attitude when heads drop out (HeadSetStep): each
// epoch of every mounted head combined again with each proper subset, the
// differences from the full set's attitude averaged per day.
class HeadSetSteps {
public:
    explicit HeadSetSteps(HeadMask mounted) noexcept : mounted_(mounted) {}
    // An epoch combined from every mounted head (heads, n) into q_full at t.
    void add(const combine::Combiner<double>& combiner, const combine::HeadAttitude<double>* heads, std::uint8_t n,
             const Quaternion<double>& q_full, double t);
    // Each set's RMS over days of the daily mean into sum.steps; sum.full.
    void finish(CombineSummary& sum) const;

private:
    struct DaySum {
        std::size_t n = 0;
        std::array<double, 3> sum{};
    };
    HeadMask mounted_;
    std::array<std::map<long long, DaySum>, 1U << kMaxHeads> daily_;  // per subset, per day, the sum of d_S
    double t_first_ = 0.0;
    bool any_epoch_ = false;
};

}  // namespace ascorr::host::detail
