#include "ascorr_host/correct/earth_velocity.hpp"

#include <erfa.h>

#include <array>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <limits>
#include <memory>
#include <mutex>

#include "ascorr/core/constants.hpp"

namespace ascorr::host {

EarthState earth_state_exact(double t) {
    double pvh[2][3];
    double pvb[2][3];
    // Split the date so that the fraction keeps full precision.
    const double days = t / kSecondsPerDay;
    (void)eraEpv00(kJ2000JulianDate, days, pvh, pvb);  // status 1 (outside 1900–2100): `valid` below
    constexpr double kAuPerDayToKmS = kAstronomicalUnitKm / kSecondsPerDay;
    EarthState s;
    s.v_bary_kms = {pvb[1][0] * kAuPerDayToKmS, pvb[1][1] * kAuPerDayToKmS, pvb[1][2] * kAuPerDayToKmS};
    s.sun_distance_au = std::sqrt(pvh[0][0] * pvh[0][0] + pvh[0][1] * pvh[0][1] + pvh[0][2] * pvh[0][2]);
    s.valid = in_ephemeris_span(t);
    return s;
}

bool in_ephemeris_span(double t) noexcept {
    return t >= kEphemerisFirstT && t < kEphemerisEndT;  // false for NaN
}

namespace {

constexpr int kCoefficients = EarthVelocity::kDegree + 1;
// 73049 days: 4566 segments, the last one reaching past 2100 (evaluated
// there by eraEpv00 all the same; at() refuses times beyond kEphemerisEndT).
constexpr std::size_t kSegments =
    static_cast<std::size_t>((kEphemerisEndT - kEphemerisFirstT) / EarthVelocity::kSegmentS) + 1;
constexpr std::size_t kFillLocks = 64;

// Chebyshev coefficients of vx, vy, vz (km/s) and the Sun distance (au) over
// one day, in x = 2(t − t_start)/L − 1 ∈ [−1, 1].
struct Segment {
    std::array<std::array<double, kCoefficients>, 4> c;
};

class Table {
public:
    Table() : segments_(new Segment[kSegments]), ready_(new std::atomic<bool>[kSegments]) {
        for (std::size_t i = 0; i < kSegments; ++i) {
            ready_[i].store(false, std::memory_order_relaxed);
        }
    }
    const Segment& segment(std::size_t i) {
        if (!ready_[i].load(std::memory_order_acquire)) {
            const std::lock_guard<std::mutex> lock(fill_[i % kFillLocks]);
            if (!ready_[i].load(std::memory_order_relaxed)) {
                fill(i, segments_[i]);
                ready_[i].store(true, std::memory_order_release);
            }
        }
        return segments_[i];
    }

private:
    // Interpolation at the Chebyshev nodes x_k = cos(π(k + ½)/n):
    // c_j = (2/n) Σ_k f(x_k) T_j(x_k), c_0 halved.
    static void fill(std::size_t i, Segment& s) {
        const double start = kEphemerisFirstT + static_cast<double>(i) * EarthVelocity::kSegmentS;
        std::array<std::array<double, kCoefficients>, 4> f{};
        std::array<double, kCoefficients> theta{};
        for (int k = 0; k < kCoefficients; ++k) {
            theta[static_cast<std::size_t>(k)] = kPi * (k + 0.5) / kCoefficients;
            const double x = std::cos(theta[static_cast<std::size_t>(k)]);
            const EarthState e = earth_state_exact(start + 0.5 * (x + 1.0) * EarthVelocity::kSegmentS);
            const auto kk = static_cast<std::size_t>(k);
            f[0][kk] = e.v_bary_kms.x;
            f[1][kk] = e.v_bary_kms.y;
            f[2][kk] = e.v_bary_kms.z;
            f[3][kk] = e.sun_distance_au;
        }
        for (std::size_t q = 0; q < 4; ++q) {
            for (int j = 0; j < kCoefficients; ++j) {
                double sum = 0.0;
                for (int k = 0; k < kCoefficients; ++k) {
                    sum += f[q][static_cast<std::size_t>(k)] * std::cos(j * theta[static_cast<std::size_t>(k)]);
                }
                s.c[q][static_cast<std::size_t>(j)] = (j == 0 ? 1.0 : 2.0) * sum / kCoefficients;
            }
        }
    }

    std::unique_ptr<Segment[]> segments_;  // not value-initialised: pages are touched only when used
    std::unique_ptr<std::atomic<bool>[]> ready_;
    std::array<std::mutex, kFillLocks> fill_;  // threads fill different segments at once
};

Table& table() {
    static Table t;  // thread-safe initialisation (C++11)
    return t;
}

// Clenshaw's recurrence for Σ c_j T_j(x).
double clenshaw(const std::array<double, kCoefficients>& c, double x) noexcept {
    double b1 = 0.0;
    double b2 = 0.0;
    for (int j = kCoefficients - 1; j >= 1; --j) {
        const double b0 = 2.0 * x * b1 - b2 + c[static_cast<std::size_t>(j)];
        b2 = b1;
        b1 = b0;
    }
    return x * b1 - b2 + c[0];
}

}  // namespace

EarthState EarthVelocity::at(double t) const {
    // The heads of one epoch share their t: each thread keeps its last answer,
    // which is a function of t alone, so a repeated t costs one comparison and
    // gives the same bits (NaN never equals the kept t).
    thread_local double last_t = std::numeric_limits<double>::quiet_NaN();
    thread_local EarthState last{};
    if (t == last_t) {
        return last;
    }
    if (!in_ephemeris_span(t)) {
        return {{0.0, 0.0, 0.0}, 1.0, false};
    }
    const double u = (t - kEphemerisFirstT) / kSegmentS;
    const double fl = std::floor(u);
    const auto i = std::min(static_cast<std::size_t>(fl), kSegments - 1);
    const double x = 2.0 * (u - static_cast<double>(i)) - 1.0;
    const Segment& s = table().segment(i);
    last = {{clenshaw(s.c[0], x), clenshaw(s.c[1], x), clenshaw(s.c[2], x)}, clenshaw(s.c[3], x), true};
    last_t = t;
    return last;
}

}  // namespace ascorr::host
