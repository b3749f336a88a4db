#include "ascorr_host/correct/workers.hpp"

#include <algorithm>
#include <exception>
#include <thread>
#include <vector>

namespace ascorr::host {

std::size_t worker_count() noexcept {
    const unsigned hw = std::thread::hardware_concurrency();
    return std::clamp<std::size_t>(hw == 0 ? 1 : hw, 1, kMaxWorkers);
}

std::size_t worker_count(std::size_t items, std::size_t min_items_per_worker) noexcept {
    const std::size_t by_size = std::max<std::size_t>(1, items / std::max<std::size_t>(1, min_items_per_worker));
    return std::min(worker_count(), by_size);
}

void run_workers(std::size_t n, const std::function<void(std::size_t)>& work) {
    std::vector<std::exception_ptr> errors(n);
    const auto guarded = [&](std::size_t i) {
        try {
            work(i);
        } catch (...) {
            errors[i] = std::current_exception();
        }
    };
    {
        std::vector<std::thread> threads;
        threads.reserve(n > 0 ? n - 1 : 0);
        for (std::size_t i = 1; i < n; ++i) {
            threads.emplace_back(guarded, i);
        }
        if (n > 0) {
            guarded(0);
        }
        for (std::thread& t : threads) {
            t.join();
        }
    }
    for (const std::exception_ptr& e : errors) {
        if (e) {
            std::rethrow_exception(e);
        }
    }
}

void for_each_piece(std::size_t items, std::size_t pieces,
                    const std::function<void(std::size_t begin, std::size_t end)>& body) {
    const std::size_t k = std::max<std::size_t>(pieces, 1);
    const auto at = [&](std::size_t j) { return items * j / k; };
    run_workers(k, [&](std::size_t j) { body(at(j), at(j + 1)); });
}

}  // namespace ascorr::host
