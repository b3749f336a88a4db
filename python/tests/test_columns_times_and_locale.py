"""The Python side's columns and times: an uninitialised Model, integer columns
by one rule with the file reader (flags, head indices, status), datetime64
times, near-miss column names, the locale and the selection of clean rows."""

import pickle
import re
import subprocess

import numpy as np
import pandas
import pytest

import ascorr
from conftest import DATA

SOLUTIONS = DATA / "solutions.csv"
MODEL = DATA / "model_table2.csv"
LLONG_MAX = 2**63 - 1


@pytest.fixture
def ex():
    return ascorr.read_solutions(str(SOLUTIONS))


# ---- 15: Model.__new__ without __init__

def test_an_uninitialised_model_raises_type_error_on_every_use(ex):
    m = ascorr.Model.__new__(ascorr.Model)
    uses = {
        "coefficients": lambda: m.coefficients,
        "heads": lambda: m.heads,
        "quadratic": lambda: m.quadratic,
        "to_csv": lambda: m.to_csv(),
        "write": lambda: m.write("/nonexistent/never-written.csv"),
        "==": lambda: m == ascorr.read_model(str(MODEL)),
        "== (other)": lambda: ascorr.read_model(str(MODEL)) == m,
        "pickle": lambda: pickle.dumps(m),
        "correct": lambda: ascorr.correct(ex["t"], ex["chu"], ex["q"], ex["temps"], ex["v"], model=m),
    }
    for what, use in uses.items():
        with pytest.raises(TypeError, match="never initialised") as e:
            use()
        assert "read_model(), fit() or Model(coefficients)" in str(e.value), what
    assert "not initialised" in repr(m)
    # A method called on something that is no Model at all is refused too, never read as one.
    with pytest.raises(TypeError, match="expected an ascorr.Model"):
        ascorr.Model.to_csv(5)
    # __init__ after __new__, and pickling (which is __new__ then __setstate__), still work.
    m.__init__(ascorr.read_model(str(MODEL)).coefficients, "ABC")
    assert m == ascorr.read_model(str(MODEL)) and pickle.loads(pickle.dumps(m)) == m


# ---- 9 and 19: integers by one rule (flags, head indices, status)

def test_flags_beyond_long_long_name_the_range_as_the_command_line(ex, tmp_path, exe):
    n = len(ex["t"])
    for bad in (2**63, 2**64 - 1):
        flags = np.zeros(n, np.uint64)
        flags[2] = bad
        with pytest.raises(ValueError) as e:
            ascorr.stats(ex["t"], ex["chu"], ex["q"], ex["temps"], ex["v"], flags, ex["confidence"])
        assert str(e.value) == (f"argument 'flags': row 2: '{bad}' is out of range: expected an integer in "
                                f"[0, {LLONG_MAX}]")
        assert "negative" not in str(e.value)
    # The command line's words for the same value in a file.
    text = SOLUTIONS.read_text().splitlines()
    header = text[0].split(",")
    row = text[1].split(",")
    row[header.index("flags")] = str(2**63)
    bad_file = tmp_path / "flags.csv"
    bad_file.write_text("\n".join([text[0], ",".join(row)]) + "\n")
    r = subprocess.run([exe, "stats", "--in", str(bad_file)], capture_output=True, text=True)
    assert r.returncode != 0 and f"'{2**63}' is out of range: expected an integer in [0, {LLONG_MAX}]" in r.stderr
    # Negative flags: the same words.
    flags = np.zeros(n, np.int64)
    flags[1] = -1
    with pytest.raises(ValueError, match=r"row 1: '-1' is out of range: expected an integer in \[0, "):
        ascorr.write_solutions(str(tmp_path / "x.csv"), ex["t"], ex["chu"], ex["q"], flags=flags)


def test_flags_and_head_indices_as_floats_must_be_integral(ex):
    n = len(ex["t"])
    args = (ex["t"], ex["chu"], ex["q"], ex["temps"], ex["v"])
    # Integral floats (pandas' fillna leaves float64) are the integers they hold.
    as_float = ex["flags"].astype(np.float64)
    assert ascorr.stats(*args, as_float, ex["confidence"]) == ascorr.stats(*args, ex["flags"], ex["confidence"])
    for bad in (0.9, 4.9, 2.5, np.nan, np.inf, -1.0):
        flags = np.zeros(n)
        flags[3] = bad
        with pytest.raises(ValueError, match=r"argument 'flags': row 3: .*expected an integer in \[0, "):
            ascorr.stats(*args, flags, ex["confidence"])
    indices = np.array([ascorr.HEADS.index(c) for c in ex["chu"]])
    a = ascorr.correct(ex["t"], indices.astype(np.float64), ex["q"], ex["temps"], ex["v"])
    b = ascorr.correct(ex["t"], ex["chu"], ex["q"], ex["temps"], ex["v"])
    assert a[0].tobytes() == b[0].tobytes() and np.array_equal(a[1], b[1])
    half = indices.astype(np.float64)
    half[0] = 0.5
    with pytest.raises(ValueError, match=r"argument 'chu': row 0: expected an integer .*got '0.5' \(a head index\)"):
        ascorr.correct(ex["t"], half, ex["q"], ex["temps"], ex["v"])


@pytest.mark.parametrize("column, values, message", [
    ("flags", [0.9, 4.9, 2.5], "column 'flags': row 0: expected an integer in [0, 9223372036854775807], got '0.9'"),
    ("flags", [0.0, 4.9, 2.0], "column 'flags': row 1: expected an integer in [0, 9223372036854775807], got '4.9'"),
    ("flags", np.array([0, 2**63, 1], np.uint64),
     "column 'flags': row 1: '9223372036854775808' is out of range: expected an integer in [0, 9223372036854775807]"),
    ("chu", [0.0, 1.0, 2.5], "column 'chu': row 2: expected an integer"),
    ("status", [3.0, 2.5, 3.0], "column 'status': row 1: expected an integer in [0, 65535], got '2.5'"),
    ("t", pandas.to_datetime(["2020-01-01", "2020-01-02", "2020-01-03"]),
     "column 't': dtype datetime64[ns] is not taken: times are float64 seconds since J2000.0 TT"),
    ("qw", [True, False, True], "column 'qw': expected numbers, got dtype bool"),
    ("chu", [1.5, "B", "C"], "column 'chu': expected head letters (strings) or head indices (integers)"),
])
def test_from_frame_takes_integers_as_the_arrays_rule_does(ex, column, values, message):
    df = ascorr.to_frame(ex).iloc[:3].copy()
    df[column] = values
    with pytest.raises(ValueError) as e:
        ascorr.from_frame(df)
    assert message in str(e.value)


def test_from_frame_takes_integral_floats_as_integers(ex):
    df = ascorr.to_frame(ex)
    df["flags"] = df["flags"].astype(np.float64)
    df["chu"] = [float(ascorr.HEADS.index(c)) for c in ex["chu"]]
    f = ascorr.from_frame(df)
    assert f["flags"].dtype == np.int64 and np.array_equal(f["flags"], ex["flags"])
    assert f["chu"].dtype == np.int64 and [ascorr.HEADS[i] for i in f["chu"]] == list(ex["chu"])


# ---- 8: the locale changes nothing

def comma_decimal_locale(tmp_dir):
    """The name of a locale whose decimal point is a comma, set for LC_ALL: the
    system's de_DE/fr_FR if it has one, else de_DE compiled with localedef from
    the `locales` package's definitions (toolchain/debian-packages.txt) into
    tmp_dir (LOCPATH), as test_formats does. None when neither can be had."""
    import locale
    import os
    import shutil

    names = ("de_DE.UTF-8", "de_DE.utf8", "fr_FR.UTF-8", "fr_FR.utf8")
    for name in names:
        try:
            locale.setlocale(locale.LC_ALL, name)
            return name
        except locale.Error:
            pass
    if shutil.which("localedef") is None:
        return None
    target = tmp_dir / "de_DE.UTF-8"
    r = subprocess.run(["localedef", "-i", "de_DE", "-f", "UTF-8", str(target)], capture_output=True, text=True)
    if not target.is_dir():
        return None
    os.environ["LOCPATH"] = str(tmp_dir)  # glibc reads it at each setlocale
    try:
        locale.setlocale(locale.LC_ALL, "de_DE.UTF-8")
        return "de_DE.UTF-8"
    except locale.Error:
        return None


@pytest.fixture
def comma_locale(tmp_path):
    """Runs the test under a comma-decimal locale (LC_ALL); yields the locale
    the interpreter had (its LC_CTYPE from the environment, the rest "C"),
    which is restored afterwards (plain "C" would make open() ASCII)."""
    import locale
    import os

    saved_locpath = os.environ.get("LOCPATH")
    original = locale.setlocale(locale.LC_ALL)
    try:
        name = comma_decimal_locale(tmp_path)
        if name is None:
            pytest.skip("NO COMMA-DECIMAL LOCALE on this machine: install the Debian package `locales` "
                        "(toolchain/debian-packages.txt); CI has it")
        assert locale.localeconv()["decimal_point"] == ",", name
        yield original
    finally:
        locale.setlocale(locale.LC_ALL, original)
        if saved_locpath is None:
            os.environ.pop("LOCPATH", None)
        else:
            os.environ["LOCPATH"] = saved_locpath


@pytest.fixture(scope="module")
def short_mission(exe, tmp_path_factory):
    """20 simulated days, one solution per head every 120 s (enough for a fit)."""
    path = tmp_path_factory.mktemp("mission3") / "mission.csv"
    r = subprocess.run([exe, "simulate", "--out", str(path), "--days", "20", "--step", "120"], capture_output=True,
                       text=True)
    assert r.returncode == 0, r.stderr
    return ascorr.read_solutions(str(path))


def everything_written(d, tmp_path, tag):
    """Every text the library writes for Python from the arrays d: the model file
    (to_csv, write), the fit report, the stats table, a refusal's message."""
    args = (d["t"], d["chu"], d["q"], d["temps"], d["v"], d["flags"], d["confidence"])
    model, report = ascorr.fit(*args, min_days=19, lag=0)
    path = tmp_path / f"model-{tag}.csv"
    model.write(str(path))
    assert ascorr.read_model(str(path)) == model  # read_model refused '-4,67e-01'
    s = ascorr.stats(*args, model=model)
    try:
        ascorr.fit(*args, min_days=25.5)
    except ascorr.FitRefused as e:
        refusal = str(e)
    return {"to_csv": model.to_csv(), "write": path.read_text(), "fit report": report["text"],
            "stats table": s["table"], "fit refusal": refusal}


def test_a_comma_decimal_locale_changes_nothing(short_mission, tmp_path, comma_locale):
    import locale

    under_comma = everything_written(short_mission, tmp_path, "comma")
    locale.setlocale(locale.LC_ALL, comma_locale)
    assert locale.localeconv()["decimal_point"] == "."
    under_c = everything_written(short_mission, tmp_path, "c")
    for what, text in under_c.items():
        assert re.search(r"\d\.\d", text), what  # the control: each text holds decimal numbers
        assert under_comma[what] == text, what


# ---- 17: a column that looks like one ascorr reads

@pytest.mark.parametrize("known, written", [("t_chu", "T_CHU"), ("t_chu", "tchu"), ("confidence", "confidance"),
                                            ("vx", "VX")])
def test_a_near_miss_column_is_refused_alike_everywhere(exe, ex, tmp_path, known, written):
    text = SOLUTIONS.read_text()
    header, body = text.split("\n", 1)
    names = header.split(",")
    names[names.index(known)] = written
    path = tmp_path / "misspelt.csv"
    path.write_text(",".join(names) + "\n" + body)
    column = 1 + sum(len(n) + 1 for n in names[:names.index(written)])
    words = (f"column '{written}' is not a column ascorr reads, but looks like '{known}', which the header lacks "
             f"(column names are case-sensitive, docs/contract.md, section 3): rename it '{known}', or give it a "
             f"name unlike the columns ascorr reads")
    out = tmp_path / "out.csv"
    r = subprocess.run([exe, "correct", "--in", str(path), "--model", str(MODEL), "--out", str(out)],
                       capture_output=True, text=True)
    assert r.returncode != 0 and f"{path}:1:{column}: {words}" in r.stderr, r.stderr
    assert not out.exists()
    with pytest.raises(ascorr.InputError) as e:
        ascorr.read_solutions(str(path))
    assert f"{path}:1:{column}: {words}" in str(e.value)
    with pytest.raises(ValueError) as e:
        ascorr.from_frame(ascorr.to_frame(ex).rename(columns={known: written}))
    assert str(e.value) == f"from_frame: {words}"
    # Control: the same file with the column as the contract spells it is read.
    path.write_text(text)
    assert len(ascorr.read_solutions(str(path))["t"]) == len(ex["t"])


def test_unknown_columns_unlike_the_known_ones_are_kept(ex, tmp_path):
    df = ascorr.to_frame(ex).assign(t_028=1.0, x=2.0, note="n")
    assert set(ascorr.from_frame(df)["extra"]) == {"t_028", "x", "note"}


# ---- 12: a confidence that is not given is not clean, everywhere

def cli_json(exe, *args):
    r = subprocess.run([exe, *map(str, args)], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    return r


def test_a_missing_confidence_is_not_clean_anywhere(exe, short_mission, tmp_path):
    import json

    d = dict(short_mission)
    n = len(d["t"])
    d["confidence"] = d["confidence"].copy()
    gone = np.zeros(n, bool)
    gone[::7] = True
    gone &= (d["flags"] == 0) & (d["confidence"] <= 5)  # rows that were clean but for their confidence
    assert gone.sum() > 100
    d["confidence"][gone] = np.nan
    args = (d["t"], d["chu"], d["q"], d["temps"], d["v"], d["flags"], d["confidence"])
    empty = tmp_path / "empty.csv"  # NaN confidences are written as empty fields
    ascorr.write_solutions(str(empty), *args)
    header, *rows = empty.read_text().splitlines()
    col = header.split(",").index("confidence")
    nan = tmp_path / "nan.csv"
    nan.write_text("\n".join([header] + [",".join(f if j != col or f else "nan" for j, f in
                                                  enumerate(row.split(","))) for row in rows]) + "\n")
    assert nan.read_text().count(",nan") >= gone.sum()

    s = ascorr.stats(*args)
    for path in (empty, nan):
        j = json.loads(cli_json(exe, "stats", "--in", path, "--json").stdout)
        assert {p: v["n"] for p, v in j["pairs"].items()} == {p: v["n"] for p, v in s["pairs"].items()}, path
    clean = ascorr.stats(*args[:5], d["flags"], short_mission["confidence"])
    assert all(s["pairs"][p]["n"] < clean["pairs"][p]["n"] for p in s["pairs"])  # the rows were left out

    model, report = ascorr.fit(*args, min_days=19, lag=0)
    dropped = report["dropped"]["confidence > 5 or missing"]
    assert dropped >= gone.sum()
    for path in (empty, nan):
        r = cli_json(exe, "fit", "--in", path, "--out", tmp_path / "m.csv", "--min-days", 19, "--lag", 0)
        text = r.stdout + r.stderr
        assert f"confidence > 5 or missing {dropped}" in text, text
        assert ascorr.read_model(str(tmp_path / "m.csv")) == model

    q, status, history = ascorr.self_calibrate(*args)
    assert history, "no model adopted: the comparison would be empty"
    for path in (empty, nan):
        out = tmp_path / "sc.csv"
        cli_json(exe, "correct", "--in", path, "--self-calibrate", "--out", out)
        got = ascorr.read_solutions(str(out))["status"]
        assert np.array_equal(got, status), path
