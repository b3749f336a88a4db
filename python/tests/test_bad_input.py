"""Every bad-input class of ascorr.correct and the readers: a wrong shape or dtype
raises ValueError naming the argument; per-row problems are status bits and the
other rows come back corrected."""

import numpy as np
import pytest

import ascorr
from conftest import DATA


@pytest.fixture
def ex():
    return ascorr.read_solutions(str(DATA / "solutions.csv"))


@pytest.fixture
def model():
    return ascorr.read_model(str(DATA / "model_table2.csv"))


def args(ex, **change):
    a = dict(t=ex["t"], chu=ex["chu"], q=ex["q"], temps=ex["temps"], v=ex["v"])
    a.update(change)
    return a


@pytest.mark.parametrize(
    "name,value",
    [
        ("t", lambda ex: ex["t"][:, None]),                        # (n, 1)
        ("t", lambda ex: ex["t"].astype(str)),                     # strings
        ("t", lambda ex: ex["t"].astype(complex)),                 # complex
        ("chu", lambda ex: ex["chu"][:-1]),                        # n - 1 rows
        ("chu", lambda ex: np.full(len(ex["t"]), 0.5)),            # float, not integral
        ("chu", lambda ex: ex["chu"][:, None]),                    # 2-D
        ("q", lambda ex: ex["q"][:, :3]),                          # (n, 3)
        ("q", lambda ex: ex["q"][:-1]),                            # n - 1 rows
        ("q", lambda ex: ex["q"].ravel()),                         # 1-D
        ("q", lambda ex: ex["q"] > 0),                             # bool
        ("temps", lambda ex: ex["temps"][:, :2]),                  # (n, 2)
        ("temps", lambda ex: np.full((len(ex["t"]), 3), "x")),     # strings
        ("v", lambda ex: ex["v"][1:]),                             # n - 1 rows
        ("v", lambda ex: ex["v"].T),                               # (3, n)
    ],
)
def test_wrong_shape_or_dtype_names_the_argument(ex, name, value):
    with pytest.raises(ValueError, match=f"argument '{name}'"):
        ascorr.correct(**args(ex, **{name: value(ex)}))


def test_bad_keyword_values(ex, model, tmp_path):
    with pytest.raises(ValueError, match="argument 'scalar'"):
        ascorr.correct(**args(ex), scalar="half")
    with pytest.raises(ValueError, match="argument 'model'"):
        ascorr.correct(**args(ex), model="model_table2.csv")
    big = ascorr.Model(np.full((4, 3, 4), 1e6))  # beyond the Q30 coefficient formats: refused, not saturated
    with pytest.raises(ValueError, match="argument 'model'.*fixed-point"):
        ascorr.correct(**args(ex), model=big, scalar="fixed")
    with pytest.raises(ValueError, match="argument 'coefficients'"):
        ascorr.Model(np.zeros((3, 3, 4)))
    with pytest.raises(ValueError, match="argument 'coefficients'.*not finite"):
        ascorr.Model(np.full((4, 3, 4), np.nan))
    with pytest.raises(ValueError, match="argument 'heads'"):
        ascorr.Model(np.zeros((4, 3, 4)), heads="AX")


def test_per_row_problems_are_status_bits_and_no_row_is_lost(ex, model):
    n = len(ex["t"])
    q = ex["q"].copy()
    temps = ex["temps"].copy()
    v = ex["v"].copy()
    chu = ex["chu"].astype("U2")
    q[0] = [np.nan, 0, 0, 0]      # 16, unchanged
    q[1] *= 3.0                   # 16, unchanged
    chu[2] = "E"                  # 16
    temps[3, 1] = np.nan          # 8
    temps[4, 0] = -273.0          # 8 + 64
    v[5, 2] = np.nan              # 4 + 32 (incomplete)
    v[6] = np.nan                 # 4
    v[7] = [3e5, 0, 0]            # 4 + 32 (beyond 1000 km/s, above c)
    chu[8] = "D"                  # 256: no coefficients for D in Table 2
    big = model.coefficients
    big[2, 0, 0] = 4000.0         # C alpha c0 beyond 1 degree: 128 for rows of C
    q_out, st = ascorr.correct(ex["t"], chu, q, temps, v, model=model)
    assert len(st) == n == len(q_out)
    want = {0: 16, 1: 16, 2: 16, 3: 1 | 8, 4: 1 | 8 | 64, 5: 2 | 4 | 32, 6: 2 | 4, 7: 2 | 4 | 32, 8: 1 | 256}
    for i, s in want.items():
        assert st[i] == s, (i, st[i], s)
    for i in (0, 1, 2):
        assert q_out[i].tobytes() == q[i].tobytes()
    assert np.all(st[9:] == 3)
    _, st2 = ascorr.correct(ex["t"], ex["chu"], ex["q"], ex["temps"], ex["v"], model=ascorr.Model(big, heads="ABC"))
    assert np.all(st2[ex["chu"] == "C"] == 1 | 128)
    assert np.all(st2[ex["chu"] != "C"] == 3)


def test_temps_and_v_may_be_none(ex):
    _, st = ascorr.correct(ex["t"], ex["chu"], ex["q"], None, None, model=ascorr.read_model(str(DATA / "model_table2.csv")))
    assert np.all(st == 4 | 8)


def test_malformed_files_raise_input_error_with_file_line_column(tmp_path):
    bad_model = tmp_path / "model.csv"
    bad_model.write_text("chu,axis,c0,c1,c2,c3\nA,alpha,1,2,x,4\n")
    with pytest.raises(ascorr.InputError, match=r"model.csv:2:\d+: "):
        ascorr.read_model(str(bad_model))
    bad = tmp_path / "solutions.csv"
    bad.write_text("t,chu,qw,qx,qy,qz\n1,A,1,0,0,0\n2,A,1,0,zero,0\n")
    with pytest.raises(ascorr.InputError, match=r"solutions.csv:3:\d+: column 'qy'"):
        ascorr.read_solutions(str(bad))
    assert issubclass(ascorr.InputError, ValueError) and issubclass(ascorr.FitRefused, ValueError)
    with pytest.raises(ascorr.InputError):
        ascorr.read_model(str(tmp_path / "missing.csv"))
