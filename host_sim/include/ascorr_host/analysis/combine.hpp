// ascorr_host/analysis/combine.hpp: the combined attitude of a file (`ascorr combine`,
// `ascorr correct ... --combined`; docs/contract.md, "Combined attitude").
//
// Rows become epochs (t to the millisecond, any row order) and every epoch
// one row of the combined file, in time order, by the core's combiner
// (ascorr/combine/combiner.hpp) in double. Which rows it averages:
//  - a row is usable when it is clean (flags 0, confidence a number <= 5,
//    as docs/contract.md's Statistics) and, in a corrected file, its status
//    has none of 16 (rejected), 4, 8 (a stage skipped for a missing input),
//    128, 256 (the thermal stage skipped for its model): in a corrected file
//    these bits appear only for a stage the run asked for, so "a stage the
//    run asked for and did not apply" is read from the row itself;
//  - a mix of corrected and uncorrected rows is decided per epoch: the
//    epoch's stages are those applied (status 1, 2) to any of its usable
//    rows, and a row without one of them is left out ("stage missing"). A
//    raw solutions file has no status: its attitudes are taken as they are;
//  - two rows of one head in one epoch: both left out (which is right
//    cannot be told), the epoch gets bit 4 and the message names both lines;
//  - a head not in the mountings, a chu that is no head: left out, bit 4;
//  - what the combiner's gates find inconsistent, a quaternion that is not
//    unit: left out, bit 4 (two heads that disagree: neither, bit 4 | 8).
// Every left-out head of the bad-input kinds is reported on the log
// (Diagnostics: the first 20 of each kind, then counts); flagged, rejected
// and skipped-stage rows are counted in the summary.
//
// Memory: rows in time order (the usual file) are combined as they are read,
// one epoch held. At the first row out of time order the pass stops and the
// rows are read again, kept (56 bytes each with its epoch key) and sorted; a pass that cannot be
// restarted (an output that is a stream, standard output or a FIFO) keeps
// the rows from the start.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <iosfwd>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "ascorr/combine/combiner.hpp"
#include "ascorr/combine/usable.hpp"
#include "ascorr/core/heads.hpp"
#include "ascorr/core/quaternion.hpp"
#include "ascorr/core/status.hpp"
#include "ascorr_host/correct/correct_file.hpp"
#include "ascorr_host/formats/combined_csv.hpp"
#include "ascorr_host/formats/mountings_csv.hpp"

namespace ascorr::host {

// Why a head's row of an epoch is not averaged in: the core's one rule
// (combine/usable.hpp), for the summaries.
using combine::kLeftOutKinds;
using combine::left_out_name;
using combine::LeftOut;

// The row as the core's selection sees it (a raw row: status 0).
combine::RowFacts row_facts(const CorrectedRow& r) noexcept;

// The camera head's own selection of the row (flags 0, confidence <= 5):
// what a target's pipeline takes with a solution (SOLUTION_IN's clean bit).
bool clean_for_combination(const CorrectedRow& r) noexcept;

// Every row of a corrected or solutions file as the combination takes it, in
// file order (status: the corrected file's column; InputError at
// file:line:column when it is not an integer in [0, 65535]). label: for the
// progress on a terminal.
void for_each_corrected_row(const std::string& path, const std::function<void(const CorrectedRow&)>& fn,
                            const std::string& label);

// The step at head-set changes, without a truth: at every epoch where the
// full set (every mounted head) is averaged in, the epoch is combined again
// with each proper subset S of it, and d_S = θ of q_S ⊗ q_full* (CRF axes,
// arcsec) is averaged per day (whole days since the first epoch). step is the
// RMS over days of the daily mean of d_S: the systematic jump of the combined
// attitude when the head set changes from the full set to S (noise averages
// out in the daily mean; what the heads' mountings and corrections leave
// between them does not).
struct HeadSetStep {
    std::size_t days = 0;
    std::array<double, 3> rms_daily_mean{};  // arcsec, CRF x, y, z
};

struct CombineSummary {
    std::size_t rows = 0;
    std::size_t epochs = 0;                                  // rows of the combined file
    std::array<std::size_t, 4> status_bit{};                 // epochs with bit 1, 2, 4, 8
    std::array<std::size_t, kLeftOutKinds> rows_left_out{};  // by LeftOut (kUsed: rows averaged in)
    bool out_of_order = false;                               // the rows were sorted
    HeadMask full = 0;                                       // the mounted heads
    std::array<HeadSetStep, 1U << kMaxHeads> steps{};        // by subset mask of `full` (days 0: none)
};
std::string describe(const CombineSummary& s);

// Thrown by a streaming stage at the first row out of time order; the
// caller runs again with a stage that keeps the rows.
struct RowsOutOfOrder {
    std::size_t line;
};

// The consistency gate (combine/combiner.hpp; the contract's "The consistency
// gate"). Unset: on the ground each epoch's gate follows its stages
// (combine::default_gate: a floor of 2″ with the aberration and the thermal
// stage applied, 10″ otherwise), on a target the flight's (10″, pre-flight
// mountings); set: the same for every epoch.
struct GateOptions {
    std::optional<double> sigmas;        // k, [3, 100]
    std::optional<double> floor_arcsec;  // f, [1, 3600] arcsec
};
// The gate of an epoch whose usable rows have (both_stages) or lack both stages.
combine::CombinerConfig gate_config(const GateOptions& g, bool both_stages) noexcept;
// The options over `base` (replay: the flight's gate, combine::flight_gate).
combine::CombinerConfig gate_config(const GateOptions& g, const combine::CombinerConfig& base) noexcept;

// The ground's gates of GateOptions, one combiner's tables for each kind of
// epoch (combine's and align's): the epoch's stages pick one.
class StageGates {
public:
    StageGates(const combine::Mountings& m, const GateOptions& g)
        : both_(m, gate_config(g, true)), other_(m, gate_config(g, false)) {}
    bool valid() const noexcept { return both_.valid() && other_.valid(); }
    // The combiner of an epoch whose usable rows have `stages` (status & 3).
    const combine::Combiner<double>& of(StatusBits stages) const noexcept {
        return stages == combine::kStagesApplied ? both_ : other_;
    }

private:
    combine::Combiner<double> both_;
    combine::Combiner<double> other_;
};

// The formal covariance's off-diagonal (xy, xz, yz; arcsec²) of each head
// set's combination (combine/subset_tables.hpp's P_S⁻¹), by HeadMask; zeros
// for a set with a head not in `mounted`.
using SubsetCovariances = std::array<std::array<double, 3>, combine::kSubsetCount>;
SubsetCovariances subset_covariances(const combine::Mountings& m, HeadMask mounted) noexcept;

// Rows in, one combined row per epoch out (see the top).
class CombineStage : public CorrectedRowSink {
public:
    enum class Mode { kStream, kKeep };
    // Writes into out (an output of the run's OutputSet, committed by the
    // caller); m: usable mountings with sigmas (refuse_unusable_mountings
    // with the same gate). file: the input's name, for messages.
    CombineStage(const MountingsFile& m, const GateOptions& gate, AtomicFile& out, std::string file, std::ostream& log,
                 Mode mode, CombinedColumns columns = {});
    // The same into rows (Mode::kKeep), each as a reader of the combined file
    // reads it (as_written): no file at all.
    CombineStage(const MountingsFile& m, const GateOptions& gate, std::vector<AttitudeRow>& rows, std::string file,
                 std::ostream& log, CombinedColumns columns = {});
    ~CombineStage() override;
    CombineStage(const CombineStage&) = delete;
    CombineStage& operator=(const CombineStage&) = delete;

    // Stream mode: throws RowsOutOfOrder for a row of an epoch before the
    // latest one, when the output can be written again (not streamed);
    // a streamed output keeps the rows instead.
    void add(const CorrectedRow& row) override;
    // Combines what is held, writes the last rows, prints the summary of
    // messages cut short.
    void finish() override;
    const CombineSummary& summary() const noexcept;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

struct CombineOptions {
    std::string in;         // corrected or solutions file
    std::string mountings;  // with sigmas
    std::string out;
    GateOptions gate;
    CombinedColumns columns;  // --covariance
};

// `ascorr combine`. Mountings without sigmas: each head's noise is estimated
// from the input (align.hpp's estimator, align_rows; its refusals are
// AlignRefused) and reported on log. Throws InputError (file:line:column) for
// a malformed input or mountings file, std::runtime_error for unusable
// mountings; writes nothing then.
CombineSummary combine_file(const CombineOptions& opt, std::ostream& log);
// The command's files (atomic_file.hpp's OutputSet): "--in", "--mountings"; "--out".
std::vector<NamedPath> combine_inputs(const CombineOptions& opt);
std::vector<NamedPath> combine_outputs(const CombineOptions& opt);
// The same into outputs (opened from combine_outputs, committed by the
// caller; a run made again on rows out of order opens them anew).
CombineSummary combine_file(const CombineOptions& opt, OutputSet& outputs, std::ostream& log);

// Refuses mountings the combiner cannot use with the gate (InputError at the
// head's line, or std::runtime_error for the head set), or without sigmas
// (correct --combined: the noise cannot be estimated before the rows are
// corrected). The tables are those a target builds (Combiner<double> refuses
// what the fixed-point formats cannot hold), for both defaults of the gate
// when it is unset: what a target would refuse is refused here, and why.
void refuse_unusable_mountings(const MountingsFile& m, const std::string& path, const GateOptions& gate = {});
// The same for the gates given (replay: the target's).
void refuse_unusable_mountings(const MountingsFile& m, const std::string& path,
                               const std::vector<combine::CombinerConfig>& gates);

// `ascorr correct ... --mountings M --combined A`: corrects (correct_file) and
// combines the corrected rows in the same pass; the corrected file, the model
// history and the combined file are one OutputSet, committed together. Rows
// out of time order: the run is made again with the rows kept, into the
// outputs opened anew (the first run's messages and files are dropped).
struct CorrectAndCombine {
    CorrectSummary corrected;
    CombineSummary combined;
};
CorrectAndCombine correct_and_combine(const CorrectOptions& opt, const std::string& mountings,
                                      const std::string& combined, std::ostream& log, const GateOptions& gate = {},
                                      CombinedColumns columns = {});
// The run's files: correct_inputs and "--mountings"; correct_outputs and "--combined".
std::vector<NamedPath> correct_and_combine_inputs(const CorrectOptions& opt, const std::string& mountings);
std::vector<NamedPath> correct_and_combine_outputs(const CorrectOptions& opt, const std::string& combined);
// The same into outputs (opened from correct_and_combine_outputs, committed by the caller).
CorrectAndCombine correct_and_combine(const CorrectOptions& opt, const std::string& mountings,
                                      const std::string& combined, OutputSet& outputs, std::ostream& log,
                                      const GateOptions& gate = {}, CombinedColumns columns = {});

}  // namespace ascorr::host
