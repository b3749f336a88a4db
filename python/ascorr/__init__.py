"""ascorr: thermal and aberration correction of uASC star-tracker attitude solutions.

The same core and host library as the ``ascorr`` command line, on NumPy arrays
(one row per solution, nothing dropped). Conventions (README.md): times in s
since J2000.0 TT; quaternions Hamilton, scalar first, q_chu_icrf maps ICRF
components into CHU components; velocities km/s; angles arcsec.

Functions: read_model, correct, earth_velocity, iba, stats, fit,
read_solutions, write_solutions, to_frame. Classes: Model. Exceptions:
InputError and FitRefused (both ValueError). HEADS: the head letters in
index order (from the core's ascorr/heads.hpp).

Arguments: a wrong value raises ValueError "argument 'NAME': expected ..., got
..."; a missing or unknown argument raises TypeError naming it. Paths are str
or os.PathLike (pathlib.Path). Enumerations ('double'/'float'/'fixed',
'itrf'/'gcrs', 'linear'/'quadratic') are names, in any case, as on the command
line; numbers are not names. Booleans are True or False (None is neither).
"""

import functools as _functools
import inspect as _inspect

from . import _ascorr
from ._ascorr import HEADS, FitRefused, InputError, Model  # noqa: F401


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


correct = _checked(_ascorr.correct, "correct")
earth_velocity = _checked(_ascorr.earth_velocity, "earth_velocity")
fit = _checked(_ascorr.fit, "fit")
iba = _checked(_ascorr.iba, "iba")
read_model = _checked(_ascorr.read_model, "read_model")
read_solutions = _checked(_ascorr.read_solutions, "read_solutions")
stats = _checked(_ascorr.stats, "stats")
write_solutions = _checked(_ascorr.write_solutions, "write_solutions")
Model.__init__ = _checked(Model.__init__, "Model", method=True)
Model.write = _checked(Model.write, "Model.write", method=True)

__all__ = [
    "FitRefused",
    "InputError",
    "Model",
    "correct",
    "earth_velocity",
    "fit",
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
