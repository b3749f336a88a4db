// `ascorr align`: the passes over the rows, the refusals, the report
// (ascorr_host/analysis/align.hpp).
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <memory>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "ascorr/core/status.hpp"
#include "ascorr/pipeline/epoch_key.hpp"
#include "ascorr_host/analysis/align.hpp"
#include "ascorr_host/analysis/epochs.hpp"
#include "ascorr_host/formats/atomic_file.hpp"
#include "ascorr_host/formats/csv.hpp"
#include "ascorr_host/formats/solutions_csv.hpp"
#include "ascorr_text/c_format.hpp"
#include "ascorr_text/input_error.hpp"

namespace ascorr::host {

namespace {

std::string time_text(double t) {
    char buf[48];
    text::c_snprintf(buf, sizeof buf, "%.3f", t);
    return buf;
}

std::string period_text(const std::optional<double>& from, const std::optional<double>& to) {
    if (!from && !to) {
        return "the whole file";
    }
    return "[" + (from ? time_text(*from) : std::string("start")) + ", " + (to ? time_text(*to) : std::string("end")) +
           "]";
}

bool in_period(double t, const AlignOptions& opt) noexcept {
    return (!opt.from || t >= *opt.from) && (!opt.to || t <= *opt.to);
}

// What one pass counts (the last pass's counts go into the report).
struct PassCounts {
    std::size_t rows = 0;
    std::size_t rows_in_period = 0;
    std::size_t epochs = 0;
    std::array<std::size_t, kLeftOutKinds> left_out{};
    std::array<std::array<std::size_t, kLeftOutKinds>, kMaxHeads> head_left_out{};
};

using CurrentMountings = std::array<Quaternion<double>, kMaxHeads>;

// A row of an epoch, as the selection sees it, and why it is left out on its own.
struct Judged {
    CorrectedRow row;
    combine::RowFacts facts;
    LeftOut why;
};

// The core's step 2 over the epoch's rows (combine/usable.hpp; a second row
// of a head was refused when read): `why` from each row's own; a usable row
// without a stage another has, or not unit, is left out. Returns the stages.
StatusBits select_rows(const Epoch<Judged>& e, std::array<LeftOut, kMaxHeads>& why) noexcept {
    combine::RowFacts facts[kMaxHeads];
    LeftOut whys[kMaxHeads];
    std::uint8_t heads[kMaxHeads];
    std::size_t n = 0;
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        if (e.head[h]) {
            facts[n] = e.head[h]->facts;
            whys[n] = e.head[h]->why;
            heads[n++] = h;
        }
    }
    const StatusBits stages = combine::select_epoch(facts, whys, n, combine::Repeated::kLeaveAllOut);
    for (std::size_t i = 0; i < n; ++i) {
        why[heads[i]] = whys[i];
    }
    return stages;
}

// The combination's consistency gate for a pass after the first: its tables
// from the current mountings and the noise of the pass before (StageGates:
// the gate follows the epoch's stages). The heads of the epoch still usable
// that it finds inconsistent get LeftOut::kInconsistent.
void apply_gate(const StageGates& gates, const Epoch<Judged>& e, StatusBits stages,
                std::array<LeftOut, kMaxHeads>& why) noexcept {
    combine::HeadAttitude<double> heads[kMaxHeads];
    std::uint8_t n = 0;
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        if (e.head[h] && why[h] == LeftOut::kUsed) {
            heads[n++] = {e.head[h]->row.q_chu_icrf, h, true};
        }
    }
    const HeadMask out = n >= 2 ? gates.of(stages).combine(heads, n).inconsistent : HeadMask{0};
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        why[h] = (out & head_bit(h)) != 0U ? LeftOut::kInconsistent : why[h];
    }
}

// One epoch into the sums: each usable head's CRF attitude (the rows the
// gate, if any, leaves in).
void add_epoch(const Epoch<Judged>& e, const CurrentMountings& q_chu_crf, const StageGates* gate, AlignSums& sums,
               PassCounts& c) {
    std::array<LeftOut, kMaxHeads> why{};
    const StatusBits stages = select_rows(e, why);
    if (gate != nullptr) {
        apply_gate(*gate, e, stages, why);
    }
    std::array<std::optional<Quaternion<double>>, kMaxHeads> q_crf_icrf{};
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        if (!e.head[h]) {
            continue;
        }
        ++c.left_out[static_cast<std::size_t>(why[h])];
        ++c.head_left_out[h][static_cast<std::size_t>(why[h])];
        if (why[h] == LeftOut::kUsed) {
            q_crf_icrf[h] = conjugate(q_chu_crf[h]) * e.head[h]->row.q_chu_icrf;
        }
    }
    ++c.epochs;
    sums.add(e.t, q_crf_icrf);
}

// A row earlier than the epoch before it: the pass cannot stream (align_rows
// sorts the rows and starts again).
struct OutOfOrder {};

// The epochs of rows in time order, each handed on when the next begins
// (consecutive rows with one millisecond key, pipeline/epoch_key.hpp), so the
// noise windows see them in time order and the memory is one epoch's. A
// second row of one head in an epoch: InputError (both lines named).
class OrderedEpochs {
public:
    OrderedEpochs(const std::string& file, std::function<void(const Epoch<Judged>&)> sink)
        : file_(file), sink_(std::move(sink)) {}

    void add(std::uint8_t head, std::size_t line, const Judged& j) {
        const std::int64_t key = epoch_key(j.row.t);
        if (keys_.ends_before(key)) {
            if (key < keys_.key()) {
                throw OutOfOrder{};
            }
            flush();
        }
        if (keys_.add(key)) {
            epoch_.t = static_cast<double>(key) / 1000.0;  // the key's time: the same whichever row comes first
        }
        if (epoch_.head[head]) {
            throw second_solution(file_, line, head, j.row.t, epoch_.line[head]);
        }
        epoch_.head[head] = j;
        epoch_.line[head] = line;
    }
    void finish() {
        if (keys_.is_open()) {
            flush();
        }
    }

private:
    void flush() {
        sink_(epoch_);
        epoch_ = Epoch<Judged>{};
        keys_.close();
    }

    const std::string& file_;
    std::function<void(const Epoch<Judged>&)> sink_;
    pipeline::ConsecutiveEpochs keys_;
    Epoch<Judged> epoch_;
};

// One pass over the rows (in time order) with the current mountings.
void run_pass(const CorrectedRowSource& rows, const std::string& file, const MountingsFile& m,
              const CurrentMountings& q_chu_crf, const StageGates* gate, const AlignOptions& opt, AlignSums& sums,
              PassCounts& c) {
    OrderedEpochs epochs(file, [&](const Epoch<Judged>& e) { add_epoch(e, q_chu_crf, gate, sums, c); });
    const HeadMask mounted = combine::mounted_heads(m.mountings);
    rows([&](const CorrectedRow& r) {
        ++c.rows;
        if (!in_period(r.t, opt)) {
            return;
        }
        ++c.rows_in_period;
        const combine::RowFacts f = row_facts(r);
        const LeftOut why = combine::left_out_alone(f, mounted);
        if (why == LeftOut::kNotAHead || why == LeftOut::kNotInMountings || why == LeftOut::kNoEpoch) {
            ++c.left_out[static_cast<std::size_t>(why)];
            return;
        }
        epochs.add(r.head, r.line, Judged{r, f, why});
    });
    epochs.finish();
    sums.finish();
}

// The rows in time order: kept in memory and sorted by their epoch key
// (stable: file order within an epoch), for a file that is not in time order.
CorrectedRowSource sorted_rows(const CorrectedRowSource& rows) {
    auto kept = std::make_shared<std::vector<CorrectedRow>>();
    rows([&](const CorrectedRow& r) { kept->push_back(r); });
    const auto key = [](const CorrectedRow& r) {
        return std::abs(r.t) < kMaxEpochTimeS ? epoch_key(r.t) : std::numeric_limits<std::int64_t>::max();
    };
    std::stable_sort(kept->begin(), kept->end(),
                     [&](const CorrectedRow& a, const CorrectedRow& b) { return key(a) < key(b); });
    return [kept](const std::function<void(const CorrectedRow&)>& fn) {
        for (const CorrectedRow& r : *kept) {
            fn(r);
        }
    };
}

std::string reasons_text(const std::array<std::size_t, kLeftOutKinds>& n) {
    std::string s;
    for (std::size_t k = 1; k < kLeftOutKinds; ++k) {
        if (n[k] != 0U) {
            s += (s.empty() ? "" : ", ") + std::to_string(n[k]) + " " + left_out_name(static_cast<LeftOut>(k));
        }
    }
    return s.empty() ? std::string("none left out") : s;
}

// The refusals found after each pass: no row, a head without clean epochs
// (the gate may leave a head none), too few epochs.
void refuse_thin_data(const std::string& file, const AlignSums& sums, const PassCounts& c, HeadMask heads,
                      const AlignOptions& opt) {
    const std::string where = text::input_name(file) + " in " + period_text(opt.from, opt.to);
    if (c.rows_in_period == 0U) {
        throw AlignRefused("the period is empty: no row of " + where);
    }
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        if (has_head(heads, h) && sums.head_epochs(h) == 0U) {
            std::size_t n = 0;
            for (const std::size_t k : c.head_left_out[h]) {
                n += k;
            }
            throw AlignRefused(std::string("CHU ") + kHeadLetters[h] +
                               " (in the mountings) has no clean epoch with "
                               "another head of " +
                               where + ": " + std::to_string(n) + " rows (" + reasons_text(c.head_left_out[h]) + ")");
        }
    }
    if (sums.joint_epochs() < opt.min_epochs) {
        throw AlignRefused("too few epochs: " + std::to_string(sums.joint_epochs()) +
                           " with two or more usable heads of " + where + ", align needs " +
                           std::to_string(opt.min_epochs));
    }
}

double largest(const Alignment& a) {
    double m = 0.0;
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        if (has_head(a.heads, h)) {
            m = std::max(m, a.delta_arcsec[h].cwiseAbs().maxCoeff());
        }
    }
    return m;
}

// The rotation (CRF axes, arcsec) head h's current mounting is turned by from the given one.
Eigen::Vector3d turned_from(const MountingsFile& m, const CurrentMountings& q, std::uint8_t h) noexcept {
    return rotation_arcsec(conjugate(m.mountings.head[h].q_chu_crf) * q[h], {1.0, 0.0, 0.0, 0.0});
}

using Information = std::array<Eigen::Matrix3d, kMaxHeads>;

// The counts of a pass, into the report (the last one's stay).
void count_into(AlignReport& r, const AlignSums& sums, const PassCounts& c) {
    r.rows = c.rows;
    r.rows_in_period = c.rows_in_period;
    r.rows_left_out = c.left_out;
    r.epochs = c.epochs;
    r.joint_epochs = sums.joint_epochs();
    r.single_epochs = sums.single_epochs();
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        r.head[h].epochs = sums.head_epochs(h);
    }
}

// One pass's estimate: the noise (into r), the weights w it gives under the
// current mountings q, and the δ under the datum on the total rotation from m.
Alignment estimate(const AlignSums& sums, const MountingsFile& m, const CurrentMountings& q, AlignReport& r,
                   Information& w) {
    std::array<Eigen::Vector3d, kMaxHeads> b{};
    std::array<Eigen::Vector3d, kMaxHeads> turned{};
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        b[h] = boresight_crf(q[h]);
        turned[h] = has_head(r.heads, h) ? turned_from(m, q, h) : Eigen::Vector3d::Zero();
    }
    try {
        r.noise = estimate_noise(sums, r.heads, b);
        for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
            w[h] = information_crf(q[h], r.noise.head[h].sigma_cross_arcsec, r.noise.head[h].sigma_about_arcsec);
        }
        return solve_alignment(sums, r.heads, w, turned);
    } catch (const std::invalid_argument& e) {
        throw AlignRefused(e.what());
    }
}

// M2 (the final mountings q with the estimated noise), each head's account
// and the weighted mean of the rotations from m.
void finish_report(AlignReport& r, const MountingsFile& m, const CurrentMountings& q, const Alignment& a,
                   const Information& w) {
    Eigen::Matrix3d w_sum = Eigen::Matrix3d::Zero();
    Eigen::Vector3d wr = Eigen::Vector3d::Zero();
    r.aligned = m;
    r.aligned.sigmas = true;
    r.aligned.line = {};
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        if (!has_head(r.heads, h)) {
            continue;
        }
        const combine::HeadMounting& given = m.mountings.head[h];
        combine::HeadMounting& out = r.aligned.mountings.head[h];
        HeadAlignment& ha = r.head[h];
        out.q_chu_crf = q[h];
        out.sigma_cross_arcsec = r.noise.head[h].sigma_cross_arcsec;
        out.sigma_about_arcsec = r.noise.head[h].sigma_about_arcsec;
        ha.noise = r.noise.head[h];
        ha.given_sigma_cross_arcsec = m.sigmas ? given.sigma_cross_arcsec : std::nan("");
        ha.given_sigma_about_arcsec = m.sigmas ? given.sigma_about_arcsec : std::nan("");
        ha.rotation_arcsec = turned_from(m, q, h);
        ha.rotation_sd_arcsec = a.covariance[h].diagonal().cwiseMax(0.0).cwiseSqrt();
        w_sum += w[h];
        wr += w[h] * ha.rotation_arcsec;
    }
    r.weighted_mean_arcsec = w_sum.inverse() * wr;
}

AlignReport start_report(const std::string& file, const MountingsFile& m, const AlignOptions& opt) {
    try {
        refuse_bad_time_range(opt.from, opt.to);
    } catch (const std::invalid_argument& e) {
        throw AlignRefused(e.what());
    }
    if (!noise_window_valid(opt.noise_window_s)) {
        throw AlignRefused("--noise-window " + number_text(opt.noise_window_s) +
                           ": expected 0 (one mean over the period) or " + "a window in [" +
                           number_text(kMinNoiseWindowS) + ", " + number_text(kMaxNoiseWindowS) + "] s");
    }
    AlignReport r;
    r.in = file;
    r.from = opt.from;
    r.to = opt.to;
    r.noise_window_s = opt.noise_window_s;
    r.heads = combine::mounted_heads(m.mountings);
    if (head_count(r.heads) < 2U) {
        throw AlignRefused("the mountings have " + std::to_string(head_count(r.heads)) +
                           " head: align needs two or more (their relative attitudes are its data)");
    }
    return r;
}

// x with four significant digits, for messages.
std::string digits4(double x) {
    char buf[32];
    text::c_snprintf(buf, sizeof buf, "%.4g", x);
    return buf;
}

// The gate left out the same rows in two passes: within one row or a
// thousandth of them (a row at the gate's edge may go either way as the
// noise settles in its last digits).
bool same_rows_gated(std::size_t now, std::size_t before) noexcept {
    const std::size_t diff = now > before ? now - before : before - now;
    return diff <= std::max<std::size_t>(1U, std::max(now, before) / 1000U);
}

// The gate of the next pass: the current mountings with the noise just
// estimated; none when the combination cannot use them (refused at the end).
std::unique_ptr<StageGates> next_gate(const AlignReport& r, const CurrentMountings& q, const GateOptions& g) {
    combine::Mountings m{};
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        if (has_head(r.heads, h)) {
            m.head[h] = {true, q[h], r.noise.head[h].sigma_cross_arcsec, r.noise.head[h].sigma_about_arcsec};
        }
    }
    auto gate = std::make_unique<StageGates>(m, g);
    return gate->valid() ? std::move(gate) : nullptr;
}

// Noise the data do not determine (a formal 1σ above kMaxNoiseRelativeSd of
// the σ) or outside the mountings file's range: refused after each pass
// (before it builds the next pass's gate), naming the head and the numbers.
void refuse_undetermined_noise(const AlignReport& r, const std::string& file) {
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        if (!has_head(r.heads, h)) {
            continue;
        }
        const HeadNoise& n = r.noise.head[h];
        const std::string head = std::string("CHU ") + kHeadLetters[h];
        if (n.sd_cross_arcsec > kMaxNoiseRelativeSd * n.sigma_cross_arcsec ||
            n.sd_about_arcsec > kMaxNoiseRelativeSd * n.sigma_about_arcsec || !std::isfinite(n.sd_cross_arcsec) ||
            !std::isfinite(n.sd_about_arcsec)) {
            throw AlignRefused(head + ": its noise is not determined by the data (sigma_cross " +
                               digits4(n.sigma_cross_arcsec) + " +- " + digits4(n.sd_cross_arcsec) + ", sigma_about " +
                               digits4(n.sigma_about_arcsec) + " +- " + digits4(n.sd_about_arcsec) + " arcsec from " +
                               std::to_string(r.head[h].epochs) + " epochs with another head of " +
                               text::input_name(file) + "): align needs each within " +
                               number_text(100.0 * kMaxNoiseRelativeSd) + " % (more epochs of that head)");
        }
        for (const double sigma : {n.sigma_cross_arcsec, n.sigma_about_arcsec}) {
            if (!(sigma >= combine::kMinSigmaArcsec && sigma <= combine::kMaxSigmaArcsec)) {
                throw AlignRefused(head + ": its noise estimate " + digits4(sigma) +
                                   " arcsec is outside the [0.001, 1000] arcsec a mountings file (and the "
                                   "combination) takes: " +
                                   (sigma < combine::kMinSigmaArcsec
                                        ? "the heads' relative attitudes carry no noise (data simulated without it?)"
                                        : "the heads do not see the same attitude") +
                                   "; nothing written");
            }
        }
    }
}

// Mountings the combination could not use (a target's tables): refused.
void refuse_unusable_result(const AlignReport& r, const std::string& file, const AlignOptions& opt) {
    try {
        refuse_unusable_mountings(r.aligned, text::input_name(file) + " (the mountings align estimated)", opt.gate);
    } catch (const std::runtime_error& e) {
        throw AlignRefused(e.what());
    }
}

}  // namespace

AlignReport align_rows(const CorrectedRowSource& rows, const std::string& file, const MountingsFile& m,
                       const AlignOptions& opt) {
    AlignReport r = start_report(file, m, opt);
    CurrentMountings q{};
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        q[h] = m.mountings.head[h].present ? m.mountings.head[h].q_chu_crf : Quaternion<double>{1.0, 0.0, 0.0, 0.0};
    }
    Alignment a;
    Information w{};
    r.last_update_arcsec = std::numeric_limits<double>::infinity();
    CorrectedRowSource in_order = rows;
    std::unique_ptr<StageGates> gate;  // none in the first pass: no noise to gate with
    std::size_t gated = 0;             // rows this pass left out as inconsistent
    std::size_t before = 0;            // and the pass before
    bool gated_pass = false;           // this pass had the gate (or could not have it)
    for (bool settled = false; !settled;) {
        if (r.passes == kMaxAlignPasses) {
            throw AlignRefused("the mountings did not converge in " + std::to_string(kMaxAlignPasses) +
                               " passes (the last turned a head by " + number_text(r.last_update_arcsec) +
                               " arcsec, and its gate left out " + std::to_string(gated) +
                               " rows as inconsistent where the pass before left out " + std::to_string(before) +
                               "): are the given mountings within a degree of the heads'?");
        }
        AlignSums sums(opt.noise_window_s);
        PassCounts c;
        try {
            run_pass(in_order, file, m, q, gate.get(), opt, sums, c);
        } catch (const OutOfOrder&) {  // the first pass only: the sorted rows are in order
            in_order = sorted_rows(rows);
            r.rows_sorted = true;
            continue;
        }
        ++r.passes;
        refuse_thin_data(file, sums, c, r.heads, opt);
        count_into(r, sums, c);
        a = estimate(sums, m, q, r, w);
        refuse_undetermined_noise(r, file);
        for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
            if (has_head(r.heads, h)) {
                q[h] = canonical(renormalized(q[h] * rotation_quaternion(a.delta_arcsec[h])));
            }
        }
        r.last_update_arcsec = largest(a);
        before = gated;
        gated = c.left_out[static_cast<std::size_t>(LeftOut::kInconsistent)];
        // Not settled before a pass with the gate (or without one, when the
        // combination cannot use the noise: refused below).
        settled = gated_pass && r.last_update_arcsec < kAlignToleranceArcsec && same_rows_gated(gated, before);
        // The gate once the mountings are near (a head given half a degree
        // off is still tens of arcsec off after the first pass), and from
        // then on: what it leaves out may move the mountings again.
        gated_pass = gated_pass || r.last_update_arcsec < kGateAfterUpdateArcsec;
        gate = gated_pass ? next_gate(r, q, opt.gate) : nullptr;
    }
    finish_report(r, m, q, a, w);
    refuse_unusable_result(r, file, opt);
    return r;
}

CorrectedRowSource rows_of_file(const std::string& path) {
    return [path](const std::function<void(const CorrectedRow&)>& fn) { for_each_corrected_row(path, fn, "align"); };
}

AlignReport align_file(const AlignOptions& opt) {
    OutputSet outputs({{"--out", opt.out}}, {{"--in", opt.in}, {"--mountings", opt.mountings}});
    AlignReport r = align_file(opt, outputs);
    outputs.commit();
    return r;
}

AlignReport align_file(const AlignOptions& opt, OutputSet& outputs) {
    refuse_output_over_input({{"--in", opt.in}, {"--mountings", opt.mountings}}, {{"--out", opt.out}});
    const MountingsFile m = read_mountings_file(opt.mountings);
    AlignReport r = align_rows(rows_of_file(opt.in), opt.in, m, opt);
    r.mountings = opt.mountings;
    r.out = opt.out;
    outputs["--out"].write(format_mountings(r.aligned));
    return r;
}

namespace {

std::string fixed(double x, int decimals) {
    char buf[64];
    text::c_snprintf(buf, sizeof buf, "%.*f", decimals, x);
    return buf;
}

}  // namespace

std::string describe(const AlignReport& r) {
    std::ostringstream s;
    s << "align: " << text::input_name(r.in) << ", " << period_text(r.from, r.to) << ": " << r.rows_in_period
      << " rows, " << r.epochs << " epochs of the mountings' heads, " << r.joint_epochs
      << " with two or more usable heads (used), " << r.single_epochs << " with one\n";
    s << "rows left out: " << reasons_text(r.rows_left_out) << "\n";
    if (r.rows_sorted) {
        s << "rows out of time order: sorted in memory (a file in time order streams)\n";
    }
    s << "noise: REML from the heads' relative attitudes about their mean over " << number_text(r.noise_window_s)
      << " s windows (" << fixed(r.noise.dof, 0) << " degrees of freedom), " << noise_model_text(r.noise.model) << ", "
      << r.noise.iterations << " iterations" << (r.noise.converged ? "" : " (not converged)") << "\n";
    s << "mountings: " << r.passes << " passes, last update " << number_text(r.last_update_arcsec)
      << " arcsec; CRF kept: information-weighted mean rotation (x, y, z) " << fixed(r.weighted_mean_arcsec.x(), 6)
      << " " << fixed(r.weighted_mean_arcsec.y(), 6) << " " << fixed(r.weighted_mean_arcsec.z(), 6) << " arcsec\n";
    s << "head  epochs  rotation from the given mounting, CRF x, y, z (arcsec +- 1 sigma)    "
         "sigma_cross (arcsec)  sigma_about (arcsec)\n";
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        if (!has_head(r.heads, h)) {
            continue;
        }
        const HeadAlignment& a = r.head[h];
        char line[400];
        text::c_snprintf(line, sizeof line,
                         "%c     %7zu  %+10.3f +- %.3f  %+10.3f +- %.3f  %+10.3f +- %.3f    %7.3f +- %.3f     %7.3f +- "
                         "%.3f\n",
                         kHeadLetters[h], a.epochs, a.rotation_arcsec.x(), a.rotation_sd_arcsec.x(),
                         a.rotation_arcsec.y(), a.rotation_sd_arcsec.y(), a.rotation_arcsec.z(),
                         a.rotation_sd_arcsec.z(), a.noise.sigma_cross_arcsec, a.noise.sd_cross_arcsec,
                         a.noise.sigma_about_arcsec, a.noise.sd_about_arcsec);
        s << line;
    }
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        const HeadAlignment& a = r.head[h];
        if (has_head(r.heads, h) && !std::isnan(a.given_sigma_cross_arcsec)) {
            s << "CHU " << kHeadLetters[h] << ": the given mountings said sigma_cross "
              << number_text(a.given_sigma_cross_arcsec) << ", sigma_about " << number_text(a.given_sigma_about_arcsec)
              << " (not used)\n";
        }
    }
    return s.str();
}

}  // namespace ascorr::host
