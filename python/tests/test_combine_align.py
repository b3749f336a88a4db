"""read_mountings(), combine() and align() against the command line's files
(`ascorr combine`, `ascorr align`) on a small simulated mission: bit for bit."""

import numpy as np
import pytest

import ascorr
from conftest import read_csv_text, run_cli


@pytest.fixture(scope="module")
def corrected(exe, tmp_path_factory):
    """Two days at 120 s, corrected with the simulator's truth; its mountings file."""
    d = tmp_path_factory.mktemp("combine_align")
    raw = d / "mission.csv"
    run_cli(exe, "simulate", "--out", raw, "--days", 2, "--step", 120, "--seed", 4)
    out = d / "corrected.csv"
    run_cli(exe, "correct", "--in", raw, "--out", out, "--model", f"{raw}.truth.csv")
    return d, out, d / "mission.csv.mountings.csv"


def arrays(path):
    s = ascorr.read_solutions(path)
    return dict(t=s["t"], chu=s["chu"], q=s["q"], status=s["status"], flags=s["flags"], confidence=s["confidence"])


def test_align_on_arrays_is_ascorr_align(exe, corrected):
    d, data, mountings = corrected
    run_cli(exe, "align", "--in", data, "--mountings", mountings, "--out", d / "m2.csv")
    from_cli = ascorr.read_mountings(d / "m2.csv")
    m2, report = ascorr.align(**arrays(data), mountings=ascorr.read_mountings(mountings))
    assert m2["heads"] == from_cli["heads"] == "ABC"
    for key in ("q", "sigma_cross", "sigma_about"):
        assert np.array_equal(m2[key], from_cli[key]), key
    assert report["noise_model"] == "per_head"
    assert report["rotation"].shape == (3, 3)
    assert np.all(np.abs(report["weighted_mean"]) < 1e-6)
    # the noise is the simulator's (1.5" across, 10" about) within 6 formal sigma
    assert np.all(np.abs(report["sigma_cross"] - 1.5) < 6 * report["sd_cross"])
    assert np.all(np.abs(report["sigma_about"] - 10.0) < 6 * report["sd_about"])


def test_combine_on_arrays_is_ascorr_combine(exe, corrected):
    d, data, mountings = corrected
    run_cli(exe, "combine", "--in", data, "--mountings", mountings, "--out", d / "combined.csv")
    header, rows = read_csv_text(d / "combined.csv")
    assert header == ["t", "qw", "qx", "qy", "qz", "heads", "sigma_x", "sigma_y", "sigma_z", "status"]
    c = ascorr.combine(**arrays(data), mountings=ascorr.read_mountings(mountings))
    assert len(c["t"]) == len(rows)
    number = lambda x: float(x) if x else np.nan  # noqa: E731
    assert np.array_equal(c["t"], [float(r[0]) for r in rows])
    assert np.array_equal(c["q"], [[number(x) for x in r[1:5]] for r in rows], equal_nan=True)
    assert list(c["heads"]) == [r[5] for r in rows]
    assert np.array_equal(c["sigma"], [[number(x) for x in r[6:9]] for r in rows], equal_nan=True)
    assert np.array_equal(c["status"], [int(r[9]) for r in rows])
    assert {"ABC", "AB"} <= set(c["heads"])  # a Sun-blinded head: two-head epochs too


def test_bad_arguments_name_the_argument(corrected):
    _, data, mountings = corrected
    a = arrays(data)
    m = ascorr.read_mountings(mountings)
    with pytest.raises(ValueError, match="argument 'mountings'"):
        ascorr.combine(**a, mountings="mountings.csv")
    bad = dict(m, q=m["q"][:2])
    with pytest.raises(ValueError, match=r"argument 'mountings\['q'\]'"):
        ascorr.align(**a, mountings=bad)
    not_unit = dict(m, q=m["q"] * 1.01)
    with pytest.raises(ValueError, match="not unit"):
        ascorr.align(**a, mountings=not_unit)
    with pytest.raises(ValueError, match="argument 'status'"):
        ascorr.align(**dict(a, status=a["status"][:-1]), mountings=m)
    with pytest.raises(ValueError, match="no sigma"):
        ascorr.combine(**a, mountings=dict(m, sigma_cross=None, sigma_about=None))
    with pytest.raises(ascorr.AlignRefused, match="the period is empty"):
        ascorr.align(**a, mountings=m, t_from=0.0, t_to=1.0)
    with pytest.raises(ValueError, match="t_from"):
        ascorr.align(**a, mountings=m, t_from=2.0, t_to=1.0)
    with pytest.raises(ascorr.AlignRefused, match="too few epochs"):
        ascorr.align(**a, mountings=m, min_epochs=10**9)
    with pytest.raises(ValueError, match="argument 'noise_window'"):
        ascorr.align(**a, mountings=m, noise_window=-1.0)
    with pytest.raises(TypeError, match="mountings"):
        ascorr.align(a["t"], a["chu"], a["q"])


def test_combine_needs_no_file_and_no_temporary_folder(exe, corrected, monkeypatch):
    # Issue 37, class 11: combine() failed with "temp_directory_path" when
    # TMPDIR did not exist; it keeps the combination in memory now.
    d, data, mountings = corrected
    c0 = ascorr.combine(**arrays(data), mountings=ascorr.read_mountings(mountings))
    monkeypatch.setenv("TMPDIR", str(d / "no-such-folder"))
    c1 = ascorr.combine(**arrays(data), mountings=ascorr.read_mountings(mountings))
    for key in ("t", "q", "sigma", "status"):
        assert np.array_equal(c0[key], c1[key], equal_nan=True), key
    assert not (d / "no-such-folder").exists()


def test_combine_gate_as_the_command_line(exe, corrected):
    d, data, mountings = corrected
    run_cli(exe, "combine", "--in", data, "--mountings", mountings, "--out", d / "g10.csv", "--gate-floor", 10,
            "--gate-sigmas", 8)
    _, rows = read_csv_text(d / "g10.csv")
    c = ascorr.combine(**arrays(data), mountings=ascorr.read_mountings(mountings), gate_floor=10.0, gate_sigmas=8)
    assert np.array_equal(c["status"], [int(r[9]) for r in rows])
    a = arrays(data)
    m = ascorr.read_mountings(mountings)
    for kw, match in ((dict(gate_floor=0.5), "gate_floor"), (dict(gate_sigmas=200.0), "gate_sigmas"),
                      (dict(gate_floor=float("nan")), "gate_floor")):
        with pytest.raises(ValueError, match=match):
            ascorr.combine(**a, mountings=m, **kw)


def test_sigmas_a_target_refuses_raise_saying_why(corrected):
    # Issue 37, class 6: sigma_cross 0.01" for A against 1.5" gave every
    # epoch status 12 and every row "quaternion not unit".
    _, data, mountings = corrected
    m = ascorr.read_mountings(mountings)
    cross = m["sigma_cross"].copy()
    cross[0] = 0.01
    with pytest.raises(ValueError, match="CHU A: its consistency gate in head set .* a target refuses"):
        ascorr.combine(**arrays(data), mountings=dict(m, sigma_cross=cross))
