// ascorr/calib/orbit_collector.hpp: the cycle side of the on-board estimator
// (estimator.hpp): which orbit a selected cycle belongs to, that orbit's sums
// (orbit_sums.hpp) and their references; and, once per orbit in double, the
// closed orbit's means (orbit_means()) and the references they give the
// next orbit opened (reference_from()).
//
// Orbits are bins of the on-board clock: orbit k is [k·P, (k+1)·P) µs, P the
// configured orbit period, k = floor(t/P) (negative times included). A cycle
// costs two comparisons; the 64-bit division (a library call on the M3) only
// when the orbit changes.
//
// References (OrbitReference): the first orbit's are its first cycle (the
// exact d_h and temperatures); each later orbit takes the means of the last
// orbit the estimator processed (set_next_reference), or, when that orbit was
// too short or still being processed, keeps the one before. Any reference
// within arcseconds of the orbit's d_h gives full precision (orbit_sums.hpp).
//
// No allocation, no division but the orbit change's, fixed-size state.
#pragma once

#include <cmath>
#include <cstdint>

#include "../core/quaternion.hpp"
#include "../core/scalar_traits.hpp"
#include "estimator_types.hpp"
#include "head_rotation.hpp"
#include "orbit_sums.hpp"

namespace ascorr::calib {

// An orbit handed from the cycle to the per-orbit work.
template <typename T, std::size_t N = kCalibHeads>
struct ClosedOrbit {
    OrbitSums<T, N> sums{};
    OrbitReference<T, N> ref{};
    std::int64_t bin = 0;  // floor(t / P)
};

template <typename T, std::size_t N = kCalibHeads>
class OrbitCollector {
public:
    // period_us > 0 (EstimatorConfig's bounds, estimator_types.hpp).
    explicit OrbitCollector(std::int64_t period_us) noexcept : period_us_(period_us) {}

    bool is_open() const noexcept { return open_; }

    // Whether a cycle at t_us starts an orbit: none is open, or t_us is
    // outside the open one. Two comparisons.
    bool starts_orbit(std::int64_t t_us) const noexcept { return !open_ || t_us < start_us_ || t_us >= end_us_; }

    // Opens the orbit of cycle c (the current one must have been closed or
    // dropped) with empty sums and the references (see the top).
    void open(const CalibCycle<T, N>& c) noexcept {
        bin_ = orbit_bin(c.t_us, period_us_);
        start_us_ = bin_ * period_us_;
        end_us_ = start_us_ + period_us_;
        open_ = true;
        sums_ = OrbitSums<T, N>{};
        if (next_ref_ready_) {
            ref_ = next_ref_;
            next_ref_ready_ = false;
        } else if (!ref_valid_) {
            const Quaternion<T> q_icrf_a = conjugate(c.q_chu_icrf[0]);
            for (std::size_t k = 0; k + 1 < kFrameHeads; ++k) {
                ref_.r[k] = c.q_chu_icrf[k + 1] * q_icrf_a;
            }
            for (std::size_t h = 0; h < kFrameHeads; ++h) {
                take_temperatures(h, c.temperatures[h]);
            }
        }
        ref_valid_ = true;
    }

    // One cycle of the open orbit (starts_orbit(c.t_us) false). A further
    // head's first selected cycle ever gives its references.
    void add(const CalibCycle<T, N>& c) noexcept {
        if constexpr (N > kFrameHeads) {
            last_t_us_ = c.t_us;
            last_q_a_ = c.q_chu_icrf[0];
            for (std::size_t h = kFrameHeads; h < N && c.heads != kFrameMask; ++h) {
                if (((static_cast<unsigned>(c.heads) >> h) & 1U) != 0U) {
                    first_reference(h, c.q_chu_icrf[h], c.temperatures[h]);
                }
            }
        }
        sums_.add(c.q_chu_icrf, c.temperatures, ref_, c.heads);
    }

    // Further head h (≥ kFrameHeads) of the last cycle added, selected after
    // it (the link's solutions come one by one); false: no such cycle is
    // open at t_us, or h was not sent with it.
    bool add_head(std::size_t h, std::int64_t t_us, const Quaternion<T>& q_h,
                  const HeadTemperatures<T>& temps) noexcept {
        if (!open_ || t_us != last_t_us_ || h < kFrameHeads || h >= N) {
            return false;
        }
        first_reference(h, q_h, temps);
        sums_.add_head(h, conjugate(last_q_a_), q_h, temps, ref_);
        return true;
    }

    // The references of the orbit opened last (those of the heads a closed
    // orbit does not have carry over).
    const OrbitReference<T, N>& latest_reference() const noexcept { return next_ref_ready_ ? next_ref_ : ref_; }

    // Ends the open orbit, handing it over.
    void close(ClosedOrbit<T, N>& out) noexcept {
        open_ = false;
        out.sums = sums_;
        out.ref = ref_;
        out.bin = bin_;
    }

    // Ends the open orbit, dropping its sums (frozen, reset, or the previous
    // orbit still being processed).
    void drop() noexcept { open_ = false; }

    // The references of the next orbit opened.
    void set_next_reference(const OrbitReference<T, N>& r) noexcept {
        next_ref_ = r;
        next_ref_ready_ = true;
    }

private:
    void take_temperatures(std::size_t h, const HeadTemperatures<T>& tp) noexcept {
        ref_.t_ref[h][0] = tp.t_chu.value;
        ref_.t_ref[h][1] = tp.t_029.value;
        ref_.t_ref[h][2] = tp.t_032.value;
    }

    // A further head's references from its first selected cycle ever.
    void first_reference(std::size_t h, const Quaternion<T>& q_h, const HeadTemperatures<T>& tp) noexcept {
        if (((static_cast<unsigned>(ref_heads_) >> h) & 1U) != 0U) {
            return;
        }
        ref_heads_ = static_cast<std::uint8_t>(ref_heads_ | (1U << h));
        ref_.r[h - 1U] = q_h * conjugate(last_q_a_);
        take_temperatures(h, tp);
        if (next_ref_ready_) {
            next_ref_.r[h - 1U] = ref_.r[h - 1U];
            for (std::size_t j = 0; j < 3; ++j) {
                next_ref_.t_ref[h][j] = ref_.t_ref[h][j];
            }
        }
    }

    std::int64_t period_us_;
    bool open_ = false;
    std::int64_t bin_ = 0;
    std::int64_t start_us_ = 0;  // [start, end) of the open orbit
    std::int64_t end_us_ = 0;
    OrbitSums<T, N> sums_{};
    OrbitReference<T, N> ref_{};
    bool ref_valid_ = false;
    OrbitReference<T, N> next_ref_{};
    bool next_ref_ready_ = false;
    std::uint8_t ref_heads_ = kFrameMask;  // heads with references (a further head: from its first cycle)
    std::int64_t last_t_us_ = 0;           // the last cycle added (further heads only)
    Quaternion<T> last_q_a_{};             // its head A (q_a_icrf)
};

// A closed orbit's means of N heads, in double: d_B, d_C, … (unit; the mean
// of δ_h, normalised, times r_h, normalised again) and the 3·N mean
// temperatures (°C), of the heads with at least min_count cycles in the orbit
// (has; the frame heads': the orbit's).
template <std::size_t N = kCalibHeads>
struct OrbitMeans {
    Quaternion<double> d[N - 1];
    double t[N][3];
    bool has[N];
};

// The means of o's sums (o.sums flushed, o.sums.count > 0); a further head
// has means when it has min_count cycles; why means of d_h suffice:
// orbit_sums.hpp, at the top.
template <typename T, std::size_t N>
OrbitMeans<N> orbit_means(const ClosedOrbit<T, N>& o, std::uint32_t min_count = 1U) noexcept {
    using Tr = ScalarTraits<T>;
    OrbitMeans<N> m{};
    for (std::size_t h = 0; h < N; ++h) {
        const std::uint32_t n = o.sums.count_of(h);
        m.has[h] = h < kFrameHeads || (n >= min_count && n > 0U);
        if (!m.has[h]) {
            continue;
        }
        const double inv = 1.0 / static_cast<double>(n);
        if (h > 0U) {
            const std::size_t k = h - 1U;
            const auto& s = o.sums.dq[k];
            const Quaternion<double> mean{s[0].value() * inv, s[1].value() * inv, s[2].value() * inv,
                                          s[3].value() * inv};
            const double sm = 1.0 / std::sqrt(squared_norm(mean));
            const Quaternion<T>& r = o.ref.r[k];
            const Quaternion<double> rd{Tr::to_double(r.w), Tr::to_double(r.x), Tr::to_double(r.y), Tr::to_double(r.z)};
            const Quaternion<double> unit{mean.w * sm, mean.x * sm, mean.y * sm, mean.z * sm};
            const Quaternion<double> dk = unit * rd;
            const double sn = 1.0 / std::sqrt(squared_norm(dk));
            m.d[k] = {dk.w * sn, dk.x * sn, dk.y * sn, dk.z * sn};
        }
        for (std::size_t j = 0; j < 3; ++j) {
            m.t[h][j] = Tr::to_double(o.ref.t_ref[h][j]) + o.sums.dt[h][j].value() * inv;
        }
    }
    return m;
}

// The references an orbit's means give the next orbit (rounded to T); the
// heads without means keep those of `r`.
template <typename T, std::size_t N>
OrbitReference<T, N> reference_from(const OrbitMeans<N>& m, OrbitReference<T, N> r = {}) noexcept {
    using Tr = ScalarTraits<T>;
    for (std::size_t h = 0; h < N; ++h) {
        if (!m.has[h]) {
            continue;
        }
        if (h > 0U) {
            const Quaternion<double>& d = m.d[h - 1U];
            r.r[h - 1U] = {Tr::from_double(d.w), Tr::from_double(d.x), Tr::from_double(d.y), Tr::from_double(d.z)};
        }
        for (std::size_t j = 0; j < 3; ++j) {
            r.t_ref[h][j] = Tr::celsius(m.t[h][j]);
        }
    }
    return r;
}

}  // namespace ascorr::calib
