"""to_frame and from_frame (pandas): the file's columns and numbers both ways,
and a DataFrame into every call that takes arrays gives what the file gives,
bit for bit."""

import numpy as np
import pandas
import pytest

import ascorr
from conftest import DATA, read_csv_text, run_cli


@pytest.fixture(scope="module")
def files(exe, tmp_path_factory):
    """A solutions file (20 simulated days, one epoch every 120 s) and its corrected file."""
    d = tmp_path_factory.mktemp("frames")
    mission, corrected = d / "mission.csv", d / "corrected.csv"
    run_cli(exe, "simulate", "--out", mission, "--days", 20, "--step", 120)
    run_cli(exe, "correct", "--in", mission, "--model", DATA / "model_table2.csv", "--out", corrected)
    return {"solutions": mission, "corrected": corrected, "worked example": DATA / "solutions.csv"}


def assert_same_arrays(a, b):
    assert a.keys() == b.keys()
    assert a["extra"].keys() == b["extra"].keys()
    for k in a["extra"]:
        assert np.array_equal(a["extra"][k], b["extra"][k]), k
    for k in a.keys() - {"extra"}:
        assert a[k].dtype == b[k].dtype and a[k].shape == b[k].shape, (k, a[k].dtype, b[k].dtype)
        if a[k].dtype.kind == "f":
            assert a[k].tobytes() == b[k].tobytes(), k  # bit for bit, NaN where NaN
        else:
            assert np.array_equal(a[k], b[k]), k


@pytest.mark.parametrize("which", ["solutions", "corrected", "worked example"])
def test_to_frame_has_the_files_columns_and_numbers(files, which):
    path = files[which]
    d = ascorr.read_solutions(str(path))
    df = ascorr.to_frame(d)
    header, rows = read_csv_text(path)
    assert list(df.columns) == header and len(df) == len(rows)
    assert df["qw"].to_numpy().tobytes() == d["q"][:, 0].copy().tobytes()
    assert df["t_032"].to_numpy().tobytes() == d["temps"][:, 2].copy().tobytes()
    assert df["vz"].to_numpy().tobytes() == d["v"][:, 2].copy().tobytes()
    assert list(df["chu"]) == [row[header.index("chu")] for row in rows]
    if which == "corrected":
        assert list(df["status"]) == [int(row[header.index("status")]) for row in rows]


@pytest.mark.parametrize("which", ["solutions", "corrected", "worked example"])
def test_from_frame_inverts_to_frame(files, which):
    d = ascorr.read_solutions(str(files[which]))
    assert_same_arrays(ascorr.from_frame(ascorr.to_frame(d)), d)


def test_a_frame_from_pandas_read_csv_into_every_call(files, tmp_path):
    """pandas.read_csv of the file (round-trip float parsing), then from_frame:
    correct, iba, stats, fit and write_solutions give what the file's arrays give."""
    path = files["solutions"]
    d = ascorr.read_solutions(str(path))
    f = ascorr.from_frame(pandas.read_csv(path, float_precision="round_trip"))
    assert_same_arrays(f, d)
    model = ascorr.read_model(str(DATA / "model_table2.csv"))
    args = lambda x: (x["t"], x["chu"], x["q"], x["temps"], x["v"])  # noqa: E731
    for scalar in ("double", "fixed"):
        (qa, sa), (qb, sb) = (ascorr.correct(*args(x), model=model, scalar=scalar) for x in (f, d))
        assert qa.tobytes() == qb.tobytes() and np.array_equal(sa, sb)
    iba_f, iba_d = ascorr.iba(f["t"], f["chu"], f["q"]), ascorr.iba(d["t"], d["chu"], d["q"])
    assert iba_f.keys() == iba_d.keys() == {"A-B", "A-C", "B-C"}
    for pair in iba_f:
        assert all(a.tobytes() == b.tobytes() for a, b in zip(iba_f[pair], iba_d[pair]))
    stats = [ascorr.stats(*args(x), x["flags"], x["confidence"], model=model) for x in (f, d)]
    assert stats[0] == stats[1] and stats[0]["rows"] == len(d["t"])
    (m_f, r_f), (m_d, r_d) = (ascorr.fit(*args(x), x["flags"], x["confidence"], min_days=19, lag=0) for x in (f, d))
    assert m_f.coefficients.tobytes() == m_d.coefficients.tobytes() and r_f.keys() == r_d.keys()
    assert all(np.array_equal(r_f[k], r_d[k]) for k in r_f), [k for k in r_f if not np.array_equal(r_f[k], r_d[k])]
    out = {}
    for name, x in (("frame", f), ("file", d)):
        out[name] = tmp_path / f"{name}.csv"
        ascorr.write_solutions(str(out[name]), *args(x), x["flags"], x["confidence"])
    assert out["frame"].read_bytes() == out["file"].read_bytes()


def test_from_frame_takes_columns_in_any_order_and_fills_absent_ones_as_a_file_does(files):
    d = ascorr.read_solutions(str(files["worked example"]))
    df = ascorr.to_frame(d)
    f = ascorr.from_frame(df[["qz", "chu", "qx", "t", "qy", "qw", "t_032", "t_chu", "t_029"]])
    assert np.isnan(f["v"]).all() and f["v"].shape == (len(df), 3)
    assert np.isnan(f["confidence"]).all() and (f["flags"] == 0).all() and f["flags"].dtype == np.int64
    assert f["q"].tobytes() == d["q"].tobytes() and f["temps"].tobytes() == d["temps"].tobytes()
    # Without velocities: the aberration stage is skipped (status 4), as for a file without them.
    q, status = ascorr.correct(f["t"], f["chu"], f["q"], f["temps"], f["v"])
    assert (status & 4).all()


def test_from_frame_head_indices_and_pandas_missing_values(files):
    d = ascorr.read_solutions(str(files["worked example"]))
    df = ascorr.to_frame(d)
    model = ascorr.read_model(str(DATA / "model_table2.csv"))
    indices = df.assign(chu=[ascorr.HEADS.index(c) for c in df["chu"]])
    f = ascorr.from_frame(indices)
    assert f["chu"].dtype == np.int64
    a = ascorr.correct(f["t"], f["chu"], f["q"], f["temps"], f["v"], model=model)
    b = ascorr.correct(d["t"], d["chu"], d["q"], d["temps"], d["v"], model=model)
    assert a[0].tobytes() == b[0].tobytes() and np.array_equal(a[1], b[1])
    # Nullable columns: pd.NA in a real column is NaN (the thermal stage skipped, status 8).
    nullable = df.astype({"t_chu": "Float64"})
    nullable.loc[1, "t_chu"] = pandas.NA
    f = ascorr.from_frame(nullable)
    assert np.isnan(f["temps"][1, 0]) and not np.isnan(f["temps"][0, 0])
    assert ascorr.correct(f["t"], f["chu"], f["q"], f["temps"], f["v"], model=model)[1][1] & 8


@pytest.mark.parametrize("change, message", [
    (lambda df: df.drop(columns=["qx"]), "no column 'qx'"),
    (lambda df: df.drop(columns=["t", "chu"]), "no column 't', 'chu'"),
    (lambda df: df.drop(columns=["vy", "vz"]), "no column 'vy', 'vz' beside ['vx']"),
    (lambda df: df.assign(chu=[None] + list(df["chu"][1:])), "column 'chu': row 0 is missing"),
    (lambda df: df.astype({"flags": "Int64"}).assign(flags=pandas.array([1, pandas.NA] + [0] * (len(df) - 2),
                                                                         dtype="Int64")),
     "column 'flags': row 1 is missing"),
    (lambda df: df.assign(qw=["x"] * len(df)), "column 'qw'"),
    (lambda df: df.assign(status=[3, -1] + [3] * (len(df) - 2)), "column 'status': row 1: '-1' is out of range: expected an integer in [0, 65535]"),
])
def test_from_frame_refuses_what_it_cannot_take_naming_the_column(files, change, message):
    df = ascorr.to_frame(ascorr.read_solutions(str(files["worked example"])))
    with pytest.raises(ValueError) as e:
        ascorr.from_frame(change(df))
    assert message in str(e.value)
