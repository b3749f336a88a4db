"""correct(states=...) against `ascorr correct --states`: rows without their own
velocity get the on-board velocity service's, bit for bit, in every scalar."""

import numpy as np
import pytest

import ascorr
from conftest import DATA, core_constant, read_csv_text, run_cli
from test_correct import assert_same_as_cli, random_solutions, write_csv_exact

T0 = 801964800.184  # 2025-06-01, inside the Earth series' span (2000-2050)
MU = core_constant("kEarthGmKm3S2")  # km^3/s^2


def write_states(path, bad_line=False):
    """GCRS states every 10 s for 10 minutes of a circular 460 km orbit inclined
    87.4 deg (written here, not by ascorr); optionally one implausible state."""
    r0 = core_constant("kEarthEquatorialRadiusKm") + 460.0
    w = np.sqrt(MU / r0**3)
    inc = np.radians(87.4)
    lines = ["t,x,y,z,vx,vy,vz"]
    for k in range(61):
        t = T0 + 10.0 * k
        a = w * (t - T0)
        r = r0 * np.array([np.cos(a), np.sin(a) * np.cos(inc), np.sin(a) * np.sin(inc)])
        v = r0 * w * np.array([-np.sin(a), np.cos(a) * np.cos(inc), np.cos(a) * np.sin(inc)])
        if bad_line and k == 30:
            r = r / 100.0  # inside the Earth: refused by the service
        lines.append(",".join(repr(float(x)) for x in (t, *r, *v)))
    path.write_text("\n".join(lines) + "\n")


def rows_around_the_states(n, seed):
    d = random_solutions(n, seed)
    rng = np.random.default_rng(seed + 1)
    d["t"] = np.sort(rng.uniform(T0 - 60.0, T0 + 900.0, n))  # before, during and after the states
    d["v"][rng.random(n) < 0.6] = np.nan  # most rows without their own velocity
    return d


@pytest.mark.parametrize("scalar", ["double", "float", "fixed"])
def test_states_bit_for_bit(exe, tmp_path, scalar):
    states = tmp_path / "states.csv"
    write_states(states)
    d = rows_around_the_states(3000, seed=12)
    path = tmp_path / "solutions.csv"
    write_csv_exact(path, d)
    _, input_rows = read_csv_text(path)
    out = tmp_path / "corrected.csv"
    model_path = DATA / "model_table2.csv"
    run_cli(exe, "correct", "--in", path, "--out", out, "--model", model_path, "--scalar", scalar, "--states", states,
            "--states-frame", "gcrs", "--max-propagation", 120)
    header, rows = read_csv_text(out)
    q, status = ascorr.correct(d["t"], d["chu"], d["q"], d["temps"], d["v"], model=ascorr.read_model(str(model_path)),
                               scalar=scalar, states=states, states_frame="gcrs", max_propagation=120.0)
    assert_same_as_cli(d, q, status, header, rows, input_rows)
    no_v = np.all(np.isnan(d["v"]), axis=1)
    ok = (status & 16) == 0
    assert np.any(no_v & ok & ((status & 1) != 0)), "no row corrected with the service's velocity"
    assert np.any(no_v & ok & (d["t"] < T0) & (status & 4 != 0)), "no row before the first state"
    assert np.any(no_v & ok & ((status & 512) != 0)), "no row beyond the propagation limit"
    # Without states those rows have no velocity: the states changed them.
    _, plain = ascorr.correct(d["t"], d["chu"], d["q"], d["temps"], d["v"])
    assert np.all(plain[no_v & ok] & 4 != 0)


@pytest.mark.parametrize("scalar", ["double", "float", "fixed"])
def test_states_any_row_order(tmp_path, scalar):
    """Rows out of time order get the same bits, row for row, as in time order."""
    states = tmp_path / "states.csv"
    write_states(states)
    d = rows_around_the_states(3000, seed=13)
    kw = dict(model=ascorr.read_model(str(DATA / "model_table2.csv")), scalar=scalar, states=states,
              states_frame="gcrs", max_propagation=120.0)
    q, status = ascorr.correct(d["t"], d["chu"], d["q"], d["temps"], d["v"], **kw)
    for order in (np.random.default_rng(5).permutation(len(d["t"])), np.arange(len(d["t"]))[::-1]):
        qo, so = ascorr.correct(d["t"][order], d["chu"][order], d["q"][order], d["temps"][order], d["v"][order], **kw)
        assert np.array_equal(so, status[order])
        assert np.array_equal(qo, q[order], equal_nan=True)  # (rejected rows: NaN kept)


def test_states_bad_arguments_and_refused_states(tmp_path):
    d = rows_around_the_states(50, seed=2)
    args = (d["t"], d["chu"], d["q"], d["temps"], d["v"])
    states = tmp_path / "states.csv"
    write_states(states, bad_line=True)
    with pytest.warns(UserWarning, match="states.csv:32"):
        ascorr.correct(*args, states=str(states), states_frame="gcrs")
    with pytest.raises(ValueError, match="argument 'states_frame'"):
        ascorr.correct(*args, states=states, states_frame="icrf")
    with pytest.raises(ValueError, match="argument 'max_propagation'"):
        ascorr.correct(*args, states=states, max_propagation=0.0)
    with pytest.raises(ValueError, match="argument 'states'"):
        ascorr.correct(*args, states=42)
    (tmp_path / "bad.csv").write_text("t,x,y,z,vx,vy,vz\n1,2,3\n")
    with pytest.raises(ascorr.InputError, match=r"bad.csv:2:\d+"):
        ascorr.correct(*args, states=tmp_path / "bad.csv")
