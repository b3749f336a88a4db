// ascorr/calib/orbit_window.hpp: the recent orbits the on-board estimator
// (estimator.hpp) keeps, for the adoption gate's residual comparison and for
// the orbits held back as outliers: a ring of kWindow records, the oldest
// overwritten. Fixed size, no allocation.
#pragma once

#include <cstddef>
#include <cstdint>

#include "estimator_types.hpp"

namespace ascorr::calib {

// One orbit as the filter sees it (N heads).
template <std::size_t N = kCalibHeads>
struct OrbitRecord {
    std::int64_t bin;
    double e[N][3];  // arcsec, relative to N_h
    double x[N][3];  // T1, T2 − T1, T3 − T1 (°C), orbit means
    bool held;       // held back as an outlier, not (yet) in the filter
    bool has[N];     // head h's means are in the orbit (the frame heads always)

    std::uint8_t heads() const noexcept {
        std::uint8_t m = 0;
        for (std::size_t h = 0; h < N; ++h) {
            m = static_cast<std::uint8_t>(m | (has[h] ? 1U << h : 0U));
        }
        return m;
    }
    // The bench's T029 and T032 (°C): head A's T1 + (T2 − T1), T1 + (T3 − T1).
    double t2() const noexcept { return x[0][0] + x[0][1]; }
    double t3() const noexcept { return x[0][0] + x[0][2]; }
};

template <std::size_t N = kCalibHeads>
class OrbitWindow {
public:
    void clear() noexcept { size_ = 0; }
    std::size_t size() const noexcept { return size_; }
    // The i-th oldest record, i < size().
    OrbitRecord<N>& at(std::size_t i) noexcept { return ring_[(first_ + i) % kWindow]; }
    const OrbitRecord<N>& at(std::size_t i) const noexcept { return ring_[(first_ + i) % kWindow]; }
    // Appends o; when full, o replaces the oldest.
    void push(const OrbitRecord<N>& o) noexcept {
        if (size_ < kWindow) {
            ring_[(first_ + size_) % kWindow] = o;
            ++size_;
        } else {
            ring_[first_] = o;
            first_ = (first_ + 1U) % kWindow;
        }
    }

private:
    OrbitRecord<N> ring_[kWindow]{};
    std::size_t first_ = 0;
    std::size_t size_ = 0;
};

}  // namespace ascorr::calib
