#include "ascorr_host/correct/states_velocity.hpp"

#include "ascorr_host/correct/workers.hpp"

namespace ascorr::host {

namespace {

// The index + 1 of the latest accepted state at or before t (0: none).
std::size_t state_after(const StatesFile& states, std::int64_t t_us) {
    const auto& a = states.accepted;
    const auto it =
        std::upper_bound(a.begin(), a.end(), t_us, [](std::int64_t x, const StateRecord& s) { return x < s.t.us; });
    return static_cast<std::size_t>(it - a.begin());
}

}  // namespace

template <typename T>
StatesVelocityTable<T>::StatesVelocityTable(const StatesFile& states, const VelocityServiceConfig& cfg,
                                            std::vector<std::int64_t> times_us, std::size_t workers) {
    std::sort(times_us.begin(), times_us.end());
    times_us.erase(std::unique(times_us.begin(), times_us.end()), times_us.end());
    const std::size_t n = times_us.size();
    entries_.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        entries_[i].t_us = times_us[i];
    }
    std::vector<std::int64_t>().swap(times_us);  // free it before the answers are computed
    // Runs of about equal length, each cut where the state changes.
    workers = std::max<std::size_t>(workers, 1);
    std::vector<std::size_t> cut{0};
    for (std::size_t w = 1; w < workers; ++w) {
        std::size_t i = std::max(cut.back(), n * w / workers);
        while (i > 0 && i < n && state_after(states, entries_[i].t_us) == state_after(states, entries_[i - 1].t_us)) {
            ++i;
        }
        if (i > cut.back() && i < n) {
            cut.push_back(i);
        }
    }
    cut.push_back(n);
    std::vector<ServiceCost> costs(cut.size() - 1);
    const auto run = [&](std::size_t k) {
        StatesVelocity<T> sv(states, cfg);
        for (std::size_t i = cut[k]; i < cut[k + 1]; ++i) {
            entries_[i].v = sv.at(TtTime{entries_[i].t_us});
        }
        costs[k] = sv.cost();
    };
    run_workers(cut.size() - 1, run);
    for (const ServiceCost& c : costs) {
        cost_ += c;
    }
    // The buckets: the smallest power-of-two width that gives at most n of them.
    if (n == 0) {
        return;
    }
    const auto span = static_cast<std::uint64_t>(entries_.back().t_us - entries_.front().t_us);
    while ((span >> shift_) + 1U > n) {
        ++shift_;
    }
    const auto buckets = static_cast<std::size_t>((span >> shift_) + 1U);
    bucket_.assign(buckets + 1, n);
    std::size_t i = 0;
    for (std::size_t b = 0; b < buckets; ++b) {
        const auto start = entries_.front().t_us + static_cast<std::int64_t>(static_cast<std::uint64_t>(b) << shift_);
        while (i < n && entries_[i].t_us < start) {
            ++i;
        }
        bucket_[b] = i;
    }
}

template class StatesVelocityTable<double>;
template class StatesVelocityTable<float>;
template class StatesVelocityTable<Q30>;

}  // namespace ascorr::host
