# Type stub of the ascorr package (the compiled module ascorr._ascorr and
# ascorr.to_frame). Docstrings: help(ascorr.correct) etc.
from os import PathLike
from typing import Any, Literal, Optional, TypedDict, Union

import numpy as np
import numpy.typing as npt

_Real = npt.ArrayLike  # any real dtype; float64 C-contiguous is used in place
_Path = Union[str, PathLike[str]]

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
    def write(self, path: str) -> None: ...
    def to_csv(self) -> str: ...

def read_model(path: str) -> Model: ...
def correct(
    t: _Real,
    chu: npt.ArrayLike,
    q: _Real,
    temps: Optional[_Real],
    v: Optional[_Real],
    model: Optional[Model] = ...,
    scalar: Literal["double", "float", "fixed"] = ...,
    aberration: bool = ...,
    states: Optional[_Path] = ...,
    states_frame: Literal["itrf", "gcrs"] = ...,
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
) -> tuple[Model, dict[str, Any]]: ...
def read_solutions(path: str) -> dict[str, npt.NDArray[Any]]: ...
def write_solutions(
    path: str,
    t: _Real,
    chu: npt.ArrayLike,
    q: _Real,
    temps: Optional[_Real] = ...,
    v: Optional[_Real] = ...,
    flags: Optional[npt.ArrayLike] = ...,
    confidence: Optional[_Real] = ...,
    status: Optional[npt.ArrayLike] = ...,
) -> None: ...
def to_frame(solutions: dict[str, npt.NDArray[Any]]) -> Any: ...  # pandas.DataFrame
