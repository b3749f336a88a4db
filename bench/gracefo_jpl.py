#!/usr/bin/env python3
"""The worked example on real flight data (docs/ground.md, "Real flight data"),
measured: the public GRACE-FO sample (tests/data/gracefo) imported with the
defaults, aligned from QSA1B's mountings (one mean, 33 epochs), combined,
interpolated at SCA1B's times and compared with JPL's SCA1B, per satellite:
the RMS about the mean per CRF axis (the constant offset between ascorr's CRF
and JPL's removed), the epochs compared, the heads' noise align found and how
far it turned the 2018 mountings; and how well the sample determines a time
offset (tools/gracefo/calibrate_time_offset.py). Its last line is the JSON
that tools/figures/record keeps.

    bench/gracefo_jpl.py --exe build/ci/host_sim/ascorr
"""
import argparse
import csv
import json
import math
import pathlib
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tools" / "gracefo"))
import calibrate_time_offset as cal  # noqa: E402


def run(exe, *args):
    return subprocess.run([exe, *map(str, args)], check=True, capture_output=True, text=True)


def satellite(exe, data, work, sat):
    f = lambda p: data / f"{p}_{sat}_04.txt"  # noqa: E731
    w = lambda name: work / f"{name}_{sat}.csv"  # noqa: E731
    day = cal.DAY
    run(exe, "import", "gracefo", "--sca1a", f(f"SCA1A_{day}"), "--qsa1b", f("QSA1B_2018-05-22"), "--tim1b",
        f(f"TIM1B_{day}"), "--clk1b", f(f"CLK1B_{day}"), "--sca1b", f(f"SCA1B_{day}"), "--out", w("sol"),
        "--mountings", w("m"), "--reference", w("ref"))
    report = run(exe, "align", "--in", w("sol"), "--mountings", w("m"), "--out", w("m2"), "--min-epochs", 30,
                 "--noise-window", 0).stdout
    run(exe, "combine", "--in", w("sol"), "--mountings", w("m2"), "--out", w("comb"))
    run(exe, "interpolate", "--in", w("comb"), "--at", w("ref"), "--out", w("at"))
    with open(w("ref")) as a, open(w("at")) as b:
        pairs = [(r, x) for r, x in zip(csv.DictReader(a), csv.DictReader(b)) if x["qw"]]
    keys = ("qw", "qx", "qy", "qz")
    errors = [cal.error_arcsec([float(x[k]) for k in keys], [float(r[k]) for k in keys]) for r, x in pairs]
    turn = {}  # from align's report: head, epochs, then x +- sx, y +- sy, z +- sz
    for line in report.splitlines():
        parts = line.split()
        if parts and parts[0] in ("A", "B", "C") and len(parts) >= 11:
            turn[parts[0]] = round(math.sqrt(sum(float(parts[i]) ** 2 for i in (2, 5, 8))), 1)
    with open(w("m2")) as m:
        sigmas = {r["chu"]: [round(float(r["sigma_cross"]), 2), round(float(r["sigma_about"]), 1)]
                  for r in csv.DictReader(m)}
    return {"epochs_compared": len(errors), "rms_about_mean_arcsec": [round(x, 2) for x in cal.rms_about_mean(errors)],
            "sigma_cross_about_arcsec": sigmas, "mounting_turn_arcsec": turn}


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--exe", required=True)
    p.add_argument("--data", default=str(ROOT / "tests" / "data" / "gracefo"))
    a = p.parse_args()
    data = pathlib.Path(a.data)
    result = {}
    with tempfile.TemporaryDirectory() as d:
        work = pathlib.Path(d)
        for sat in cal.SATELLITES:
            result[sat] = satellite(a.exe, data, work, sat)
            print(sat, result[sat])
        offsets = (-1.0, -0.5, -0.28, 0.0, 0.5, 1.0)
        spread = {}
        for sat in cal.SATELLITES:
            found = {o: cal.errors_at(a.exe, data, work, sat, o) for o in offsets}
            common = set.intersection(*(set(found[o]) for o in offsets))
            rms = [math.sqrt(sum(x * x for x in cal.rms_about_mean([found[o][t] for t in sorted(common)])) / 3)
                   for o in offsets]
            spread[sat] = round(max(rms) - min(rms), 4)
        result["time_offset_rms_spread_arcsec"] = spread
        result["time_offsets_tried_s"] = list(offsets)
    print(json.dumps(result, sort_keys=True))


if __name__ == "__main__":
    main()
