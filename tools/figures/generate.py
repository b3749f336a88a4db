#!/usr/bin/env python3
"""Writes docs/figures.md, every measured figure of the benchmarks, from their
JSON in docs/figures/ (written by tools/figures/record, one file per
benchmark run). Python 3 standard library only.

    python3 tools/figures/generate.py           # writes docs/figures.md
    python3 tools/figures/generate.py --check   # exit 1 when docs/figures.md is not what the JSON gives

A file that is missing leaves its section out (and says so); a file whose
keys are not the benchmark's stops with the file and the key named.
"""

import argparse
import json
import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
DATA = ROOT / "docs" / "figures"
PAGE = ROOT / "docs" / "figures.md"
REGENERATE = "python3 tools/figures/generate.py"

# The benchmark behind each data file, and how to run it again.
SOURCES = {
    "target-bench": "tools/figures/record target-bench toolchain/run-target-bench",
    "acquisition-bench": "tools/figures/record acquisition-bench toolchain/run-acquisition-bench",
    "row-order": "tools/figures/record row-order bench/row-order-bench build/ci",
    "row-order-states": "tools/figures/record row-order-states bench/row-order-bench --states build/ci",
    "self-calibration-memory": "tools/figures/record self-calibration-memory bench/self-calibration-memory build/ci",
    "python-correct-1s": "PYTHONPATH=build/ci/python tools/figures/record python-correct-1s /usr/bin/python3 "
                         "bench/python_correct.py --exe build/ci/host_sim/ascorr --step 1",
    "python-correct-60s": "PYTHONPATH=build/ci/python tools/figures/record python-correct-60s /usr/bin/python3 "
                          "bench/python_correct.py --exe build/ci/host_sim/ascorr --step 60",
    "gracefo-jpl": "tools/figures/record gracefo-jpl /usr/bin/python3 bench/gracefo_jpl.py --exe build/ci/host_sim/ascorr",
    "by-hand": "by hand: edit docs/figures/by-hand.json (each entry says how it was measured)",
}

TARGET_NAMES = {"cortex-m4f": "M4F", "cortex-m3": "M3"}
NOT_TARGETS = {"earth_series", "estimator", "sun_learner", "host", "baseline", "flight_loop"}


class DataError(Exception):
    pass


def load(name):
    path = DATA / f"{name}.json"
    if not path.exists():
        return None
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except ValueError as e:
        raise DataError(f"{path.relative_to(ROOT)}: not JSON: {e}") from e
    for key in ("command", "date", "commit", "result"):
        if key not in data:
            raise DataError(f"{path.relative_to(ROOT)}: no key '{key}' (write it with tools/figures/record)")
    data["file"] = str(path.relative_to(ROOT))
    return data


def get(data, *keys):
    """data["result"][k0][k1]..., or DataError naming the file and the path."""
    node = data["result"]
    for i, k in enumerate(keys):
        if not isinstance(node, dict) or k not in node:
            raise DataError(f"{data['file']}: no key '{'.'.join(keys[:i + 1])}'")
        node = node[k]
    return node


def num(x, digits=None):
    """Integers with thin grouping (12,345), reals as given or to `digits` significant places."""
    if x is None:
        return "—"
    if isinstance(x, int) or (isinstance(x, float) and x.is_integer() and abs(x) >= 1000):
        return f"{int(x):,}"
    if digits is not None:
        return f"{x:.{digits}g}"
    return f"{x:g}"


def table(head, rows):
    out = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    out += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
    return out


def targets_of(data):
    return [k for k in data["result"] if k not in NOT_TARGETS]


def tname(t):
    return TARGET_NAMES.get(t, t)


def core_section(d):
    out = ["## The correction core", "",
           "Instructions per corrected solution, thermal + aberration with the Table 2 model unless said "
           "(QEMU -icount on the targets, callgrind on the host), against the baseline measured in the same "
           "run (plain double, Eigen, full trigonometry, `eraAb`); the error is the largest against the double "
           "core over the worked examples and 2000 random solutions. Budgets: "
           "[firmware.md](firmware.md#budgets).", ""]
    cols = []
    for t in targets_of(d):
        for s in get(d, t):
            if s in ("float", "fixed"):
                cols.append((t, s, f"{tname(t)} {s}"))
    for s in ("double", "float", "fixed"):
        cols.append(("host", s, f"host {s}"))
    rows = []
    for label, key in (("thermal + aberration", "instructions_per_solution"), ("aberration only", "aberration_only"),
                       ("thermal only", "thermal_only"), ("with a quadratic model", "both_quadratic_model"),
                       ("thermal only, quadratic model", "thermal_only_quadratic_model"),
                       ("validation + renormalisation alone", "validation_and_renormalisation_only"),
                       ("the lag stage of a lagged head (issue 40's budget: 1.2× with it)", "lag_stage"),
                       ("thermal + aberration with the lag stage, ratio", "with_lag_ratio"),
                       ("the Sun term of a head, folded into the thermal stage", "sun_term"),
                       ("thermal + aberration with the Sun term, ratio", "with_sun_ratio"),
                       ("combined attitude, per epoch of three heads", "combination_three_heads"),
                       ("combined attitude, error vs double (arcsec)", "combination_max_error_arcsec"),
                       ("ratio to the baseline", "baseline_ratio"), ("error vs double (arcsec)", "max_error_arcsec")):
        row = [label]
        for t, s, _ in cols:
            fig = get(d, t, s)
            v = fig.get(key)
            row.append(num(v, 2) if key == "max_error_arcsec" else num(v, 4) if key == "combination_max_error_arcsec" else (f"{v}×" if key in ("baseline_ratio", "with_lag_ratio", "with_sun_ratio") and v is not None else num(v)))
        rows.append(row)
    rows.append(["baseline"] + [num(get(d, t, "baseline", "instructions_per_solution")) for t, _, _ in cols])
    out += table([""] + [c for _, _, c in cols], rows)
    out += [""]
    mem_rows = []
    for t in targets_of(d):
        for k, v in get(d, t).items():
            if k.startswith("core_"):
                mem_rows.append([f"{tname(t)} {k[5:]}", f"{num(v['flash_bytes'])} B", f"{num(v['ram_bytes'])} B",
                                 f"≤ {num(v['stack_bytes'])} B"])
    out += ["The core's object in the flight scalar of each target (flash: .text + .rodata; stack: the sum of "
            "every frame in the object, an upper bound of any call chain in it):", ""]
    out += table(["core", "flash", "RAM", "stack"], mem_rows)
    return out + [""]


def series_section(d):
    s = get(d, "earth_series")
    n = s["interval_s"]
    out = ["## Earth series", "",
           "The on-board Earth ephemeris (`earth_series()`, double, software floating point on both targets) "
           f"per evaluation, and per second of flight when evaluated every {n} s and interpolated; flash is code "
           "and coefficient table, stack its own frames (plus libm's `sin`, `cos`, `remainder`).", ""]
    ts = [t for t in s if t != "interval_s"]
    rows = [["instructions per evaluation"] + [num(s[t]["instructions_per_evaluation"]) for t in ts],
            [f"per second of flight, every {n} s"] + [num(s[t]["instructions_per_flight_second"]) for t in ts],
            ["flash / stack"] + [f"{num(s[t]['flash_bytes'])} B / {num(s[t]['stack_bytes'])} B" for t in ts]]
    return out + table([""] + [tname(t) for t in ts], rows) + [""]


def flight_section(d):
    f = get(d, "flight_loop")
    ts = list(f)
    out = ["## The flight loop", "",
           "The flight image's own report under QEMU (`firmware/app/main.cpp`; instructions are SysTick counts "
           "× 40 under -icount): the velocity service's parts, its steady-state cost per 22 Hz cycle against the "
           "correction of three heads, and the run's worst cycle (its thermistor acquisition's settling waits "
           "included).", ""]
    rows = [
        ["velocity query, per solution"] + [num(f[t]["parts"]["query"]) for t in ts],
        ["state update (checks + ITRF → GCRS)"] + [num(f[t]["parts"]["state_update"]) for t in ts],
        ["node from a fresh state (force, Earth from its grid)"] + [num(f[t]["parts"]["node"]) for t in ts],
        ["RK4 step (in gaps / from an uplink)"] + [num(f[t]["parts"]["rk4_step"]) for t in ts],
        ["Earth series, once per minute"] + [num(f[t]["parts"]["earth_series"]) for t in ts],
        ["steady state per cycle, three heads: service / correction"] +
        [f"{num(f[t]['steady_state']['service'])} / {num(f[t]['steady_state']['correction'])}" for t in ts],
        ["worst cycle, SysTick counts (of the period)"] +
        [f"{num(f[t]['worst_cycle_systick'])} (of {num(f[t]['period_systick'])})" for t in ts],
        ["cycles / overruns"] + [f"{num(f[t]['cycles'])} / {num(f[t]['overruns'])}" for t in ts],
        ["stack high-water mark, painted (of the stack)"] +
        [f"{num(f[t]['stack']['high_water'])} B (of {num(f[t]['stack']['size'])} B)" for t in ts],
    ]
    return out + table([""] + [tname(t) for t in ts], rows) + [""]


def period_share(d, t, instructions):
    """ " (x % of a 22 Hz period)" when the flight loop's period is recorded (SysTick counts × 40)."""
    loop = d["result"].get("flight_loop", {}).get(t)
    if not loop:
        return ""
    return f" ({100 * instructions / (loop['period_systick'] * 40):.1f} % of a 22 Hz period)"


def estimator_section(d):
    e = get(d, "estimator")
    ts = [t for t in e if e[t] is not None]
    out = ["## The estimator", "",
           "The on-board estimator of the thermal model in the flight loop (its report; the correction is the "
           "loop's own, four heads per cycle, three in brackets).", ""]
    rows = [
        ["estimator per cycle, mean (model + feed; feed every 2nd cycle)"] + [num(e[t]["per_cycle"]) for t in ts],
        ["correction per cycle (three heads)"] +
        [f"{num(e[t]['correction_per_cycle'])} ({num(e[t]['correction_three_heads'])})" for t in ts],
        ["worst estimator cycle (a feed that closes an orbit)"] + [num(e[t]["worst_cycle"]) for t in ts],
        ["per-orbit update (double, idle time), per orbit"] +
        [f"{num(e[t]['per_orbit'])} in {e[t]['steps_per_orbit']} steps" for t in ts],
        ["worst idle step"] + [num(e[t]["worst_step"]) + period_share(d, t, e[t]["worst_step"]) for t in ts],
        ["estimator RAM (`sizeof(Estimator)`)"] + [f"{num(e[t]['ram_bytes'])} B" for t in ts],
    ]
    return out + table([""] + [tname(t) for t in ts], rows) + [""]


def side_learners_section(d):
    e = get(d, "sun_learner")
    r = d["result"]
    ts = list(e)
    # Each target's flight scalar: the one its core's memory is recorded for (core_<scalar>).
    flight = {t: next(k[len("core_"):] for k in r[t] if k.startswith("core_")) for t in ts}
    lag = {t: r[t][flight[t]] for t in ts}
    out = ["## The side learners", "",
           "The self-calibration's lag search (`calib/lag_search.hpp`, the core's scalar for the thermal stage, "
           "double for the IBAs) and Sun-term learner (`calib/sun_learner.hpp`, double), software floating point "
           "on both targets, measured alone by the target bench (the Sun learner is in the flight loop too). Per 22 Hz cycle, "
           "the mean over the cycles, against the estimator's per cycle: the lag search takes every fed cycle "
           "(every 2nd), the Sun learner one per interval; its solve runs after each orbit in idle time, a step "
           "at a time.", ""]

    def per_cycle(t, mean):
        base = (r.get("estimator", {}).get(t) or {}).get("per_cycle")
        if not base:
            return num(round(mean))
        share = f"{mean / base:.0f}×" if mean >= 2 * base else f"{100 * mean / base:.0f} % of"
        return f"{num(round(mean))} ({share} the estimator's)"
    rows = [
        ["the lag search, per fed cycle (the flight scalar)"] +
        [f"{num(lag[t]['lag_search_per_fed_cycle'])} ({flight[t]})" for t in ts],
        ["… per 22 Hz cycle"] + [per_cycle(t, lag[t]["lag_search_per_fed_cycle"] / 2) for t in ts],
        ["the Sun-term learner, per epoch taken"] + [num(e[t]["per_take"]) for t in ts],
        ["… per 22 Hz cycle, one taken per interval"] +
        [f"{per_cycle(t, e[t]['per_take'] / (22 * e[t]['interval_us'] * 1e-6))}, {e[t]['interval_us'] / 1e6:g} s"
         for t in ts],
        ["its solve per orbit (idle time" + (f"; of every {e[ts[0]]['warm_solves']}, one from the identity, "
                                              "the others from the last basis)" if "warm_solves" in e[ts[0]] else ")")] +
        [f"{num(e[t]['per_orbit'])} in {e[t]['steps_per_orbit']} steps ({e[t]['orbit_s']} s orbit)" for t in ts],
        ["… from the identity / from the last basis (the bench's mean)"] +
        [f"{num(e[t]['cold_solve'])} in {e[t]['cold_steps']} / {num(e[t]['warm_solve'])} in {e[t]['warm_steps']}"
         if "cold_solve" in e[t] else "—" for t in ts],
        ["… per 22 Hz cycle"] + [per_cycle(t, e[t]["per_orbit"] / (22 * e[t]["orbit_s"])) for t in ts],
        ["its worst idle step"] + [num(e[t]["worst_step"]) + period_share(d, t, e[t]["worst_step"]) for t in ts],
        ["RAM: the lag search, the Sun-term learner (`sizeof`)"] +
        [f"{num(lag[t]['lag_search_ram_bytes'])} B, {num(e[t]['ram_bytes'])} B" for t in ts],
        ["the Sun-term learner's stack (its entry's frames summed; callees in libgcc and libm not included)"] +
        [f"{num(e[t]['stack_bytes'])} B" for t in ts],
    ]
    return out + table([""] + [tname(t) for t in ts], rows) + [""]


def acquisition_section(d):
    r = d["result"]
    ts = list(r)
    cols = []
    for t in ts:
        for path in ("fixed", "float", "float_soft"):
            if path in r[t]:
                cols.append((t, path, f"{tname(t)} {'float (soft-float)' if path == 'float_soft' else path}"))
    out = ["## Thermistor acquisition", "",
           "Instructions per 1 Hz sample set of eight channels (QEMU -icount), the fixed-point HAL path against "
           "the float one in the same run (on a target without FPU, the float path in libgcc's soft float); "
           "the worst 22 Hz cycle of each flight image, waits included.", ""]
    rows = [["one acquisition: 8 × (1 + 9) conversions, medians, counts → °C, checks"] +
            [num(get(d, t, p, "acquire")) for t, p, _ in cols],
            ["of which counts → °C and checks"] + [num(get(d, t, p, "update")) for t, p, _ in cols],
            ["four heads' votes (every 22 Hz cycle)"] + [num(get(d, t, p, "heads")) for t, p, _ in cols]]
    out += table([""] + [c for _, _, c in cols], rows)
    out += [""]
    for t in ts:
        fixed, other = r[t]["fixed"]["acquire"], r[t].get("float", r[t].get("float_soft"))["acquire"]
        out.append(f"- {tname(t)}: fixed point / float per acquisition {fixed / other:.2f}; worst cycle "
                   f"{num(r[t]['worst_cycle_systick'])} SysTick counts of {num(r[t]['period_systick'])}.")
    return out + [""]


def row_order_section(d):
    r = d["result"]
    out = ["## Row order and time span", "",
           f"`ascorr correct` on {num(r['rows'])} rows (Table 2 model), wall time the median of three runs, as a "
           "ratio to the rows 1 s apart in time order measured in the same run; instructions per row by callgrind "
           f"on {num(r['callgrind_rows'])} rows.", ""]
    ipr = r["instructions_per_row"]
    rows = [["1 s apart, time order (the baseline)", f"{r['wall_s']['time_order']} s", "1", num(ipr["time_order"])],
            ["the same rows shuffled", f"{r['wall_s']['shuffled']} s", r["ratio"]["shuffled"], num(ipr["shuffled"])],
            ["spread over 30 years, time order", f"{r['wall_s']['span30y_time_order']} s",
             r["ratio"]["span30y_time_order"], "—"],
            ["spread over 30 years, shuffled", f"{r['wall_s']['span30y_shuffled']} s", r["ratio"]["span30y_shuffled"],
             num(ipr["span30y_shuffled"])]]
    return out + table(["rows", "wall", "ratio to time order", "instructions per row"], rows) + [""]


def states_section(d):
    r = d["result"]
    what = {"gnss2d": "2 days at 1 s, 3 heads, 1 Hz GCRS states",
            "uplink7d": "a week every 2 s, 3 heads, one uplinked state, `--max-propagation 604800`"}
    out = ["## Row order with states", "",
           "`ascorr correct --states` on rows without `vx,vy,vz` (Table 2 model): time order (the baseline of each "
           "feed), shuffled and reversed; median of three runs, wall and CPU time; instructions per row by "
           "callgrind on thinned copies over the same span.", ""]
    rows = []
    for feed, f in r.items():
        ipr = f["instructions_per_row"]
        rows.append([f"{what.get(feed, feed)} ({num(f['rows'])} rows)",
                     f"{f['wall_s']['time_order']} s wall, {f['cpu_s']['time_order']} s CPU",
                     f"{f['ratio']['shuffled']}× wall, {f['cpu_ratio']['shuffled']}× CPU",
                     f"{f['ratio']['reversed']}× wall, {f['cpu_ratio']['reversed']}× CPU",
                     f"{num(ipr['time_order'])} / {num(ipr['shuffled'])} / {num(ipr['reversed'])} "
                     f"({num(f['callgrind_rows'])} rows)"])
    return out + table(["feed", "time order", "shuffled", "reversed",
                        "instructions per row: time order / shuffled / reversed"], rows) + [""]


def self_calibration_memory_section(d):
    r = d["result"]
    out = ["## Self-calibration's memory", "",
           f"`ascorr correct --self-calibrate` on {num(r['rows'])} rows of A, B and C at 1 s ({num(r['file_mib'])} "
           "MiB of CSV), peak resident memory (maximum RSS) and wall time of one run: rows out of time order are "
           "sorted within 64 MiB, beyond it in sorted runs on a temporary file, so the shuffled rows cost about what "
           "plain `correct` does (was 140–190 B a row kept in memory: 1.75 GB for these rows).", ""]
    p, w = r["peak_rss_mib"], r["wall_s"]
    rows = [["time order", f"{num(p['time_order'])} MiB", f"{w['time_order']} s"],
            ["shuffled", f"{num(p['shuffled'])} MiB", f"{w['shuffled']} s"]]
    return out + table(["rows", "peak RSS", "wall"], rows) + [""]


def python_section(runs):
    out = ["## Python module", "",
           "`ascorr.correct` on arrays in memory against `ascorr correct` on the same rows as a CSV file and "
           "against the same correction written with pandas and pyerfa (`bench/python_correct.py`; three heads "
           "per epoch, Table 2 model, double); CPU time of all threads, best of three (pandas + pyerfa: one "
           "run), rows per second in wall time. Goals: the module ≥ 5× the command line, ≥ 100× pandas + pyerfa.",
           ""]
    rows = []
    for d in runs:
        r = d["result"]
        rows.append([f"{num(r['rows'])} rows, an epoch every {num(r['step_s'])} s",
                     f"{r['cli_cpu_s']} s CPU, {r['cli_rows_per_s'] / 1e6:.2f} M rows/s",
                     f"{r['python_cpu_s']} s CPU, {r['python_rows_per_s'] / 1e6:.2f} M rows/s",
                     f"{r['pandas_erfa_cpu_s']} s CPU, {r['pandas_erfa_rows_per_s'] / 1e6:.3f} M rows/s",
                     f"{r['ratio_cli_cpu']}× CPU, {r['ratio_cli_wall']}× wall",
                     f"{r['ratio_pandas_cpu']}× CPU, {r['ratio_pandas_wall']}× wall",
                     f"{r['pandas_max_diff_arcsec']:.1e}″"])
    return out + table(["data", "`ascorr correct`", "`ascorr.correct`", "pandas + pyerfa", "module vs command line",
                        "module vs pandas + pyerfa", "largest difference"], rows) + [""]


def gracefo_section(d):
    r = d["result"]
    out = ["## Real flight data: GRACE-FO against JPL", "",
           "The public GRACE-FO sample (`tests/data/gracefo`: 2023-06-01, 16.5 s of 2 Hz SCA1A records of three "
           "heads per satellite) through `import gracefo` (defaults), `align` (from QSA1B's 2018 mountings, one "
           "mean), `combine` and `interpolate` at SCA1B's times, against JPL's SCA1B (`bench/gracefo_jpl.py`; "
           "docs/ground.md, \"Real flight data\"). RMS about the mean: JPL's CRF and ascorr's differ by a "
           "constant rotation, removed. Bound in the tests: 3″ per axis.", ""]
    rows = []
    for sat in ("C", "D"):
        x = r[sat]
        rows.append([f"GRACE {sat}", str(x["epochs_compared"]),
                     " / ".join(f"{v:.2f}" for v in x["rms_about_mean_arcsec"]),
                     ", ".join(f"{h} {c:.2f} / {a:.1f}" for h, (c, a) in sorted(x["sigma_cross_about_arcsec"].items())),
                     ", ".join(f"{h} {v:.0f}″" for h, v in sorted(x["mounting_turn_arcsec"].items())),
                     f"{r['time_offset_rms_spread_arcsec'][sat]:.3f}″"])
    tried = ", ".join(f"{o:+g}" for o in r["time_offsets_tried_s"])
    return out + table(["satellite", "SCA1B epochs", "RMS x / y / z (arcsec)",
                        "σ across / about per head (arcsec, align)", "mountings turned by align",
                        f"RMS spread over time offsets {tried} s"], rows) + [""]


def by_hand_section(d):
    out = ["## Measured by hand", "",
           "Figures that no benchmark prints yet, each with how it was measured "
           f"([`by-hand.json`](figures/by-hand.json), {d['date']}, commit `{d['commit']}`); "
           "a benchmark that prints one replaces its entry.", ""]
    rows = [[e["topic"], e["what"], e["figure"], e["how"]] for e in get(d, "figures")]
    return out + table(["topic", "what", "figure", "how"], rows) + [""]


def page():
    loaded = {name: load(name) for name in SOURCES}
    out = ["# Measured figures", "",
           "<!-- Generated: do not edit. Regenerate from the data in docs/figures/: -->",
           f"Generated by `{REGENERATE}` (or `cmake --build <build> --target figures`) from the benchmarks' "
           "JSON in [`figures/`](figures/); do not edit by hand. To measure again, run the benchmark's command "
           "below (it rewrites its JSON), then regenerate. Instruction counts are exact for a build; wall times "
           "were taken on a shared 2-core machine and vary by ±30 % or more with its load.", ""]
    rows = []
    for name, how in SOURCES.items():
        d = loaded[name]
        if d is None:
            rows.append([f"`{name}.json`", "not recorded", "", f"`{how}`"])
        else:
            rows.append([f"[`{name}.json`](figures/{name}.json)", d["date"], f"`{d['commit']}`", f"`{how}`"])
    out += table(["data", "measured", "commit", "command"], rows)
    out += [""]
    tb = loaded["target-bench"]
    if tb is not None:
        out += core_section(tb) + series_section(tb)
        if "flight_loop" in tb["result"]:
            out += flight_section(tb)
        out += estimator_section(tb)
        if "sun_learner" in tb["result"]:
            out += side_learners_section(tb)
    if loaded["acquisition-bench"] is not None:
        out += acquisition_section(loaded["acquisition-bench"])
    if loaded["row-order"] is not None:
        out += row_order_section(loaded["row-order"])
    if loaded["row-order-states"] is not None:
        out += states_section(loaded["row-order-states"])
    if loaded["self-calibration-memory"] is not None:
        out += self_calibration_memory_section(loaded["self-calibration-memory"])
    py = [loaded[n] for n in ("python-correct-1s", "python-correct-60s") if loaded[n] is not None]
    if py:
        out += python_section(py)
    if loaded["gracefo-jpl"] is not None:
        out += gracefo_section(loaded["gracefo-jpl"])
    if loaded["by-hand"] is not None:
        out += by_hand_section(loaded["by-hand"])
    return "\n".join(out).rstrip("\n") + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--check", action="store_true", help="compare with docs/figures.md instead of writing it")
    ap.add_argument("--out", type=pathlib.Path, default=PAGE, help="where to write (default docs/figures.md)")
    a = ap.parse_args()
    try:
        text = page()
    except (DataError, KeyError, TypeError) as e:
        sys.exit(f"tools/figures/generate.py: {e}")
    if a.check:
        current = a.out.read_text(encoding="utf-8") if a.out.exists() else ""
        if current != text:
            sys.exit(f"{a.out}: not what docs/figures/*.json give: run {REGENERATE}")
        return
    a.out.write_text(text, encoding="utf-8")


if __name__ == "__main__":
    main()
