// ascorr_host/analysis/epochs.hpp: reading a solutions file epoch by epoch.
//
// for_each_solution() (formats/solutions_csv.hpp) streams a file of any size
// in blocks of whole lines.
// EpochAssembler groups the rows of the heads that share an epoch (t to the
// millisecond, docs/contract.md), in any row order. Which heads make an epoch
// complete:
//  - a given HeadMask (fit: the heads of its analysis): the epoch is handed on
//    as soon as all of them are in;
//  - or the heads the file has shown so far (stats, plot: they do not know
//    the file's heads beforehand): the epoch is handed on once it holds every
//    head seen so far and a row of a later epoch has been read (in a file in
//    time order, when the next epoch begins).
// The incomplete ones are handed on at the end. A second row of the same head
// at the same epoch is an input error.
// A row that goes back in time to or before an epoch already handed on may
// belong to it: a head whose first row comes late would be missing from
// epochs handed on without it (open), or the row is a second one of its head
// there, which nothing pending shows. late() then says to read the rows again
// with heads() given and Handed::kRemember: the epochs handed on are kept
// (their keys and lines), so that the rows group exactly in any order and a
// second row is refused wherever it comes. A file in time order is read once
// and keeps nothing handed on.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <optional>
#include <set>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "ascorr_host/analysis/iba.hpp"
#include "ascorr_host/formats/solutions_csv.hpp"
#include "ascorr_text/c_format.hpp"
#include "ascorr_text/input_error.hpp"

namespace ascorr::host {

// Refuses a NaN or infinite --from/--to and --from not before --to
// (std::invalid_argument naming the options), for stats and plot (fit has its
// own refusals, FitRefused, in fit.cpp).
void refuse_bad_time_range(const std::optional<double>& from, const std::optional<double>& to,
                           const char* from_name = "--from", const char* to_name = "--to");

template <typename Payload>
struct Epoch {
    double t = 0.0;
    std::array<std::optional<Payload>, kMaxHeads> head;  // by head index (heads.hpp)
    std::array<std::size_t, kMaxHeads> line{};           // where each head's row is
};

// The refusal of a second row of one head in one epoch (every grouper's).
inline text::InputError second_solution(const std::string& file, std::size_t line, std::uint8_t head, double t,
                                        std::size_t first_line) {
    char when[32];
    text::c_snprintf(when, sizeof when, "%.3f", t);  // |t| < 9e15: at most 16 digits before the point
    return text::InputError(file, line, 1,
                            std::string("second solution of CHU ") + head_name(head) + " at t = " + when +
                                " (the first is on line " + std::to_string(first_line) + ")");
}

// Whether an assembler keeps the epochs it handed on (late(), above).
enum class Handed : bool { kForget, kRemember };

template <typename Payload>
class EpochAssembler {
public:
    using Sink = std::function<void(const Epoch<Payload>&)>;
    // Complete with the heads of `complete`.
    EpochAssembler(std::string file, Sink sink, HeadMask complete, Handed handed = Handed::kForget)
        : file_(std::move(file)),
          sink_(std::move(sink)),
          complete_(complete),
          open_(false),
          remember_(handed == Handed::kRemember) {}
    // Complete with the heads seen so far.
    EpochAssembler(std::string file, Sink sink) : file_(std::move(file)), sink_(std::move(sink)), open_(true) {}

    // head < kMaxHeads; the caller leaves out the heads it does not analyse.
    void add(double t, std::uint8_t head, std::size_t line, Payload p) {
        if (!(std::abs(t) < kMaxEpochTimeS)) {
            return;  // no millisecond key: in no epoch (iba.hpp)
        }
        const std::int64_t key = epoch_key(t);
        if (handed_any_ && key <= handed_max_ && pending_.count(key) == 0U) {
            late_ = true;
            refuse_second_in_handed(key, t, head, line);
        }
        Entry& e = pending_[key];
        if (e.epoch.head[head]) {
            throw second_solution(file_, line, head, t, e.epoch.line[head]);
        }
        if (e.heads == 0U) {
            e.epoch.t = t;
        }
        e.epoch.head[head] = std::move(p);
        e.epoch.line[head] = line;
        e.heads |= head_bit(head);
        if (!open_) {
            if ((e.heads & complete_) == complete_) {
                hand_on(key);
            }
            return;
        }
        if (!has_head(complete_, head)) {
            complete_ |= head_bit(head);  // a new head: the epochs held without it are not complete
            held_.clear();
        }
        if ((e.heads & complete_) == complete_) {
            held_.insert(key);
        }
        if (!any_key_ || key > last_key_) {
            last_key_ = key;
            any_key_ = true;
        }
        while (!held_.empty() && *held_.begin() < last_key_) {
            hand_on(*held_.begin());
        }
    }

    // Hands on the epochs still pending: the complete ones in time order, then
    // those missing a head, in time order too (whatever the row order).
    void finish() {
        while (!held_.empty()) {
            hand_on(*held_.begin());
        }
        std::vector<std::int64_t> keys;
        keys.reserve(pending_.size());
        for (const auto& kv : pending_) {
            keys.push_back(kv.first);
        }
        std::sort(keys.begin(), keys.end());
        for (const std::int64_t k : keys) {
            sink_(pending_.at(k).epoch);
        }
        pending_.clear();
    }

    // The heads of the rows added so far (open), or the set given.
    HeadMask heads() const noexcept { return complete_; }
    // Whether a row came at or before the time of an epoch already handed on
    // (and not pending), to which it may belong: read the rows again with
    // heads() given and Handed::kRemember (above).
    bool late() const noexcept { return late_; }

private:
    struct Entry {
        Epoch<Payload> epoch;
        HeadMask heads = 0U;
    };

    void hand_on(std::int64_t key) {
        held_.erase(key);
        handed_max_ = handed_any_ ? std::max(handed_max_, key) : key;
        handed_any_ = true;
        const auto it = pending_.find(key);
        sink_(it->second.epoch);
        if (remember_) {
            handed_.emplace(key, it->second.epoch.line);
        }
        pending_.erase(it);
    }

    // A row of a head that an epoch kept as handed on has (Handed::kRemember).
    void refuse_second_in_handed(std::int64_t key, double t, std::uint8_t head, std::size_t line) const {
        const auto it = handed_.find(key);
        if (it != handed_.end() && it->second[head] != 0U) {
            throw second_solution(file_, line, head, t, it->second[head]);
        }
    }

    std::string file_;
    Sink sink_;
    HeadMask complete_ = 0U;
    bool open_ = false;
    std::unordered_map<std::int64_t, Entry> pending_;
    std::set<std::int64_t> held_;  // open: complete, waiting for a later epoch
    std::int64_t last_key_ = 0;
    bool any_key_ = false;
    bool remember_ = false;
    std::unordered_map<std::int64_t, std::array<std::size_t, kMaxHeads>> handed_;  // remember_: lines by key
    std::int64_t handed_max_ = 0;                                                  // the latest handed on (handed_any_)
    bool handed_any_ = false;
    bool late_ = false;
};

}  // namespace ascorr::host
