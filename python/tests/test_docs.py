"""Docstrings on every function, the type stub in step with the module, and the
README's example run as written."""

import ast
import os
import pathlib
import re
import subprocess
import sys

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
        if isinstance(obj, type) or name == "to_frame":
            continue
        # pybind11 puts the signature on the docstring's first line: name(a: T, b: T = ...) -> R
        first = obj.__doc__.splitlines()[0]
        params = re.findall(r"(\w+): ", first[first.index("(") + 1:first.rindex(")")])
        assert params == stubs[name], (name, params, stubs[name])


def test_readme_example_runs(exe, tmp_path):
    readme = (SOURCE / "README.md").read_text()
    section = readme[readme.index("## Python module"):]
    section = section[:section.index("\n## ", 5)]
    shell = re.search(r"```sh\n(.*?)```", section, re.S).group(1)
    code = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    # The shell block: `ascorr simulate ...` with this build's executable.
    args = shell.split("#")[0].split()
    assert args[1] == "simulate"
    subprocess.run([exe, *args[1:]], cwd=tmp_path, check=True, capture_output=True)
    os.symlink(SOURCE / "host_sim", tmp_path / "host_sim")
    p = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    assert "A-B" in p.stdout and "rows" in p.stdout


def test_version_is_the_cmake_projects(exe):
    """ascorr.__version__ and `ascorr --version` are CMake's project(VERSION)."""
    assert ascorr.__version__ == os.environ["ASCORR_VERSION"]
    out = subprocess.run([exe, "--version"], check=True, capture_output=True, text=True).stdout
    assert out == f"ascorr {ascorr.__version__}\n"
