#include "ascorr_host/analysis/combine.hpp"

#include <algorithm>
#include <cstdio>
#include <ostream>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "ascorr/combine/combined_status.hpp"
#include "ascorr/combine/combiner.hpp"
#include "ascorr/combine/subset_tables.hpp"
#include "ascorr/combine/usable.hpp"
#include "ascorr/pipeline/common_rotation_weights.hpp"
#include "ascorr/pipeline/epoch_key.hpp"
#include "ascorr_host/analysis/align.hpp"
#include "ascorr_host/analysis/combined_stats.hpp"
#include "ascorr_host/analysis/iba.hpp"
#include "ascorr_host/formats/atomic_file.hpp"
#include "ascorr_host/formats/combined_csv.hpp"
#include "ascorr_host/formats/csv.hpp"
#include "ascorr_host/formats/diagnostics.hpp"
#include "ascorr_host/formats/solutions_csv.hpp"
#include "ascorr_text/c_format.hpp"
#include "ascorr_text/input_error.hpp"
#include "ascorr_text/input_name.hpp"
#include "combine_parts.hpp"

namespace ascorr::host {

namespace {

namespace cs = combine::combined_status;
using detail::Kept;

bool flagged(const CorrectedRow& r) noexcept {
    return r.flags != 0;
}

// NaN: not confident.
bool confident(const CorrectedRow& r) noexcept {
    return r.confidence <= combine::kMaxCleanConfidenceArcsec;
}

}  // namespace

combine::RowFacts row_facts(const CorrectedRow& r) noexcept {
    return {pipeline::has_epoch_key(r.t),
            r.head,
            r.corrected ? r.status : StatusBits{0},
            flagged(r),
            confident(r),
            norm_within(r.q_chu_icrf, ScalarTraits<double>::unit_norm_tolerance)};
}

bool clean_for_combination(const CorrectedRow& r) noexcept {
    return !flagged(r) && confident(r);
}

std::string describe(const CombineSummary& s) {
    std::ostringstream o;
    o << s.epochs << " epochs from " << s.rows << " rows";
    for (std::size_t b = 0; b < s.status_bit.size(); ++b) {
        o << (b == 0 ? ": " : ", ") << s.status_bit[b] << ' ' << cs::kBitNames[b] << " (" << (1U << b) << ')';
    }
    o << "; rows averaged in " << s.rows_left_out[0];
    bool any = false;
    for (std::size_t k = 1; k < kLeftOutKinds; ++k) {
        if (s.rows_left_out[k] != 0) {
            o << (any ? ", " : "; left out: ") << s.rows_left_out[k] << ' ' << left_out_name(static_cast<LeftOut>(k));
            any = true;
        }
    }
    if (s.out_of_order) {
        o << "; rows out of time order: sorted";
    }
    // Most heads first (AB, AC, BC, then A, B, C).
    std::vector<HeadMask> sets;
    for (std::size_t set = 1; set < s.steps.size(); ++set) {
        if (s.steps[set].days != 0) {
            sets.push_back(static_cast<HeadMask>(set));
        }
    }
    std::stable_sort(sets.begin(), sets.end(), [](HeadMask a, HeadMask b) { return head_count(a) > head_count(b); });
    if (!sets.empty()) {
        o << "\nsteps from " << head_letters(s.full)
          << " (RMS over days of the daily mean of q_S - q_full, CRF x y z, arcsec):";
    }
    for (const HeadMask set : sets) {
        const HeadSetStep& st = s.steps[set];
        char buf[128];
        text::c_snprintf(buf, sizeof buf, " %s %.3f %.3f %.3f (%zu d);", head_letters(set).c_str(),
                         st.rms_daily_mean[0], st.rms_daily_mean[1], st.rms_daily_mean[2], st.days);
        o << buf;
    }
    return o.str();
}

combine::CombinerConfig gate_config(const GateOptions& g, const combine::CombinerConfig& base) noexcept {
    return {g.sigmas.value_or(base.gate_sigmas), g.floor_arcsec.value_or(base.gate_floor_arcsec)};
}

combine::CombinerConfig gate_config(const GateOptions& g, bool both_stages) noexcept {
    return gate_config(g, combine::default_gate(both_stages));
}

namespace {

std::string sigmas_text(const combine::HeadMounting& h) {
    return number_text(h.sigma_cross_arcsec) + " across, " + number_text(h.sigma_about_arcsec) + " about";
}

// Why the tables of a target refuse the gate of a head in a head set (the
// mountings passed check_mountings): its noise against the other heads'.
std::string gate_refusal(const MountingsFile& m, const combine::Combiner<double>& c,
                         const combine::CombinerConfig& cfg) {
    const std::uint8_t h = c.problem_head();
    std::string others;
    for (std::uint8_t o = 0; o < kMaxHeads; ++o) {
        if (o != h && has_head(c.problem_subset(), o)) {
            others +=
                (others.empty() ? "" : "; ") + std::string(1, head_name(o)) + " " + sigmas_text(m.mountings.head[o]);
        }
    }
    // subset_gate also fails on a singular matrix, which check_mountings'
    // conditioning test has excluded: what is left is the format's range.
    return std::string("CHU ") + head_name(h) + ": its consistency gate in head set " +
           head_letters(c.problem_subset()) +
           " is beyond the fixed-point format a target builds it in (a factor above 2^28 per radian), so a target "
           "refuses these mountings: its noise (" +
           sigmas_text(m.mountings.head[h]) + " arcsec) is too small against the other heads' (" + others +
           ") for a gate of " + number_text(cfg.gate_sigmas) + " sigmas and a floor of " +
           number_text(cfg.gate_floor_arcsec) +
           " arcsec; a target needs the heads' noise within a factor of about 100 of each other's (its gate "
           "weighs one head's residual by the others' covariance)";
}

}  // namespace

void refuse_unusable_mountings(const MountingsFile& m, const std::string& path, const GateOptions& gate) {
    refuse_unusable_mountings(m, path, {gate_config(gate, true), gate_config(gate, false)});
}

void refuse_unusable_mountings(const MountingsFile& m, const std::string& path,
                               const std::vector<combine::CombinerConfig>& gates) {
    const std::string name = text::input_name(path);
    if (!m.sigmas) {
        throw std::runtime_error(name +
                                 ": the mountings have no sigma_cross,sigma_about: give each head's noise (arcsec "
                                 "across and about its boresight), or correct first and `ascorr combine` the "
                                 "corrected file, which estimates it from the data");
    }
    std::uint8_t head = 0;
    const combine::MountingsProblem p = combine::check_mountings(m.mountings, &head);
    if (p != combine::MountingsProblem::kNone) {
        const bool one_head = head < kMaxHeads && m.line[head] != 0;
        if (one_head) {
            throw text::InputError(path, m.line[head], 1,
                                   std::string("CHU ") + head_name(head) + ": " + combine::problem_text(p));
        }
        throw std::runtime_error(name + ": " + combine::problem_text(p));
    }
    for (const combine::CombinerConfig& cfg : gates) {
        if (!combine::gate_config_valid(cfg)) {
            throw std::runtime_error(std::string("the consistency gate: ") +
                                     combine::problem_text(combine::MountingsProblem::kGateConfig) + ", given " +
                                     number_text(cfg.gate_sigmas) + " sigmas and a floor of " +
                                     number_text(cfg.gate_floor_arcsec) + " arcsec");
        }
        const combine::Combiner<double> c(m.mountings, cfg);
        if (c.problem() == combine::MountingsProblem::kNone) {
            continue;
        }
        const std::uint8_t h = c.problem_head();
        const std::string why = c.problem() == combine::MountingsProblem::kGateOutOfRange && h < kMaxHeads
                                    ? gate_refusal(m, c, cfg)
                                    : std::string(combine::problem_text(c.problem()));
        if (h < kMaxHeads && m.line[h] != 0) {
            throw text::InputError(path, m.line[h], 1, why);
        }
        throw std::runtime_error(name + ": " + why);
    }
}

SubsetCovariances subset_covariances(const combine::Mountings& m, HeadMask mounted) noexcept {
    SubsetCovariances out{};
    for (unsigned s = 1; s < combine::kSubsetCount; ++s) {
        combine::Matrix3 cov{};
        if ((s & ~mounted) == 0U && combine::subset_covariance(m, static_cast<HeadMask>(s), &cov)) {
            out[s] = {cov.m[0][1], cov.m[0][2], cov.m[1][2]};
        }
    }
    return out;
}

struct CombineStage::Impl {
    Impl(const MountingsFile& mountings, const GateOptions& gate, CombinedColumns columns, AtomicFile* out_file,
         std::vector<AttitudeRow>* out_rows, std::string file_name, std::ostream& log, Mode mode_)
        : m(mountings),
          gates(mountings.mountings, gate),
          cols(columns),
          out(out_file),
          rows_out(out_rows),
          file(std::move(file_name)),
          diag(log),
          mode(out == nullptr || out->streamed() ? Mode::kKeep : mode_) {
        if (out != nullptr) {
            buf += combined_header(cols);
            buf += '\n';
        }
        if (cols.covariance) {
            covariance = subset_covariances(mountings.mountings, mounted);
        }
    }

    void add(const CorrectedRow& r) {
        ++sum.rows;
        const combine::RowFacts f = row_facts(r);
        const LeftOut why = combine::left_out_alone(f, mounted);
        if (why == LeftOut::kNoEpoch) {
            ++sum.rows_left_out[static_cast<std::size_t>(LeftOut::kNoEpoch)];
            reports.no_epoch(r.line, r.t);
            return;
        }
        Kept k{r.t,    r.q_chu_icrf, static_cast<std::uint32_t>(r.line),
               r.head, why,          static_cast<std::uint8_t>(f.status & combine::kStagesApplied),
               f.unit};
        const std::int64_t key = epoch_key(r.t);
        if (mode == Mode::kKeep) {
            kept.push_back({key, k});
            return;
        }
        if (epochs.ends_before(key) && key < epochs.key()) {
            throw RowsOutOfOrder{r.line};
        }
        take(key, k);
    }

    void finish() {
        if (mode == Mode::kKeep) {
            std::stable_sort(kept.begin(), kept.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
            for (const auto& [key, k] : kept) {
                take(key, k);
            }
            kept.clear();
        }
        if (epochs.is_open()) {
            emit(epoch);
            epochs.close();
        }
        epoch.clear();
        flush();
        diag.summarize();
        steps.finish(sum);
    }

    // Step 2 of the core's selection (combine/usable.hpp) over the epoch's
    // rows, sorted by head and line: two rows of one head (both left out,
    // named with the first's line), a usable row without a stage another
    // usable row has, a quaternion not unit. Returns the epoch's stages.
    StatusBits select(std::vector<Kept>& rows) {
        facts.clear();
        whys.clear();
        for (const Kept& k : rows) {
            // Step 1's answer is k.why: its facts here are those of a row it kept.
            facts.push_back({true, k.head, k.stages, false, true, k.unit});
            whys.push_back(k.why);
        }
        const StatusBits stages =
            combine::select_epoch(facts.data(), whys.data(), rows.size(), combine::Repeated::kLeaveAllOut);
        reports.epoch(rows, whys, stages);
        for (std::size_t i = 0; i < rows.size(); ++i) {
            rows[i].why = whys[i];
        }
        return stages;
    }

    // A row of `key`, in time order: the open epoch is emitted first when the row is of another.
    void take(std::int64_t key, const Kept& k) {
        if (epochs.ends_before(key)) {
            emit(epoch);
            epoch.clear();
            epochs.close();
        }
        epochs.add(key);
        epoch.push_back(k);
    }

    void emit(std::vector<Kept>& rows) {
        // Heads in index order (then lines): the combiner's reference and sums,
        // hence the bits, are the same in any row order.
        std::sort(rows.begin(), rows.end(), [](const Kept& a, const Kept& b) {
            return a.head < b.head || (a.head == b.head && a.line < b.line);
        });
        // The epoch's gate by its stages (GateOptions): a raw file's rows have none.
        const combine::Combiner<double>& combiner = gates.of(select(rows));
        combine::HeadAttitude<double> heads[kMaxHeads];
        std::size_t used_row[kMaxHeads] = {};
        std::uint8_t n = 0;
        for (std::size_t i = 0; i < rows.size(); ++i) {
            if (rows[i].why == LeftOut::kUsed) {  // heads unique by now: at most kMaxHeads
                used_row[n] = i;
                heads[n++] = {rows[i].q, rows[i].head, true};
            }
        }
        const combine::CombinedAttitude<double> c = combiner.combine(heads, n);
        for (std::uint8_t i = 0; i < n; ++i) {
            const HeadMask bit = head_bit(heads[i].head);
            if ((c.used & bit) == 0U) {  // the selection took head, mounting and norm: the gate, unless it differs
                rows[used_row[i]].why = (c.inconsistent & bit) != 0U ? LeftOut::kInconsistent : LeftOut::kNotUnit;
            }
        }
        bool left_out = false;
        for (const Kept& k : rows) {
            left_out = left_out || k.why != LeftOut::kUsed;
            ++sum.rows_left_out[static_cast<std::size_t>(k.why)];
            reports.row(k);
        }
        AttitudeRow row;
        row.t = rows.front().t;  // the epoch's earliest t, as written: the same in any row order
        for (const Kept& k : rows) {
            row.t = std::min(row.t, k.t);
        }
        row.status = static_cast<unsigned>(c.status | (left_out ? cs::kHeadLeftOut : 0U));
        row.has_q = (c.status & cs::kNoHead) == 0U;
        if (row.has_q) {
            row.q_crf_icrf = c.q_crf_icrf;
            row.heads = c.used;
            const double* s = combiner.sigma_arcsec(c.subset);
            row.sigma_arcsec = {s[0], s[1], s[2]};
            row.has_cov = cols.covariance;
            row.cov_arcsec2 = covariance[c.subset];
        }
        if (c.used == mounted && head_count(mounted) >= 2) {
            steps.add(combiner, heads, n, c.q_crf_icrf, row.t);
        }
        for (std::size_t b = 0; b < sum.status_bit.size(); ++b) {
            sum.status_bit[b] += (row.status >> b) & 1U;
        }
        ++sum.epochs;
        append_combined_row(buf, row, cols);
        if (buf.size() > (1U << 20)) {
            flush();
        }
    }

    // The rows written so far into the file, or read back into rows_out.
    void flush() {
        if (out != nullptr) {
            out->write(buf);
        } else {
            read_combined_rows(buf, *rows_out, cols);
        }
        buf.clear();
    }

    const MountingsFile& m;
    StageGates gates;  // the combiner of each kind of epoch (the same tables but the gate's)
    CombinedColumns cols;
    AtomicFile* out;                     // the file, or
    std::vector<AttitudeRow>* rows_out;  // the rows
    std::string file;
    Diagnostics diag;
    Mode mode;
    std::string buf;
    std::vector<Kept> epoch;
    std::vector<combine::RowFacts> facts;  // select()'s, kept between epochs
    std::vector<LeftOut> whys;
    pipeline::ConsecutiveEpochs epochs;  // the open epoch: consecutive rows with one key
    std::vector<std::pair<std::int64_t, Kept>> kept;
    CombineSummary sum;
    HeadMask mounted = combine::mounted_heads(m.mountings);
    SubsetCovariances covariance{};  // with cols.covariance
    detail::LeftOutReports reports{diag, file};
    detail::HeadSetSteps steps{mounted};
};

CombineStage::CombineStage(const MountingsFile& m, const GateOptions& gate, AtomicFile& out, std::string file,
                           std::ostream& log, Mode mode, CombinedColumns columns)
    : impl_(std::make_unique<Impl>(m, gate, columns, &out, nullptr, std::move(file), log, mode)) {}

CombineStage::CombineStage(const MountingsFile& m, const GateOptions& gate, std::vector<AttitudeRow>& rows,
                           std::string file, std::ostream& log, CombinedColumns columns)
    : impl_(std::make_unique<Impl>(m, gate, columns, nullptr, &rows, std::move(file), log, Mode::kKeep)) {}

CombineStage::~CombineStage() = default;

void CombineStage::add(const CorrectedRow& row) {
    impl_->add(row);
}

void CombineStage::finish() {
    impl_->finish();
}

const CombineSummary& CombineStage::summary() const noexcept {
    return impl_->sum;
}

namespace {

// The status field of a corrected row, an integer of the status bits.
StatusBits status_of(const SolutionsReader& reader, const SolutionRecord& rec, int col) {
    const std::string_view f = reader.fields()[static_cast<std::size_t>(col)];
    const auto v = parse_integer(f);
    if (!v || *v < 0 || *v > 0xFFFF) {
        std::size_t column = 1;
        for (int i = 0; i < col; ++i) {
            column += reader.fields()[static_cast<std::size_t>(i)].size() + 1;
        }
        throw text::InputError(reader.file_name(), rec.line, column,
                               "column 'status': " + why_not_an_integer(f, 0, 0xFFFF));
    }
    return static_cast<StatusBits>(*v);
}

CombineSummary combine_pass(const CombineOptions& opt, const MountingsFile& m, OutputSet& outputs, std::ostream& log,
                            CombineStage::Mode mode) {
    CombineStage stage(m, opt.gate, outputs["--out"], opt.in, log, mode, opt.columns);
    for_each_corrected_row(
        opt.in, [&stage](const CorrectedRow& r) { stage.add(r); }, "combine");
    stage.finish();
    return stage.summary();
}

// A run over rows that streams them (CombineStage::Mode::kStream) and, at
// the first row out of time order, runs again keeping them (kKeep) into the
// outputs opened anew by reopen() (the first run's temporary files removed);
// sorted tells which. The first run's messages wait: a second run says them
// again, so they are said once either way.
template <typename Result>
Result stream_then_keep(const std::function<Result(CombineStage::Mode, std::ostream&)>& pass,
                        const std::function<void()>& reopen, std::ostream& log, bool& sorted) {
    std::ostringstream first;
    try {
        Result r = pass(CombineStage::Mode::kStream, first);
        log << first.str();
        sorted = false;
        return r;
    } catch (const RowsOutOfOrder&) {
    } catch (...) {
        log << first.str();
        throw;
    }
    reopen();
    sorted = true;
    return pass(CombineStage::Mode::kKeep, log);
}

}  // namespace

void for_each_corrected_row(const std::string& path, const std::function<void(const CorrectedRow&)>& fn,
                            const std::string& label) {
    int status_col = -1;
    for_each_solution_row(
        path, [&status_col](const SolutionsReader& h) { status_col = h.header().index(kStatusColumn); },
        [&](const SolutionsReader& reader, const SolutionRecord& rec) {
            fn(CorrectedRow::of(
                rec, status_col >= 0 ? std::optional<StatusBits>(status_of(reader, rec, status_col)) : std::nullopt));
        },
        label);
}

std::vector<NamedPath> correct_and_combine_inputs(const CorrectOptions& opt, const std::string& mountings) {
    std::vector<NamedPath> inputs = correct_inputs(opt);
    inputs.push_back({"--mountings", mountings});
    return inputs;
}

std::vector<NamedPath> correct_and_combine_outputs(const CorrectOptions& opt, const std::string& combined) {
    std::vector<NamedPath> outputs = correct_outputs(opt);
    outputs.push_back({"--combined", combined});
    return outputs;
}

CorrectAndCombine correct_and_combine(const CorrectOptions& opt, const std::string& mountings,
                                      const std::string& combined, std::ostream& log, const GateOptions& gate,
                                      CombinedColumns columns) {
    OutputSet outputs(correct_and_combine_outputs(opt, combined), correct_and_combine_inputs(opt, mountings));
    CorrectAndCombine r = correct_and_combine(opt, mountings, combined, outputs, log, gate, columns);
    outputs.commit();
    return r;
}

CorrectAndCombine correct_and_combine(const CorrectOptions& opt, const std::string& mountings,
                                      const std::string& combined, OutputSet& outputs, std::ostream& log,
                                      const GateOptions& gate, CombinedColumns columns) {
    refuse_output_over_input(correct_and_combine_inputs(opt, mountings), correct_and_combine_outputs(opt, combined));
    const MountingsFile m = read_mountings_file(mountings);
    refuse_unusable_mountings(m, mountings, gate);
    // Self-calibration protects the combined attitude of these mountings (the
    // rule `combined`, docs/contract.md, "The common rotation").
    CorrectOptions run = opt;
    if (opt.self_calibrate) {
        run.common_rotation = pipeline::common_rotation_weights(m.mountings);  // sigmas: refused above without
    }
    const auto pass = [&](CombineStage::Mode mode, std::ostream& to) {
        CombineStage stage(m, gate, outputs["--combined"], opt.in, to, mode, columns);
        CorrectAndCombine r;
        r.corrected = correct_file(run, outputs, to, &stage);
        r.combined = stage.summary();
        return r;
    };
    // A corrected file that goes to a stream cannot be written twice: the
    // rows are kept from the start instead of a second run.
    if (outputs["--out"].streamed()) {
        return pass(CombineStage::Mode::kKeep, log);
    }
    bool sorted = false;
    CorrectAndCombine r = stream_then_keep<CorrectAndCombine>(
        pass,
        [&] {
            outputs = OutputSet(correct_and_combine_outputs(opt, combined), correct_and_combine_inputs(opt, mountings));
        },
        log, sorted);
    r.combined.out_of_order = sorted;
    return r;
}

namespace {

// m with each head's noise estimated from the rows of `in` (align_rows), reported on log.
MountingsFile with_estimated_noise(const MountingsFile& m, const std::string& in, const std::string& path,
                                   const GateOptions& gate, std::ostream& log) {
    AlignOptions ao;
    ao.in = in;
    ao.mountings = path;
    ao.gate = gate;
    const AlignReport r = align_rows(rows_of_file(in), in, m, ao);
    MountingsFile out = m;
    out.sigmas = true;
    std::ostringstream o;
    o << "ascorr combine: " << text::input_name(path)
      << " has no sigmas: each head's noise estimated from the data (ascorr align's REML estimate, "
      << noise_model_text(r.noise.model) << "; arcsec, +- 1 sigma):";
    for (std::uint8_t h = 0; h < kMaxHeads; ++h) {
        if (!m.mountings.head[h].present) {
            continue;
        }
        const HeadNoise& n = r.head[h].noise;
        out.mountings.head[h].sigma_cross_arcsec = n.sigma_cross_arcsec;
        out.mountings.head[h].sigma_about_arcsec = n.sigma_about_arcsec;
        char buf[160];
        text::c_snprintf(buf, sizeof buf, " %c across %.3f +- %.3f, about %.3f +- %.3f;", head_name(h),
                         n.sigma_cross_arcsec, n.sd_cross_arcsec, n.sigma_about_arcsec, n.sd_about_arcsec);
        o << buf;
    }
    log << o.str() << '\n';
    return out;
}

}  // namespace

std::vector<NamedPath> combine_inputs(const CombineOptions& opt) {
    return {{"--in", opt.in}, {"--mountings", opt.mountings}};
}

std::vector<NamedPath> combine_outputs(const CombineOptions& opt) {
    return {{"--out", opt.out}};
}

CombineSummary combine_file(const CombineOptions& opt, std::ostream& log) {
    OutputSet outputs(combine_outputs(opt), combine_inputs(opt));
    const CombineSummary s = combine_file(opt, outputs, log);
    outputs.commit();
    return s;
}

CombineSummary combine_file(const CombineOptions& opt, OutputSet& outputs, std::ostream& log) {
    refuse_output_over_input(combine_inputs(opt), combine_outputs(opt));
    MountingsFile m = read_mountings_file(opt.mountings);
    if (!m.sigmas) {
        m = with_estimated_noise(m, opt.in, opt.mountings, opt.gate, log);
    }
    refuse_unusable_mountings(m, opt.mountings, opt.gate);
    bool sorted = false;
    CombineSummary s = stream_then_keep<CombineSummary>(
        [&](CombineStage::Mode mode, std::ostream& to) { return combine_pass(opt, m, outputs, to, mode); },
        [&] { outputs = OutputSet(combine_outputs(opt), combine_inputs(opt)); }, log, sorted);
    s.out_of_order = sorted;
    return s;
}

}  // namespace ascorr::host
