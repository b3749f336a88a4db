// ascorr_host/correct/workers.hpp: the host's one way of splitting a job over
// threads, for `ascorr correct` (blocks of a file, the states' runs) and the
// Python module (rows of arrays).
//
// The pieces are independent and each writes only its own results, so the
// output does not depend on how many threads ran: the same bytes on any
// machine.
#pragma once

#include <cstddef>
#include <functional>

namespace ascorr::host {

// At most this many threads: beyond it the file's reading and writing, not the
// correction, set the pace.
inline constexpr std::size_t kMaxWorkers = 8;

// Threads for a job: the hardware's, 1..kMaxWorkers.
std::size_t worker_count() noexcept;
// Threads for a job of `items` independent items: as worker_count(), but no
// more than one per min_items_per_worker (below it a thread costs more than it
// saves), and at least one.
std::size_t worker_count(std::size_t items, std::size_t min_items_per_worker) noexcept;

// Runs work(0) .. work(n - 1), work(0) on the calling thread and each other on
// its own, and returns when all have ended. An exception of a piece is
// rethrown here (the first piece's first), after every thread has ended.
void run_workers(std::size_t n, const std::function<void(std::size_t)>& work);

// Runs body(begin, end) over [0, items) in `pieces` contiguous ranges of about
// equal size (piece j: [items * j / pieces, items * (j + 1) / pieces)), one
// per thread (run_workers). pieces 0 counts as 1.
void for_each_piece(std::size_t items, std::size_t pieces,
                    const std::function<void(std::size_t begin, std::size_t end)>& body);

}  // namespace ascorr::host
