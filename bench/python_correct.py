#!/usr/bin/env python3
"""Benchmark (not a test): ascorr.correct on N rows already in memory, against
`ascorr correct` on the same rows as a CSV file and against the same
correction written with pandas and pyerfa, in one run, on the same machine.

    PYTHONPATH=build/ci/python /usr/bin/python3 bench/python_correct.py --exe build/ci/host_sim/ascorr [--rows 1000000]

Rows: random unit quaternions of heads A, B and C at each epoch, one epoch
every --step seconds (1 s: the 1 Hz of Swarm's star-tracker products; 60 s is
`ascorr simulate`'s default), temperatures and spacecraft velocity present,
Table 2 model, double. The command line's time includes reading and writing
the files (that is its job); the module's is the call alone (arrays in, arrays
out); the pandas + pyerfa version's is the call on a DataFrame already in
memory (pandas_correct below: erfa.epv00 once per distinct epoch, erfa.ab per
row, the thermal stage as in docs/contract.md, in quaternions). Each is the
best of --repeat runs (the pandas one: one run), in wall time and in CPU time
(all threads; the machine may be shared, CPU time is the steadier figure). The
three must agree: status bits and the file's 15 decimals for the command line,
--max-diff arcsec for pandas + pyerfa (a different Earth ephemeris: ERFA's
eraEpv00 at each epoch against the module's table). Prints a table and a JSON
line last: rows per second of each, and the ratios (goals: >= 5x the command
line, >= 100x pandas + pyerfa).
"""

import argparse
import json
import os
import pathlib
import resource
import subprocess
import sys
import tempfile
import time

import erfa
import numpy as np
import pandas as pd

import ascorr

ROOT = pathlib.Path(__file__).resolve().parents[1]
ARCSEC = np.pi / 180 / 3600


def rows(n, step, seed=1):
    rng = np.random.default_rng(seed)
    t = 4.6e8 + step * (np.arange(n) // 3)
    chu = np.array(["A", "B", "C"])[np.arange(n) % 3]
    q = rng.normal(size=(n, 4))
    q /= np.linalg.norm(q, axis=1)[:, None]
    temps = rng.uniform(-30, 40, (n, 3))
    v = rng.uniform(-7.6, 7.6, (n, 3))
    return t, chu, q, temps, v


def qmul(a, b):
    """Hamilton products of (n, 4) quaternions, scalar first."""
    aw, ax, ay, az = a.T
    bw, bx, by, bz = b.T
    return np.stack([aw * bw - ax * bx - ay * by - az * bz, aw * bx + ax * bw + ay * bz - az * by,
                     aw * by - ax * bz + ay * bw + az * bx, aw * bz + ax * by - ay * bx + az * bw], axis=1)


def axis_rotation(axis, angle):
    """Quaternions whose matrix is the paper's elementary R1/R2/R3(angle), a
    rotation of the frame: Eigen's matrix of a turn by -angle about the axis."""
    q = np.zeros((len(angle), 4))
    q[:, 0] = np.cos(angle / 2)
    q[:, 1 + axis] = -np.sin(angle / 2)
    return q


def pandas_correct(df, coefficients):
    """docs/contract.md section 2 on a DataFrame (columns of a solutions file),
    with pyerfa: aberration, then the linear thermal model (coefficients:
    (heads, 3, >= 4) arcsec, the head's row by its index in ascorr.HEADS).
    Returns the corrected (n, 4) quaternions, w >= 0."""
    # The Earth's barycentric velocity and Sun distance, once per distinct epoch (TT taken for TDB).
    epochs = pd.Index(df["t"].unique())
    pvh, pvb = erfa.epv00(erfa.DJ00, epochs.to_numpy() / 86400.0)
    at = epochs.get_indexer(df["t"])
    v_earth = pvb["v"][at] * (erfa.DAU / 1e3 / 86400.0)  # au/d -> km/s
    sun_au = np.linalg.norm(pvh["p"], axis=1)[at]
    q = df[["qw", "qx", "qy", "qz"]].to_numpy()
    w, x, y, z = q.T
    # Aberration: the boresight (third row of R(q)) through eraAb, the smallest
    # rotation taking it there, applied on the inertial side (q * q_ab^-1).
    z_raw = np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], axis=1)
    beta = (v_earth + df[["vx", "vy", "vz"]].to_numpy()) / (erfa.CMPS / 1e3)
    bm1 = np.sqrt(1 - np.einsum("ij,ij->i", beta, beta))
    z_corr = erfa.ab(z_raw, beta, sun_au, bm1)
    axis = np.cross(z_raw, z_corr)
    sin_t = np.linalg.norm(axis, axis=1)
    theta = np.arctan2(sin_t, np.einsum("ij,ij->i", z_raw, z_corr))
    half = np.sin(theta / 2) / np.where(sin_t > 0, sin_t, 1)
    q_ab_inv = np.column_stack([np.cos(theta / 2), -half[:, None] * axis])
    q = qmul(q, q_ab_inv)
    # Thermal: angles per head and axis, R3(gamma) R2(beta) R1(alpha) on the CHU side.
    c = coefficients[df["chu"].map({h: i for i, h in enumerate(ascorr.HEADS)}).to_numpy()]
    t1, t2, t3 = (df[name].to_numpy() for name in ("t_chu", "t_029", "t_032"))
    regressors = np.stack([np.ones_like(t1), t1, t2 - t1, t3 - t1], axis=1)
    angles = np.einsum("nak,nk->na", c[:, :, :4], regressors) * ARCSEC
    q_th = qmul(qmul(axis_rotation(2, angles[:, 2]), axis_rotation(1, angles[:, 1])), axis_rotation(0, angles[:, 0]))
    q = qmul(q_th, q)
    q /= np.linalg.norm(q, axis=1)[:, None]
    return np.where(q[:, :1] < 0, -q, q)


def angle_arcsec(a, b):
    """Angles between the attitudes of two (n, 4) quaternion arrays."""
    return 2 * np.arcsin(np.clip(np.linalg.norm(qmul(a * [1, -1, -1, -1], b)[:, 1:], axis=1), 0, 1)) / ARCSEC


def best(fn, repeat):
    """(wall, cpu) seconds, each the least of repeat runs; cpu counts this
    process's threads and its children (the command line)."""
    walls, cpus = [], []
    for _ in range(repeat):
        r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
        c0 = time.process_time()
        t0 = time.perf_counter()
        fn()
        walls.append(time.perf_counter() - t0)
        r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpus.append(time.process_time() - c0 + (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime))
    return min(walls), min(cpus)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--exe", required=True, help="the ascorr executable")
    ap.add_argument("--rows", type=int, default=1_000_000)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--step", type=float, default=1.0, help="seconds between epochs (3 rows each)")
    ap.add_argument("--max-diff", type=float, default=1e-3,
                    help="arcsec allowed between pandas + pyerfa and the module")
    a = ap.parse_args()
    model_path = ROOT / "host_sim" / "data" / "model_table2.csv"
    model = ascorr.read_model(str(model_path))
    t, chu, q, temps, v = rows(a.rows, a.step)
    df = pd.DataFrame({"t": t, "chu": chu, "qw": q[:, 0], "qx": q[:, 1], "qy": q[:, 2], "qz": q[:, 3],
                       "t_chu": temps[:, 0], "t_029": temps[:, 1], "t_032": temps[:, 2],
                       "vx": v[:, 0], "vy": v[:, 1], "vz": v[:, 2]})
    with tempfile.TemporaryDirectory() as d:
        src = os.path.join(d, "solutions.csv")
        out = os.path.join(d, "corrected.csv")
        ascorr.write_solutions(src, t, chu, q, temps, v)
        mb = os.path.getsize(src) / 1e6
        cli = best(lambda: subprocess.run([a.exe, "correct", "--in", src, "--out", out, "--model", str(model_path)],
                                          check=True, capture_output=True), a.repeat)
        py = best(lambda: ascorr.correct(t, chu, q, temps, v, model=model), a.repeat)
        # The same answers: status bits equal, quaternions equal to the file's 15 decimals.
        c = ascorr.read_solutions(out)
        q_py, st_py = ascorr.correct(t, chu, q, temps, v, model=model)
        assert np.array_equal(c["status"], st_py) and np.max(np.abs(c["q"] - q_py)) <= 6e-16  # 15 decimals (5e-16) plus the reading back (half an ulp)
    assert (st_py == 3).all(), np.unique(st_py)
    result = {}
    pd_time = best(lambda: result.update(q=pandas_correct(df, model.coefficients)), 1)
    diff = float(angle_arcsec(result["q"], q_py).max())
    assert diff <= a.max_diff, f"pandas + pyerfa and the module differ by {diff} arcsec"
    (cli, cli_cpu), (py, py_cpu), (pe, pe_cpu) = cli, py, pd_time
    print(f"{a.rows} rows ({mb:.0f} MB of CSV), an epoch every {a.step:g} s, best of {a.repeat}, "
          f"{os.cpu_count()} cores")
    print(f"  ascorr correct (CSV in, CSV out):   {cli:7.3f} s wall {a.rows / cli / 1e6:6.2f} M rows/s, "
          f"{cli_cpu:7.3f} s CPU")
    print(f"  ascorr.correct (arrays in memory):  {py:7.3f} s wall {a.rows / py / 1e6:6.2f} M rows/s, "
          f"{py_cpu:7.3f} s CPU")
    print(f"  pandas + pyerfa (one run):          {pe:7.3f} s wall {a.rows / pe / 1e6:6.2f} M rows/s, "
          f"{pe_cpu:7.3f} s CPU; largest difference to the module {diff:.1e} arcsec")
    print(f"  module vs command line: {cli / py:.1f}x wall, {cli_cpu / py_cpu:.1f}x CPU (goal >= 5x)")
    print(f"  module vs pandas + pyerfa: {pe / py:.0f}x wall, {pe_cpu / py_cpu:.0f}x CPU (goal >= 100x)")
    print(json.dumps({"rows": a.rows, "step_s": a.step, "cli_s": round(cli, 4), "python_s": round(py, 4),
                      "pandas_erfa_s": round(pe, 4), "cli_cpu_s": round(cli_cpu, 4),
                      "python_cpu_s": round(py_cpu, 4), "pandas_erfa_cpu_s": round(pe_cpu, 4),
                      "cli_rows_per_s": round(a.rows / cli), "python_rows_per_s": round(a.rows / py),
                      "pandas_erfa_rows_per_s": round(a.rows / pe),
                      "ratio_cli_wall": round(cli / py, 2), "ratio_cli_cpu": round(cli_cpu / py_cpu, 2),
                      "ratio_pandas_wall": round(pe / py, 1), "ratio_pandas_cpu": round(pe_cpu / py_cpu, 1),
                      "pandas_max_diff_arcsec": diff}))


if __name__ == "__main__":
    sys.exit(main())
