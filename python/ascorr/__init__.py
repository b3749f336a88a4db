"""ascorr: thermal and aberration correction of uASC star-tracker attitude solutions.

The same core and host library as the ``ascorr`` command line, on NumPy arrays
(one row per solution, nothing dropped). Conventions (README.md): times in s
since J2000.0 TT; quaternions Hamilton, scalar first, q_chu_icrf maps ICRF
components into CHU components; velocities km/s; angles arcsec.

Functions: read_model, correct, earth_velocity, iba, stats, fit,
read_solutions, write_solutions, to_frame. Classes: Model. Exceptions:
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
from ._version import __version__  # noqa: F401

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
