#!/usr/bin/env python3
"""The default --time-offset of `ascorr import gracefo`, calibrated once on the
public sample (tests/data/gracefo; docs/ground.md, "Real flight data").

For each trial offset the sample of both satellites is imported with it,
aligned (from QSA1B's mountings, one mean: 33 epochs), combined, and compared
at its own epochs with SCA1B interpolated there (the epochs every trial can
compare): the RMS about the mean per CRF axis (the constant offset between
ascorr's CRF and JPL's removed). The offset that
minimises the RMS over both satellites and the three axes is printed with the
curve around it. Usage: calibrate_time_offset.py ASCORR_EXE [DATA_DIR]
"""
import csv
import math
import pathlib
import subprocess
import sys
import tempfile

SATELLITES = ("C", "D")
DAY = "2023-06-01"


def run(exe, *args):
    subprocess.run([exe, *map(str, args)], check=True, capture_output=True, text=True)


def read(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def qmul(a, b):
    w1, x1, y1, z1 = a
    w2, x2, y2, z2 = b
    return (w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2, w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
            w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2, w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2)


def error_arcsec(q, ref):
    """Rotation vector of q ⊗ ref* (arcsec), written out here, not ascorr's."""
    d = qmul(q, (ref[0], -ref[1], -ref[2], -ref[3]))
    if d[0] < 0:
        d = tuple(-c for c in d)
    s = math.sqrt(d[1] ** 2 + d[2] ** 2 + d[3] ** 2)
    k = 0.0 if s == 0 else 2 * math.atan2(s, d[0]) / s * 180 / math.pi * 3600
    return [c * k for c in d[1:]]


def slerp(a, b, u):
    """The rotation at constant rate from a to b, written out here (not ascorr's)."""
    if sum(x * y for x, y in zip(a, b)) < 0:
        b = [-x for x in b]
    d = qmul(b, (a[0], -a[1], -a[2], -a[3]))
    s = math.sqrt(d[1] ** 2 + d[2] ** 2 + d[3] ** 2)
    angle = 2 * math.atan2(s, d[0])
    k = 0.0 if s == 0 else math.sin(u * angle / 2) / s
    return qmul((math.cos(u * angle / 2), d[1] * k, d[2] * k, d[3] * k), a)


def errors_at(exe, data, work, sat, offset):
    """{t: error (arcsec, CRF x y z)} of the combined attitude at its own epochs
    against SCA1B interpolated there: SCA1B, fused with the gyros, is smooth, so
    interpolating it adds no noise and averages none away (interpolating the
    combination instead would average two epochs' noise by an amount that
    depends on the offset itself)."""
    f = lambda p: data / f"{p}_{sat}_04.txt"  # noqa: E731
    w = lambda name: work / f"{name}_{sat}.csv"  # noqa: E731
    run(exe, "import", "gracefo", "--sca1a", f(f"SCA1A_{DAY}"), "--qsa1b", f("QSA1B_2018-05-22"), "--tim1b",
        f(f"TIM1B_{DAY}"), "--clk1b", f(f"CLK1B_{DAY}"), "--sca1b", f(f"SCA1B_{DAY}"), "--out", w("sol"),
        "--mountings", w("m"), "--reference", w("ref"), "--time-offset", offset)
    run(exe, "align", "--in", w("sol"), "--mountings", w("m"), "--out", w("m2"), "--min-epochs", 30,
        "--noise-window", 0)
    run(exe, "combine", "--in", w("sol"), "--mountings", w("m2"), "--out", w("comb"))
    ref = [(float(r["t"]), [float(r[k]) for k in ("qw", "qx", "qy", "qz")]) for r in read(w("ref"))]
    out = {}
    for i, r in enumerate(read(w("comb"))):
        t = float(r["t"])
        j = next((j for j in range(1, len(ref)) if ref[j][0] >= t), None)
        if r["qw"] and j is not None and ref[j - 1][0] <= t:
            q_ref = slerp(ref[j - 1][1], ref[j][1], (t - ref[j - 1][0]) / (ref[j][0] - ref[j - 1][0]))
            out[i] = error_arcsec([float(r[k]) for k in ("qw", "qx", "qy", "qz")], q_ref)
    return out


def rms_about_mean(errors):
    """Per axis, the RMS about the mean of errors (a list of 3-vectors)."""
    mean = [sum(e[a] for e in errors) / len(errors) for a in range(3)]
    return [math.sqrt(sum((e[a] - mean[a]) ** 2 for e in errors) / len(errors)) for a in range(3)]


def main():
    exe = sys.argv[1]
    data = pathlib.Path(sys.argv[2] if len(sys.argv) > 2 else pathlib.Path(__file__).parents[2] / "tests/data/gracefo")
    trials = [round(-1.0 + 0.01 * i, 2) for i in range(121)]
    with tempfile.TemporaryDirectory() as d:
        work = pathlib.Path(d)
        found = {(o, sat): errors_at(exe, data, work, sat, o) for o in trials for sat in SATELLITES}
    # The same epochs for every trial: those SCA1B covers in every trial.
    common = {sat: set.intersection(*(set(found[(o, sat)]) for o in trials)) for sat in SATELLITES}
    curve = {}
    for o in trials:
        per = {sat: rms_about_mean([found[(o, sat)][t] for t in sorted(common[sat])]) for sat in SATELLITES}
        curve[o] = (math.sqrt(sum(x * x for sat in SATELLITES for x in per[sat]) / (3 * len(SATELLITES))), per)
    best = min(curve, key=lambda o: curve[o][0])
    print("epochs compared: " + ", ".join(f"{sat} {len(common[sat])}" for sat in SATELLITES))
    print("offset_s  rms_arcsec  (RMS about the mean per satellite, CRF x y z)")
    for o in trials:
        if abs(o - best) <= 0.1 + 1e-9 or round(o * 10) == o * 10:
            total, per = curve[o]
            text = "  ".join(f"{sat}: " + " ".join(f"{x:.2f}" for x in per[sat]) for sat in SATELLITES)
            print(f"{o:+.2f}  {total:.3f}  {text}{'  <- best' if o == best else ''}")
    print(f"best: {best:+.2f} s")


if __name__ == "__main__":
    main()
