"""ascorr: thermal and aberration correction of uASC star-tracker attitude solutions.

The same core and host library as the ``ascorr`` command line, on NumPy arrays
(one row per solution, nothing dropped). Conventions (README.md): times in s
since J2000.0 TT; quaternions Hamilton, scalar first, q_chu_icrf maps ICRF
components into CHU components; velocities km/s; angles arcsec.

Functions: read_model, correct, earth_velocity, iba, stats, fit,
read_solutions, write_solutions, to_frame, from_frame. Classes: Model. Exceptions:
InputError and FitRefused (both ValueError). HEADS: the head letters in
index order (from the core's ascorr/heads.hpp).
"""

from ._ascorr import (  # noqa: F401
    HEADS,
    FitRefused,
    InputError,
    Model,
    correct,
    earth_velocity,
    fit,
    iba,
    read_model,
    read_solutions,
    stats,
    write_solutions,
)

__all__ = [
    "FitRefused",
    "InputError",
    "Model",
    "correct",
    "earth_velocity",
    "fit",
    "from_frame",
    "iba",
    "read_model",
    "read_solutions",
    "stats",
    "to_frame",
    "write_solutions",
]

_COLUMNS = {
    "q": ("qw", "qx", "qy", "qz"),
    "temps": ("t_chu", "t_029", "t_032"),
    "v": ("vx", "vy", "vz"),
}


def to_frame(solutions):
    """A pandas DataFrame with the file's column names (t, chu, qw..qz, t_chu,
    t_029, t_032, vx, vy, vz, flags, confidence[, status]) from the dict that
    read_solutions() returns. Needs pandas (ImportError otherwise)."""
    import pandas  # optional dependency

    columns = {}
    for key, value in solutions.items():
        if key in _COLUMNS:
            for j, name in enumerate(_COLUMNS[key]):
                columns[name] = value[:, j]
        else:
            columns[key] = value
    return pandas.DataFrame(columns)


# Column groups that from_frame() may find absent: NaN, as read_solutions()
# gives for a file without them.
_OPTIONAL_GROUPS = ("temps", "v")


def _column(frame, name, dtype):
    """frame[name] as a NumPy array of dtype; pandas' missing values (NaN, None,
    pd.NA) become NaN in a real column and are refused in an integer one."""
    import numpy as np

    series = frame[name]
    try:
        if np.dtype(dtype).kind == "f":
            return series.to_numpy(dtype=dtype, na_value=np.nan)
        missing = series.isna().to_numpy()
        if missing.any():
            raise ValueError(f"row {series.index[missing.argmax()]!r} is missing")
        return series.to_numpy(dtype=dtype)
    except (TypeError, ValueError) as e:
        raise ValueError(f"from_frame: column '{name}': {e}") from None


def from_frame(frame):
    """The dict of arrays that read_solutions() returns (keys are correct()'s,
    stats()'s, fit()'s and write_solutions()'s argument names) from a pandas
    DataFrame with the file's column names, in any order: to_frame()'s
    inverse. t, chu and qw..qz are required (ValueError naming the missing
    ones); absent t_chu/t_029/t_032, vx/vy/vz or confidence are NaN and absent
    flags 0, as in a file without them; missing values (NaN, None, pd.NA) are
    NaN, except in chu, flags and status, where they are refused. chu holds
    head letters (strings) or head indices (integers); "status" is kept when
    present (a corrected file). Rows are taken in the frame's order; its index
    only names rows in messages."""
    import numpy as np
    import pandas

    columns = set(frame.columns)
    required = ["t", "chu", *_COLUMNS["q"]]
    missing = [c for c in required if c not in columns]
    if missing:
        raise ValueError(f"from_frame: no column {', '.join(map(repr, missing))} (have {list(frame.columns)})")
    n = len(frame)
    out = {"t": _column(frame, "t", np.float64)}
    chu = frame["chu"]
    if chu.isna().any():
        raise ValueError(f"from_frame: column 'chu': row {chu.index[chu.isna().to_numpy().argmax()]!r} is missing")
    integer = pandas.api.types.is_integer_dtype(chu.dtype)
    out["chu"] = _column(frame, "chu", np.int64) if integer else chu.to_numpy(dtype=str)
    for key in ("q", "temps", "v"):
        names = _COLUMNS[key]
        present = [c in columns for c in names]
        if all(present):
            out[key] = np.column_stack([_column(frame, c, np.float64) for c in names])
        elif not any(present) and key in _OPTIONAL_GROUPS:
            out[key] = np.full((n, len(names)), np.nan)
        else:
            absent = ", ".join(repr(c) for c, p in zip(names, present) if not p)
            raise ValueError(f"from_frame: no column {absent} beside {[c for c in names if c in columns]}")
    out["flags"] = _column(frame, "flags", np.int64) if "flags" in columns else np.zeros(n, np.int64)
    out["confidence"] = _column(frame, "confidence", np.float64) if "confidence" in columns else np.full(n, np.nan)
    if "status" in columns:
        status = _column(frame, "status", np.int64)
        bad = (status < 0) | (status > np.iinfo(np.uint16).max)
        if bad.any():
            raise ValueError(f"from_frame: column 'status': row {frame.index[bad.argmax()]!r} is not a status "
                             f"(0 to 65535): {status[bad.argmax()]}")
        out["status"] = status.astype(np.uint16)
    return out
