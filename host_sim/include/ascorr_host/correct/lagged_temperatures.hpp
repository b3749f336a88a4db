// ascorr_host/correct/lagged_temperatures.hpp: each row's temperatures as a
// lagged model's terms take them (the model file's lag_s; issue 40).
//
// A head with a lag τ (ModelFile::lag_s) has its three channels stepped
// through pipeline::TemperatureLag<double> over all of its rows in time
// order, whatever order the rows come in: the row's terms then take the
// lagged temperatures L at its t. Rows at the same t of a head are stepped
// in the order of their readings (a channel advances once, at the first
// valid one), so the answer does not depend on the rows' order; every row at
// that t gets the state after them all.
// A channel whose row has no reading (or one outside the core's domain)
// keeps the row's own (missing or out of range) reading, so the core says
// why it cannot use it, as without a lag (lagged_reading_usable). A head
// without a lag keeps its readings. A lagged head's row whose t is not a time
// (tt_from_seconds) has its channels marked missing: status 8, no thermal
// stage, rather than the unlagged readings.
// Double on every scalar: the core is given L as it is given a reading.
// Memory: a LagReading (48 bytes) per row of a lagged head while the table is
// built, then an Entry (40 bytes) per distinct time: about 11 MB per hour of
// three heads at 22 Hz, for the whole input.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "ascorr/core/heads.hpp"
#include "ascorr/pipeline/head_lags.hpp"
#include "ascorr/pipeline/temperature_lag.hpp"
#include "ascorr_host/formats/solutions_csv.hpp"

namespace ascorr::host {

// One row's reading, as the table is built from it.
struct LagReading {
    std::int64_t t_us = 0;  // tt_from_seconds(t)
    std::uint8_t head = 0;
    std::array<double, 3> temperature{};  // t_chu, t_029, t_032 (°C)
    std::array<bool, 3> present{};
};

// The order the lag steps readings in: by head, then time, then the readings
// themselves (a missing one first), so that rows at one t step the same way in
// any input order.
bool lag_order(const LagReading& a, const LagReading& b) noexcept;

// One head's readings, sorted by lag_order, through a lag of tau_s (accepted
// by TemperatureLag::configure): at(t_us, lagged, valid) once per distinct t,
// with the state after its last reading (lagged[k] = L of channel k, valid[k]
// once the channel has started). The one walk of the table below and of the
// fit's choice of the lag (fit_lag.hpp).
template <typename At>
void walk_lag(double tau_s, const LagReading* first, const LagReading* last, At&& at) {
    pipeline::TemperatureLag<double> lag;
    if (!lag.configure(tau_s)) {  // the model's reader and fit's options refuse such a τ first
        throw std::invalid_argument("walk_lag: a lag of " + std::to_string(tau_s) + " s is out of its range");
    }
    for (const LagReading* r = first; r != last; ++r) {
        lag.step(r->t_us, {{r->temperature[0], r->present[0]},
                           {r->temperature[1], r->present[1]},
                           {r->temperature[2], r->present[2]}});
        if (r + 1 != last && (r + 1)->t_us == r->t_us) {
            continue;  // the state after every row at this t
        }
        std::array<double, 3> lagged{};
        std::array<bool, 3> valid{};
        for (std::uint8_t k = 0; k < 3; ++k) {
            const TemperatureReading<double> l = lag.lagged(k);
            lagged[k] = l.value;
            valid[k] = l.valid;
        }
        at(r->t_us, lagged, valid);
    }
}

// Whether a row's reading of a channel takes the lagged value: the row has
// it, within the core's domain, and the channel's lag has started.
inline bool lagged_reading_usable(bool present, double reading, bool lag_valid) noexcept {
    return present && temperature_in_domain<double>(reading) && lag_valid;
}

class LaggedTemperatures {
public:
    // lag_s by head index (0: no lag; otherwise within the lag's range,
    // checked by the model's reader); readings of any heads, any order (the
    // heads without a lag are dropped).
    LaggedTemperatures(const std::array<double, kMaxHeads>& lag_s, std::vector<LagReading> readings);

    bool lags(std::uint8_t head) const noexcept { return head < kMaxHeads && lag_s_[head] != 0.0; }
    // Each head's τ in s (0: none), by head index.
    const std::array<double, kMaxHeads>& lag_s() const noexcept { return lag_s_; }

    // rec's temperatures as its terms take them (above); unchanged when its
    // head has no lag.
    void apply(SolutionRecord& rec) const;

private:
    struct Entry {
        std::int64_t t_us;
        std::array<double, 3> lagged;
        std::array<bool, 3> valid;
    };
    std::array<double, kMaxHeads> lag_s_{};
    std::array<std::vector<Entry>, kMaxHeads> series_{};  // per head, by t_us
};

// Lags that change with time: a self-calibration's learnt lag (`correct
// --self-calibrate --lag auto`), each model of its history with the lag the
// search had taken when it became active. Each head on its own: from the
// first model whose lag of that head differs from the one before (at first:
// none) up to the next such model, the head's rows take that lag, started
// afresh at its first reading there (as a lag stage configured then); so a
// head whose lag stays the same keeps its lag running whatever the models or
// the other heads do. Rows before, or in a span of no lag, keep their
// readings; a row whose t is not a time has no temperatures when some span
// lags its head (as LaggedTemperatures).
class LagSchedule {
public:
    struct Version {
        std::int64_t from_us;                 // TT µs: the rows whose t rounds to at least this
        std::array<double, kMaxHeads> lag_s;  // by head index, 0 none (a head the model lacks: 0)
    };
    // versions in time order; readings of every head, any order.
    LagSchedule(const std::vector<Version>& versions, std::vector<LagReading> readings);

    bool any() const noexcept { return lagged_ != 0U; }
    // rec's temperatures as its terms take them at its t (above).
    void apply(SolutionRecord& rec) const;

private:
    struct Span {
        std::int64_t from_us;
        std::optional<LaggedTemperatures> table;  // nullopt: no lag
    };
    std::array<std::vector<Span>, kMaxHeads> spans_{};  // per head, in time order
    HeadMask lagged_ = 0U;                              // the heads some span lags
};

// The reading of rec for the table; false when its t is not a time or its
// head is not one of kMaxHeads.
bool lag_reading_of(const SolutionRecord& rec, LagReading& out) noexcept;

// The readings of every row of `heads` that rows gives, sorted by lag_order
// (one reading of the rows).
std::vector<LagReading> lag_readings(const RowSource& rows,
                                     HeadMask heads = static_cast<HeadMask>((1U << kMaxHeads) - 1U));

// rows as their terms take them: each row through lag.apply (the table must
// have been made from the same rows).
RowSource lagged_rows(const RowSource& rows, const LaggedTemperatures& lag);

// The table of a model's lagged heads over the rows (nullopt when no head of
// `lag_s` lags: then the rows are not read).
std::optional<LaggedTemperatures> lagged_temperatures(const std::array<double, kMaxHeads>& lag_s,
                                                      const RowSource& rows);

}  // namespace ascorr::host
