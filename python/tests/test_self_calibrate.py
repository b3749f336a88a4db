"""ascorr.self_calibrate against `ascorr correct --self-calibrate`: the same
numbers, status bits and model history, in every scalar, on a simulated mission."""

import numpy as np
import pytest

import ascorr
from conftest import read_csv_text, run_cli


@pytest.fixture(scope="module")
def mission(exe, tmp_path_factory):
    d = tmp_path_factory.mktemp("selfcal")
    run_cli(exe, "simulate", "--out", d / "m.csv", "--days", "8", "--step", "300", "--seed", "4")
    return d


@pytest.mark.parametrize("scalar", ["double", "float", "fixed"])
def test_same_as_the_command_line(exe, mission, scalar):
    out = mission / f"c_{scalar}.csv"
    hist = mission / f"h_{scalar}.csv"
    run_cli(exe, "correct", "--in", mission / "m.csv", "--out", out, "--self-calibrate", "--scalar", scalar,
            "--model-history", hist)
    header, rows = read_csv_text(out)
    s = ascorr.read_solutions(str(mission / "m.csv"))
    q, status, history = ascorr.self_calibrate(
        s["t"], s["chu"], s["q"], s["temps"], s["v"], flags=s["flags"], confidence=s["confidence"], scalar=scalar)
    st_col = header.index("status")
    assert [int(r[st_col]) for r in rows] == [int(x) for x in status]
    cols = [header.index(c) for c in ("qw", "qx", "qy", "qz")]
    cli_q = np.array([[float(r[c]) for c in cols] for r in rows])
    assert np.max(np.abs(cli_q - q)) <= 1e-15
    assert (status & 256).sum() > 0, "rows before the first model get 256"
    h_header, h_rows = read_csv_text(hist)
    assert h_header[:2] == ["t", "version"]
    assert len(history) >= 1, "no model adopted: the comparison below would be empty"
    versions = sorted({int(r[1]) for r in h_rows})
    assert versions == [h["version"] for h in history]
    assert [float(r[0]) for r in h_rows[::9]] == pytest.approx([h["t"] for h in history], abs=5e-4)
    assert (status[s["t"] >= history[0]["t"]] & 256).sum() == 0, "every row from the first model on has one"
    crc = h_header.index("crc32c")
    assert [f"{h['crc32c']:08x}" for h in history] == [r[crc] for r in h_rows[::9]]
    tt_us = h_header.index("tt_us")
    assert [int(r[tt_us]) for r in h_rows[::9]] == [h["tt_us"] for h in history]
    origin = h_header.index("origin")
    assert [r[origin] for r in h_rows[::9]] == [h["origin"]["A"] for h in history]


def test_bad_arguments(mission):
    s = ascorr.read_solutions(str(mission / "m.csv"))
    with pytest.raises(ValueError, match="time_constant"):
        ascorr.self_calibrate(s["t"], s["chu"], s["q"], s["temps"], s["v"], time_constant=0.5)
    with pytest.raises(ValueError, match="scalar"):
        ascorr.self_calibrate(s["t"], s["chu"], s["q"], s["temps"], s["v"], scalar="half")
    for bad in (599.0, float("nan"), 86401.0):
        with pytest.raises(ValueError, match=r"argument 'orbit_period': expected seconds in \[600, 86400\]"):
            ascorr.self_calibrate(s["t"], s["chu"], s["q"], s["temps"], s["v"], orbit_period=bad)


def test_the_orbit_period_as_on_the_command_line(exe, mission):
    hist = mission / "h_period.csv"
    run_cli(exe, "correct", "--in", mission / "m.csv", "--out", mission / "c_period.csv", "--self-calibrate",
            "--orbit-period", "6000", "--model-history", hist)
    s = ascorr.read_solutions(str(mission / "m.csv"))
    _, _, history = ascorr.self_calibrate(s["t"], s["chu"], s["q"], s["temps"], s["v"], flags=s["flags"],
                                          confidence=s["confidence"], orbit_period=6000.0)
    h_header, h_rows = read_csv_text(hist)
    crc = h_header.index("crc32c")
    assert [f"{h['crc32c']:08x}" for h in history] == [r[crc] for r in h_rows[::9]]


def test_a_quadratic_model_is_refused_as_on_the_command_line(mission, tmp_path):
    # One rule with `correct --self-calibrate` and `replay --self-calibrate`:
    # the estimator starts from a linear model (refuse_quadratic_initial_model).
    lines = (tmp_path / "q.csv")
    lines.write_text("chu,axis,c0,c1,c2,c3,c1_2,c2_2,c3_2\n"
                     "A,alpha,0,0,0,0,0,0,0\nA,beta,0,0,0,0,0,0,0\nA,gamma,0,0,0,0,0,0,0\n"
                     "B,alpha,0,0,0,0,0,0,0\nB,beta,0,0,0,0,0,0,0\nB,gamma,0,0,0,0,0,1e-3,0\n")
    s = ascorr.read_solutions(str(mission / "m.csv"))
    with pytest.raises(ValueError, match=r"argument 'model'.*head B gamma has a quadratic term \(c2_2\)"):
        ascorr.self_calibrate(s["t"], s["chu"], s["q"], s["temps"], s["v"], model=ascorr.read_model(str(lines)))


def test_a_model_beyond_the_float_range_is_refused_for_float(mission, tmp_path):
    # As on the command line (check_float_range): c1 = c2 = 6000"/degC, which
    # fixed point accepts, cannot be evaluated in float within its bound.
    p = tmp_path / "big.csv"
    p.write_text("chu,axis,c0,c1,c2,c3\nA,alpha,0,6000,6000,0\nA,beta,0,0,0,0\nA,gamma,0,0,0,0\n")
    m = ascorr.read_model(str(p))
    s = ascorr.read_solutions(str(mission / "m.csv"))
    for call in (ascorr.correct, ascorr.self_calibrate):
        with pytest.raises(ValueError, match=r"argument 'model'.*beyond what the float core evaluates"):
            call(s["t"], s["chu"], s["q"], s["temps"], s["v"], model=m, scalar="float")
    ascorr.correct(s["t"], s["chu"], s["q"], s["temps"], s["v"], model=m, scalar="fixed")
