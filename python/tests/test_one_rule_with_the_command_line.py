"""The Python side by the command line's rules: nothing lost (unknown
columns, atomic writes), nothing silently wrong (Earth velocity outside the
ephemeris, rejected quaternions in iba, float32 times, aberration=None, the RMS
of one epoch), one rule with the command line (times beyond the ephemeris,
enumeration names, fit's settings), argument errors that name the argument,
and write_solutions() writing only what read_solutions() reads."""

import json
import os
import re
import pathlib
import pickle
import stat
import warnings

import numpy as np
import pytest

import ascorr
from conftest import DATA, read_csv_text, run_cli

SOLUTIONS = DATA / "solutions.csv"
MODEL = DATA / "model_table2.csv"


@pytest.fixture
def ex():
    return ascorr.read_solutions(str(SOLUTIONS))


@pytest.fixture(scope="module")
def mission(exe, tmp_path_factory):
    """40 simulated days, one solution per head every 120 s."""
    path = tmp_path_factory.mktemp("mission") / "mission.csv"
    run_cli(exe, "simulate", "--out", path, "--days", 40, "--step", 120)
    return path


def states_before_each_row(ex, path):
    """A states file with one state (a 500 km circular orbit, GCRS) 60 s before each row."""
    lines = ["t,x,y,z,vx,vy,vz"] + ["%r,6878,0,0,0,7.6,0" % (t - 60) for t in sorted(set(ex["t"]))]
    path.write_text("\n".join(lines) + "\n")
    return path


def first_rows(d, n):
    return {k: (v[:n] if k != "extra" else {c: x[:n] for c, x in v.items()}) for k, v in d.items()}


def args(ex, **change):
    a = dict(t=ex["t"], chu=ex["chu"], q=ex["q"], temps=ex["temps"], v=ex["v"])
    a.update(change)
    return a


def with_extra_columns(tmp_path):
    """The example solutions with three columns ascorr does not know, one of them
    quoted (RFC 4180, a comma and a doubled quote inside) and one empty."""
    names, rows = read_csv_text(SOLUTIONS)
    path = tmp_path / "extra.csv"
    lines = [",".join(["orbit"] + names[:3] + ['"a, b"'] + names[3:] + ["note"])]
    for i, r in enumerate(rows):
        lines.append(",".join([str(100 + i)] + r[:3] + [f'"x, ""{i}"""'] + r[3:] + ["" if i % 2 else f"n{i}"]))
    path.write_text("\n".join(lines) + "\n")
    return path


# ---- 1. Unknown columns survive read_solutions -> write_solutions; atomic writes


def test_unknown_columns_survive_the_round_trip(exe, tmp_path):
    src = with_extra_columns(tmp_path)
    d = ascorr.read_solutions(str(src))
    assert list(d["extra"]) == ["orbit", '"a, b"', "note"]
    out = tmp_path / "out.csv"
    ascorr.write_solutions(str(out), **d)
    names_in, rows_in = read_csv_text(src)
    text = out.read_text().splitlines()
    header = text[0]
    for name in ("orbit", '"a, b"', "note"):
        assert name in header
    # Every field of every unknown column, verbatim, row by row.
    raw_in = src.read_text().splitlines()
    for i, line in enumerate(text[1:]):
        assert line.endswith(f'{100 + i},"x, ""{i}""",' + ("" if i % 2 else f"n{i}")), line
        assert raw_in[i + 1].startswith(f"{100 + i},")
    back = ascorr.read_solutions(str(out))
    for k in ("t", "q", "temps", "v", "confidence"):
        assert np.array_equal(back[k], d[k], equal_nan=True), k
    assert {k: list(v) for k, v in back["extra"].items()} == {k: list(v) for k, v in d["extra"].items()}
    # A corrected file (the command line keeps the columns) round trips with its status.
    corrected = tmp_path / "corrected.csv"
    run_cli(exe, "correct", "--in", src, "--out", corrected, "--model", MODEL)
    c = ascorr.read_solutions(str(corrected))
    again = tmp_path / "again.csv"
    ascorr.write_solutions(str(again), **c)
    c2 = ascorr.read_solutions(str(again))
    assert np.array_equal(c2["status"], c["status"]) and list(c2["extra"]) == list(c["extra"])
    assert list(c2["extra"]["note"]) == list(d["extra"]["note"])


def test_write_solutions_replaces_an_existing_file_atomically(ex, tmp_path):
    target = tmp_path / "target.csv"
    target.write_text("old\n")
    target.chmod(0o640)
    link = tmp_path / "link.csv"
    link.symlink_to(target.name)
    ascorr.write_solutions(str(link), **ex)  # through the link: the target replaced, the link and the mode kept
    assert link.is_symlink() and stat.S_IMODE(target.stat().st_mode) == 0o640
    assert np.array_equal(ascorr.read_solutions(str(target))["q"], ex["q"])
    before = target.read_bytes()
    status = np.full(len(ex["t"]), 3)
    status[-1] = 70000  # the last row refused: nothing written, not even half
    with pytest.raises(ValueError, match=r"argument 'status': row 11: 70000 is out of range"):
        ascorr.write_solutions(str(target), **ex, status=status)
    assert target.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["link.csv", "target.csv"]  # no temporary file left


# ---- 4. earth_velocity outside 1900-2100


def test_earth_velocity_outside_the_ephemeris_is_nan():
    inside = np.array([0.0, -3.1e9, 3.1e9])  # 2000, 1901, 2098
    outside = np.array([-3.2e9, 3.2e9, 1e300, -1e300, np.nan])  # 1898, 2101, absurd, not a number
    for exact in (False, True):
        v, d = ascorr.earth_velocity(np.concatenate([inside, outside]), exact=exact)
        assert np.all(np.isfinite(v[:3])) and np.all(np.abs(d[:3] - 1.0) < 0.02)
        assert np.all(np.isnan(v[3:])) and np.all(np.isnan(d[3:])), (v[3:], d[3:])
    doc = ascorr.earth_velocity.__doc__
    assert "600 s" not in doc and "1900-2100" in doc and "NaN" in doc


# ---- 5. iba and the quaternions the core rejects


def test_iba_leaves_out_quaternions_the_core_rejects(mission):
    ex = first_rows(ascorr.read_solutions(str(mission)), 300)
    chu, t = ex["chu"], ex["t"]
    ref = ascorr.iba(t, chu, ex["q"])
    full = np.intersect1d(ref["A-B"][0], ref["A-C"][0])  # epochs with A, B and C
    a_rows = np.flatnonzero((chu == "A") & np.isin(t, full))
    q = ex["q"].copy()
    q[a_rows[0]] = 0.0       # zero: an IBA of 0 before
    q[a_rows[1]] *= 2.0      # not unit
    q[a_rows[2]] *= 1 + 1e-7  # within the core's tolerance: kept
    _, status = ascorr.correct(**args(ex, q=q))
    assert status[a_rows[0]] == status[a_rows[1]] == 16 and status[a_rows[2]] != 16
    with pytest.warns(UserWarning, match=r"<arrays, 1-based row>:\d+: quaternion not unit"):
        got = ascorr.iba(t, chu, q)
    for pair in ("A-B", "A-C"):
        assert t[a_rows[0]] not in got[pair][0] and t[a_rows[1]] not in got[pair][0]
        assert t[a_rows[2]] in got[pair][0]
        assert len(got[pair][0]) == len(ref[pair][0]) - 2
        assert np.all(got[pair][1] > 1000.0)  # no angle of 0 from a zero quaternion
    assert np.array_equal(got["B-C"][1], ref["B-C"][1])


# ---- 7. float32 times, aberration=None, the RMS of one epoch


def test_float32_times_are_refused(ex):
    for f in (np.float32, np.float16):
        t = (np.arange(len(ex["t"])) * 100.0).astype(f)  # small times: float16 holds them too
        with pytest.raises(ValueError, match=r"argument 't': expected float64 \(or integer\) times, got dtype"):
            ascorr.correct(**args(ex, t=t))
        with pytest.raises(ValueError, match="argument 't'"):
            ascorr.earth_velocity(t)
        with pytest.raises(ValueError, match="argument 't'"):
            ascorr.iba(t, ex["chu"], ex["q"])
    with pytest.raises(ValueError, match="argument 't_from'"):
        ascorr.stats(**args(ex), t_from=np.float32(ex["t"][0]))
    # float64, integers and lists of Python floats are times.
    ascorr.correct(**args(ex, t=list(ex["t"])))
    ascorr.correct(**args(ex, t=ex["t"].astype(np.int64)))


def test_aberration_none_is_not_false(ex):
    for bad in (None, 0, 1, "no", np.float64(0)):
        with pytest.raises(ValueError, match="argument 'aberration': expected True or False"):
            ascorr.correct(**args(ex), aberration=bad)
    _, off = ascorr.correct(**args(ex), aberration=np.bool_(False))
    assert np.all(off & 1 == 0)
    with pytest.raises(ValueError, match="argument 'exact': expected True or False"):
        ascorr.earth_velocity(ex["t"], exact=None)


def test_one_epoch_gives_no_rms(exe, mission, tmp_path):
    ex = ascorr.read_solutions(str(mission))
    full = np.intersect1d(*(ascorr.iba(ex["t"], ex["chu"], ex["q"])[p][0] for p in ("A-B", "B-C")))
    first = ex["t"] == full[0]  # one epoch, with a clean row of each head
    one = {k: (v[first] if k != "extra" else v) for k, v in ex.items()}
    s = ascorr.stats(one["t"], one["chu"], one["q"], one["temps"], one["v"], one["flags"], one["confidence"])
    for pair, got in s["pairs"].items():
        assert got["n"] == 1
        assert got["original"] is None and got["aberration"] is None and got["original_smoothed"] is None, pair
    path = tmp_path / "one.csv"
    ascorr.write_solutions(str(path), **one)
    cli = json.loads(run_cli(exe, "stats", "--in", path, "--json").stdout)
    assert all(p["original"] is None and p["n"] == 1 for p in cli["pairs"].values())
    # Two epochs: a number again.
    two = np.isin(ex["t"], full[:2])
    s2 = ascorr.stats(ex["t"][two], ex["chu"][two], ex["q"][two], ex["temps"][two], ex["v"][two], ex["flags"][two],
                      ex["confidence"][two])
    assert all(p["n"] == 2 and p["original"] is not None for p in s2["pairs"].values())


# ---- 13. Times beyond the ephemeris: the command line's outcome


def test_times_beyond_the_ephemeris_are_rows_as_on_the_command_line(exe, ex, tmp_path):
    model = ascorr.read_model(str(MODEL))
    t = ex["t"].copy()
    t[[1, 4, 7]] = [1e300, -1e16, 2e15]
    d = dict(ex, t=t)
    path = tmp_path / "far.csv"
    ascorr.write_solutions(str(path), **d)
    out = tmp_path / "far.corrected.csv"
    p = run_cli(exe, "correct", "--in", path, "--out", out, "--model", MODEL)
    assert "outside the span of the Earth ephemeris" in p.stderr
    assert not re.search(r"\d{25}", p.stderr), p.stderr  # no 300-digit number
    cli = ascorr.read_solutions(str(out))
    q, status = ascorr.correct(t, ex["chu"], ex["q"], ex["temps"], ex["v"], model=model)
    assert np.array_equal(status, cli["status"])
    assert list(status[[1, 4, 7]]) == [2 | 4 | 32] * 3
    assert np.all(np.abs(q - cli["q"]) <= 6e-16)
    # Beyond +-9e15 s a time has no millisecond key: such rows are in no epoch (they were all one
    # epoch, "second solution of CHU A at t = <300 digits>", here and on the command line).
    far = np.array([1e300, 2e300, -1e20, 1e300])
    chu = np.array(["A", "A", "B", "B"])
    unit = np.tile([1.0, 0.0, 0.0, 0.0], (4, 1))
    assert all(len(v[0]) == 0 for v in ascorr.iba(far, chu, unit).values())
    farfile = tmp_path / "far2.csv"
    ascorr.write_solutions(str(farfile), far, chu, unit)
    p = run_cli(exe, "stats", "--in", farfile)
    assert not re.search(r"\d{25}", p.stdout + p.stderr)


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_a_time_that_is_not_finite_is_refused_as_by_the_command_line(ex, bad):
    t = ex["t"].copy()
    t[5] = bad
    with pytest.raises(ValueError, match=r"argument 't': row 5: time -?(nan|inf) is not finite") as e:
        ascorr.correct(**args(ex, t=t))
    assert len(str(e.value)) < 200


# ---- 14. Argument errors name the argument; paths; Model == and pickling


def bad_calls(ex):
    a = args(ex)
    return [
        ("model", lambda: ascorr.correct(**a, model=3)),
        ("scalar", lambda: ascorr.correct(**a, scalar=None)),
        ("max_propagation", lambda: ascorr.correct(**a, max_propagation="6h")),
        ("states", lambda: ascorr.correct(**a, states=3)),
        ("path", lambda: ascorr.read_solutions(3)),
        ("path", lambda: ascorr.read_solutions(b"solutions.csv")),
        ("path", lambda: ascorr.read_model(None)),
        ("path", lambda: ascorr.write_solutions(None, **ex)),
        ("heads", lambda: ascorr.Model(np.zeros((4, 3, 4)), heads=["A"])),
        ("t_from", lambda: ascorr.stats(**a, t_from="yesterday")),
        ("t_to", lambda: ascorr.stats(**a, t_to=[1.0])),
        ("min_days", lambda: ascorr.fit(**a, min_days="30")),
        ("min_orbits", lambda: ascorr.fit(**a, min_orbits=1.5)),
        ("min_orbits", lambda: ascorr.fit(**a, min_orbits=-1)),
        ("max_condition", lambda: ascorr.fit(**a, max_condition=None)),
        ("orbit_period", lambda: ascorr.fit(**a, orbit_period="5400")),
        ("holdout", lambda: ascorr.fit(**a, holdout="0.25")),
        ("min_temperature_range", lambda: ascorr.fit(**a, min_temperature_range=True)),
        ("extra", lambda: ascorr.write_solutions("never.csv", **dict(ex, extra=[1, 2]))),
        ("t", lambda: ascorr.correct(**dict(a, t=None))),
        ("chu", lambda: ascorr.correct(**dict(a, chu=None))),
        ("q", lambda: ascorr.iba(ex["t"], ex["chu"], None)),
    ]


def test_argument_errors_name_the_argument_and_what_it_accepts(ex, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    for name, call in bad_calls(ex):
        with pytest.raises(ValueError) as e:
            call()
        text = str(e.value)
        assert f"argument '{name}'" in text and "expected" in text, (name, text)
        assert "incompatible" not in text and "Unable to cast" not in text, text
    assert not (tmp_path / "never.csv").exists()
    # Missing, unknown or extra arguments: Python's own words, with the signature, never an overload dump.
    for call, what in [
        (lambda: ascorr.correct(ex["t"], ex["chu"], ex["q"]), "missing a required argument: 'temps'"),
        (lambda: ascorr.correct(**args(ex), scaler="float"), "unexpected keyword argument 'scaler'"),
        (lambda: ascorr.iba(ex["t"], ex["chu"], ex["q"], ex["temps"]), "too many positional arguments"),
        (lambda: ascorr.Model(), "missing a required argument: 'coefficients'"),
        (lambda: ascorr.read_model(str(MODEL)).write(), "missing a required argument: 'path'"),
    ]:
        with pytest.raises(TypeError) as e:
            call()
        assert what in str(e.value) and "incompatible" not in str(e.value), str(e.value)


def test_stats_names_its_period_by_the_keywords(ex):
    with pytest.raises(ValueError, match=r"^the period is empty: t_from 10 is not before t_to 5$"):
        ascorr.stats(**args(ex), t_from=10.0, t_to=5.0)  # refused, as by `ascorr stats --from 10 --to 5`
    s = ascorr.stats(**args(ex), t_from=1.0, t_to=5.0)
    assert "no rows in [1, 5] s (t_from/t_to)" in s["messages"] and "--" not in s["messages"]


def test_pathlib_paths_are_accepted_wherever_a_path_is(ex, tmp_path):
    model = ascorr.read_model(MODEL)
    assert model == ascorr.read_model(str(MODEL))
    d = ascorr.read_solutions(SOLUTIONS)
    assert np.array_equal(d["q"], ascorr.read_solutions(str(SOLUTIONS))["q"])
    ascorr.write_solutions(tmp_path / "s.csv", **d)
    model.write(tmp_path / "m.csv")
    assert (tmp_path / "m.csv").read_text() == model.to_csv()
    states = states_before_each_row(ex, tmp_path / "states.csv")
    no_v = np.full_like(ex["v"], np.nan)
    _, st_path = ascorr.correct(**args(ex, v=no_v), states=states, states_frame="gcrs")
    _, st_str = ascorr.correct(**args(ex, v=no_v), states=str(states), states_frame="gcrs")
    assert np.array_equal(st_path, st_str) and np.all(st_path & 1 == 1)


def test_model_equality_and_pickling():
    m = ascorr.read_model(str(MODEL))
    assert m == ascorr.Model(m.coefficients, heads=m.heads)
    assert m != ascorr.Model(m.coefficients, heads="AB")
    c = m.coefficients
    c[0, 0, 0] += 1e-9
    assert m != ascorr.Model(c, heads=m.heads)
    assert (m == "model") is False and m != None  # noqa: E711
    q = ascorr.Model(np.ones((4, 3, 7)), heads="ABCD")
    for model in (m, q):
        back = pickle.loads(pickle.dumps(model))
        assert back == model and back.to_csv() == model.to_csv() and back.quadratic == model.quadratic


# ---- 15. Enumerations: the command line's names, any case; numbers are not names


def test_enumerations_are_names_in_any_case_and_numbers_are_refused(exe, ex, tmp_path):
    model = ascorr.read_model(str(MODEL))
    ref = ascorr.correct(**args(ex), model=model, scalar="fixed")
    for spelling in ("FIXED", "Fixed"):
        got = ascorr.correct(**args(ex), model=model, scalar=spelling)
        assert got[0].tobytes() == ref[0].tobytes() and np.array_equal(got[1], ref[1])
    states = states_before_each_row(ex, tmp_path / "states.csv")
    no_v = np.full_like(ex["v"], np.nan)
    gcrs = ascorr.correct(**args(ex, v=no_v), states=states, states_frame="gcrs")
    upper = ascorr.correct(**args(ex, v=no_v), states=states, states_frame="GCRS")
    assert gcrs[0].tobytes() == upper[0].tobytes()
    # The command line takes the same spelling and gives the same numbers.
    sol = tmp_path / "s.csv"
    ascorr.write_solutions(str(sol), **dict(ex, v=no_v))
    out = tmp_path / "o.csv"
    run_cli(exe, "correct", "--in", sol, "--out", out, "--states", states, "--states-frame", "GCRS")
    assert np.array_equal(ascorr.read_solutions(str(out))["status"], upper[1])
    for name, value in [("scalar", 2), ("scalar", 2.0), ("scalar", True), ("states_frame", 1), ("states_frame", 0),
                        ("scalar", "quad"), ("states_frame", "itrf93")]:
        with pytest.raises(ValueError, match=rf"argument '{name}': expected '.*' \(a name, in any case\), got"):
            ascorr.correct(**args(ex), **{name: value})
    for value in (1, 2, "cubic"):
        with pytest.raises(ValueError, match=r"argument 'terms': expected 'linear' or 'quadratic'"):
            ascorr.fit(**args(ex), terms=value)


# ---- 16. write_solutions writes nothing read_solutions would refuse


def test_write_solutions_refuses_what_read_solutions_would_refuse(ex, tmp_path):
    out = tmp_path / "out.csv"
    n = len(ex["t"])

    def refused(match, **change):
        with pytest.raises(ValueError, match=match):
            ascorr.write_solutions(str(out), **dict(ex, **change))
        assert not out.exists()

    status = np.full(n, 3)
    for bad in (70000, -1, 2**64 - 1):
        s = status.astype(np.uint64 if bad > 0 else np.int64)
        s[4] = bad
        refused(rf"argument 'status': row 4: {bad} is out of range: a status is an integer in \[0, 65535\]", status=s)
    s = status.copy()
    s[2] = 1 | 4  # aberration both applied and skipped
    refused(r"argument 'status': row 2: 5 is not a status correct\(\) gives", status=s)
    chu = ex["chu"].astype("U2")
    chu[3] = "E"
    refused(r"argument 'chu': row 3: not a camera head .* with status 3", chu=chu, status=status)
    refused(r"argument 'chu': row 3: .* cannot be written", chu=np.where(np.arange(n) == 3, 'x"y', ex["chu"]))
    refused(r"(?s)argument 'extra': column 'note', row 1: .* is not one CSV field",
            extra={"note": np.array(["a", "b\nc"] + ["d"] * (n - 2))})
    refused(r"argument 'extra': column 'note', row 0: 'a,b' is not one CSV field",
            extra={"note": np.array(["a,b"] * n)})
    refused(r"argument 'extra': column 'flags' is written from", extra={"flags": np.zeros(n)})
    refused(r"argument 'extra': column 'note': expected shape \(12,\)", extra={"note": np.zeros(n - 1)})
    # What read_solutions reads is written: an unknown head without status (status 16 when corrected),
    # and with status 16; a quoted extra field; numbers in an extra column.
    s = status.copy()
    s[3] = 16
    ascorr.write_solutions(str(out), **dict(ex, chu=chu, status=s, extra={"orbit": np.arange(n), "n": ['"a,b"'] * n}))
    back = ascorr.read_solutions(str(out))
    assert back["chu"][3] == "E" and back["status"][3] == 16
    assert list(back["extra"]["orbit"]) == [str(i) for i in range(n)] and back["extra"]["n"][0] == '"a,b"'


# ---- 20. fit's terms, holdout and min_temperature_range


def test_fit_takes_terms_holdout_and_min_temperature_range_as_the_command_line(exe, mission, tmp_path):
    d = ascorr.read_solutions(str(mission))
    a = (d["t"], d["chu"], d["q"], d["temps"], d["v"], d["flags"], d["confidence"])
    out = tmp_path / "quadratic.csv"
    cli = run_cli(exe, "fit", "--in", mission, "--out", out, "--min-days", 30, "--terms", "quadratic",
                  "--holdout", 0.3, "--lag", 0)
    model, report = ascorr.fit(*a, min_days=30, terms="quadratic", holdout=0.3, lag=0)
    assert model.quadratic and report["terms"] == "quadratic"
    assert model.to_csv() == out.read_text()
    assert model == ascorr.read_model(str(out))
    assert "--" not in report["text"] and "terms='quadratic'" in report["text"]
    as_keywords = (cli.stdout.replace("--terms quadratic", "terms='quadratic'").replace("--lag auto", "lag='auto'")
                   .replace("--sun-term auto", "sun_term='auto'"))
    assert as_keywords.replace("--lag", "lag") == report["text"]
    # The defaults are the command line's: linear, holdout 0.25, 2 degC.
    linear = tmp_path / "linear.csv"
    run_cli(exe, "fit", "--in", mission, "--out", linear, "--min-days", 30)
    assert ascorr.fit(*a, min_days=30)[0].to_csv() == linear.read_text()
    # Refusals name the keywords, not the options.
    with pytest.raises(ascorr.FitRefused) as e:
        ascorr.fit(*a, min_days=30, terms="quadratic", min_temperature_range=100)
    text = str(e.value)
    assert "(min_temperature_range); use terms='linear'" in text and "--" not in text, text
    for kw, value in (("holdout", 0.7), ("holdout", np.nan), ("min_temperature_range", -1.0)):
        with pytest.raises(ascorr.FitRefused, match=rf"^{kw} must be") as e:
            ascorr.fit(*a, min_days=30, **{kw: value})
        assert "--" not in str(e.value)
    with pytest.raises(ascorr.FitRefused, match=r"^min_days .*: must be a positive number of days"):
        ascorr.fit(*a, min_days=-1.0)
