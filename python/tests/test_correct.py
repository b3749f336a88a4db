"""ascorr.correct against `ascorr correct`: the same numbers and status bits, bit
for bit, in every scalar, on the worked examples and on a random set that holds
every per-row problem; no row lost."""

import numpy as np
import pytest

import ascorr
from conftest import DATA, read_csv_text, run_cli

SCALARS = ["double", "float", "fixed"]
# (CLI options, correct() keywords) of the three configurations of the examples.
CONFIGS = {
    "both": (["--model", DATA / "model_table2.csv"], dict(model=True, aberration=True)),
    "aberration_only": ([], dict(model=False, aberration=True)),
    "thermal_only": (["--model", DATA / "model_table2.csv", "--no-aberration"], dict(model=True, aberration=False)),
}


def cli_correct(exe, tmp_path, solutions, scalar, options):
    out = tmp_path / f"corrected_{scalar}.csv"
    run_cli(exe, "correct", "--in", solutions, "--out", out, "--scalar", scalar, *options)
    return read_csv_text(out)


def assert_same_as_cli(d, q, status, header, rows, input_rows):
    """q, status from the module; header, rows from the CLI's corrected file; input_rows the solutions file's."""
    assert len(rows) == len(d["t"]) == len(q) == len(status), "a row was lost"
    cols = [header.index(c) for c in ("qw", "qx", "qy", "qz")]
    st_col = header.index("status")
    mismatches = []
    for i, row in enumerate(rows):
        if int(row[st_col]) != int(status[i]):
            mismatches.append((i, "status", row[st_col], status[i]))
            continue
        if status[i] & 16:
            # rejected: the CLI copies the input text, the module the input numbers, both unchanged
            assert [row[c] for c in cols] == [input_rows[i][c] for c in cols]
            assert q[i].tobytes() == d["q"][i].tobytes()
        else:
            text = [f"{x:.15f}" for x in q[i]]
            if text != [row[c] for c in cols]:
                mismatches.append((i, "q", [row[c] for c in cols], text))
    assert not mismatches, mismatches[:5]


@pytest.mark.parametrize("scalar", SCALARS)
@pytest.mark.parametrize("config", CONFIGS)
def test_worked_examples_bit_for_bit(exe, tmp_path, scalar, config):
    options, kw = CONFIGS[config]
    header, rows = cli_correct(exe, tmp_path, DATA / "solutions.csv", scalar, options)
    _, input_rows = read_csv_text(DATA / "solutions.csv")
    d = ascorr.read_solutions(str(DATA / "solutions.csv"))
    model = ascorr.read_model(str(DATA / "model_table2.csv")) if kw["model"] else None
    q, status = ascorr.correct(d["t"], d["chu"], d["q"], d["temps"], d["v"], model=model, scalar=scalar,
                               aberration=kw["aberration"])
    assert q.dtype == np.float64 and q.shape == (len(rows), 4) and status.shape == (len(rows),)
    assert_same_as_cli(d, q, status, header, rows, input_rows)


def random_solutions(n, seed):
    """n random rows in the formats' ranges, with every per-row problem mixed in."""
    rng = np.random.default_rng(seed)
    t = rng.uniform(4.0e8, 7.5e8, n)  # 2012..2023
    chu = rng.choice(np.array(list(ascorr.HEADS)), n)
    q = rng.normal(size=(n, 4))
    q /= np.linalg.norm(q, axis=1)[:, None]
    temps = rng.uniform(-30.0, 40.0, (n, 3))
    v = rng.uniform(-7.6, 7.6, (n, 3))
    k = n // 20
    bad = rng.permutation(n)
    groups = [bad[j * k:(j + 1) * k] for j in range(12)]
    q[groups[0], 1] = np.nan                       # 16: not finite
    q[groups[1]] *= 1.01                           # 16: not unit
    chu[groups[2]] = "E"                           # 16: unknown head
    q[groups[3]] *= 1.0 + 2e-7                     # accepted, normalised
    temps[groups[4], rng.integers(0, 3, k)] = np.nan  # 8: missing
    temps[groups[5], 0] = 250.0                    # 8 + 64: beyond +-200 C
    temps[groups[6], 2] = np.inf                   # 8 + 64
    v[groups[7]] = np.nan                          # 4: missing
    v[groups[8], 1] = np.nan                       # 4 + 32: incomplete
    v[groups[9]] = [2000.0, 0.0, 0.0]              # 4 + 32: beyond 1000 km/s
    v[groups[10], 2] = np.inf                      # 4 + 32: not finite
    q[groups[11]] = -q[groups[11]]                 # w < 0 on input
    return dict(t=t, chu=chu, q=q, temps=temps, v=v)


def write_csv_exact(path, d):
    """The solutions file, written here with repr() (exact round trip), not by ascorr."""
    with open(path, "w") as f:
        f.write("t,chu,qw,qx,qy,qz,t_chu,t_029,t_032,vx,vy,vz\n")
        for i in range(len(d["t"])):
            fields = [repr(float(d["t"][i])), str(d["chu"][i])]
            fields += [repr(float(x)) for x in (*d["q"][i], *d["temps"][i], *d["v"][i])]
            f.write(",".join(fields) + "\n")


@pytest.mark.parametrize("scalar", SCALARS)
def test_random_set_bit_for_bit(exe, tmp_path, scalar):
    d = random_solutions(4000, seed=15)
    path = tmp_path / "random.csv"
    write_csv_exact(path, d)
    _, input_rows = read_csv_text(path)
    model = ascorr.read_model(str(DATA / "model_table2.csv"))
    header, rows = cli_correct(exe, tmp_path, path, scalar, ["--model", DATA / "model_table2.csv"])
    q, status = ascorr.correct(d["t"], d["chu"], d["q"], d["temps"], d["v"], model=model, scalar=scalar)
    assert_same_as_cli(d, q, status, header, rows, input_rows)
    # The set is not vacuous: every status class occurs, and most rows are corrected.
    for bit in (1, 2, 4, 8, 16, 32, 64, 256):
        assert np.any(status & bit), f"no row with status bit {bit}"
    assert np.count_nonzero(status == 3) > len(status) // 4


def test_large_input_uses_threads_and_agrees_with_single_rows():
    """50,000 rows run on several threads (16,384 rows per thread at least) give
    the same bits as the rows corrected one at a time."""
    d = random_solutions(50000, seed=3)
    model = ascorr.read_model(str(DATA / "model_table2.csv"))
    q, status = ascorr.correct(d["t"], d["chu"], d["q"], d["temps"], d["v"], model=model)
    for i in range(0, 50000, 997):
        qi, si = ascorr.correct(d["t"][i:i + 1], d["chu"][i:i + 1], d["q"][i:i + 1], d["temps"][i:i + 1],
                                d["v"][i:i + 1], model=model)
        assert si[0] == status[i]
        assert qi[0].tobytes() == q[i].tobytes()


def test_chu_as_indices_float32_and_non_contiguous_inputs_give_the_same_bits():
    d = random_solutions(2000, seed=7)
    model = ascorr.read_model(str(DATA / "model_table2.csv"))
    ref_q, ref_st = ascorr.correct(d["t"], d["chu"], d["q"], d["temps"], d["v"], model=model)
    heads = np.array([ascorr.HEADS.index(c) if c in ascorr.HEADS else 9 for c in d["chu"]], dtype=np.int32)
    q2, st2 = ascorr.correct(d["t"], heads, d["q"], d["temps"], d["v"], model=model)
    assert np.array_equal(st2, ref_st) and q2.tobytes() == ref_q.tobytes()
    objects = np.array(list(d["chu"]), dtype=object)
    q3, st3 = ascorr.correct(list(d["t"]), objects, d["q"], d["temps"], d["v"], model=model)
    assert np.array_equal(st3, ref_st) and q3.tobytes() == ref_q.tobytes()
    # Non-contiguous views (Fortran order, strided) are converted: same result.
    wide = np.zeros((2000, 8))
    wide[:, ::2] = d["q"]
    q4, st4 = ascorr.correct(d["t"], d["chu"], wide[:, ::2], np.asfortranarray(d["temps"]), d["v"], model=model)
    assert np.array_equal(st4, ref_st) and q4.tobytes() == ref_q.tobytes()
    # float32 inputs (other than t) are converted to float64 first: the same as converting them ourselves.
    f32 = {k: (v.astype(np.float32) if k not in ("chu", "t") else v) for k, v in d.items()}
    q5, st5 = ascorr.correct(f32["t"], f32["chu"], f32["q"], f32["temps"], f32["v"], model=model)
    q6, st6 = ascorr.correct(*(f32[k].astype(np.float64) if k != "chu" else f32[k] for k in ("t", "chu", "q", "temps", "v")),
                             model=model)
    assert np.array_equal(st5, st6) and q5.tobytes() == q6.tobytes()


def test_write_solutions_round_trip_and_cli_agreement(exe, tmp_path):
    d = random_solutions(500, seed=11)
    d["flags"] = np.arange(500) % 3
    d["confidence"] = np.where(np.arange(500) % 5 == 0, np.nan, 1.5)
    path = tmp_path / "written.csv"
    ascorr.write_solutions(str(path), d["t"], d["chu"], d["q"], d["temps"], d["v"], d["flags"], d["confidence"])
    back = ascorr.read_solutions(str(path))
    assert list(back["chu"]) == list(d["chu"])
    for k in ("t", "q", "temps", "v", "confidence"):
        assert np.array_equal(back[k], d[k], equal_nan=True), k
    assert np.array_equal(back["flags"], d["flags"])
    # The corrected file comes back with its status column.
    out = tmp_path / "corrected.csv"
    run_cli(exe, "correct", "--in", path, "--out", out)
    c = ascorr.read_solutions(str(out))
    q, status = ascorr.correct(d["t"], d["chu"], d["q"], d["temps"], d["v"])
    assert np.array_equal(c["status"], status)
    ok = (status & 16) == 0
    assert np.all(np.abs(c["q"][ok] - q[ok]) <= 6e-16)  # 15 decimals (5e-16) plus reading back (ulp/2)


def test_contiguous_float64_inputs_are_not_copied():
    """NumPy reports its buffers to tracemalloc: with float64 C-contiguous inputs
    the call allocates its two outputs and no copy of q, temps or v; float32
    q, temps and v (the control) show their conversions."""
    import tracemalloc

    n = 100_000
    d = random_solutions(n, seed=5)
    outputs = n * 4 * 8 + n * 2
    inputs = n * (4 + 3 + 3 + 1) * 8

    def peak(args):
        tracemalloc.start()
        tracemalloc.reset_peak()
        ascorr.correct(*args)
        p = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
        return p

    f64 = [d["t"], d["chu"], d["q"], d["temps"], d["v"]]
    f32 = [f64[0]] + [x.astype(np.float32) if x.dtype.kind == "f" else x for x in f64[1:]]
    converted = n * (4 + 3 + 3) * 8
    assert peak(f64) < outputs + 0.1 * inputs
    assert peak(f32) > outputs + 0.9 * converted
