#include "ascorr_host/states_velocity.hpp"

#include <thread>

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
                                            std::vector<std::int64_t> times_us, std::size_t workers)
    : t_us_(std::move(times_us)) {
    std::sort(t_us_.begin(), t_us_.end());
    t_us_.erase(std::unique(t_us_.begin(), t_us_.end()), t_us_.end());
    t_us_.shrink_to_fit();
    v_.resize(t_us_.size());
    // Runs of about equal length, each cut where the state changes.
    const std::size_t n = t_us_.size();
    std::vector<std::size_t> cut{0};
    for (std::size_t w = 1; w < std::max<std::size_t>(workers, 1); ++w) {
        std::size_t i = std::max(cut.back(), n * w / workers);
        while (i > 0 && i < n && state_after(states, t_us_[i]) == state_after(states, t_us_[i - 1])) {
            ++i;  // (a binary search per time: only at the cuts, and O(n) at worst for one state)
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
            v_[i] = sv.at(TtTime{t_us_[i]});
        }
        costs[k] = sv.cost();
    };
    std::vector<std::thread> threads;
    for (std::size_t k = 1; k + 1 < cut.size(); ++k) {
        threads.emplace_back(run, k);
    }
    run(0);
    for (auto& t : threads) {
        t.join();
    }
    for (const ServiceCost& c : costs) {
        cost_ += c;
    }
}

template class StatesVelocityTable<double>;
template class StatesVelocityTable<float>;
template class StatesVelocityTable<Q30>;

}  // namespace ascorr::host
