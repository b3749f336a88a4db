"""Shared fixtures: the command line built by the same tree (ASCORR_EXE, set by
CTest) and the worked examples (tests/data/)."""

import os
import pathlib
import subprocess
import sys

import pytest

SOURCE = pathlib.Path(os.environ.get("ASCORR_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
DATA = SOURCE / "tests" / "data"


sys.path.insert(0, str(SOURCE / "tools"))
from core_constants import core_constant  # noqa: E402,F401  (the firmware side's constants)


@pytest.fixture(scope="session")
def exe():
    path = os.environ.get("ASCORR_EXE")
    if not path or not os.path.exists(path):
        pytest.fail("ASCORR_EXE must name the ascorr executable of this build (CTest sets it)")
    return path


def run_cli(exe, *args):
    """Runs `ascorr args...`; returns its completed process (fails the test on a non-zero exit)."""
    p = subprocess.run([exe, *map(str, args)], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    return p


def read_csv_text(path):
    """Header names and rows as lists of field texts."""
    lines = pathlib.Path(path).read_text().splitlines()
    return lines[0].split(","), [line.split(",") for line in lines[1:] if line]
