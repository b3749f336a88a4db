#!/usr/bin/python3
"""Generates firmware/include/ascorr/nav/earth_series_table.hpp: the coefficients of
the on-board Earth ephemeris series (firmware/include/ascorr/nav/earth_series.hpp).

A least-squares fit of ERFA's eraEpv00 (python3-erfa) over the series' span
plus a margin: the Earth's barycentric velocity (BCRS/ICRF axes, km/s) and its
heliocentric distance (au), on a basis of cos/sin of integer combinations of
the IERS 2003 fundamental arguments (ERFA's fa*03 functions, linear parts),
each with a quadratic amplitude in the normalised time tau in [-1, 1].
The frequencies are chosen greedily: at each step, the candidate combination
that carries the most energy of the residual velocity (divided by a small
penalty for higher-order combinations, so that the physical term wins over an
alias of it) joins the basis, the whole basis is refitted, and the loop stops
when the largest velocity error on the fitting grid is below --target m/s.
The distance then gets the terms it needs beyond those (same choice on its
residual, to --target-au); the velocity does not use them. Last, per output,
the smallest coefficients are dropped while the sum of their largest
contributions stays within --prune-kms (each velocity component) or
--prune-au, and the others are refitted. The result is checked on a
quarter-day grid over the span and written, formatted with the repository's
.clang-format (clang-format).

Run by hand (not by CI; tests/test_earth_series.cpp checks the committed table
against liberfa), from anywhere:
    /usr/bin/python3 tools/earth_series/generate.py
Needs python3-erfa and python3-numpy (toolchain/debian-packages.txt) and
clang-format. About two minutes on the 2-core machine. Deterministic: same
packages, same table.
"""
import argparse
import itertools
import os
import subprocess
import sys

import erfa
import numpy as np

REPO = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))

sys.path.insert(0, os.path.join(REPO, "tools"))
from core_constants import core_constant  # noqa: E402

AU_KM = core_constant("kAstronomicalUnitKm")
DAY = core_constant("kSecondsPerDay")
JULIAN_CENTURY_S = 36525.0 * DAY

# Fundamental arguments (ERFA function, name in the header, what it is).
ARGUMENTS = [
    ("fave03", "Ve", "mean longitude of Venus"),
    ("fae03", "E", "mean longitude of the Earth(-Moon barycentre)"),
    ("fama03", "Ma", "mean longitude of Mars"),
    ("faju03", "J", "mean longitude of Jupiter"),
    ("fasa03", "Sa", "mean longitude of Saturn"),
    ("faur03", "U", "mean longitude of Uranus"),
    ("fane03", "Ne", "mean longitude of Neptune"),
    ("fad03", "D", "mean elongation of the Moon from the Sun"),
    ("fal03", "l", "mean anomaly of the Moon"),
    ("faf03", "F", "mean argument of latitude of the Moon"),
]
K = len(ARGUMENTS)
SHORT = [a[1] for a in ARGUMENTS]
INDEX = {s: i for i, s in enumerate(SHORT)}

# Span: 2000-01-01 00:00 TT .. 2051-01-01 00:00 TT, in TT seconds since J2000.0
# (J2000.0 = 2000-01-01 12:00 TT; 51 years with 13 leap days).
FIRST_TT = -0.5 * DAY
LAST_TT = FIRST_TT + (51 * 365 + 13) * DAY
MARGIN = 60.0 * DAY  # the fit extends this far beyond each end
DEGREE = 2  # amplitude polynomial degree in tau


def linear_arguments():
    """Phase at J2000.0 (rad) and rate (rad/s) of each fundamental argument:
    ERFA's value at t = 0 and a central difference (the quadratic and higher
    terms of the Delaunay arguments, <= 1e-4 rad over the span, are absorbed by
    the quadratic amplitudes)."""
    h = 1e-4  # Julian centuries
    phase, rate = [], []
    for fn, _, _ in ARGUMENTS:
        f = getattr(erfa, fn)
        d = np.angle(np.exp(1j * (f(h) - f(-h))))
        phase.append(float(f(0.0)))
        rate.append(float(d / (2 * h) / JULIAN_CENTURY_S))
    return np.array(phase), np.array(rate)


def reference(t):
    """eraEpv00 at TT seconds t (TDB = TT here): barycentric velocity km/s, Sun distance au."""
    v = np.empty((len(t), 3))
    r = np.empty(len(t))
    for i, ti in enumerate(t):
        (ph, _), (_, vb) = erfa.epv00(core_constant("kJ2000JulianDate"), ti / DAY)
        v[i] = vb
        r[i] = np.linalg.norm(ph)
    return v * (AU_KM / DAY), r


def candidates(rate):
    out = set()

    def add(d):
        v = [0] * K
        for s, k in d.items():
            v[INDEX[s]] += k
        if abs(np.dot(v, rate)) < 1e-14:
            return
        if np.dot(v, rate) < 0:
            v = [-x for x in v]
        out.add(tuple(v))

    for p in SHORT[:7]:
        for k in range(1, 7):
            add({p: k})
    for p in ["Ve", "Ma", "J", "Sa", "U", "Ne"]:  # perturbations of the Earth's orbit
        for a, b in itertools.product(range(-8, 9), repeat=2):
            if a and b:
                add({"E": a, p: b})
    for p, q in itertools.combinations(["J", "Sa", "U", "Ne"], 2):  # the Sun's reflex motion
        for a, b in itertools.product(range(-5, 6), repeat=2):
            if a and b:
                add({p: a, q: b})
    for a, b, c, d in itertools.product(range(-2, 3), range(-4, 5), range(-3, 4), range(-2, 3)):  # the Moon
        if b or c or d:
            add({"E": a, "D": b, "l": c, "F": d})
    for a, b, c in itertools.product(range(-4, 5), repeat=3):
        if a and b and c:
            add({"E": a, "Ve": b, "J": c})
            add({"E": a, "Ma": b, "J": c})
            add({"E": a, "Ve": b, "Ma": c})
    return sorted(out, key=lambda v: (sum(abs(x) for x in v), v))


class Basis:
    def __init__(self, phase, rate):
        self.phase, self.rate = phase, rate
        self.tc = 0.5 * (FIRST_TT + LAST_TT)
        self.hs = 0.5 * (LAST_TT - FIRST_TT)

    def design(self, terms, t):
        """Columns, BASES per term: tau^p cos(theta), tau^p sin(theta) for p = 0..DEGREE
        (column term * BASES + 2p + (0 cos, 1 sin)); the secular term's sines are zero."""
        tau = (t - self.tc) / self.hs
        cols = []
        for vec in terms:
            a = np.dot(vec, self.phase) + np.dot(vec, self.rate) * t
            c, s = (np.cos(a), np.sin(a)) if any(vec) else (np.ones_like(t), np.zeros_like(t))
            for p in range(DEGREE + 1):
                cols.append(c * tau**p)
                cols.append(s * tau**p)
        return np.array(cols).T


BASES = 2 * (DEGREE + 1)
OUTPUTS = ["v_x", "v_y", "v_z", "s"]


def prune(a, y, budget):
    """Least squares of y on the columns of a, then the smallest coefficients
    dropped while the sum of their largest contributions (|x_j| max|a_j|, a
    bound of the change anywhere in the span) stays within budget, then the
    kept ones refitted. Returns the coefficients (zero where dropped)."""
    x, *_ = np.linalg.lstsq(a, y, rcond=None)
    size = np.abs(x) * np.abs(a).max(0)
    keep = np.ones(len(x), bool)
    spent = 0.0
    for j in np.argsort(size):
        if size[j] == 0.0 or spent + size[j] <= budget:
            spent += size[j]
            keep[j] = False
    out = np.zeros(len(x))
    out[keep], *_ = np.linalg.lstsq(a[:, keep], y, rcond=None)
    return out


def fmt(x):
    return "%.17g" % x


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--target", type=float, default=0.8, help="largest velocity error on the fit grid, m/s")
    ap.add_argument("--target-au", type=float, default=1e-5, help="largest Sun distance error on the fit grid, au")
    ap.add_argument("--prune-kms", type=float, default=1e-3, help="budget of dropped coefficients per velocity axis, km/s")
    ap.add_argument("--prune-au", type=float, default=5e-6, help="budget of dropped distance coefficients, au")
    ap.add_argument("--penalty", type=float, default=0.25, help="score divisor per order above one")
    ap.add_argument("--out", default=os.path.join(REPO, "firmware", "include", "ascorr", "nav", "earth_series_table.hpp"))
    args = ap.parse_args()

    phase, rate = linear_arguments()
    basis = Basis(phase, rate)
    t = np.arange(FIRST_TT - MARGIN, LAST_TT + MARGIN, 1.0 * DAY)
    v, r = reference(t)
    cands = candidates(rate)
    cvec = np.array(cands, dtype=float)
    order = np.abs(cvec).sum(1)
    print("candidates: %d; fit grid: %d epochs" % (len(cands), len(t)), file=sys.stderr)

    terms = [tuple([0] * K)]
    while True:
        a = basis.design(terms, t)
        coef, *_ = np.linalg.lstsq(a, v, rcond=None)
        res = v - a @ coef
        err = np.linalg.norm(res, axis=1) * 1000.0
        if len(terms) > 1:
            print("%2d %-28s rms %.3f max %.3f m/s" % (len(terms) - 1, name(terms[-1]), np.sqrt((err**2).mean()),
                                                        err.max()), file=sys.stderr)
        if err.max() < args.target or len(terms) > 80:
            break
        score = np.zeros(len(cands))
        for s in range(0, len(cands), 400):
            ph = np.outer(t, cvec[s:s + 400] @ rate) + cvec[s:s + 400] @ phase
            score[s:s + 400] = ((np.cos(ph).T @ res)**2).sum(1) + ((np.sin(ph).T @ res)**2).sum(1)
        score /= 1.0 + args.penalty * (order - 1.0)
        for j in np.argsort(-score):
            if cands[j] not in terms:
                terms.append(cands[j])
                break

    # Sun distance on the same frequencies, plus those it needs beyond them
    # (same greedy choice on the distance residual, to --target-au); the
    # velocity keeps its own terms only.
    velocity_columns = len(terms) * BASES
    while True:
        a = basis.design(terms, t)
        coef_r, *_ = np.linalg.lstsq(a, r, rcond=None)
        res = r - a @ coef_r
        print("   %-28s Sun distance max %.3g au" % (name(terms[-1]), np.abs(res).max()), file=sys.stderr)
        if np.abs(res).max() < args.target_au or len(terms) > 80:
            break
        score = np.zeros(len(cands))
        for s in range(0, len(cands), 400):
            ph = np.outer(t, cvec[s:s + 400] @ rate) + cvec[s:s + 400] @ phase
            score[s:s + 400] = (np.cos(ph).T @ res)**2 + (np.sin(ph).T @ res)**2
        score /= 1.0 + args.penalty * (order - 1.0)
        for j in np.argsort(-score):
            if cands[j] not in terms:
                terms.append(cands[j])
                break
    # Coefficients per output, the negligible ones dropped (budgets per output:
    # --prune-kms for each velocity component, --prune-au for the distance).
    av = a[:, :velocity_columns]
    pad = np.zeros(a.shape[1] - velocity_columns)
    coef = np.column_stack([np.concatenate([prune(av, v[:, i], args.prune_kms), pad]) for i in range(3)] +
                           [prune(a, r, args.prune_au)])
    # Order terms by their largest velocity coefficient (the secular term first).
    amp = [np.abs(coef[k * BASES:(k + 1) * BASES, :3]).max() for k in range(len(terms))]
    order_idx = [0] + sorted(range(1, len(terms)), key=lambda i: -amp[i])
    terms = [terms[i] for i in order_idx]
    coef = np.concatenate([coef[k * BASES:(k + 1) * BASES] for k in order_idx])

    # Check on a finer grid (quarter day, offset) over the span itself.
    tv = np.arange(FIRST_TT + 0.1 * DAY, LAST_TT, 0.25 * DAY)
    vv, rv = reference(tv)
    pred = basis.design(terms, tv) @ coef
    dv = np.linalg.norm(pred[:, :3] - vv, axis=1) * 1000.0
    dr = np.abs(pred[:, 3] - rv)
    print("check (quarter day, %d epochs): |dv| max %.3f m/s rms %.3f m/s; |dr| max %.3g au; %d coefficients" %
          (len(tv), dv.max(), np.sqrt((dv**2).mean()), dr.max(), np.count_nonzero(coef)), file=sys.stderr)
    write_header(args.out, phase, rate, basis, terms, coef, dv.max(), dr.max(), (args.prune_kms, args.prune_au))


def name(vec):
    s = " ".join("%+d%s" % (k, SHORT[i]) for i, k in enumerate(vec) if k)
    return s if s else "secular"


def write_header(path, phase, rate, basis, terms, coef, dv_max, dr_max, args_prune):
    used = [j for j in range(K) if any(vec[j] for vec in terms)]
    maxmul = {j: max(abs(vec[j]) for vec in terms) for j in used}
    lines = []
    w = lines.append
    w("// ascorr/nav/earth_series_table.hpp: coefficients of the on-board Earth ephemeris")
    w("// series (earth_series.hpp). GENERATED by tools/earth_series/generate.py from")
    w("// ERFA eraEpv00 (python3-erfa %s); do not edit, regenerate:" % erfa.__version__)
    w("//     /usr/bin/python3 tools/earth_series/generate.py")
    w("// Fit check on a quarter-day grid over the span: |dv| <= %.3f m/s, |ds| <= %.2g au." % (dv_max, dr_max))
    w("#pragma once")
    w("")
    w("#include <cstdint>")
    w("")
    w("namespace ascorr::earth_series_table {")
    w("")
    w("// Span, TT seconds since J2000.0: 2000-01-01 00:00 TT .. 2051-01-01 00:00 TT.")
    w("inline constexpr double kFirstTt = %s;" % fmt(FIRST_TT))
    w("inline constexpr double kLastTt = %s;" % fmt(LAST_TT))
    w("// tau = (t - kCentreTt) * kInverseHalfSpanS, in [-1, 1] over the span.")
    w("inline constexpr double kCentreTt = %s;" % fmt(basis.tc))
    w("inline constexpr double kInverseHalfSpanS = 1.0 / %s;" % fmt(basis.hs))
    w("")
    w("// Fundamental arguments the terms use (IERS 2003, ERFA fa*03, linear parts):")
    w("// phase at J2000.0 (rad) and rate (rad per TT second).")
    w("inline constexpr int kArguments = %d;" % len(used))
    for i, j in enumerate(used):
        w("//  %d %-2s %s (%s)" % (i, SHORT[j], ARGUMENTS[j][2], ARGUMENTS[j][0]))
    w("inline constexpr double kPhaseRad[kArguments] = {")
    for j in used:
        w("    %s,  // %s" % (fmt(phase[j]), SHORT[j]))
    w("};")
    w("inline constexpr double kRateRadS[kArguments] = {")
    for j in used:
        w("    %s,  // %s" % (fmt(rate[j]), SHORT[j]))
    w("};")
    w("")
    w("// Powers exp(i*m*argument), m = 1 .. the largest |multiple| of that argument,")
    w("// in slots: slot p holds argument kPowerArgument[p] to kPowerMultiple[p]; a")
    w("// power m > 1 follows the slot of m - 1 of its argument. kPowerSlot[j][m - 1]")
    w("// is the slot of argument j to the power m (-1: not used).")
    slots = []
    for i, j in enumerate(used):
        for m in range(1, maxmul[j] + 1):
            slots.append((i, m))
    mm = max(maxmul.values())
    w("inline constexpr int kMaxMultiple = %d;" % mm)
    w("inline constexpr int kPowers = %d;" % len(slots))
    w("inline constexpr std::uint8_t kPowerArgument[kPowers] = {%s};" % ", ".join(str(i) for i, _ in slots))
    w("inline constexpr std::uint8_t kPowerMultiple[kPowers] = {%s};" % ", ".join(str(m) for _, m in slots))
    w("inline constexpr std::int16_t kPowerSlot[kArguments][kMaxMultiple] = {")
    for i, j in enumerate(used):
        row = [slots.index((i, m)) if (i, m) in slots else -1 for m in range(1, mm + 1)]
        w("    {%s},  // %s" % (", ".join(str(x) for x in row), SHORT[j]))
    w("};")
    w("")
    w("// The secular term (theta = 0) first, then by decreasing largest velocity")
    w("// coefficient, then the terms of the distance alone; in each comment the")
    w("// argument and that coefficient.")
    w("inline constexpr int kTerms = %d;" % len(terms))
    w("inline constexpr std::int16_t kMultiple[kTerms][kArguments] = {")
    for k, vec in enumerate(terms):
        big = 1000.0 * np.abs(coef[k * BASES:(k + 1) * BASES, :3]).max()
        size = "%.3g m/s" % big if big > 0.0 else "distance only, %.2g au" % np.abs(coef[k * BASES:(k + 1) * BASES,
                                                                                          3]).max()
        w("    {%s},  // %d: %s, %s" % (", ".join(str(vec[j]) for j in used), k, name(vec), size))
    w("};")
    w("")
    w("// Outputs: 0..2 v_x, v_y, v_z (km/s, ICRF axes), 3 Sun distance (au).")
    w("inline constexpr int kOutputs = 4;")
    w("// Amplitude polynomial degree in tau.")
    w("inline constexpr int kDegree = %d;" % DEGREE)
    w("// Bases of a term: b = 2p + f is tau^p cos(theta) (f = 0) or tau^p sin(theta) (f = 1).")
    w("inline constexpr int kBases = 2 * (kDegree + 1);")
    w("")
    w("// The coefficients that are not negligible (the others were dropped with a")
    w("// bound on the sum of their largest contributions: %.3g m/s per velocity" % (args_prune[0] * 1000.0))
    w("// component, %.3g au in distance; the kept ones refitted), by term: those of" % args_prune[1])
    w("// term k are kFirst[k] .. kFirst[k + 1] - 1. Coefficient n adds")
    w("// kValue[n] * basis (kCode[n] % kBases) to output kCode[n] / kBases.")
    nz = [(k, o, b, coef[k * BASES + b, o]) for k in range(len(terms)) for o in range(4) for b in range(BASES)
          if coef[k * BASES + b, o] != 0.0]
    first = [0]
    for k in range(len(terms)):
        first.append(first[-1] + sum(1 for e in nz if e[0] == k))
    w("inline constexpr int kCoefficients = %d;" % len(nz))
    w("inline constexpr std::int16_t kFirst[kTerms + 1] = {%s};" % ", ".join(str(x) for x in first))
    w("inline constexpr std::uint8_t kCode[kCoefficients] = {")
    for k in range(len(terms)):
        codes = [str(o * BASES + b) for kk, o, b, _ in nz if kk == k]
        w("    %s,  // term %d" % (", ".join(codes), k))
    w("};")
    w("inline constexpr double kValue[kCoefficients] = {")
    for k in range(len(terms)):
        w("    // term %d: %s" % (k, name(terms[k])))
        for kk, o, b, x in nz:
            if kk == k:
                w("    %s,  // %s tau^%d %s" % (fmt(x), OUTPUTS[o], b // 2, "sin" if b % 2 else "cos"))
    w("};")
    w("")
    w("}  // namespace ascorr::earth_series_table")
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")
    # The repository's style, wherever the output goes.
    style = os.path.join(REPO, ".clang-format")
    subprocess.run(["clang-format", "-i", "--style=file:" + style, path], check=True)
    print("wrote %s: %d terms, %d arguments, %d powers" % (path, len(terms), len(used), len(slots)), file=sys.stderr)


if __name__ == "__main__":
    main()
