#include <cmath>

#include "ascorr/core/constants.hpp"
#include "ascorr/core/rotation_vector.hpp"
#include "combine_parts.hpp"

namespace ascorr::host::detail {

void HeadSetSteps::add(const combine::Combiner<double>& combiner, const combine::HeadAttitude<double>* heads,
                       std::uint8_t n, const Quaternion<double>& q_full, double t) {
    if (!any_epoch_) {
        t_first_ = t;
        any_epoch_ = true;
    }
    const auto day = static_cast<long long>(std::floor((t - t_first_) / kSecondsPerDay));
    combine::HeadAttitude<double> subset[kMaxHeads];
    for (unsigned sub = 1; sub < mounted_; ++sub) {
        const auto set = static_cast<HeadMask>(sub);
        if ((set & ~mounted_) != 0) {
            continue;
        }
        for (std::uint8_t i = 0; i < n; ++i) {
            subset[i] = heads[i];
            subset[i].usable = has_head(set, heads[i].head);
        }
        const combine::CombinedAttitude<double> c = combiner.combine(subset, n);
        if (c.used != set) {
            continue;  // the gate left a head of the subset out: no step of this set
        }
        DaySum& d = daily_[set][day];
        const Vector3<double> v = rotation_vector_arcsec(c.q_crf_icrf, q_full);
        ++d.n;
        d.sum[0] += v.x;
        d.sum[1] += v.y;
        d.sum[2] += v.z;
    }
}

void HeadSetSteps::finish(CombineSummary& sum) const {
    sum.full = mounted_;
    for (unsigned set = 1; set < mounted_; ++set) {
        HeadSetStep& st = sum.steps[set];
        std::array<double, 3> sq{};
        for (const auto& [day, d] : daily_[set]) {
            for (std::size_t a = 0; a < 3; ++a) {
                const double mean = d.sum[a] / static_cast<double>(d.n);
                sq[a] += mean * mean;
            }
            ++st.days;
        }
        for (std::size_t a = 0; a < 3; ++a) {
            st.rms_daily_mean[a] = st.days == 0 ? 0.0 : std::sqrt(sq[a] / static_cast<double>(st.days));
        }
    }
}

}  // namespace ascorr::host::detail
