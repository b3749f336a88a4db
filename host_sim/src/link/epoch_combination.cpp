// `ascorr replay --combined`: each epoch combined on the target and on the host, compared, written (EpochCombination).
#include <cstring>
#include <optional>
#include <ostream>
#include <string>
#include <utility>

#include "ascorr_host/analysis/iba.hpp"
#include "ascorr_host/formats/combined_csv.hpp"
#include "replay_parts.hpp"

namespace ascorr::host::detail {

template <typename T>
EpochCombination<T>::EpochCombination(const MountingsFile& m, const combine::CombinerConfig& gate,
                                      LinkClient<T>& client, link::LinkPipeline<T>& host, std::string file,
                                      std::ostream& log)
    : client_(client), host_(host), combiner_(m.mountings, gate), file_(std::move(file)), log_(log) {
    client_.load_mountings(m.mountings, gate);
    host_.use_combiner(&combiner_);
    text_ = std::string(kCombinedHeader) + "\n";
}

template <typename T>
void EpochCombination<T>::before(double t) {
    const std::optional<std::int64_t> key = pipeline::epoch_key_of(t);
    if (grouper_.ends_before(key)) {
        close(true);
    }
    if (key && grouper_.add(*key)) {
        t_ = t;
    }
}

template <typename T>
void EpochCombination<T>::after(double t) {
    if (!pipeline::has_epoch_key(t)) {
        close(false);
    }
}

template <typename T>
void EpochCombination<T>::finish(ReplaySummary& sum) {
    if (grouper_.is_open()) {
        close(true);
    }
    sum.combined = true;
    sum.combined_epochs = epochs_;
    sum.combined_mismatches = mismatches_;
    sum.combination_instructions_per_epoch = costed_ == 0 ? 0.0 : instructions_ / static_cast<double>(costed_);
}

template <typename T>
void EpochCombination<T>::close(bool write) {
    grouper_.close();
    const link::Combined<T> got = client_.combine_epoch();
    const combine::CombinedAttitude<T> want = host_.close();
    const bool same = got.status == want.status && got.used == want.used && got.left_out == want.left_out &&
                      got.inconsistent == want.inconsistent &&
                      std::memcmp(&got.q_crf_icrf, &want.q_crf_icrf, sizeof got.q_crf_icrf) == 0;
    if (!same && ++mismatches_ <= kMaxCalibMessages) {
        log_ << file_ << ": epoch t = " << number_text(t_) << ": the target's combined attitude differs from the "
             << "host's (status " << unsigned{got.status} << " vs " << unsigned{want.status} << ", heads "
             << head_letters(got.used) << " vs " << head_letters(want.used) << ")\n";
    }
    if (!write) {
        return;
    }
    ++epochs_;
    if ((got.status & combine::combined_status::kTwoOrMoreHeads) != 0U) {
        instructions_ += got.instructions;
        ++costed_;
    }
    AttitudeRow row;
    row.t = t_;
    row.has_q = (got.status & combine::combined_status::kNoHead) == 0U;
    row.q_crf_icrf = widen(got.q_crf_icrf);
    row.heads = row.has_q ? got.used : 0U;
    const double* sigma = combiner_.sigma_arcsec(got.used);
    row.sigma_arcsec = {sigma[0], sigma[1], sigma[2]};
    row.status = got.status;
    append_combined_row(text_, row);
}

template class EpochCombination<float>;
template class EpochCombination<Q30>;

}  // namespace ascorr::host::detail
