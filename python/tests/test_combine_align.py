"""read_mountings(), combine() and align() against the command line's files
(`ascorr combine`, `ascorr align`) on a small simulated mission: bit for bit."""

import subprocess

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


def information_crf(q_chu_crf, sigma_cross, sigma_about):
    """A head's information in CRF axes, (1/arcsec^2): M^T diag(1/sc^2, 1/sc^2, 1/sa^2) M,
    M = R(q_chu_crf) from the Hamilton product written out (not ascorr's code)."""
    w, x, y, z = q_chu_crf / np.linalg.norm(q_chu_crf)
    m = np.array([[1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
                  [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
                  [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])
    return m.T @ np.diag([sigma_cross**-2, sigma_cross**-2, sigma_about**-2]) @ m


def check_covariance(cov, sigma, heads, m):
    """cov (k, 3) and sigma (k, 3) of rows with heads (k,) against numpy's (sum W_i)^-1
    (to 1e-9 of sigma_a sigma_b); returns the largest |cov_ab| / (sigma_a sigma_b)."""
    info = {h: information_crf(m["q"][i], m["sigma_cross"][i], m["sigma_about"][i]) for i, h in enumerate(m["heads"])}
    largest = 0.0
    for c, s, h in zip(cov, sigma, heads):
        if not h:
            assert np.all(np.isnan(c))
            continue
        p = np.linalg.inv(sum(info[x] for x in h))
        scale = np.sqrt(np.diag(p))
        pairs = np.array([scale[0] * scale[1], scale[0] * scale[2], scale[1] * scale[2]])
        want = np.array([p[0, 1], p[0, 2], p[1, 2]])
        assert np.all(np.abs(c - want) <= 1e-9 * pairs), (h, c, want)
        assert np.allclose(s, scale, rtol=1e-9)
        largest = max(largest, float(np.max(np.abs(want) / pairs)))
    return largest


def test_covariance_is_the_inverse_of_the_summed_information(exe, corrected):
    # Issue 39, item 3: the columns cov_xy,cov_xz,cov_yz equal (sum W_i)^-1's
    # off-diagonal to 1e-9 (relative to sigma_a sigma_b); the sigmas are its
    # diagonal's roots; Python's are the file's to the bit.
    d, data, mountings = corrected
    run_cli(exe, "combine", "--in", data, "--mountings", mountings, "--out", d / "cov.csv", "--covariance")
    header, rows = read_csv_text(d / "cov.csv")
    assert header[10:] == ["cov_xy", "cov_xz", "cov_yz"]
    number = lambda x: float(x) if x else np.nan  # noqa: E731
    cov = np.array([[number(x) for x in r[10:13]] for r in rows])
    sigma = np.array([[number(x) for x in r[6:9]] for r in rows])
    m = ascorr.read_mountings(mountings)
    c = ascorr.combine(**arrays(data), mountings=m, covariance=True)
    assert np.array_equal(c["cov"], cov, equal_nan=True)
    assert {"ABC", "AB"} <= {r[5] for r in rows}
    assert check_covariance(cov, sigma, [r[5] for r in rows], m) > 0.05  # not vacuous: AB's is sizeable
    # Heads of unequal noise: the three-head set's off-diagonal is sizeable too.
    m2 = dict(m, sigma_cross=np.array([1.0, 2.0, 4.0]), sigma_about=np.array([7.0, 12.0, 30.0]))
    c2 = ascorr.combine(**arrays(data), mountings=m2, covariance=True)
    full = c2["heads"] == "ABC"
    assert check_covariance(c2["cov"][full], c2["sigma"][full], c2["heads"][full], m2) > 0.05
    # Mutation check: another head set's covariance fails the bound.
    with pytest.raises(AssertionError):
        check_covariance(c2["cov"][full][:1], c2["sigma"][full][:1], ["AB"], m2)
    without = ascorr.combine(**arrays(data), mountings=m)
    assert "cov" not in without
    assert np.array_equal(without["sigma"], c["sigma"], equal_nan=True)


def test_correct_combined_writes_the_same_covariance(exe, corrected):
    d, data, mountings = corrected
    raw = d / "mission.csv"
    run_cli(exe, "correct", "--in", raw, "--out", d / "c2.csv", "--model", f"{raw}.truth.csv", "--mountings",
            mountings, "--combined", d / "c2-combined.csv", "--covariance")
    run_cli(exe, "combine", "--in", d / "c2.csv", "--mountings", mountings, "--out", d / "c2-again.csv",
            "--covariance")
    assert (d / "c2-combined.csv").read_text() == (d / "c2-again.csv").read_text()
    p = subprocess.run([exe, "correct", "--in", raw, "--out", d / "c3.csv", "--covariance"], capture_output=True,
                       text=True)
    assert p.returncode == 2 and "--covariance requires --combined" in p.stderr, p.stderr


def test_interpolate_on_arrays_is_ascorr_interpolate(exe, corrected):
    # Issue 39, item 5: interpolate() gives the command line's rows to the digit,
    # in the order of the times asked for, covariance included.
    d, data, mountings = corrected
    run_cli(exe, "combine", "--in", data, "--mountings", mountings, "--out", d / "ci.csv", "--covariance")
    c = ascorr.combine(**arrays(data), mountings=ascorr.read_mountings(mountings), covariance=True)
    at = np.concatenate([c["t"][:50] + 37.5, [c["t"][0] - 1.0, c["t"][10]], c["t"][100:40:-7] + 60.0])
    (d / "at.csv").write_text("t\n" + "".join(f"{x!r}\n" for x in at))
    run_cli(exe, "interpolate", "--in", d / "ci.csv", "--at", d / "at.csv", "--out", d / "ii.csv", "--max-gap", 130)
    header, rows = read_csv_text(d / "ii.csv")
    assert header[10:] == ["cov_xy", "cov_xz", "cov_yz"]
    i = ascorr.interpolate(c, at, max_gap=130.0)
    number = lambda x: float(x) if x else np.nan  # noqa: E731
    assert np.array_equal(i["t"], at)
    assert np.array_equal(i["q"], [[number(x) for x in r[1:5]] for r in rows], equal_nan=True)
    assert list(i["heads"]) == [r[5] for r in rows]
    assert np.array_equal(i["sigma"], [[number(x) for x in r[6:9]] for r in rows], equal_nan=True)
    assert np.array_equal(i["cov"], [[number(x) for x in r[10:13]] for r in rows], equal_nan=True)
    assert np.array_equal(i["status"], [int(r[9]) for r in rows])
    assert i["status"][50] == 8 and i["status"][51] == c["status"][10]  # before the first epoch; at an epoch
    assert np.sum(i["status"] & 1) > 50


def test_interpolate_refuses_what_the_file_reader_refuses(corrected):
    _, data, mountings = corrected
    c = ascorr.combine(**arrays(data), mountings=ascorr.read_mountings(mountings))
    bad = dict(c, q=c["q"] * 1.1)
    with pytest.raises(ValueError, match=r"argument 'combined': <arrays, 1-based row>:1:\d+: .*not a unit"):
        ascorr.interpolate(bad, c["t"][:3])
    with pytest.raises(ValueError, match="row 2 is not after row 1"):
        ascorr.interpolate(dict(c, t=c["t"][::-1].copy()), c["t"][:3])
    with pytest.raises(ValueError, match="max_gap"):
        ascorr.interpolate(c, c["t"][:3], max_gap=0.0)
    with pytest.raises(ValueError, match="without key 'sigma'"):
        ascorr.interpolate({k: v for k, v in c.items() if k != "sigma"}, c["t"][:3])
    with pytest.raises(ValueError, match="argument 'at'"):
        ascorr.interpolate(c, np.array([np.nan]))
    n = len(c["t"])
    with pytest.raises(ValueError, match=r"argument 'combined\['heads'\]'"):
        ascorr.interpolate(dict(c, heads="ABC" * n), c["t"][:3])
    with pytest.raises(ValueError, match="row 2 is 'A,B'"):
        ascorr.interpolate(dict(c, heads=np.array(["AB", "A,B"] + ["AB"] * (n - 2))), c["t"][:3])
