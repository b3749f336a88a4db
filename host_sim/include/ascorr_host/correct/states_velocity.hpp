// ascorr_host/correct/states_velocity.hpp: a solution row's velocity from the states,
// by the on-board service (velocity_service.hpp) in the row's scalar.
//
// The service's answer for a time depends only on the latest accepted state at
// or before it (the propagation grid is anchored at the state), so the host
// may jump: for each row it picks that state by binary search, restarts the
// service from it when it changed, and advances. A DPU fed the same states in
// time order gives the same bits (tests/test_states_cli.cpp checks the jumps
// against a sequential service).
//
// Jumping is cheap only forwards: a row earlier than the one before restarts
// the propagation from its state (up to horizon/10 s RK4 steps), and each
// change of state costs a frame conversion and the Earth series. So a file's
// rows are not asked in file order: StatesVelocityTable asks the service for
// every distinct row time once, in time order (the work of a DPU fed the rows
// in time order, whatever their order in the file), and StatesVelocity then
// reads the answer by binary search (tests/test_states_row_order.cpp).
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "ascorr/nav/velocity_service.hpp"
#include "ascorr_host/formats/states_csv.hpp"

namespace ascorr::host {

// The longest `--max-propagation` the host accepts: the on-board service's
// longest horizon (kMaxHorizonUs, velocity_service.hpp: 7 days).
inline constexpr double kMaxPropagationLimitS = static_cast<double>(kMaxHorizonUs) * 1e-6;

// Whether `--max-propagation` (or the Python module's max_propagation) is
// acceptable: at least the on-board clock's microsecond (a shorter horizon
// would round to none) and at most kMaxPropagationLimitS; NaN is not.
inline constexpr double kMinPropagationS = 1e-6;
inline bool max_propagation_acceptable(double max_propagation_s) {
    return max_propagation_s >= kMinPropagationS && max_propagation_s <= kMaxPropagationLimitS;
}

// The refusal text for an unacceptable value, one wording for CLI and Python.
inline constexpr const char* kMaxPropagationRule =
    "must be at least 1e-06 s (one microsecond) and at most 604800 s (7 days)";
static_assert(kMaxPropagationLimitS == 604800.0, "kMaxPropagationRule states the limit in seconds");

// Service configuration for `--max-propagation SECONDS` (max_propagation_acceptable;
// InputError-free: the callers check it): advance() catches up in one call.
inline VelocityServiceConfig service_config(double max_propagation_s) {
    return velocity_service_config(static_cast<std::int64_t>(std::llround(max_propagation_s * 1e6)));
}

// The velocity service's work for a set of rows: states pushed, RK4 steps,
// velocity nodes built (VelocityService::steps_taken, nodes_built).
struct ServiceCost {
    std::uint64_t states_pushed = 0;
    std::uint64_t rk4_steps = 0;
    std::uint64_t nodes_built = 0;

    ServiceCost& operator+=(const ServiceCost& o) noexcept {
        states_pushed += o.states_pushed;
        rk4_steps += o.rk4_steps;
        nodes_built += o.nodes_built;
        return *this;
    }
};

template <typename T>
class StatesVelocityTable;

// The velocity at a row's time: from `table` when it holds that time, else
// by the jumps above (cheap for rows in time order).
template <typename T>
class StatesVelocity {
public:
    StatesVelocity(const StatesFile& states, const VelocityServiceConfig& cfg,
                   const StatesVelocityTable<T>* table = nullptr)
        : states_(states), cfg_(cfg), svc_(cfg), table_(table) {}

    ServiceVelocity<T> at(double t_s) {
        TtTime t{};
        if (!tt_from_seconds(t_s, t)) {
            ServiceVelocity<T> out = VelocityService<T>(cfg_).velocity_at(TtTime{0});
            out.status = status::kNoVelocity | status::kVelocityInvalid;
            return out;
        }
        if (table_ != nullptr) {
            if (const ServiceVelocity<T>* v = table_->find(t)) {
                return *v;
            }
        }
        return at(t);
    }

    ServiceVelocity<T> at(TtTime t) {
        const auto& a = states_.accepted;
        const auto it =
            std::upper_bound(a.begin(), a.end(), t, [](const TtTime& x, const StateRecord& s) { return x < s.t; });
        if (it == a.begin()) {
            return VelocityService<T>(cfg_).velocity_at(t);  // no state yet: status 4
        }
        const auto idx = static_cast<std::size_t>(it - a.begin()) - 1;
        if (idx != current_) {
            cost_.rk4_steps += svc_.steps_taken();
            cost_.nodes_built += svc_.nodes_built();
            ++cost_.states_pushed;
            svc_ = VelocityService<T>(cfg_);
            svc_.push_state(a[idx].t, a[idx].r_km, a[idx].v_kms, states_.frame);
            current_ = idx;
        }
        svc_.advance(t, OnBoardEarth{});
        return svc_.velocity_at(t);
    }

    // The work done so far: a deterministic measure of cost (row order must not change it much).
    ServiceCost cost() const noexcept {
        return {cost_.states_pushed, cost_.rk4_steps + svc_.steps_taken(), cost_.nodes_built + svc_.nodes_built()};
    }

private:
    const StatesFile& states_;
    VelocityServiceConfig cfg_;
    VelocityService<T> svc_;
    std::size_t current_ = static_cast<std::size_t>(-1);
    ServiceCost cost_{};  // of the services replaced so far
    const StatesVelocityTable<T>* table_;
};

// The service's answers at a set of times, computed once in time order, then
// read-only (any number of threads). A row's answer is found through a direct
// index of time buckets (about one time per bucket), so rows in any order cost
// about two memory reads, not a binary search through the whole table.
// Memory per distinct time: 8 bytes of time, sizeof(ServiceVelocity<T>) (48
// bytes for double, 24 for float and Q30) and 8 bytes of index.
template <typename T>
class StatesVelocityTable {
public:
    // times_us: TtTime microseconds, in any order, repeats allowed. The sorted
    // times are cut into up to `workers` runs at changes of state (no state is
    // propagated twice), each run asked in time order by its own thread.
    StatesVelocityTable(const StatesFile& states, const VelocityServiceConfig& cfg, std::vector<std::int64_t> times_us,
                        std::size_t workers);

    // The answer at t, or nullptr when t is not one of the table's times.
    const ServiceVelocity<T>* find(TtTime t) const noexcept {
        if (entries_.empty() || t.us < entries_.front().t_us || t.us > entries_.back().t_us) {
            return nullptr;
        }
        const auto b = static_cast<std::size_t>(static_cast<std::uint64_t>(t.us - entries_.front().t_us) >> shift_);
        const auto first = entries_.begin() + static_cast<std::ptrdiff_t>(bucket_[b]);
        const auto last = entries_.begin() + static_cast<std::ptrdiff_t>(bucket_[b + 1]);
        const auto it = std::lower_bound(first, last, t.us, [](const Entry& e, std::int64_t x) { return e.t_us < x; });
        return it != last && it->t_us == t.us ? &it->v : nullptr;
    }

    std::size_t size() const noexcept { return entries_.size(); }
    // The service's work to fill the table.
    const ServiceCost& cost() const noexcept { return cost_; }

private:
    struct Entry {
        std::int64_t t_us;
        ServiceVelocity<T> v;
    };
    std::vector<Entry> entries_;  // increasing t_us
    // Bucket k holds the entries from bucket_[k] to bucket_[k + 1]: times in
    // [t_first + k·2^shift_, t_first + (k + 1)·2^shift_) µs.
    std::vector<std::size_t> bucket_;
    unsigned shift_ = 0;
    ServiceCost cost_{};
};

extern template class StatesVelocityTable<double>;
extern template class StatesVelocityTable<float>;
extern template class StatesVelocityTable<Q30>;

}  // namespace ascorr::host
