"""import_gracefo() and interpolate() on the public GRACE-FO sample
(tests/data/gracefo): the arrays equal `ascorr import gracefo`'s files read back,
and the worked example of docs/ground.md ("Real flight data") in Python."""

import pathlib

import numpy as np
import pytest

import ascorr
from conftest import run_cli

DATA = pathlib.Path(__file__).resolve().parents[2] / "tests" / "data" / "gracefo"


def product(name, sat):
    day = "2018-05-22" if name == "QSA1B" else "2023-06-01"
    return DATA / f"{name}_{day}_{sat}_04.txt"


def files(sat):
    return dict(sca1a=product("SCA1A", sat), qsa1b=product("QSA1B", sat), tim1b=product("TIM1B", sat),
                clk1b=product("CLK1B", sat), sca1b=product("SCA1B", sat))


@pytest.mark.parametrize("sat", ["C", "D"])
def test_import_gracefo_is_the_command_lines_files(exe, tmp_path, sat):
    f = files(sat)
    run_cli(exe, "import", "gracefo", "--sca1a", f["sca1a"], "--qsa1b", f["qsa1b"], "--tim1b", f["tim1b"], "--clk1b",
            f["clk1b"], "--sca1b", f["sca1b"], "--out", tmp_path / "s.csv", "--mountings", tmp_path / "m.csv",
            "--reference", tmp_path / "r.csv")
    g = ascorr.import_gracefo(**f)
    assert g["satellite"] == sat
    s = ascorr.read_solutions(tmp_path / "s.csv")
    for key in ("t", "q", "flags", "confidence", "temps", "v"):
        assert np.array_equal(g["solutions"][key], s[key], equal_nan=True), key
    assert list(g["solutions"]["chu"]) == list(s["chu"])
    assert set(s["extra"]) == {"sca_mode", "qualflg", "sca_confid"}
    for key, column in s["extra"].items():
        assert list(g["solutions"]["extra"][key]) == list(column), key
    assert np.all(np.isnan(s["confidence"]))  # sca_confid is a code, not a misfit in arcsec
    m = ascorr.read_mountings(tmp_path / "m.csv")
    assert g["mountings"]["heads"] == m["heads"] == "ABC"
    assert np.array_equal(g["mountings"]["q"], m["q"]) and g["mountings"]["sigma_cross"] is None
    r = np.loadtxt(tmp_path / "r.csv", delimiter=",", skiprows=1)
    assert np.array_equal(g["reference"]["t"], r[:, 0]) and np.array_equal(g["reference"]["q"], r[:, 1:])


def test_worked_example_agrees_with_jpl_within_three_arcsec():
    # docs/ground.md, "Real flight data": import, align, combine, interpolate at
    # SCA1B's times, compare after a constant offset.
    for sat in "CD":
        g = ascorr.import_gracefo(**files(sat))
        s = g["solutions"]
        rows = dict(t=s["t"], chu=s["chu"], q=s["q"], flags=s["flags"], confidence=s["confidence"])
        m2, report = ascorr.align(**rows, mountings=g["mountings"], min_epochs=30, noise_window=0.0)
        assert np.all(report["sigma_cross"] < 5.0) and np.all(report["sigma_about"] > 15.0)
        c = ascorr.combine(**rows, mountings=m2)
        at = ascorr.interpolate(c, g["reference"]["t"])
        ok = at["status"] & 8 == 0
        assert ok.sum() >= 15
        err = np.array([rotation_arcsec(q, r) for q, r in zip(at["q"][ok], g["reference"]["q"][ok])])
        rms = err.std(axis=0)
        assert np.all(rms < 3.0), (sat, rms)


def rotation_arcsec(q, r):
    """Rotation vector of q ⊗ r* in arcsec (written out here)."""
    w1, x1, y1, z1 = q
    w2, x2, y2, z2 = r[0], -r[1], -r[2], -r[3]
    d = np.array([w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2, w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
                  w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2, w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2])
    d = d if d[0] >= 0 else -d
    s = np.linalg.norm(d[1:])
    return d[1:] * (2 * np.arctan2(s, d[0]) / s * 206264.80624709636 if s > 0 else 0.0)


def test_bad_arguments_and_records(tmp_path):
    f = files("C")
    with pytest.raises(ValueError, match="argument 'time_offset'"):
        ascorr.import_gracefo(**f, time_offset=11.0)
    with pytest.raises(ValueError, match="argument 'sca1a'"):
        ascorr.import_gracefo(**dict(f, sca1a=[]))
    bad = tmp_path / "bad.txt"
    text = product("SCA1A", "C").read_text().replace(" C 2 P ", " C 5 P ", 1)
    bad.write_text(text)
    with pytest.raises(ascorr.InputError, match=r"bad.txt:\d+:\d+: sca_id"):
        ascorr.import_gracefo(**dict(f, sca1a=bad))
    with pytest.raises(ascorr.InputError, match="a record of GRACE D among those of GRACE C"):
        ascorr.import_gracefo(**dict(f, sca1a=[product("SCA1A", "C"), product("SCA1A", "D")]))
    # several clock files are merged (here the same day twice)
    twice = ascorr.import_gracefo(**dict(f, tim1b=[f["tim1b"], f["tim1b"]], clk1b=[f["clk1b"]]))
    assert np.array_equal(twice["solutions"]["t"], ascorr.import_gracefo(**f)["solutions"]["t"])
