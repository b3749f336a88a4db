#!/usr/bin/env python3
"""Which model terms could follow the bench inside the orbit (issue 40, item 1),
measured before any is built.

For each simulated bench (`ascorr simulate --bench-lag --orbit-term
--noise-iba`, and a static one), today's default `fit` and `correct` are run,
and what they leave, the systematic IBA residual (the corrected IBA minus the
noise-only IBA, per pair and epoch; `stats --noise-iba`), is regressed per
pair on each family of candidate regressors over the first 75 % of the
epochs and measured on the last 25 % (held out), as `fit` selects its
quadratic terms. A family that a per-head model could carry takes the pair's
two heads' regressors, so the figure is what the best model of that family
could reach on the IBAs, an upper bound on its use; the noise (2 arcsec per
IBA) is not in the residual, so the held-out RMS is the systematic part alone.

The families:
  static    the temperatures again (T_CHU of the two heads, T029, T032): what
            today's model already took (a check of the method);
  rate      their rates, the central difference over the head's own rows;
  lag τ     L_τ(T) − T, a first-order filter of each temperature over the
            head's own rows (held through a gap), for τ from 300 s to 2700 s;
  lag       the τ whose training residual is smallest;
  sun       the Sun's direction in the orbital frame (v̂, the orbit normal
            n̂ and r̂ = v̂ × n̂; n̂ from two successive velocities), a low-
            precision solar ephemeris (Astronomical Almanac, 0.01 deg);
  sun v̂     its component along the velocity alone (no state: a row's own
            velocity and the date give it);
  phase     cos u, sin u, cos 2u, sin 2u of the argument of latitude u;
  phase·T   the same with amplitudes linear in T029 and T032;
  lag+sun   both.

    bench/inside_orbit_terms.py --exe build/ci/host_sim/ascorr [--days 300]

Prints a table per bench (held-out RMS per pair, arcsec) and, last, the JSON
of every figure.
"""
import argparse
import json
import math
import pathlib
import subprocess
import tempfile

import numpy as np
import pandas as pd

TAUS = (300.0, 600.0, 900.0, 1200.0, 1800.0, 2700.0)
PAIRS = (("A", "B"), ("A", "C"), ("B", "C"))
BENCHES = {
    "lag 900 s + orbit term 0.8\"": ["--bench-lag", "900", "--orbit-term", "0.8"],
    "lag 1800 s": ["--bench-lag", "1800"],
    "static": [],
}


def run(exe, *args):
    subprocess.run([str(exe), *map(str, args)], check=True, capture_output=True, text=True)


def boresight(q):
    w, x, y, z = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
    return np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], axis=1)


def sun_gcrs(t):
    """The Sun's direction (mean equator and equinox of date, within 0.3 deg of GCRS here)."""
    n = t / 86400.0
    g = np.radians(357.528 + 0.9856003 * n)
    lam = np.radians(280.460 + 0.9856474 * n) + np.radians(1.915) * np.sin(g) + np.radians(0.020) * np.sin(2 * g)
    eps = np.radians(23.439 - 4e-7 * n)
    return np.stack([np.cos(lam), np.cos(eps) * np.sin(lam), np.sin(eps) * np.sin(lam)], axis=1)


def lagged(t, x, tau):
    """L − x, L the first-order filter of x over the samples (held through gaps)."""
    out = np.empty_like(x)
    l = x[0]
    for k in range(len(x)):
        if k:
            l += -math.expm1(-(t[k] - t[k - 1]) / tau) * (x[k] - l)
        out[k] = l - x[k]
    return out


def head_series(raw, head):
    """A head's rows in time order with its temperatures, their rates and lags."""
    h = raw[raw.chu == head].sort_values("t").reset_index(drop=True)
    t = h.t.to_numpy()
    cols = {"key": h.key.to_numpy()}
    for c in ("t_chu", "t_029", "t_032"):
        x = h[c].to_numpy()
        cols[c] = x
        rate = np.full_like(x, np.nan)
        dt = t[2:] - t[:-2]
        ok = dt <= 180.0
        rate[1:-1][ok] = (x[2:] - x[:-2])[ok] / dt[ok]
        cols["rate_" + c] = rate
        for tau in TAUS:
            cols[f"lag{int(tau)}_" + c] = lagged(t, x, tau)
    return pd.DataFrame(cols)


def geometry(raw):
    """Per epoch: the Sun in the orbital frame and the argument of latitude."""
    e = raw.drop_duplicates("key").sort_values("t")
    t = e.t.to_numpy()
    v = e[["vx", "vy", "vz"]].to_numpy()
    v_hat = v / np.linalg.norm(v, axis=1)[:, None]
    n = np.cross(v[:-1], v[1:])
    n = np.vstack([n, n[-1:]])
    n /= np.linalg.norm(n, axis=1)[:, None]
    # Across a gap the two velocities are not a short arc: the normal from the
    # last short arc before it (the plane turns 1 deg a day at most).
    close = np.append(np.diff(t) <= 300.0, False)
    n = pd.DataFrame(np.where(close[:, None], n, np.nan)).ffill().bfill().to_numpy()
    r_hat = np.cross(v_hat, n)
    s = sun_gcrs(t)
    node = np.cross(np.array([0.0, 0.0, 1.0]), n)
    node /= np.linalg.norm(node, axis=1)[:, None]
    u = np.arctan2(np.einsum("ij,ij->i", r_hat, np.cross(n, node)), np.einsum("ij,ij->i", r_hat, node))
    return pd.DataFrame({
        "key": e.key.to_numpy(),
        "s_v": np.einsum("ij,ij->i", s, v_hat),
        "s_n": np.einsum("ij,ij->i", s, n),
        "s_r": np.einsum("ij,ij->i", s, r_hat),
        "cos_u": np.cos(u), "sin_u": np.sin(u), "cos_2u": np.cos(2 * u), "sin_2u": np.sin(2 * u),
    })


def residuals(corrected, noise):
    """Per pair: key → the corrected IBA minus the noise-only IBA (arcsec), clean epochs."""
    c = corrected[(corrected["flags"] == 0) & (corrected["confidence"] <= 5) & (corrected["status"] == 3)]  # `.flags` is pandas' own
    z = {h: pd.DataFrame(boresight(g[["qw", "qx", "qy", "qz"]].to_numpy()), index=g.key.to_numpy())
         for h, g in c.groupby("chu")}
    out = {}
    for a, b in PAIRS:
        za, zb = z[a].align(z[b], join="inner", axis=0)
        iba = np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", za.to_numpy(), zb.to_numpy()), -1, 1))) * 3600
        d = pd.DataFrame({"key": za.index.to_numpy(), "iba": iba})
        nz = noise[noise.pair == f"{a}-{b}"][["key", "iba"]].rename(columns={"iba": "noise"})
        d = d.merge(nz, on="key")
        out[(a, b)] = pd.DataFrame({"key": d.key, "y": d.iba - d.noise})
    return out


def held_out_rms(y, x, split):
    """RMS about the mean on the held-out part of y after least squares on [1, x] over the first part."""
    a = np.column_stack([np.ones(len(y)), x]) if x is not None else np.ones((len(y), 1))
    coef, *_ = np.linalg.lstsq(a[:split], y[:split], rcond=None)
    r = y[split:] - a[split:] @ coef
    train = y[:split] - a[:split] @ coef
    return float(np.std(r)), float(np.std(train))


def families(a, b):
    temps = lambda p: [f"{p}t_chu_{a}", f"{p}t_chu_{b}", f"{p}t_029_{a}", f"{p}t_032_{a}"]  # noqa: E731
    fam = {"none": None, "static": temps(""), "rate": temps("rate_")}
    for tau in TAUS:
        fam[f"lag {int(tau)}"] = temps(f"lag{int(tau)}_")
    fam["sun"] = ["s_v", "s_n", "s_r"]
    fam["sun v̂"] = ["s_v"]
    fam["phase"] = ["cos_u", "sin_u", "cos_2u", "sin_2u"]
    fam["phase·T"] = fam["phase"] + [f"{h}·{t}" for h in fam["phase"] for t in (f"t_029_{a}", f"t_032_{a}")]
    return fam


def study(raw, corrected, noise):
    geo = geometry(raw)
    heads = {h: head_series(raw, h) for h in ("A", "B", "C")}
    res = residuals(corrected, noise)
    table = {}
    for (a, b), r in res.items():
        d = r.merge(heads[a].add_suffix(f"_{a}").rename(columns={f"key_{a}": "key"}), on="key")
        d = d.merge(heads[b].add_suffix(f"_{b}").rename(columns={f"key_{b}": "key"}), on="key")
        d = d.merge(geo, on="key").sort_values("key")
        for p in ("cos_u", "sin_u", "cos_2u", "sin_2u"):
            for t in (f"t_029_{a}", f"t_032_{a}"):
                d[f"{p}·{t}"] = d[p] * d[t]
        fam = families(a, b)
        need = sorted({c for cols in fam.values() if cols for c in cols})
        d = d.dropna(subset=need)
        y = d.y.to_numpy()
        split = int(0.75 * len(y))
        row = {}
        for name, cols in fam.items():
            row[name] = held_out_rms(y, d[cols].to_numpy() if cols else None, split)
        best = min((k for k in row if k.startswith("lag ")), key=lambda k: row[k][1])
        row["lag"] = row[best]
        row["lag+sun"] = held_out_rms(y, d[fam[best] + fam["sun"]].to_numpy(), split)
        row["best τ"] = best
        table[f"{a}-{b}"] = row
    return table


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--exe", required=True, type=pathlib.Path)
    ap.add_argument("--days", type=float, default=300.0)
    ap.add_argument("--seed", type=int, default=40)
    args = ap.parse_args()
    report = {}
    with tempfile.TemporaryDirectory() as tmp:
        work = pathlib.Path(tmp)
        for bench, options in BENCHES.items():
            m = work / "m.csv"
            run(args.exe, "simulate", "--days", args.days, "--seed", args.seed, *options, "--noise-iba", "--out", m)
            run(args.exe, "fit", "--in", m, "--out", work / "model.csv", "--min-days", min(267.0, 0.9 * args.days))
            run(args.exe, "correct", "--in", m, "--model", work / "model.csv", "--out", work / "c.csv")
            cols = ["t", "chu", "t_chu", "t_029", "t_032", "vx", "vy", "vz", "flags", "confidence"]
            raw = pd.read_csv(m, usecols=cols)
            corrected = pd.read_csv(work / "c.csv", usecols=["t", "chu", "qw", "qx", "qy", "qz", "flags",
                                                             "confidence", "status"])
            noise = pd.read_csv(f"{m}.noise-iba.csv")
            for f in (raw, corrected, noise):
                f["key"] = np.rint(f.t.to_numpy() * 1000).astype(np.int64)
            table = study(raw, corrected, noise)
            report[bench] = table
            print(f"\n{bench}: held-out systematic IBA residual per pair, arcsec (training in brackets)")
            names = [k for k in next(iter(table.values())) if k != "best τ"]
            for name in names:
                cells = "  ".join(f"{table[p][name][0]:6.3f} ({table[p][name][1]:5.3f})" for p in table)
                print(f"  {name:9s} {cells}")
            print("  best τ   " + "  ".join(f"{table[p]['best τ']:>16s}" for p in table))
    print(json.dumps({b: {p: {k: (v[0] if isinstance(v, tuple) else v) for k, v in row.items()}
                          for p, row in t.items()} for b, t in report.items()}))


if __name__ == "__main__":
    main()
