"""The third hostile probe's classes on the Python side: an uninitialised Model
(15), integer columns by one rule with the file reader (flags, head indices,
status: 9 and 19), datetime64 times (9), near-miss column names (17), the
locale (8) and the selection of clean rows (12)."""

import pickle
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
