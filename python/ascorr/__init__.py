"""ascorr: thermal and aberration correction of uASC star-tracker attitude solutions.

The same core and host library as the ``ascorr`` command line, on NumPy arrays
(one row per solution, nothing dropped). Conventions (docs/contract.md): times in s
since J2000.0 TT; quaternions Hamilton, scalar first, q_chu_icrf maps ICRF
components into CHU components; velocities km/s; angles arcsec.

Functions: read_model, correct, self_calibrate, earth_velocity, iba, stats, fit,
read_solutions, write_solutions, to_frame, from_frame, read_mountings, combine, align.
Classes: Model. Exceptions: InputError, FitRefused and AlignRefused (all
ValueError). HEADS: the head letters in index order (from the core's
ascorr/heads.hpp).

Arguments: a wrong value raises ValueError "argument 'NAME': expected ..., got
..."; a missing or unknown argument raises TypeError naming it. Paths are str
or os.PathLike (pathlib.Path). Enumerations ('double'/'float'/'fixed',
'itrf'/'gcrs', 'linear'/'quadratic') are names, in any case, as on the command
line; numbers are not names. Booleans are True or False (None is neither).
"""

import functools as _functools
import inspect as _inspect

from . import _ascorr
from ._ascorr import HEADS, AlignRefused, FitRefused, InputError, Model  # noqa: F401
from ._version import __version__  # noqa: F401


def _signature(f):
    """The signature of a compiled function, from the first line of its
    docstring ("name(a: object, b: object = None) -> ..."): names and defaults."""
    first = f.__doc__.splitlines()[0]
    inner = first[first.index("(") + 1 : first.rindex(")")]
    params = []
    for part in inner.split(", ") if inner else []:
        name, _, default = part.partition(" = ")
        name = name.split(":")[0].strip()
        if name == "self":
            continue
        if default:
            try:
                import ast

                value = ast.literal_eval(default)
            except (ValueError, SyntaxError):
                value = default
            params.append(_inspect.Parameter(name, _inspect.Parameter.POSITIONAL_OR_KEYWORD, default=value))
        else:
            params.append(_inspect.Parameter(name, _inspect.Parameter.POSITIONAL_OR_KEYWORD))
    return _inspect.Signature(params)


def _checked(f, name, method=False):
    """f with Python's own messages for a missing, unknown or extra argument
    (naming it, with the signature), instead of pybind11's overload dump."""
    sig = _signature(f)

    @_functools.wraps(f)
    def call(*args, **kwargs):
        try:
            sig.bind(*(args[1:] if method else args), **kwargs)
        except TypeError as e:
            raise TypeError(f"ascorr.{name}(): {e}; the arguments are {sig}") from None
        return f(*args, **kwargs)

    call.__signature__ = sig
    return call


align = _checked(_ascorr.align, "align")
combine = _checked(_ascorr.combine, "combine")
correct = _checked(_ascorr.correct, "correct")
earth_velocity = _checked(_ascorr.earth_velocity, "earth_velocity")
fit = _checked(_ascorr.fit, "fit")
iba = _checked(_ascorr.iba, "iba")
read_model = _checked(_ascorr.read_model, "read_model")
read_mountings = _checked(_ascorr.read_mountings, "read_mountings")
read_solutions = _checked(_ascorr.read_solutions, "read_solutions")
self_calibrate = _checked(_ascorr.self_calibrate, "self_calibrate")
stats = _checked(_ascorr.stats, "stats")
write_solutions = _checked(_ascorr.write_solutions, "write_solutions")
Model.__init__ = _checked(Model.__init__, "Model", method=True)
Model.write = _checked(Model.write, "Model.write", method=True)

__all__ = [
    "AlignRefused",
    "FitRefused",
    "InputError",
    "Model",
    "align",
    "combine",
    "correct",
    "earth_velocity",
    "fit",
    "from_frame",
    "iba",
    "read_model",
    "read_mountings",
    "read_solutions",
    "self_calibrate",
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
    t_029, t_032, vx, vy, vz, flags, confidence[, status], and the extra
    columns) from the dict that read_solutions() returns. Needs pandas
    (ImportError otherwise)."""
    import pandas  # optional dependency

    columns = {}
    for key, value in solutions.items():
        if key in _COLUMNS:
            for j, name in enumerate(_COLUMNS[key]):
                columns[name] = value[:, j]
        elif key == "extra":
            columns.update(value)
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
    present (a corrected file); every other column goes under "extra" as text,
    as read_solutions() keeps the columns it does not know. Rows are taken in
    the frame's order; its index only names rows in messages."""
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
    known = {"t", "chu", "flags", "confidence", "status", *(c for names in _COLUMNS.values() for c in names)}
    out["extra"] = {str(c): frame[c].to_numpy(dtype=str) for c in frame.columns if c not in known}
    return out
