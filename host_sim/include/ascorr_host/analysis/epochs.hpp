// ascorr_host/analysis/epochs.hpp: reading a solutions file epoch by epoch.
//
// for_each_solution() (formats/solutions_csv.hpp) streams a file of any size
// in blocks of whole lines.
// EpochAssembler groups the rows of heads A, B and C that share an epoch
// (t to the millisecond, docs/contract.md), in any row order: an epoch is handed on
// as soon as all three heads are in, the incomplete ones at the end. A second
// row of the same head at the same epoch is an input error.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <optional>
#include <string>
#include <unordered_map>
#include <utility>

#include "ascorr_host/analysis/iba.hpp"
#include "ascorr_host/formats/input_error.hpp"
#include "ascorr_host/formats/solutions_csv.hpp"

namespace ascorr::host {

// Refuses a NaN or infinite --from/--to and --from not before --to
// (std::invalid_argument naming the options), for stats and plot (fit has its
// own refusals, FitRefused, in fit.cpp).
void refuse_bad_time_range(const std::optional<double>& from, const std::optional<double>& to,
                           const char* from_name = "--from", const char* to_name = "--to");

template <typename Payload>
struct Epoch {
    double t = 0.0;
    std::array<std::optional<Payload>, 3> head;  // A, B, C
    std::array<std::size_t, 3> line{};           // where each head's row is
};

template <typename Payload>
class EpochAssembler {
public:
    using Sink = std::function<void(const Epoch<Payload>&)>;
    EpochAssembler(std::string file, Sink sink) : file_(std::move(file)), sink_(std::move(sink)) {}

    // head 0..2; other heads are not part of any pair and are left out by the caller.
    void add(double t, std::uint8_t head, std::size_t line, Payload p) {
        if (!(std::abs(t) < kMaxEpochTimeS)) {
            return;  // no millisecond key: in no epoch (iba.hpp)
        }
        const std::int64_t key = epoch_key(t);
        Epoch<Payload>& e = pending_[key];
        if (e.head[head]) {
            char when[32];
            std::snprintf(when, sizeof when, "%.3f", t);  // |t| < 9e15: at most 16 digits before the point
            throw InputError(file_, line, 1,
                             std::string("second solution of CHU ") + head_name(head) + " at t = " + when +
                                 " (the first is on line " + std::to_string(e.line[head]) + ")");
        }
        if (!e.head[0] && !e.head[1] && !e.head[2]) {
            e.t = t;
        }
        e.head[head] = std::move(p);
        e.line[head] = line;
        if (e.head[0] && e.head[1] && e.head[2]) {
            sink_(e);
            pending_.erase(key);
        }
    }

    // Hands on the epochs still missing a head (sink order is not time order).
    void finish() {
        for (const auto& kv : pending_) {
            sink_(kv.second);
        }
        pending_.clear();
    }

private:
    std::string file_;
    Sink sink_;
    std::unordered_map<std::int64_t, Epoch<Payload>> pending_;
};

}  // namespace ascorr::host
