"""ascorr: thermal and aberration correction of uASC star-tracker attitude solutions.

The same core and host library as the ``ascorr`` command line, on NumPy arrays
(one row per solution, nothing dropped). Conventions (docs/contract.md): times in s
since J2000.0 TT; quaternions Hamilton, scalar first, q_chu_icrf maps ICRF
components into CHU components; velocities km/s; angles arcsec.

Functions: read_model, correct, self_calibrate, earth_velocity, iba, stats, fit,
read_solutions, write_solutions, to_frame, from_frame, read_mountings, combine, align,
interpolate, import_gracefo.
Classes: Model. Exceptions: InputError, FitRefused and AlignRefused (all
ValueError). HEADS: the head letters in index order (from the core's
ascorr/core/heads.hpp); MODEL_TERMS: the model's terms, the model file's
columns after chu and axis, in order (from ascorr/core/model_terms.hpp).

Arguments: a wrong value raises ValueError "argument 'NAME': expected ..., got
..."; a missing or unknown argument raises TypeError naming it. Paths are str
or os.PathLike (pathlib.Path). Enumerations ('double'/'float'/'fixed',
'itrf'/'gcrs', 'linear'/'quadratic') are names, in any case, as on the command
line; numbers are not names. Booleans are True or False (None is neither).
"""

import functools as _functools
import inspect as _inspect

from . import _ascorr
from ._ascorr import HEADS, MODEL_TERMS, AlignRefused, FitRefused, InputError, Model  # noqa: F401
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
import_gracefo = _checked(_ascorr.import_gracefo, "import_gracefo")
interpolate = _checked(_ascorr.interpolate, "interpolate")
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
    "import_gracefo",
    "interpolate",
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
    pd.NA) become NaN in a real column and are refused in an integer one.
    Dates, durations and booleans are refused, never read as numbers (a
    datetime64 would give nanoseconds since 1970, not seconds since J2000)."""
    import numpy as np

    series = frame[name]
    kind = getattr(series.dtype, "kind", "O")
    if kind in "Mm":
        what = "times are float64 seconds since J2000.0 TT (docs/contract.md, section 1): convert " \
            "them explicitly" if name == "t" else "expected real numbers"
        raise ValueError(f"from_frame: column '{name}': dtype {series.dtype} is not taken: {what}")
    if kind == "b":
        raise ValueError(f"from_frame: column '{name}': expected numbers, got dtype {series.dtype}")
    try:
        if np.dtype(dtype).kind == "f":
            return series.to_numpy(dtype=dtype, na_value=np.nan)
        missing = series.isna().to_numpy()
        if missing.any():
            raise ValueError(f"row {series.index[missing.argmax()]!r} is missing")
        return _integer_column(series, name, dtype)
    except (TypeError, ValueError) as e:
        if str(e).startswith("from_frame:"):
            raise
        raise ValueError(f"from_frame: column '{name}': {e}") from None


# The ranges of the integer columns, as the file reader takes them.
_INT64 = (-(2**63), 2**63 - 1)
_RANGES = {"flags": (0, 2**63 - 1), "status": (0, 65535), "chu": _INT64}


def _integer_column(series, name, dtype):
    """An integer column by the rule of correct()'s arrays (one rule, in the
    compiled module): integers, or floats that are all integral (pandas makes an
    integer column float64 once it held a missing value), within the column's
    range; anything else is refused, naming the row's index label."""
    import numpy as np
    import pandas

    if pandas.api.types.is_unsigned_integer_dtype(series.dtype):
        values = series.to_numpy(dtype=np.uint64)
    elif pandas.api.types.is_integer_dtype(series.dtype):
        values = series.to_numpy(dtype=np.int64)
    elif pandas.api.types.is_float_dtype(series.dtype):
        values = series.to_numpy(dtype=np.float64)
    else:
        raise ValueError(f"expected integers, got dtype {series.dtype}")
    out, bad, why = _ascorr._integers(values, *_RANGES.get(name, _INT64))
    if bad >= 0:
        raise ValueError(f"row {series.index[bad]!r}: {why}")
    return out.astype(dtype)


def from_frame(frame):
    """The dict of arrays that read_solutions() returns (keys are correct()'s,
    stats()'s, fit()'s and write_solutions()'s argument names) from a pandas
    DataFrame with the file's column names, in any order: to_frame()'s
    inverse. t, chu and qw..qz are required (ValueError naming the missing
    ones); absent t_chu/t_029/t_032, vx/vy/vz or confidence are NaN and absent
    flags 0, as in a file without them; missing values (NaN, None, pd.NA) are
    NaN, except in chu, flags and status, where they are refused. chu holds
    head letters (strings) or head indices; flags, head indices and status are
    integers, or floats that are all integral, as correct() takes them (0.9 is
    refused, never truncated); dates (datetime64) are refused, never read as
    seconds since J2000. "status" is kept when
    present (a corrected file); every other column goes under "extra" as text,
    as read_solutions() keeps the columns it does not know. Rows are taken in
    the frame's order; its index only names rows in messages."""
    import numpy as np
    import pandas

    columns = set(frame.columns)
    near_miss = _ascorr._near_miss([str(c) for c in frame.columns])
    if near_miss is not None:  # the file reader's rule and words
        raise ValueError(f"from_frame: {near_miss[1]}")
    required = ["t", "chu", *_COLUMNS["q"]]
    missing = [c for c in required if c not in columns]
    if missing:
        raise ValueError(f"from_frame: no column {', '.join(map(repr, missing))} (have {list(frame.columns)})")
    n = len(frame)
    out = {"t": _column(frame, "t", np.float64)}
    chu = frame["chu"]
    if chu.isna().any():
        raise ValueError(f"from_frame: column 'chu': row {chu.index[chu.isna().to_numpy().argmax()]!r} is missing")
    numeric = pandas.api.types.is_numeric_dtype(chu.dtype) and not pandas.api.types.is_bool_dtype(chu.dtype)
    if not numeric and not all(isinstance(x, str) for x in chu):
        raise ValueError(f"from_frame: column 'chu': expected head letters (strings) or head indices "
                         f"(integers), got dtype {chu.dtype}")
    out["chu"] = _column(frame, "chu", np.int64) if numeric else chu.to_numpy(dtype=str)
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
        out["status"] = _column(frame, "status", np.uint16)
    known = {"t", "chu", "flags", "confidence", "status", *(c for names in _COLUMNS.values() for c in names)}
    out["extra"] = {str(c): frame[c].to_numpy(dtype=str) for c in frame.columns if c not in known}
    return out
