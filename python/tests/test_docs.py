"""Docstrings on every function, the type stub in step with the module, and the
README's example run as written."""

import ast
import inspect
import os
import pathlib
import re
import struct
import subprocess
import sys

import numpy as np

import ascorr
from conftest import SOURCE

STUB = pathlib.Path(ascorr.__file__).with_name("__init__.pyi")


def stub_functions():
    tree = ast.parse(STUB.read_text())
    return {n.name: [a.arg for a in n.args.args] for n in tree.body if isinstance(n, ast.FunctionDef)}


def test_every_public_name_has_a_docstring_and_a_stub():
    stub = STUB.read_text()
    for name in ascorr.__all__:
        obj = getattr(ascorr, name)
        assert obj.__doc__ and len(obj.__doc__) > 40, name
        assert re.search(rf"^(def|class) {name}\b", stub, re.M), f"{name} missing from the stub"


def test_stub_parameters_match_the_module():
    stubs = stub_functions()
    for name in ascorr.__all__:
        obj = getattr(ascorr, name)
        if isinstance(obj, type):
            continue
        if inspect.isfunction(obj):  # written in Python (ascorr/__init__.py)
            params = list(inspect.signature(obj).parameters)
        else:
            # pybind11 puts the signature on the docstring's first line: name(a: T, b: T = ...) -> R
            first = obj.__doc__.splitlines()[0]
            params = re.findall(r"(\w+): ", first[first.index("(") + 1:first.rindex(")")])
        assert params == stubs[name], (name, params, stubs[name])


def readme_block(marker, lang):
    """The code block right after `<!-- example: marker -->` in README.md."""
    readme = (SOURCE / "README.md").read_text()
    found = re.findall(rf"<!-- example: {marker} -->\n```{lang}\n(.*?)```", readme, re.S)
    assert len(found) == 1, f"README.md: {len(found)} blocks marked '{marker}'"
    return found[0]


def png_pixels(path):
    """(width, height) from the PNG header, and the image as an (h, w, 4) array."""
    import matplotlib.image

    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and data[12:16] == b"IHDR", f"{path} is not a PNG"
    size = struct.unpack(">II", data[16:24])
    return size, matplotlib.image.imread(str(path))


def test_readme_example_runs_and_draws_its_figure(exe, tmp_path):
    shell, code = readme_block("shell", "sh"), readme_block("python", "python")
    # The shell block: `ascorr simulate ...` with this build's executable.
    args = shell.split("#")[0].split()
    assert args[1] == "simulate"
    subprocess.run([exe, *args[1:]], cwd=tmp_path, check=True, capture_output=True)
    os.symlink(SOURCE / "host_sim", tmp_path / "host_sim")
    p = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    assert "A-B" in p.stdout and "rows" in p.stdout
    # The plot branch ran (matplotlib is installed where the tests run) and drew
    # both series: 9 x 4 in at 120 dpi, the original's pixels in the first
    # colour of the cycle, the corrected ones' in the second.
    assert "no plot" not in p.stdout
    (width, height), img = png_pixels(tmp_path / "iba_A-B.png")
    assert (width, height) == (1080, 480) and img.shape[:2] == (480, 1080)
    rgb = img[..., :3]
    for colour in ("#1f77b4", "#ff7f0e"):  # matplotlib's C0, C1
        want = np.array([int(colour[i:i + 2], 16) / 255 for i in (1, 3, 5)])
        hits = int((np.abs(rgb - want).max(axis=2) < 0.02).sum())
        assert hits > 2000, f"{colour}: {hits} pixels"
    assert (rgb.min(axis=2) < 0.9).mean() > 0.02, "the figure is blank"


def test_version_is_the_cmake_projects(exe):
    """ascorr.__version__ and `ascorr --version` are CMake's project(VERSION)."""
    assert ascorr.__version__ == os.environ["ASCORR_VERSION"]
    out = subprocess.run([exe, "--version"], check=True, capture_output=True, text=True).stdout
    assert out == f"ascorr {ascorr.__version__}\n"
