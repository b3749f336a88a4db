#!/usr/bin/python3
"""Generates firmware/include/ascorr/earth_series_table.hpp: the coefficients of
the on-board Earth ephemeris series (firmware/include/ascorr/earth_series.hpp).

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

Run from the repository root (not by CI; the test against liberfa is):
    /usr/bin/python3 tools/earth_series/generate.py
Needs python3-erfa and python3-numpy (toolchain/debian-packages.txt). Takes
about a minute on the 2-core machine. Deterministic: same packages, same table.
"""
import argparse
import itertools
import subprocess
import sys

import erfa
import numpy as np

AU_KM = 149597870.7
DAY = 86400.0
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
        (ph, _), (_, vb) = erfa.epv00(2451545.0, ti / DAY)
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
        """Columns: per term, cos*tau^p, sin*tau^p (p = 0..DEGREE); the zero term has cos only."""
        tau = (t - self.tc) / self.hs
        cols = []
        for vec in terms:
            a = np.dot(vec, self.phase) + np.dot(vec, self.rate) * t
            c, s = np.cos(a), np.sin(a)
            for p in range(DEGREE + 1):
                cols.append(c * tau**p)
                if any(vec):
                    cols.append(s * tau**p)
        return np.array(cols).T

    def unpack(self, terms, coef):
        """Coefficients per term as [output][cos/sin][p]."""
        out, j = [], 0
        for vec in terms:
            cs = np.zeros((coef.shape[1], 2, DEGREE + 1))
            for p in range(DEGREE + 1):
                cs[:, 0, p] = coef[j]
                j += 1
                if any(vec):
                    cs[:, 1, p] = coef[j]
                    j += 1
            out.append(cs)
        return out


def fmt(x):
    return "%.17g" % x


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--target", type=float, default=1.0, help="largest velocity error on the fit grid, m/s")
    ap.add_argument("--target-au", type=float, default=1e-5, help="largest Sun distance error on the fit grid, au")
    ap.add_argument("--penalty", type=float, default=0.25, help="score divisor per order above one")
    ap.add_argument("--out", default="firmware/include/ascorr/earth_series_table.hpp")
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
    # (same greedy choice on the distance residual, to --target-au).
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
    coef_v, *_ = np.linalg.lstsq(a, v, rcond=None)
    coef = np.column_stack([coef_v, coef_r])
    # Order terms by their velocity amplitude (largest first; the zero term first).
    unpacked = basis.unpack(terms, coef)
    amp = [np.abs(c[:3]).max() for c in unpacked]
    order_idx = [0] + sorted(range(1, len(terms)), key=lambda i: -amp[i])
    terms = [terms[i] for i in order_idx]
    unpacked = [unpacked[i] for i in order_idx]

    # Check on a finer grid (quarter day, offset) over the span itself.
    tv = np.arange(FIRST_TT + 0.1 * DAY, LAST_TT, 0.25 * DAY)
    vv, rv = reference(tv)
    pred = basis.design(terms, tv) @ np.concatenate([pack(c, vec) for c, vec in zip(unpacked, terms)])
    dv = np.linalg.norm(pred[:, :3] - vv, axis=1) * 1000.0
    dr = np.abs(pred[:, 3] - rv)
    print("check (quarter day, %d epochs): |dv| max %.3f m/s rms %.3f m/s; |dr| max %.3g au" %
          (len(tv), dv.max(), np.sqrt((dv**2).mean()), dr.max()), file=sys.stderr)
    write_header(args.out, phase, rate, basis, terms, unpacked, dv.max(), dr.max())


def pack(cs, vec):
    rows = []
    for p in range(DEGREE + 1):
        rows.append(cs[:, 0, p])
        if any(vec):
            rows.append(cs[:, 1, p])
    return np.array(rows)


def name(vec):
    s = " ".join("%+d%s" % (k, SHORT[i]) for i, k in enumerate(vec) if k)
    return s if s else "secular"


def write_header(path, phase, rate, basis, terms, unpacked, dv_max, dr_max):
    used = [j for j in range(K) if any(vec[j] for vec in terms)]
    maxmul = {j: max(abs(vec[j]) for vec in terms) for j in used}
    lines = []
    w = lines.append
    w("// ascorr/earth_series_table.hpp: coefficients of the on-board Earth ephemeris")
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
    w("inline constexpr std::int8_t kPowerArgument[kPowers] = {%s};" % ", ".join(str(i) for i, _ in slots))
    w("inline constexpr std::int8_t kPowerMultiple[kPowers] = {%s};" % ", ".join(str(m) for _, m in slots))
    w("inline constexpr std::int8_t kPowerSlot[kArguments][kMaxMultiple] = {")
    for i, j in enumerate(used):
        row = [slots.index((i, m)) if (i, m) in slots else -1 for m in range(1, mm + 1)]
        w("    {%s},  // %s" % (", ".join(str(x) for x in row), SHORT[j]))
    w("};")
    w("")
    w("// Outputs of a term: v_x, v_y, v_z (km/s, ICRF axes), Sun distance (au).")
    w("inline constexpr int kOutputs = 4;")
    w("// Amplitude polynomial degree in tau.")
    w("inline constexpr int kDegree = %d;" % DEGREE)
    w("")
    w("// One term: argument theta = sum_j multiple[j] * argument_j, and for each")
    w("// output o the contribution sum_p tau^p (c[o][p] cos theta + s[o][p] sin theta).")
    w("struct Term {")
    w("    std::int8_t multiple[kArguments];")
    w("    double c[kOutputs][kDegree + 1];")
    w("    double s[kOutputs][kDegree + 1];")
    w("};")
    w("")
    w("// Term 0 is the secular part (theta = 0); the others by decreasing largest")
    w("// velocity coefficient. In each comment: the argument and that coefficient.")
    w("inline constexpr int kTerms = %d;" % len(terms))
    w("inline constexpr Term kTerm[kTerms] = {")
    for vec, cs in zip(terms, unpacked):
        w("    // %s: %.4g m/s" % (name(vec), 1000.0 * np.abs(cs[:3]).max()))
        w("    {{%s}," % ", ".join(str(vec[j]) for j in used))
        for part in (0, 1):
            w("     {")
            for o in range(4):
                w("         {%s}," % ", ".join(fmt(x) for x in cs[o, part]))
            w("     }%s" % ("," if part == 0 else "},"))
    w("};")
    w("")
    w("}  // namespace ascorr::earth_series_table")
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")
    subprocess.run(["clang-format", "-i", path], check=True)  # the repository's style (.clang-format)
    print("wrote %s: %d terms, %d arguments, %d powers" % (path, len(terms), len(used), len(slots)), file=sys.stderr)


if __name__ == "__main__":
    main()
