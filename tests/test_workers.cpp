// The host's splitting of a job over threads (workers.hpp) and its scalar
// names (scalar_kind.hpp), shared by `ascorr correct` and the Python module.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <mutex>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "ascorr_host/correct/scalar_kind.hpp"
#include "ascorr_host/correct/workers.hpp"

namespace ascorr::host {
namespace {

TEST(Workers, Count) {
    const std::size_t all = worker_count();
    EXPECT_GE(all, 1U);
    EXPECT_LE(all, kMaxWorkers);
    EXPECT_EQ(worker_count(0, 100), 1U);       // at least one
    EXPECT_EQ(worker_count(199, 100), 1U);     // one per 100 items
    EXPECT_EQ(worker_count(1000000, 1), all);  // never beyond the hardware's
    EXPECT_EQ(worker_count(2 * all * 100, 100), all);
    EXPECT_EQ(worker_count(5, 0), std::min<std::size_t>(all, 5));  // 0 per worker counts as 1
}

// Every item in exactly one piece, the pieces the documented ranges.
TEST(Workers, PiecesCoverEveryItemOnce) {
    for (const std::size_t items : {0U, 1U, 7U, 1000U, 1001U}) {
        for (const std::size_t pieces : {0U, 1U, 3U, 8U, 13U}) {
            const std::size_t k = pieces == 0 ? 1 : pieces;
            std::vector<std::atomic<int>> hits(items);
            std::mutex m;
            std::vector<std::pair<std::size_t, std::size_t>> got;
            for_each_piece(items, pieces, [&](std::size_t begin, std::size_t end) {
                for (std::size_t i = begin; i < end; ++i) {
                    ++hits[i];
                }
                const std::lock_guard<std::mutex> lock(m);
                got.emplace_back(begin, end);
            });
            std::vector<std::pair<std::size_t, std::size_t>> want;
            for (std::size_t p = 0; p < k; ++p) {
                want.emplace_back(items * p / k, items * (p + 1) / k);
            }
            std::sort(got.begin(), got.end());
            EXPECT_EQ(got, want) << items << " items, " << pieces << " pieces";
            for (std::size_t i = 0; i < items; ++i) {
                EXPECT_EQ(hits[i].load(), 1) << "item " << i << " of " << items << ", " << pieces << " pieces";
            }
        }
    }
}

// A piece that throws: every thread has ended, then the exception comes back
// to the caller (the first piece's first), whichever thread ran it.
TEST(Workers, ExceptionsReachTheCaller) {
    for (const std::size_t bad : {0U, 3U}) {
        std::atomic<int> ended{0};
        try {
            run_workers(5, [&](std::size_t i) {
                if (i == bad || i == 4) {
                    ++ended;
                    throw std::runtime_error("piece " + std::to_string(i));
                }
                ++ended;
            });
            ADD_FAILURE() << "no exception";
        } catch (const std::runtime_error& e) {
            EXPECT_EQ(std::string(e.what()), "piece " + std::to_string(bad));
        }
        EXPECT_EQ(ended.load(), 5);
    }
    run_workers(0, [](std::size_t) { ADD_FAILURE() << "no piece to run"; });
}

TEST(ScalarNames, OneNamePerKind) {
    EXPECT_EQ(scalar_name(ScalarKind::kDouble), "double");
    EXPECT_EQ(scalar_name(ScalarKind::kFloat), "float");
    EXPECT_EQ(scalar_name(ScalarKind::kFixed), "fixed");
    for (const ScalarName& n : kScalarNames) {
        EXPECT_EQ(scalar_from_name(n.name), n.kind);
        EXPECT_EQ(scalar_name(n.kind), n.name);
    }
    EXPECT_FALSE(scalar_from_name("Double"));  // callers fold the case first
    EXPECT_FALSE(scalar_from_name("q30"));
    EXPECT_FALSE(scalar_from_name(""));
    static_assert(scalar_from_name("fixed") == ScalarKind::kFixed);
}

}  // namespace
}  // namespace ascorr::host
