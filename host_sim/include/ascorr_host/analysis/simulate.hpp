// ascorr_host/analysis/simulate.hpp: a Swarm-like recorded data set (`ascorr simulate`).
//
// Conventions:
//  - Orbit: circular, altitude 460 km, inclination 87.4°, GCRS axes (no
//    precession: the data span a few years and only directions relative to the
//    stars and the Sun matter). The node drifts so that the orbital plane
//    turns against the Sun once per kPlaneSunPeriodDays (Swarm Alpha: 267 d).
//  - Body frame (orbital frame, spacecraft fixed in it): x along the velocity,
//    z to nadir, y = z × x. R_body_icrf has rows x, y, z in ICRF.
//  - Heads: boresights 54.7° from the zenith at azimuths 90° (A), 210° (B),
//    330° (C) from +x towards +y, hence mutually 90° apart. head_mounting(h)
//    maps body into head components, so q_chu_icrf = R_head_body·R_body_icrf.
//  - The heads simulated (--heads, default ABC): two or more of heads.hpp's.
//    A head beyond C (index h ≥ 3, D) is derived from head h − 3 (A for D),
//    so that A, B and C's rows are those of a mission without it:
//      mounting: halfway in azimuth between heads h − 3 and h − 2 (D: 150°),
//      the same zenith distance;
//      temperature: T_CHU with head h − 3's response mirrored (the seasonal
//      and orbital terms of the opposite sign), its own wander and read
//      noise; T029 and T032 are the bench's, shared by every head;
//      truth: head h − 3's coefficients with the opposite sign, unless the
//      truth model file has its own;
//      random draws (temperature, flags, noise): its own stream, mt19937_64
//      seeded by seed_seq{seed, h}.
//  - Truth: the rigid attitude. The head really points along the deformed,
//    noisy attitude q_meas = q_th* ⊗ q_noise ⊗ q_true, with q_th the thermal
//    correction of the truth model for the recorded temperatures; the raw
//    solution is q_meas with the aberration correction undone (fixed-point
//    inversion of the core's own aberration rotation). So `ascorr correct`
//    with the truth model returns q_noise ⊗ q_true, and its IBA is the floor.
//  - Heater events (the paper's §3.2 heater test, repeated): every 40–80 days
//    for 3–5 days, alternately the operational heater (the CHUs +2–3 °C and
//    THT00032 +2 °C) and the survival heater (THT00029 +3 °C), each switched
//    on and off with a half-day time constant. Their windows [start, end] (the
//    heater on; the temperatures relax for a few days after) are written
//    beside the data.
//  - The bench's common reference frame (CRF) is the body frame: the
//    mountings are q_chu_crf = head_mounting(h), the true CRF attitude
//    q_crf_icrf = R_body_icrf, so R(q_chu_icrf) = R(q_chu_crf) R(q_crf_icrf)
//    before deformation and noise. The noise is drawn in head axes: 1σ
//    kNoiseCrossArcsec about x and y (across the boresight), kNoiseAboutArcsec
//    about z (flagged rows: more in every axis); OUT.mountings.csv states
//    both, OUT.attitude.csv the true CRF attitude at every epoch (rows or not).
//  - The floor: the IBA RMS per pair of q_noise ⊗ q_true over the clean
//    epochs (docs/contract.md), written beside the data, and per day as
//    sums from which the floor of any window of whole days follows.
//  - Events for testing a self-calibrating model (none by default; windows are
//    [from, to) in days after the start, judged on the epoch's offset k·step):
//    the truth model changes on given days; data outages (no rows); a
//    thermistor whose recorded value sticks or drifts while the bench follows
//    the real temperature; a head whose measured attitude is rotated about its
//    x axis (not in the truth model, not in the floor). They draw no random
//    numbers: outside its window an event leaves every row as without it.
//  - The bench inside the orbit (BenchDynamics; none by default, and then
//    every file is byte for byte as without it). With a lag τ the bench
//    deforms with its temperatures (each T_CHU, T029, T032) through a
//    first-order filter, L ← L + (1 − e^(−Δt/τ))·(T − L) per epoch from
//    L = T at the first one, while the rows record T. With an orbit term A
//    each head is rotated, on top, by A·(v̂·ŝ) about an axis of its own (head
//    axes: A x, B y, C (y − x)/√2; a head beyond C the opposite of the head
//    three before it): one side heated along the orbit where no thermistor
//    reads, v̂·ŝ = −cos β·sin(u − u_☉), so its amplitude follows the season.
//    Both are in the measured attitudes only: not in the truth model, not in
//    the floor, so `correct` with the truth model no longer returns
//    q_noise ⊗ q_true and its IBA minus the floor's (OUT.noise-iba.csv) is
//    what the static model leaves.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <cstdint>
#include <iosfwd>
#include <string>
#include <utility>
#include <vector>

#include "ascorr_host/analysis/iba.hpp"
#include "ascorr_host/formats/atomic_file.hpp"
#include "ascorr_host/formats/mountings_csv.hpp"

namespace ascorr::host {

inline constexpr double kDefaultSimStartT = 456148800.0;  // 2014-06-16T00:00 TT, s since J2000
inline constexpr double kPlaneSunPeriodDays = 267.0;
inline constexpr double kSimAltitudeKm = 460.0;
inline constexpr double kSimInclinationDeg = 87.4;

// Days [from_day, to_day) after the start.
struct DayWindow {
    double from_day = 0.0;
    double to_day = 0.0;
};

// From `day` days after the start the truth is the model file `model`.
struct TruthChange {
    double day = 0.0;
    std::string model;
};

enum class ThermistorFaultKind { kStuck, kDrift };

// The recorded temperature `channel` (0 t_chu, 1 t_029, 2 t_032) of head
// `head`'s rows in the window: stuck at its value at the window's first epoch,
// or the real value plus rate_c_per_day per day since from_day.
struct ThermistorFault {
    std::size_t head = 0;
    std::size_t channel = 0;
    ThermistorFaultKind kind = ThermistorFaultKind::kStuck;
    DayWindow window;
    double rate_c_per_day = 0.0;  // kDrift only
};

// Head `head`'s measured attitude rotated by `arcsec` about its x axis in the window.
struct HeadBias {
    std::size_t head = 0;
    DayWindow window;
    double arcsec = 0.0;
};

// The bench inside the orbit (see the top): --bench-lag, --orbit-term.
inline constexpr double kMaxBenchLagS = 86400.0;
inline constexpr double kMaxOrbitTermArcsec = 60.0;
struct BenchDynamics {
    double lag_s = 0.0;         // τ, s, in [0, kMaxBenchLagS]; 0: the bench follows its temperatures at once
    double orbit_arcsec = 0.0;  // A, arcsec, in [0, kMaxOrbitTermArcsec]
};

struct SimulateOptions {
    std::string out;
    double days = 920.0;  // 2.5 years
    double step_s = 60.0;
    std::uint64_t seed = 1;
    std::string truth;  // model file; empty: the embedded Table 2
    double start_t = kDefaultSimStartT;
    std::vector<TruthChange> truth_changes;  // increasing day
    std::vector<DayWindow> gaps;
    std::vector<ThermistorFault> thermistor_faults;
    std::vector<HeadBias> head_biases;
    HeadMask heads = kPaperHeads;  // the heads simulated (--heads)
    BenchDynamics bench;
    bool noise_iba = false;  // --noise-iba: also OUT.noise-iba.csv
};

// Throws std::invalid_argument, naming the option (--truth-change, --gap,
// --thermistor-fault, --head-bias, --bench-lag, --orbit-term) and what it
// accepts, for events outside the mission [0, days], empty or reversed
// windows, truth changes not in increasing days, heads not simulated, fewer
// than two heads (--heads), non-finite or out-of-range values.
void refuse_bad_events(const SimulateOptions& opt);

struct HeaterEvent {
    double start = 0.0;        // heater on, s since J2000 TT
    double end = 0.0;          // heater off
    bool operational = false;  // false: the survival heater
};

struct SimulateSummary {
    std::size_t epochs = 0;
    std::size_t rows = 0;
    HeadMask heads = kPaperHeads;                      // simulated
    PairList pairs = kPaperPairs;                      // pairs_of(heads): floor is indexed by position in it
    std::array<std::size_t, kMaxHeads> outage_rows{};  // per head, not written (Sun or Moon in view)
    std::size_t flagged_rows = 0;                      // flags != 0 or confidence > 5
    std::size_t rows_without_temperature = 0;
    std::size_t rows_without_velocity = 0;
    std::array<Rms, kMaxPairs> floor{};
    std::string truth_path;
    std::string floor_path;
    std::string floor_daily_path;
    std::string truth_history_path;
    std::size_t gap_epochs = 0;        // epochs without rows (--gap)
    std::vector<HeaterEvent> heaters;  // those starting before the last epoch
    std::string heaters_path;
    std::string mountings_path;
    std::string attitude_path;
    std::string noise_iba_path;  // empty without --noise-iba
};

// Writes opt.out, opt.out + ".truth.csv" (the initial truth),
// opt.out + ".truth-history.csv" (the truth as a model history: version 0 from
// the first epoch, one version per change), opt.out + ".floor.json",
// opt.out + ".floor-daily.csv", opt.out + ".heaters.csv" (start,end,heater:
// operational or survival), opt.out + ".mountings.csv" (simulated_mountings)
// and opt.out + ".attitude.csv" (t,qw,qx,qy,qz: q_crf_icrf at every epoch k·step,
// in --gap too; combined_csv.hpp); with opt.noise_iba also
// opt.out + ".noise-iba.csv" (noise_iba_csv).
// Throws std::invalid_argument for bad options, InputError for a bad truth file.
// The eight (nine) files are one OutputSet (atomic_file.hpp): all written or none.
SimulateSummary simulate(const SimulateOptions& opt);
// The command's files: its inputs, and its eight outputs by option ("--out",
// "--out (truth model)", "--out (truth history)", "--out (noise floor)",
// "--out (daily noise floor)", "--out (heater events)", "--out (mountings)",
// "--out (true attitude)", and with --noise-iba "--out (noise-only IBAs)").
std::vector<NamedPath> simulate_inputs(const SimulateOptions& opt);
std::vector<NamedPath> simulate_outputs(const SimulateOptions& opt);
// Writes into outputs (opened from simulate_outputs, committed by the caller).
SimulateSummary simulate(const SimulateOptions& opt, OutputSet& outputs);

// Body into head components for head 0 … kMaxHeads − 1 (see the top).
Eigen::Matrix3d head_mounting(int head);

// The star trackers' noise (1σ per axis, arcsec) of clean rows: across the
// boresight (about the head's x and y) and about it (z).
inline constexpr double kSimNoiseCrossArcsec = 1.5;
inline constexpr double kSimNoiseAboutArcsec = 10.0;

// The mountings of the heads `heads`, q_chu_crf = head_mounting(h), with the
// true noise above (the file simulate writes beside the data).
MountingsFile simulated_mountings(HeadMask heads);

std::string describe(const SimulateSummary& s);
std::string floor_json(const std::array<Rms, kMaxPairs>& floor, const PairList& pairs);
std::string heaters_csv(const std::vector<HeaterEvent>& events);

// OUT.floor-daily.csv: `day,t_start,pair,n,sum,sum_sq`, a row per day since
// the start (the last may be partial) and pair: the number, sum and sum of
// squares of the floor IBAs (arcsec) of the day's clean epochs. The sums are
// accumulated in long double and written with 21 significant digits, as the
// RMS of a window needs them (IBA ~324000", RMS ~2").
struct FloorSums {
    std::size_t n = 0;
    long double sum = 0.0L;
    long double sum_sq = 0.0L;
};
using DailyFloor = std::vector<std::array<FloorSums, kMaxPairs>>;  // [day][position in pairs]
std::string floor_daily_csv(const DailyFloor& days, double start_t, const PairList& pairs);

// The floor per pair of `pairs` (by position in it) over days [from_day,
// to_day) of an OUT.floor-daily.csv: rms about the mean (NaN without epochs)
// and n; rows of other pairs are skipped. Throws InputError
// (file:line:column) for a malformed file (a pair that is not two heads of heads.hpp).
struct WindowFloor {
    double rms = 0.0;
    std::size_t n = 0;
};
std::array<WindowFloor, kMaxPairs> floor_of_days(const std::string& path, long long from_day, long long to_day,
                                                 const PairList& pairs = kPaperPairs);

// OUT.noise-iba.csv (noise_iba.cpp): `t,pair,iba`, a row per clean epoch
// (the floor's) and pair, in time order: the IBA (arcsec, 6 decimals) of the
// heads' attitudes with noise only, q_noise ⊗ q_true. A corrected file's IBA
// minus it, at the same t, is what the correction left of the deformation
// (the systematic residual, `stats --noise-iba`). Written as the mission
// runs, a row at a time, as the solutions are.
inline constexpr const char* kNoiseIbaHeader = "t,pair,iba";
void append_noise_iba_row(std::string& buf, double t, const HeadPair& pair, double iba);

// A pair's noise-only IBAs (arcsec) by t in ms, in increasing t, one per t:
// a sorted vector (16 bytes a row once read; the reader peaks at about 40).
using NoiseIbaSeries = std::vector<std::pair<long long, double>>;
// The IBA at t_ms, or nullptr.
const double* noise_iba_at(const NoiseIbaSeries& s, long long t_ms);
// The rows of the pairs `pairs` (rows of other pairs of heads.hpp's heads are
// skipped), by position in it, read through the solutions' block reader
// (csv.hpp: "cannot open FILE: reason", a directory, a NUL byte or an
// over-long line refused as there). Throws InputError (file:line:column) for
// another header, a row that is not three fields, a t that is no time of an
// epoch, a pair that is not two heads, an iba outside [0, 648000] arcsec, a
// pair twice at one t.
std::array<NoiseIbaSeries, kMaxPairs> read_noise_iba(const std::string& path, const PairList& pairs = kPaperPairs);

}  // namespace ascorr::host
