// python/src/docstrings.hpp: the docstrings of the compiled module, the one
// place they are written. The type stub (python/ascorr/__init__.pyi) carries
// the same text, and python/tests/test_docs.py fails when the two differ.
//
// Placeholders, filled from the core's ascorr/core/heads.hpp and
// model_terms.hpp by docstring() (bind.hpp): @HEADS@ the head letters
// ("ABCD"), @N_HEADS@ their number, @HEAD_LETTERS@ "'A'..'D'", @HEAD_INDICES@
// "0..3"; @N_TERMS@ the model's terms (7), @N_LINEAR_TERMS@ its linear ones
// (4), @TERMS@ their names "c0, c1, ...", @QUADRATIC_TERMS@ "c1_2, c2_2, c3_2".
#pragma once

namespace ascorr::python::docs {

inline constexpr const char* kModule = "Compiled part of the ascorr package (see help(ascorr)).";

inline constexpr const char* kInputError =
    "A malformed input file or rows (a ValueError); the message starts with file:line:column.";
inline constexpr const char* kFitRefused =
    "fit() refused the data: period too short, too few orbits or an ill-conditioned design (a ValueError).";

// ---- Model (bind_model.cpp)

inline constexpr const char* kModel = R"doc(A thermal model: per head and axis, angles in arcsec linear (and
optionally quadratic) in T_CHU, T029 - T_CHU and T032 - T_CHU (docs/contract.md, "Model file").

Model(coefficients, heads="@HEADS@"): coefficients of shape (@N_HEADS@, 3, @N_LINEAR_TERMS@) or (@N_HEADS@, 3, @N_TERMS@),
indexed [head @HEAD_LETTERS@][axis alpha, beta, gamma][@TERMS@],
in arcsec, arcsec/degC and arcsec/degC^2; heads: the heads that have
coefficients (a head not listed gets status 256 in correct()); lag_s: None
or @N_HEADS@ numbers [head @HEAD_LETTERS@], the bench's lag in s of each head, 0 (none) or
in [1, 86400] (the model file's lag_s column); sun: None or the Sun term's
coefficients, shape (@N_HEADS@, 3, 3) [head][alpha, beta, gamma][x, y, z of the Sun's
direction in the head's frame], arcsec (the model file's sun_x, sun_y, sun_z).)doc";

inline constexpr const char* kModelCoefficients =
    "Coefficients, float64 (@N_HEADS@, 3, @N_TERMS@): [head @HEAD_LETTERS@][alpha, beta, gamma][@TERMS@], arcsec (a "
    "copy).";
inline constexpr const char* kModelHeads = "The heads with coefficients, e.g. 'ABC'.";
inline constexpr const char* kModelQuadratic =
    "True when the model has (and its file will carry) the quadratic columns.";
inline constexpr const char* kModelCommonRotation =
    "The rule that fixed the rotation common to all heads: 'smallest', 'combined' or 'rigid-X' (the model "
    "file's common_rotation column; docs/contract.md).";
inline constexpr const char* kModelLag =
    "The bench's lag per head, float64 (@N_HEADS@,): [head @HEAD_LETTERS@] s, 0 none (the model file's lag_s "
    "column; its terms take the head's temperatures through a first-order lag; docs/contract.md).";
inline constexpr const char* kModelSun =
    "The Sun term, float64 (@N_HEADS@, 3, 3): [head @HEAD_LETTERS@][alpha, beta, gamma][x, y, z of the Sun's "
    "direction in the head's frame], arcsec, 0 none (the model file's sun_x, sun_y, sun_z; docs/contract.md).";
inline constexpr const char* kModelWrite =
    "Write the model file (docs/contract.md), atomically: the whole file or nothing. path: str or os.PathLike.";
inline constexpr const char* kModelToCsv = "The model file's text.";
inline constexpr const char* kModelEq =
    "Equal when both would write the same model file (heads, coefficients, columns).";

inline constexpr const char* kReadModel =
    R"doc(Read a model file (docs/contract.md, "Model file"). A malformed file raises ascorr.InputError
(a ValueError) with file:line:column, as the command line reports it.)doc";

// ---- correction (bind_correct.cpp, bind_self_calibration.cpp)

inline constexpr const char* kCorrect =
    R"doc(Correct solutions: aberration, then the thermal model; the numbers and status bits of
`ascorr correct` on the same rows, bit for bit, in every scalar.

t: float64 (n,), s since J2000.0 TT. chu: (n,) strings @HEAD_LETTERS@ or head indices
@HEAD_INDICES@. q: (n, 4) q_chu_icrf (w, x, y, z). temps: (n, 3) t_chu, t_029, t_032 in
degC, NaN where missing. v: (n, 3) spacecraft velocity, km/s GCRS, NaN where
missing. temps and v may be None (all missing). model: an ascorr.Model, or None
for no thermal stage. scalar: 'double', 'float' or 'fixed' (the core's Q30).
aberration: True or False (False skips the aberration stage; None is refused).
states: the path (str or os.PathLike) of a states file
(t,x,y,z,vx,vy,vz; `ascorr correct --states`): a row without its own velocity
(all three NaN) gets the on-board velocity service's, propagated from the
latest state at or before it (status 4 before the first state, 4+512 beyond
max_propagation seconds, 4+32 off a plausible orbit); states_frame 'itrf' (GNSS)
or 'gcrs' (uplinked). States the service refuses are reported as a warning.
The names of scalar and states_frame are those of the command line, in any
case ('GCRS' is 'gcrs'); numbers are not names.

Returns (q_corrected float64 (n, 4), status uint16 (n,)). Every row comes back;
a row that cannot be corrected keeps its quaternion exactly and says why in its
status bits (1 aberration, 2 thermal, 4 no velocity, 8 temperatures missing,
16 rejected, 32 velocity unusable, 64 temperature unusable, 128 model angle
beyond 1 deg, 256 no model for the head). A time outside the Earth ephemeris
(1900-2100, e.g. 1e300 s or a time in ms) is a row like any other: with a
velocity it gets 4+32, as on the command line. Raises ValueError naming the
argument and what it accepts for a wrong shape, dtype or value, or a time that
is not finite (the command line refuses such a row as malformed).)doc";

inline constexpr const char* kSelfCalibrate =
    R"doc(Correct with a thermal model the on-board estimator learns from the rows themselves, as
`ascorr correct --self-calibrate`: causally in time order (any row order), from the
epochs `fit` would select (flags: integers (n,) or None; confidence: (n,) arcsec,
NaN or None where not given: not clean), after the aberration stage, in `scalar`,
starting from `model` (version 0) or from none (rows before the first adopted
model get status 256).
time_constant: the estimator's forgetting in days. orbit_period: seconds in [600, 86400],
or None: from the median speed of the first 99 rows learnt from (as --orbit-period).
mountings: read_mountings()'s dict (as correct --mountings): the rotation common to all
heads is then fixed by the rule 'combined' (mountings without sigmas are refused).
lag: the bench's lag the estimator learns with, as correct --lag: 'TAU', 'X:TAU,...'
or a number (s), or None: the model's lag_s, or none; a lagged model with another lag
is refused. Every model of the history then has that lag_s, and the rows are learnt
from and corrected with their lagged temperatures. 'auto' (as correct --lag auto, from
a model without lag_s or none): the lag is learnt as the estimator runs, one for every
head; each model of the history has the lag taken when it became active (lag_s), and
a head's rows are corrected with it from the first model that changed the head's lag,
started afresh there.
sun_term: 'none' (default) or 'auto' (as correct --sun-term auto, from a model without a
Sun term or none; in every scalar): the Sun term is learnt as the estimator runs;
each model of the history has the term taken when it became active (its sun), and the
rows are corrected with it.
Returns (q_corrected float64
(n, 4), status uint16 (n,), history), history a list of {"t", "version", "crc32c",
"model", "tt_us", "origin"} for every model that became active, in time order (tt_us: when,
on the on-board clock: the rows whose t rounded to the microsecond is at least it;
origin: per head present, "given" (version 0), "learnt" or "kept" (a head the estimator
does not learn keeps the active model's coefficients).)doc";

inline constexpr const char* kEarthVelocity =
    R"doc(The Earth's barycentric velocity (ICRF axes, km/s) and heliocentric distance (au) at t
(s since J2000.0 TT), from ERFA's eraEpv00: as the correction uses it (Chebyshev
series of degree 15 on 16-day segments, within 5e-9 km/s and 5e-12 au of
eraEpv00), or with exact=True (True or False) a direct call for each t.
eraEpv00 spans 1900-2100: outside it (and for NaN) the row is NaN, velocity and
distance (the correction then has no velocity: status 4+32).
Returns (v float64 (n, 3), sun_distance_au float64 (n,)).)doc";

// ---- analysis (bind_analysis.cpp)

inline constexpr const char* kIba =
    R"doc(Inter-boresight angles: for each pair 'A-B', 'A-C', 'B-C', the angle in arcsec between the
two heads' boresights at every epoch (t to the millisecond) where both have a row.
Returns {pair: (t float64 (m,), iba float64 (m,))}, sorted by t. A row whose
quaternion the core rejects (not finite or not unit, status 16 in correct(),
a zero quaternion included) takes part in no IBA, as in stats(); a UserWarning
names such rows. A second row of one head at one epoch raises ascorr.InputError.)doc";

inline constexpr const char* kStats =
    R"doc(IBA statistics as `ascorr stats`: per pair and stage (original, aberration, thermal), the
IBA RMS about the mean over the clean epochs (flags 0, confidence a number <= 5,
temperatures and velocity present and accepted), and after 200 s smoothing.
flags: integers (n,) or None (0); confidence: (n,) arcsec, NaN where not given;
None: none given (a row without a confidence is not clean, as in a file);
t_from, t_to: the period (inclusive); noise_iba: the path of `ascorr simulate
--noise-iba`'s F.noise-iba.csv (as --noise-iba), or None.
Returns {"pairs": {pair: {"original", "aberration", "thermal", "<stage>_smoothed"
(arcsec; None with fewer than two clean epochs, or thermal without a model, as
null in `ascorr stats --json`), "n"}}, with noise_iba "systematic": {pair:
{"original", "aberration", "thermal" (the RMS about the mean of the IBA minus the
noise-only IBA at the same t; None as null in --json's "systematic"), "n" (the
epochs in both)}}, "rows", "clean_rows", "table" (the command's text, with the
systematic table), "messages" (rows left out, one line each)}.)doc";

inline constexpr const char* kFit =
    R"doc(Fit the thermal model as `ascorr fit` (the paper's procedure; see docs/ground.md),
with its defaults and checks. terms: 'linear' or 'quadratic' (also @QUADRATIC_TERMS@;
any case, as --terms); holdout: the fraction of the period (its end) held out for the
model-selection report, 0..0.5; min_temperature_range: the smallest range (degC) of
each regressor for quadratic terms; frame_heads: frame F's two heads, e.g. 'AD' (as
--frame-heads); heads: the heads to fit, F's among them, e.g. 'ABD' for a mission
without C (as --heads; None: A, B, C, F's two and every other head with rows);
mountings: read_mountings()'s dict, with sigmas (as --mountings): the rotation common
to all heads, which no IBA sees, is then fixed so that the heads' combined attitude
moves least; common_rotation: the rule for it, 'combined', 'smallest' or 'rigid-X'
(as --common-rotation; None: 'combined' with mountings, 'smallest' without); lag: the
bench's lag, as --lag: 'auto' (chosen on the held-out part, none unless the data
support one), a number of s for every head, or 'X:TAU,...' (the model's lag_s);
sun_term: 'auto' (the Sun term fitted inside the orbit, taken when the held-out part
supports it: the model's sun) or 'none', as --sun-term. Returns
(model, report): model an ascorr.Model (model.write(path) writes the model file),
report a dict (rows (of the heads fitted), rows_other_heads (left out by heads),
dropped, epochs, orbits_used, condition, singular_values, terms, common_rotation (the
rule's name), heads (the letters of the heads fitted), residual_rms and signal_rms
(len(heads), 3) arcsec [head][alpha, beta, gamma], lag (auto's verdict, '' with a lag
given), sun (sun_term='auto''s verdict, '' with 'none'), text). Raises ascorr.FitRefused (a ValueError) when the data cannot
determine the model (period shorter than min_days, fewer than min_orbits orbits,
condition number above max_condition, too small a temperature range for quadratic
terms) or a setting is out of its range; its text, and the report's, name the settings
as this function's keywords (min_temperature_range, not --min-temperature-range).)doc";

// ---- files (bind_formats.cpp)

inline constexpr const char* kReadSolutions =
    R"doc(Read a solutions file, or a corrected file, into arrays: {"t", "chu" (strings as written),
"q" (n, 4), "temps" (n, 3), "v" (n, 3) (NaN where not available), "flags" (0 when
absent), "confidence" (NaN when absent)} plus "status" for a corrected file, and "extra":
{column name as written: (n,) str, the fields as written} for every other column
(kept, as `ascorr correct` keeps them). The keys are write_solutions()'s argument
names: write_solutions(path2, **read_solutions(path1)) writes every column.
path: str or os.PathLike. Malformed rows raise ascorr.InputError with
file:line:column, as the command line.)doc";

inline constexpr const char* kWriteSolutions =
    R"doc(Write a solutions file (or, with status, a corrected file) from arrays, as the command
line writes its outputs: atomically (a temporary file renamed over the output,
whose permission bits and symbolic links are kept; on an error the existing file
is left as it was). path: str or os.PathLike. Columns: t, chu, qw..qz, t_chu,
t_029, t_032, vx, vy, vz, flags, confidence, then extra's columns in its order
({name: (n,) values}, each value written as str(value), verbatim; what read_solutions()
returned), then status. Numbers are written with the fewest digits that read
back exactly; NaN temperatures as 'nan', NaN velocities and confidences as empty
fields. Nothing is written that read_solutions() would refuse: a status outside
0..65535 or with bits correct() never sets together, a row whose chu is not a
camera head with a status other than 16, a value that is not one CSV field raise
ValueError naming the argument (or column) and the row.)doc";

// ---- the combined attitude (bind_combine.cpp)

inline constexpr const char* kAlignRefused =
    "align() refused the data: an empty period, too few epochs, a head without clean epochs with another head, "
    "noise or mountings the data do not determine (a ValueError).";

inline constexpr const char* kReadMountings =
    R"doc(Read a mountings file (docs/contract.md, "Combined attitude") into a dict:
{"heads": the letters of its heads in order (e.g. 'ABC'), "q": (k, 4) q_chu_crf
(w, x, y, z; v_chu = R(q) v_crf), "sigma_cross", "sigma_about": (k,) arcsec, or None
when the file has no sigmas}, one row per head of heads. combine() and align() take
this dict. A malformed file raises ascorr.InputError (a ValueError) with
file:line:column, as the command line reports it.)doc";

inline constexpr const char* kCombine =
    R"doc(The combined attitude of the bench, one row per epoch (rows whose t agree to the
millisecond), in time order: the numbers and status bits of `ascorr combine` on the
same rows, to the digit (q as the combined file writes it, 15 decimals).

t, chu, q: as correct()'s (q: the corrected, or raw, q_chu_icrf). mountings: a dict
as read_mountings() returns, with sigmas. status: (n,) the status of corrected rows
(as correct() returns it), or None for raw rows taken as they are. flags, confidence:
(n,) as in a solutions file, or None (0; not given). A row is averaged in when it is
clean (flags 0, confidence <= 5) and its status has none of 4, 8, 16, 128, 256.
gate_sigmas, gate_floor: the consistency gate, as --gate-sigmas ([3, 100], default 6)
and --gate-floor (arcsec, [1, 3600]; default 2 for rows with the aberration and the
thermal stage applied, 10 otherwise). Mountings a target would refuse with this gate
raise ValueError saying why. covariance: also return "cov" (m, 3), the formal
covariance's off-diagonal xy, xz, yz in arcsec^2 (--covariance's columns; NaN without
a head). Needs no file: no temporary folder is used.
Returns a dict: "t" (m,); "q" (m, 4) q_crf_icrf (w >= 0), NaN without a usable head;
"heads" (m,) str, the letters of the heads used ('' for none); "sigma" (m, 3) the
formal 1-sigma about the CRF axes, arcsec (NaN without a head); "status" (m,) the
combined file's bits (1 two or more heads, 2 one head, 4 a head left out, 8 none).
What was left out and why is given as a UserWarning, as the command line's messages.)doc";

inline constexpr const char* kAlign =
    R"doc(Estimate each head's mounting and noise from the data, as `ascorr align`, keeping
the CRF of the given mountings: the new mountings differ from the given ones by
rotations whose information-weighted mean is zero. The same numbers as the mountings
file `ascorr align` writes, to the bit.

t, chu, q, status, flags, confidence: as combine()'s. mountings: a dict as
read_mountings() returns (sigmas, if any, are not used). t_from, t_to: the period
(s since J2000 TT; None: the whole data). noise_window: the window (s) of the slowly
varying mean the noise is measured about (0: one mean over the period). min_epochs:
the fewest epochs with two or more usable heads. gate_sigmas, gate_floor: the
combination's consistency gate, as combine()'s, applied from the second pass on (a
head it finds inconsistent is left out of the sums). Returns (mountings, report):
mountings the new dict, with the estimated sigmas; report a dict (heads, rotation and
rotation_sd (k, 3): each head's rotation from the given mounting in CRF axes and its
formal 1-sigma, arcsec; sigma_cross, sd_cross, sigma_about, sd_about (k,): the
estimated noise and its formal 1-sigma, arcsec; epochs (k,): each head's epochs used;
rows, rows_in_period, left_out (counts by reason), period_epochs, joint_epochs,
single_epochs, noise_model ('per_head', or 'equal_cross' with two heads: one
sigma_cross shared), noise_window, dof, iterations, passes, last_update,
weighted_mean, text: the command line's report). Raises ascorr.AlignRefused (a
ValueError) for an empty period, too few epochs, a head of the mountings without
clean epochs with another head, or noise the data do not determine;
ascorr.InputError for two rows of one head in one epoch.)doc";

inline constexpr const char* kInterpolate =
    R"doc(The combined attitude at given times, as `ascorr interpolate` writes it: for each
time of `at` (in its order) a row of combine()'s form, interpolated on the rotation
group between the usable epochs on either side (signs made continuous; equal
attitudes give the attitude itself), the same numbers to the digit.

combined: a dict as combine() returns (with "cov" when it was called with
covariance=True; the covariance is then interpolated too), rows in time order. at:
(k,) times, s since J2000 TT, float64. max_gap: seconds to the usable epoch on either
side beyond which a time gets status 8 ([0.001, 1e6]). Returns a dict of k rows:
"sigma" from the epochs' own variances, linear in the distance to them, plus a bound
of the interpolation's error from the rate's change in the data; "heads" the union of the two
epochs' heads; "status" 1 or 2 by that union, with 4 when either epoch has it; 8 (q
and sigma NaN) beyond max_gap or outside the rows. A row the combined file's reader
would refuse raises ValueError with its words, at its 1-based row.)doc";

inline constexpr const char* kImportGracefo =
    R"doc(Read GRACE Follow-On Level-1 star-camera products (the DTU µASC, three heads) as
`ascorr import gracefo` does: the same numbers as the files it writes, read back.

sca1a: a path or a list of paths of SCA1A files of one satellite (taken in the order
of their first records). qsa1b: the QSA1B file (the heads' mountings). tim1b, clk1b:
the clock products (OBC to receiver time, receiver to GPS time; a path or a list of
paths, merged), or None (the time taken as it is). sca1b: JPL's combined attitude, or None. time_offset: seconds added
to every SCA1A time ([-10, 10]; default 0). Returns a dict: "satellite" ('C' or 'D');
"solutions", as read_solutions() returns a solutions file (t in TT, s since J2000;
chu 'A'..'C' for sca_id 1..3; q = q_chu_icrf, the conjugate of SCA1A's; temps and v
NaN; flags 4 invalid, 2 non-stellar object, 8 aberration not corrected on board, 16
time tag to be corrected by an unknown amount; confidence NaN; extra: sca_mode,
qualflg, sca_confid as written); "mountings", as read_mountings() returns, from
QSA1B, without sigmas (align() estimates them); "reference", {"t": (m,), "q": (m, 4)
q_crf_icrf, qw >= 0} from SCA1B, or None. Raises ascorr.InputError naming file, line
and column for a bad record.)doc";

}  // namespace ascorr::python::docs
