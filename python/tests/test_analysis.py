"""iba, stats, fit and earth_velocity on arrays: against the command line on the
same file (stats, fit), a NumPy evaluation of the angles (iba) and pyerfa
(earth_velocity)."""

import json
import pathlib

import numpy as np
import pytest

import ascorr
from conftest import DATA, core_constant, read_csv_text, run_cli

T0 = 456148800.0  # the simulation's first epoch
DAY = core_constant("kSecondsPerDay")


@pytest.fixture(scope="module")
def mission(exe, tmp_path_factory):
    """40 simulated days, one solution per head every 120 s (a second or so)."""
    d = tmp_path_factory.mktemp("mission")
    path = d / "mission.csv"
    run_cli(exe, "simulate", "--out", path, "--days", 40, "--step", 120)
    return path


def as_args(d):
    return d["t"], d["chu"], d["q"], d["temps"], d["v"]


def test_fit_on_arrays_is_ascorr_fit(exe, mission, tmp_path):
    out = tmp_path / "model.csv"
    run_cli(exe, "fit", "--in", mission, "--out", out, "--min-days", 30, "--lag", 0)  # auto: the lag's test
    d = ascorr.read_solutions(str(mission))
    model, report = ascorr.fit(*as_args(d), d["flags"], d["confidence"], min_days=30, lag=0)
    assert model.to_csv() == out.read_text()
    assert report["orbits_used"] > 100 and report["condition"] > 1.0
    assert report["residual_rms"].shape == (3, 3)
    written = tmp_path / "written.csv"
    model.write(str(written))
    assert written.read_text() == out.read_text()
    assert ascorr.read_model(str(written)).to_csv() == model.to_csv()


def test_fit_with_mountings_is_ascorr_fit_and_names_its_rule(exe, mission, tmp_path):
    """The rule for the rotation common to all heads: mountings= as --mountings
    (rule 'combined'), common_rotation= as --common-rotation; the model says
    which, and survives pickling and its file."""
    import pickle

    mountings_path = str(mission) + ".mountings.csv"
    out = tmp_path / "model.csv"
    run_cli(exe, "fit", "--in", mission, "--out", out, "--min-days", 30, "--mountings", mountings_path, "--lag", 0)
    d = ascorr.read_solutions(str(mission))
    m = ascorr.read_mountings(mountings_path)
    model, report = ascorr.fit(*as_args(d), d["flags"], d["confidence"], min_days=30, mountings=m, lag=0)
    assert model.to_csv() == out.read_text()
    assert model.common_rotation == "combined" and report["common_rotation"] == "combined"
    assert ascorr.read_model(str(out)).common_rotation == "combined"
    assert pickle.loads(pickle.dumps(model)) == model
    plain, report = ascorr.fit(*as_args(d), d["flags"], d["confidence"], min_days=30, lag=0)
    assert plain.common_rotation == "smallest" and plain != model
    rigid, _ = ascorr.fit(*as_args(d), d["flags"], d["confidence"], min_days=30, common_rotation="rigid-B", lag=0)
    assert rigid.common_rotation == "rigid-B"
    # The rule changes no IBA: the thermal-corrected stats are the same.
    a = ascorr.stats(*as_args(d), d["flags"], d["confidence"], model=model)
    b = ascorr.stats(*as_args(d), d["flags"], d["confidence"], model=plain)
    for pair in ("A-B", "A-C", "B-C"):
        assert a["pairs"][pair]["thermal"] == pytest.approx(b["pairs"][pair]["thermal"], abs=1e-4)  # 2nd order
    with pytest.raises(ValueError, match="common_rotation"):
        ascorr.fit(*as_args(d), min_days=30, common_rotation="largest")
    with pytest.raises(ascorr.FitRefused, match="needs the mountings"):
        ascorr.fit(*as_args(d), min_days=30, common_rotation="combined")
    # Self-calibration with the same mountings: the rule on board, the IBAs its own.
    q1, s1, h1 = ascorr.self_calibrate(*as_args(d), d["flags"], d["confidence"], mountings=m)
    q0, s0, h0 = ascorr.self_calibrate(*as_args(d), d["flags"], d["confidence"])
    assert (s1 == s0).all() and not np.array_equal(q1, q0)
    # The same candidates adopted at the same times; between them, re-gauged versions.
    assert {m["tt_us"] for m in h0} <= {m["tt_us"] for m in h1} and len(h1) > len(h0)
    with pytest.raises(ValueError, match="mountings.*no sigma_cross"):
        ascorr.self_calibrate(*as_args(d), mountings=dict(m, sigma_cross=None, sigma_about=None))


def test_fit_refuses_too_short_a_period(mission):
    d = ascorr.read_solutions(str(mission))
    with pytest.raises(ascorr.FitRefused, match="modelling period too short"):
        ascorr.fit(*as_args(d), d["flags"], d["confidence"])  # 40 days < 267
    with pytest.raises(ascorr.FitRefused, match="empty"):
        ascorr.fit(*as_args(d), t_from=T0 + 10, t_to=T0)


@pytest.mark.parametrize("period", [(None, None), (T0 + 5 * DAY, T0 + 20 * DAY)])
def test_stats_on_arrays_is_ascorr_stats(exe, mission, period):
    model_path = DATA / "model_table2.csv"
    options = ["--model", model_path, "--json"]
    if period[0] is not None:
        options += ["--from", repr(period[0]), "--to", repr(period[1])]
    cli = json.loads(run_cli(exe, "stats", "--in", mission, *options).stdout)
    d = ascorr.read_solutions(str(mission))
    s = ascorr.stats(*as_args(d), d["flags"], d["confidence"], model=ascorr.read_model(str(model_path)),
                     t_from=period[0], t_to=period[1])
    for pair, want in cli["pairs"].items():
        got = s["pairs"][pair]
        assert got["n"] == want["n"] > 1000
        for stage in ("original", "aberration", "thermal"):
            assert f"{got[stage]:.6f}" == f"{want[stage]:.6f}", (pair, stage)
    assert s["clean_rows"] > 0 and "A-B" in s["table"]


def test_stats_noise_iba_is_ascorr_stats_and_numpy(exe, tmp_path):
    """noise_iba= as --noise-iba: the systematic residual per pair and stage is
    the command line's, and its original stage is NumPy's IBA minus the
    noise-only IBA at the same t, RMS about the mean (a bench lagging by 900 s:
    a residual well above zero). A malformed file names its line."""
    import pandas as pd

    path = tmp_path / "lag.csv"
    run_cli(exe, "simulate", "--out", path, "--days", 6, "--step", 120, "--bench-lag", 900, "--noise-iba")
    noise = pathlib.Path(str(path) + ".noise-iba.csv")
    cli = json.loads(run_cli(exe, "stats", "--in", path, "--noise-iba", noise, "--json").stdout)
    d = ascorr.read_solutions(str(path))
    s = ascorr.stats(*as_args(d), d["flags"], d["confidence"], noise_iba=noise)
    assert "systematic" not in ascorr.stats(*as_args(d), d["flags"], d["confidence"])
    assert list(s["systematic"]) == list(cli["systematic"]) == ["A-B", "A-C", "B-C"]
    assert "systematic IBA residual" in s["table"]
    ibas = ascorr.iba(d["t"], d["chu"], d["q"])
    n = pd.read_csv(noise)
    for pair, want in cli["systematic"].items():
        got = s["systematic"][pair]
        assert got["n"] == want["n"] > 1000 and got["thermal"] is None and want["thermal"] is None
        for stage in ("original", "aberration"):
            assert f"{got[stage]:.6f}" == f"{want[stage]:.6f}", (pair, stage)
        t, iba = ibas[pair]
        ref = n[n["pair"] == pair].set_index(np.round(n[n["pair"] == pair]["t"] * 1000).astype(np.int64))["iba"]
        key = np.round(t * 1000).astype(np.int64)
        both = np.isin(key, ref.index)
        assert both.sum() == got["n"]  # every simulated row is clean
        r = iba[both] - ref.loc[key[both]].to_numpy()
        assert got["original"] == pytest.approx(np.std(r), abs=2e-6) and got["original"] > 0.05
    bad = tmp_path / "bad-noise.csv"
    bad.write_text(noise.read_text().replace("A-C", "A-X", 1))
    with pytest.raises(ascorr.InputError, match=r"bad-noise.csv:\d+"):
        ascorr.stats(*as_args(d), noise_iba=bad)
    with pytest.raises(ValueError, match="argument 'noise_iba': expected a path"):
        ascorr.stats(*as_args(d), noise_iba=3)
    with pytest.raises(ValueError, match="argument 'noise_iba': an empty path names no file"):
        ascorr.stats(*as_args(d), noise_iba="")


def test_iba_against_numpy(mission):
    d = ascorr.read_solutions(str(mission))
    got = ascorr.iba(d["t"], d["chu"], d["q"])
    w, x, y, z = d["q"].T
    z_icrf = np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), w * w - x * x - y * y + z * z], axis=1)
    key = np.round(d["t"] * 1000).astype(np.int64)
    for pair, (a, b) in {"A-B": ("A", "B"), "A-C": ("A", "C"), "B-C": ("B", "C")}.items():
        ia = {k: i for i, k in enumerate(key) if d["chu"][i] == a}
        ib = {k: i for i, k in enumerate(key) if d["chu"][i] == b}
        common = sorted(set(ia) & set(ib))
        za = z_icrf[[ia[k] for k in common]]
        zb = z_icrf[[ib[k] for k in common]]
        ref = np.degrees(np.arctan2(np.linalg.norm(np.cross(za, zb), axis=1), np.sum(za * zb, axis=1))) * 3600
        t, angle = got[pair]
        assert len(t) == len(common) > 1000
        assert np.array_equal(t, d["t"][[ia[k] for k in common]])
        assert np.max(np.abs(angle - ref)) < 1e-6  # arcsec


def test_iba_and_stats_in_any_row_order(mission):
    """Shuffled rows give the same epochs: an epoch is never handed on before
    every head's rows are known (before, a shuffle lost a few)."""
    d = ascorr.read_solutions(str(mission))
    ref_iba = ascorr.iba(d["t"], d["chu"], d["q"])
    ref_stats = ascorr.stats(*as_args(d), d["flags"], d["confidence"])
    for seed in (1, 2, 3):
        p = np.random.default_rng(seed).permutation(len(d["t"]))
        s = {k: v[p] for k, v in d.items() if isinstance(v, np.ndarray) and len(v) == len(p)}
        got = ascorr.iba(s["t"], s["chu"], s["q"])
        assert list(got) == list(ref_iba)
        for pair, (t, angle) in ref_iba.items():
            assert np.array_equal(got[pair][0], t) and np.array_equal(got[pair][1], angle), (seed, pair)
        st = ascorr.stats(*as_args(s), s["flags"], s["confidence"])
        for pair, want in ref_stats["pairs"].items():
            assert st["pairs"][pair]["n"] == want["n"], (seed, pair)
            assert st["pairs"][pair]["aberration"] == want["aberration"], (seed, pair)


def test_iba_duplicate_epoch_is_an_input_error(mission):
    d = ascorr.read_solutions(str(mission))
    chu = d["chu"].copy()
    chu[1] = chu[0]  # two rows of one head at the first epoch
    with pytest.raises(ascorr.InputError, match="second solution of CHU A"):
        ascorr.iba(d["t"], chu, d["q"])
    # A row of the first epoch of every head again, last: refused as well
    # (its epoch was complete, and handed on, long before).
    t = d["t"]
    values, counts = np.unique(t, return_counts=True)
    k = np.flatnonzero(t == values[counts == 3][0])[0]
    with pytest.raises(ascorr.InputError, match=f"second solution of CHU {d['chu'][k]}.*first is on line {k + 1}"):
        ascorr.iba(np.append(t, t[k]), np.append(d["chu"], d["chu"][k]), np.vstack([d["q"], d["q"][k]]))


def test_earth_velocity_against_pyerfa():
    erfa = pytest.importorskip("erfa")  # python3-erfa (toolchain/debian-packages.txt)
    t = np.linspace(0.0, 25 * 365.25 * DAY, 2001) + 123.456
    au_per_day = core_constant("kAstronomicalUnitKm") / DAY
    pvh, pvb = erfa.epv00(core_constant("kJ2000JulianDate"), t / DAY)
    v_ref = pvb["v"] * au_per_day
    d_ref = np.linalg.norm(pvh["p"], axis=1)
    v, dist = ascorr.earth_velocity(t, exact=True)
    assert np.max(np.abs(v - v_ref)) < 1e-9 and np.max(np.abs(dist - d_ref)) < 1e-12
    v, dist = ascorr.earth_velocity(t)  # the series the correction uses
    assert np.max(np.abs(v - v_ref)) < 1e-7  # km/s: below 4e-8 arcsec of aberration
    assert np.max(np.abs(dist - d_ref)) < 1e-9


def test_four_heads_fit_stats_and_iba_are_the_command_lines(exe, tmp_path):
    """A mission of heads A-D (simulate --heads ABCD): fit, stats and iba return
    every head and its six pairs, as the command line does."""
    path = tmp_path / "four.csv"
    run_cli(exe, "simulate", "--out", path, "--days", 40, "--step", 120, "--heads", "ABCD")
    out = tmp_path / "model.csv"
    run_cli(exe, "fit", "--in", path, "--out", out, "--min-days", 30, "--lag", 0)
    d = ascorr.read_solutions(str(path))
    model, report = ascorr.fit(*as_args(d), d["flags"], d["confidence"], min_days=30, lag=0)
    assert model.to_csv() == out.read_text() and model.heads == "ABCD"
    assert report["heads"] == "ABCD" and report["residual_rms"].shape == (4, 3)
    six = ["A-B", "A-C", "A-D", "B-C", "B-D", "C-D"]
    cli = json.loads(run_cli(exe, "stats", "--in", path, "--model", out, "--json").stdout)
    s = ascorr.stats(*as_args(d), d["flags"], d["confidence"], model=model)
    assert list(cli["pairs"]) == list(s["pairs"]) == six
    for pair, want in cli["pairs"].items():
        assert s["pairs"][pair]["n"] == want["n"] > 1000
        assert f"{s['pairs'][pair]['thermal']:.6f}" == f"{want['thermal']:.6f}", pair
    assert list(ascorr.iba(d["t"], d["chu"], d["q"])) == six


def test_a_mission_without_c_is_fitted_on_its_heads_as_the_command_line(exe, tmp_path):
    """Heads A, B and D flew (no C): the default fit is refused naming C and the
    keywords that fit the others; frame_heads and heads give the command line's
    model byte for byte; bad head letters are refused naming the keyword."""
    path = tmp_path / "abd.csv"
    run_cli(exe, "simulate", "--out", path, "--days", 40, "--step", 120, "--heads", "ABD")
    d = ascorr.read_solutions(str(path))
    with pytest.raises(ascorr.FitRefused, match=r"C has no rows there: heads and frame_heads name the heads "
                                               r"to fit \(e\.g\. heads='ABD' frame_heads='AD'\)"):
        ascorr.fit(*as_args(d), d["flags"], d["confidence"], min_days=30)
    out = tmp_path / "model.csv"
    run_cli(exe, "fit", "--in", path, "--out", out, "--min-days", 30, "--heads", "ABD", "--frame-heads", "AD",
            "--lag", 0)
    model, report = ascorr.fit(*as_args(d), d["flags"], d["confidence"], min_days=30, lag=0, heads="ABD",
                               frame_heads="AD")
    assert model.to_csv() == out.read_text() and model.heads == "ABD"
    assert report["heads"] == "ABD" and report["residual_rms"].shape == (3, 3)
    assert "frame F of heads A and D" in report["text"]
    with pytest.raises(ascorr.FitRefused, match=r"heads='ABD': frame F's heads AC are not among them"):
        ascorr.fit(*as_args(d), d["flags"], d["confidence"], min_days=30, heads="ABD")
    for keyword, value in [("frame_heads", "CA"), ("frame_heads", "ABC"), ("frame_heads", 2), ("heads", "A"),
                           ("heads", "ABE"), ("heads", b"AB")]:
        with pytest.raises(ValueError, match=f"argument '{keyword}': expected .* of the heads ABCD"):
            ascorr.fit(*as_args(d), d["flags"], d["confidence"], min_days=30, **{keyword: value})


def test_model_terms_are_the_model_files_columns():
    # ascorr.MODEL_TERMS comes from the core's table (ascorr/core/model_terms.hpp):
    # the coefficients' last axis and the model file's columns after chu, axis.
    terms = ascorr.MODEL_TERMS
    assert terms[0] == "c0" and len(terms) == len(set(terms)) and all(isinstance(t, str) for t in terms)
    c = np.zeros((len(ascorr.HEADS), 3, len(terms)))
    c[1, 2, -1] = 1.5  # the last term: a quadratic one, so the file carries every column
    model = ascorr.Model(c)
    assert model.coefficients.shape == (len(ascorr.HEADS), 3, len(terms)) and model.quadratic
    assert model.to_csv().splitlines()[0] == ",".join(("chu", "axis") + terms)
    linear = ascorr.Model(np.zeros((len(ascorr.HEADS), 3, 4)))
    assert linear.to_csv().splitlines()[0] == ",".join(("chu", "axis") + terms[:4])


@pytest.fixture(scope="module")
def lag_mission(exe, tmp_path_factory):
    """30 days of a bench that lags its thermistors by 1800 s, a solution per head every 120 s."""
    d = tmp_path_factory.mktemp("lag_mission")
    path = d / "lag.csv"
    run_cli(exe, "simulate", "--out", path, "--days", 30, "--step", 120, "--bench-lag", 1800)
    return path


@pytest.fixture(scope="module")
def lag_learnt_mission(exe, tmp_path_factory):
    """50 days of a bench that lags by 1800 s, every 240 s (seed 40): the search decides after 30."""
    path = tmp_path_factory.mktemp("lag_learnt") / "lag.csv"
    run_cli(exe, "simulate", "--out", path, "--days", 50, "--step", 240, "--seed", 40, "--bench-lag", 1800)
    return path


def test_self_calibrate_lag_auto_is_ascorr_correct_self_calibrate_lag_auto(exe, lag_learnt_mission, tmp_path):
    """lag='auto' as correct --self-calibrate --lag auto: the lag learnt as the estimator runs,
    the same corrections to the bit and the same lag per model; a lagged model to start from
    is refused."""
    d, q, hist, h_header, h_rows = self_calibrated_as_by_the_cli(exe, lag_learnt_mission, tmp_path, "auto")
    assert h_header[-1] == "lag_s" and len(h_rows) == 9 * len(hist)
    lags = [a["model"].lag_s[0] for a in hist]
    assert [float(r[-1]) for r in h_rows[::9]] == lags
    assert lags[0] == 0.0 and lags[-1] > 0.0, lags  # none at first, then the lag learnt
    # Mutation: with the lag never taken (given as none) the corrections differ.
    q_none, _, _ = ascorr.self_calibrate(*as_args(d), d["flags"], d["confidence"], lag=0)
    assert np.abs(q_none - q).max() > 1e-9
    with pytest.raises(ValueError, match="lag='auto' learns it from none"):
        ascorr.self_calibrate(*as_args(d), model=hist[-1]["model"], lag="auto")


def test_self_calibrate_sun_term_auto_is_ascorr_correct_self_calibrate_sun_term_auto(exe, sun_mission, tmp_path):
    """sun_term='auto' as correct --self-calibrate --sun-term auto: the Sun term learnt as the
    estimator runs, the same corrections to the bit and the same term per model."""
    d, q, hist, h_header, h_rows = self_calibrated_as_by_the_cli(exe, sun_mission, tmp_path, "0", "auto")
    assert h_header[-3:] == ["sun_x", "sun_y", "sun_z"] and len(h_rows) == 9 * len(hist)
    for a, first in zip(hist, h_rows[::9]):
        assert [float(x) for x in first[-3:]] == list(a["model"].sun[0, 0]), a["version"]
    assert not hist[0]["model"].sun.any() and np.abs(hist[-1]["model"].sun).max() > 0.01  # none, then a term
    # Mutation: without the learner the corrections differ.
    q_none, _, _ = ascorr.self_calibrate(*as_args(d), d["flags"], d["confidence"], lag=0)
    assert np.abs(q_none - q).max() > 1e-9
    # In fixed point the same history's terms (the learner sums in double) within the core's rounding.
    q_fixed, _, hist_fixed = ascorr.self_calibrate(*as_args(d), d["flags"], d["confidence"], lag=0, scalar="fixed",
                                                   sun_term="auto")
    assert np.abs(hist_fixed[-1]["model"].sun).max() > 0.01
    with pytest.raises(ValueError, match="sun_term"):
        ascorr.self_calibrate(*as_args(d), sun_term="yes")


def corrected_as_by_the_cli(exe, mission, model_path, d, tmp_path):
    """correct(model=read_model(path)) and `ascorr correct --model path` on the same rows (d, read from
    mission): the same status and corrections to the bit; (q, status)."""
    corrected = tmp_path / "corrected.csv"
    run_cli(exe, "correct", "--in", mission, "--model", model_path, "--out", corrected)
    header, rows = read_csv_text(corrected)
    q, status = ascorr.correct(*as_args(d), model=ascorr.read_model(str(model_path)))
    cols = [header.index(c) for c in ("qw", "qx", "qy", "qz")]
    assert [int(r[header.index("status")]) for r in rows] == list(status)
    same = [[f"{x:.15f}" for x in q[i]] == [r[c] for c in cols] for i, r in enumerate(rows) if not status[i] & 16]
    assert all(same) and len(same) > 0.9 * len(rows)
    return q, status


def test_fit_lag_and_correct_are_ascorr_fit_and_correct(exe, lag_mission, tmp_path):
    """lag= as --lag (auto, a number, X:TAU); the lagged model corrects the rows as
    `ascorr correct` does, to the bit, in any row order; Model(lag_s=) and pickling keep it."""
    import pickle

    d = ascorr.read_solutions(str(lag_mission))
    for cli, py in (("auto", "auto"), ("1800", 1800), ("A:900,C:1800", "A:900,C:1800")):
        out = tmp_path / f"model_{cli.replace(':', '_').replace(',', '_')}.csv"
        run_cli(exe, "fit", "--in", lag_mission, "--out", out, "--min-days", 20, "--lag", cli)
        model, report = ascorr.fit(*as_args(d), d["flags"], d["confidence"], min_days=20, lag=py)
        assert model.to_csv() == out.read_text(), cli
        assert (report["lag"] != "") == (cli == "auto")
        if cli == "auto":
            assert report["lag"].startswith("lagged: "), report["lag"]  # the second pass ran
    assert list(model.lag_s) == [900.0, 0.0, 1800.0, 0.0]
    assert "lagged" in repr(model)
    assert pickle.loads(pickle.dumps(model)) == model
    assert ascorr.Model(model.coefficients, model.heads, lag_s=model.lag_s, sun=model.sun) == model
    assert ascorr.Model(model.coefficients, model.heads) != model

    q, status = corrected_as_by_the_cli(exe, lag_mission, out, d, tmp_path)
    # Reversed rows: the same corrections, reversed.
    rev = [np.asarray(a)[::-1].copy() for a in as_args(d)]
    q_rev, status_rev = ascorr.correct(*rev, model=model)
    q_fwd, status_fwd = ascorr.correct(*as_args(d), model=model)
    assert np.array_equal(q_rev[::-1], q_fwd) and np.array_equal(status_rev[::-1], status_fwd)
    # Without the lag the corrections differ: the lag is used.
    q_none, _ = ascorr.correct(*as_args(d), model=ascorr.Model(model.coefficients, model.heads))
    assert np.abs(q_none - q_fwd).max() > 1e-9

    # stats with the lagged model: the command line's numbers.
    cli_stats = json.loads(run_cli(exe, "stats", "--in", lag_mission, "--model", out, "--json").stdout)
    py_stats = ascorr.stats(*as_args(d), d["flags"], d["confidence"], model=model)
    for pair, v in cli_stats["pairs"].items():
        assert py_stats["pairs"][pair]["thermal"] == pytest.approx(v["thermal"], abs=1e-6), pair
    with pytest.raises(ValueError, match="head A lags by 900 s, but the self-calibration lags it by 1800 s"):
        ascorr.self_calibrate(*as_args(d), d["flags"], d["confidence"], model=model, lag=1800)
    with pytest.raises(ValueError, match="lag"):
        ascorr.fit(*as_args(d), min_days=20, lag=-3)
    with pytest.raises(ValueError, match="A:900,A:1"):
        ascorr.fit(*as_args(d), min_days=20, lag="A:900,A:1")
    with pytest.raises(ValueError, match="lag_s"):
        ascorr.Model(model.coefficients, model.heads, lag_s=[1e6, 0, 0, 0])


@pytest.fixture(scope="module")
def sun_mission(exe, tmp_path_factory):
    """40 days of a bench that lags by 900 s and turns with the Sun along the orbit (0.8 arcsec), every 120 s."""
    path = tmp_path_factory.mktemp("sun_mission") / "sun.csv"
    run_cli(exe, "simulate", "--out", path, "--days", 40, "--step", 120, "--seed", 3, "--bench-lag", 900,
            "--orbit-term", 0.8)
    return path


def test_fit_sun_term_and_correct_are_ascorr_fit_and_correct(exe, sun_mission, tmp_path):
    """sun_term= as --sun-term; the model's Sun term corrects and scores as `ascorr correct` and `stats --model`
    do, to the bit; Model(sun=) and pickling keep it; the scalars and self_calibrate that do not take it refuse it."""
    import pickle

    d = ascorr.read_solutions(str(sun_mission))
    out = tmp_path / "sun_model.csv"
    run_cli(exe, "fit", "--in", sun_mission, "--out", out, "--min-days", 20)
    model, report = ascorr.fit(*as_args(d), d["flags"], d["confidence"], min_days=20)
    assert model.to_csv() == out.read_text()
    assert report["sun"].startswith("taken: "), report["sun"]
    assert "sun_term='auto'" in report["text"] and "--" not in report["text"]
    assert model.sun.shape == (4, 3, 3) and np.abs(model.sun[:3]).max() > 0.01 and not model.sun[3].any()
    assert "with a Sun term" in repr(model)
    assert pickle.loads(pickle.dumps(model)) == model
    again = ascorr.Model(model.coefficients, model.heads, lag_s=model.lag_s, sun=model.sun)
    assert again == model and ascorr.Model(model.coefficients, model.heads, lag_s=model.lag_s) != model
    none, none_report = ascorr.fit(*as_args(d), d["flags"], d["confidence"], min_days=20, sun_term="none")
    assert not none.sun.any() and none_report["sun"] == ""

    q, status = corrected_as_by_the_cli(exe, sun_mission, out, d, tmp_path)
    q_none, _ = ascorr.correct(*as_args(d), model=ascorr.Model(model.coefficients, model.heads, lag_s=model.lag_s))
    assert np.abs(q_none - q).max() > 1e-7  # the term is applied

    cli_stats = json.loads(run_cli(exe, "stats", "--in", sun_mission, "--model", out, "--json").stdout)
    py_stats = ascorr.stats(*as_args(d), d["flags"], d["confidence"], model=model)
    for pair, v in cli_stats["pairs"].items():
        assert py_stats["pairs"][pair]["thermal"] == pytest.approx(v["thermal"], abs=1e-6), pair

    for scalar, bound in (("float", 1e-6), ("fixed", 1e-7)):  # the core's own Sun term in its scalar
        q_scalar, _ = ascorr.correct(*as_args(d), model=model, scalar=scalar)
        assert np.abs(q_scalar - q).max() < bound, scalar
    with pytest.raises(ValueError, match="model.*learns a Sun term from none"):
        ascorr.self_calibrate(*as_args(d), d["flags"], d["confidence"], model=model)
    bad = model.sun.copy()
    bad[0, 0] = [1800.0, -1800.0, 1.0]
    with pytest.raises(ValueError, match="sun.*head A alpha.*3601 arcsec is beyond"):
        ascorr.Model(model.coefficients, model.heads, sun=bad)
    with pytest.raises(ValueError, match="sun.*shape"):
        ascorr.Model(model.coefficients, model.heads, sun=np.zeros((4, 3)))
    with pytest.raises(ValueError, match="sun_term"):
        ascorr.fit(*as_args(d), min_days=20, sun_term="yes")


def self_calibrated_as_by_the_cli(exe, mission, tmp_path, lag, sun_term="none"):
    """self_calibrate(lag=, sun_term=) and `ascorr correct --self-calibrate --lag --sun-term` on the
    same rows: the same status and corrections to the bit; (rows, q, history, the history file's
    header and rows)."""
    d = ascorr.read_solutions(str(mission))
    corrected = tmp_path / "sc.csv"
    history = tmp_path / "sc.history.csv"
    run_cli(exe, "correct", "--in", mission, "--self-calibrate", "--lag", lag, "--sun-term", sun_term, "--out",
            corrected, "--model-history", history)
    q, status, hist = ascorr.self_calibrate(*as_args(d), d["flags"], d["confidence"], lag=lag, sun_term=sun_term)
    header, rows = read_csv_text(corrected)
    cols = [header.index(c) for c in ("qw", "qx", "qy", "qz")]
    assert [int(r[header.index("status")]) for r in rows] == list(status)
    same = [[f"{x:.15f}" for x in q[i]] == [r[c] for c in cols] for i, r in enumerate(rows) if not status[i] & 16]
    assert all(same) and len(same) > 0.9 * len(rows)
    h_header, h_rows = read_csv_text(history)
    return d, q, hist, h_header, h_rows


def test_self_calibrate_lag_is_ascorr_correct_self_calibrate(exe, lag_mission, tmp_path):
    """lag= as correct --self-calibrate --lag: the same corrections to the bit and the same
    history, whose models carry the lag; a bad lag is refused."""
    d, q, hist, h_header, h_rows = self_calibrated_as_by_the_cli(exe, lag_mission, tmp_path, "A:1800,B:1800,C:900")
    assert h_header[-1] == "lag_s"
    assert len(h_rows) == 9 * len(hist)
    for a in hist:
        assert list(a["model"].lag_s) == [1800.0, 1800.0, 900.0, 0.0]
    # Without the lag the corrections differ: the lag is used.
    q_none, _, _ = ascorr.self_calibrate(*as_args(d), d["flags"], d["confidence"])
    assert np.abs(q_none - q).max() > 1e-9
    with pytest.raises(ValueError, match="lag"):
        ascorr.self_calibrate(*as_args(d), lag=0.5)
