# Type stub of the ascorr package (the compiled module ascorr._ascorr and
# ascorr.to_frame, ascorr.from_frame). Docstrings: help(ascorr.correct) etc.
from os import PathLike
from typing import Any, Optional, TypedDict, Union

import numpy as np
import numpy.typing as npt

_Real = npt.ArrayLike  # any real dtype; float64 C-contiguous is used in place
_Path = Union[str, PathLike[str]]  # every path argument: str or os.PathLike (pathlib.Path)

__version__: str  # project(VERSION) of the CMake build
HEADS: str  # the head letters in index order, from the core (ascorr/heads.hpp)

class InputError(ValueError): ...
class FitRefused(ValueError): ...

class Model:
    def __init__(self, coefficients: npt.ArrayLike, heads: Optional[str] = ...) -> None: ...
    @property
    def coefficients(self) -> npt.NDArray[np.float64]: ...  # (len(HEADS), 3, 7) arcsec
    @property
    def heads(self) -> str: ...
    @property
    def quadratic(self) -> bool: ...
    def write(self, path: _Path) -> None: ...
    def to_csv(self) -> str: ...
    def __eq__(self, other: object) -> bool: ...  # the same model file; Model pickles
    def __getstate__(self) -> tuple[npt.NDArray[np.float64], str, bool]: ...
    def __setstate__(self, state: tuple[npt.NDArray[np.float64], str, bool]) -> None: ...

# Enumerations are names in any case ("GCRS" is "gcrs"), as on the command line.
def read_model(path: _Path) -> Model: ...
def correct(
    t: _Real,
    chu: npt.ArrayLike,
    q: _Real,
    temps: Optional[_Real],
    v: Optional[_Real],
    model: Optional[Model] = ...,
    scalar: str = ...,  # "double", "float" or "fixed", any case
    aberration: bool = ...,
    states: Optional[_Path] = ...,
    states_frame: str = ...,  # "itrf" or "gcrs", any case
    max_propagation: float = ...,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.uint16]]: ...
def earth_velocity(t: _Real, exact: bool = ...) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
def iba(
    t: _Real, chu: npt.ArrayLike, q: _Real
) -> dict[str, tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]]: ...

class _PairStats(TypedDict):
    original: Optional[float]
    aberration: Optional[float]
    thermal: Optional[float]
    original_smoothed: Optional[float]
    aberration_smoothed: Optional[float]
    thermal_smoothed: Optional[float]
    n: int

class _Stats(TypedDict):
    pairs: dict[str, _PairStats]
    rows: int
    clean_rows: int
    table: str
    messages: str

def stats(
    t: _Real,
    chu: npt.ArrayLike,
    q: _Real,
    temps: Optional[_Real],
    v: Optional[_Real],
    flags: Optional[npt.ArrayLike] = ...,
    confidence: Optional[_Real] = ...,
    model: Optional[Model] = ...,
    t_from: Optional[float] = ...,
    t_to: Optional[float] = ...,
) -> _Stats: ...
def fit(
    t: _Real,
    chu: npt.ArrayLike,
    q: _Real,
    temps: Optional[_Real],
    v: Optional[_Real],
    flags: Optional[npt.ArrayLike] = ...,
    confidence: Optional[_Real] = ...,
    t_from: Optional[float] = ...,
    t_to: Optional[float] = ...,
    min_days: float = ...,
    min_orbits: int = ...,
    max_condition: float = ...,
    orbit_period: Optional[float] = ...,
    terms: str = ...,  # "linear" or "quadratic", any case
    holdout: float = ...,
    min_temperature_range: float = ...,
) -> tuple[Model, dict[str, Any]]: ...
class _ActiveModel(TypedDict):
    t: float
    version: int
    crc32c: int
    model: Model

def self_calibrate(
    t: _Real,
    chu: npt.ArrayLike,
    q: _Real,
    temps: Optional[_Real],
    v: Optional[_Real],
    flags: Optional[npt.ArrayLike] = ...,
    confidence: Optional[_Real] = ...,
    model: Optional[Model] = ...,
    scalar: Literal["double", "float", "fixed"] = ...,
    time_constant: float = ...,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.uint16], list[_ActiveModel]]: ...
def read_solutions(path: _Path) -> dict[str, Any]: ...  # arrays, and "extra": dict[str, NDArray[str_]]
def write_solutions(
    path: _Path,
    t: _Real,
    chu: npt.ArrayLike,
    q: _Real,
    temps: Optional[_Real] = ...,
    v: Optional[_Real] = ...,
    flags: Optional[npt.ArrayLike] = ...,
    confidence: Optional[_Real] = ...,
    status: Optional[npt.ArrayLike] = ...,
    extra: Optional[dict[str, npt.ArrayLike]] = ...,
) -> None: ...
def to_frame(solutions: dict[str, npt.NDArray[Any]]) -> Any: ...  # pandas.DataFrame
def from_frame(frame: Any) -> dict[str, npt.NDArray[Any]]: ...  # frame: pandas.DataFrame
