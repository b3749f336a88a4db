#!/usr/bin/env python3
"""Benchmark (not a test): ascorr.correct on N rows already in memory against
`ascorr correct` on the same rows as a CSV file, in one run, on the same machine.

    PYTHONPATH=build/ci/python python3 bench/python_correct.py --exe build/ci/host_sim/ascorr [--rows 1000000]

Rows: random unit quaternions of heads A, B and C at each epoch, one epoch
every --step seconds (1 s: the 1 Hz of Swarm's star-tracker products; 60 s is
`ascorr simulate`'s default), temperatures and spacecraft velocity present,
Table 2 model, double. The Earth's velocity is evaluated (eraEpv00, about
3.3e5 instructions) once per 600 s of data by both, so sparse data costs both
more per row. The command line's time includes reading and writing the files
(that is its job); the module's is the call alone (arrays in, arrays out).
Each is the best of --repeat runs, in wall time and in CPU time (all threads;
the machine may be shared, CPU time is the steadier figure). Prints a table
and a JSON line last: rows per second of each, and the ratios (goal: >= 10).
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

import numpy as np

import ascorr

ROOT = pathlib.Path(__file__).resolve().parents[1]


def rows(n, step, seed=1):
    rng = np.random.default_rng(seed)
    t = 4.6e8 + step * (np.arange(n) // 3)
    chu = np.array(["A", "B", "C"])[np.arange(n) % 3]
    q = rng.normal(size=(n, 4))
    q /= np.linalg.norm(q, axis=1)[:, None]
    temps = rng.uniform(-30, 40, (n, 3))
    v = rng.uniform(-7.6, 7.6, (n, 3))
    return t, chu, q, temps, v


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
    a = ap.parse_args()
    model_path = ROOT / "host_sim" / "data" / "model_table2.csv"
    model = ascorr.read_model(str(model_path))
    t, chu, q, temps, v = rows(a.rows, a.step)
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
    (cli, cli_cpu), (py, py_cpu) = cli, py
    print(f"{a.rows} rows ({mb:.0f} MB of CSV), an epoch every {a.step:g} s, best of {a.repeat}, "
          f"{os.cpu_count()} cores")
    print(f"  ascorr correct (CSV in, CSV out):   {cli:7.3f} s wall {a.rows / cli / 1e6:6.2f} M rows/s, "
          f"{cli_cpu:7.3f} s CPU")
    print(f"  ascorr.correct (arrays in memory):  {py:7.3f} s wall {a.rows / py / 1e6:6.2f} M rows/s, "
          f"{py_cpu:7.3f} s CPU")
    print(f"  ratio: {cli / py:.1f}x wall, {cli_cpu / py_cpu:.1f}x CPU (goal >= 10x)")
    print(json.dumps({"rows": a.rows, "step_s": a.step, "cli_s": round(cli, 4), "python_s": round(py, 4),
                      "cli_cpu_s": round(cli_cpu, 4), "python_cpu_s": round(py_cpu, 4),
                      "cli_rows_per_s": round(a.rows / cli), "python_rows_per_s": round(a.rows / py),
                      "ratio_wall": round(cli / py, 2), "ratio_cpu": round(cli_cpu / py_cpu, 2)}))


if __name__ == "__main__":
    sys.exit(main())
