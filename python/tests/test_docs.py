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


def test_every_public_name_has_a_docstring_and_a_stub():
    stub = STUB.read_text()
    for name in ascorr.__all__:
        obj = getattr(ascorr, name)
        assert obj.__doc__ and len(obj.__doc__) > 40, name
        assert re.search(rf"^(def|class) {name}\b", stub, re.M), f"{name} missing from the stub"


def module_parameters(obj):
    """[(name, has a default)] of a public function or method, as the module
    defines it (pybind11's first docstring line for a compiled one)."""
    if inspect.isfunction(obj) and not hasattr(obj, "__wrapped__"):  # written in Python (ascorr/__init__.py)
        return [(p.name, p.default is not p.empty) for p in inspect.signature(obj).parameters.values()]
    # pybind11 puts the signature on the docstring's first line: name(a: T, b: T = ...) -> R
    first = obj.__doc__.splitlines()[0]
    inner = first[first.index("(") + 1:first.rindex(")")]
    params = [(m.group(1), m.group(2) is not None) for m in re.finditer(r"(\w+): [^,=]+?( = [^,]+)?(?:, |$)", inner)]
    return [p for p in params if p[0] != "self"]


def module_docstring(obj):
    """The docstring of a public name as help() shows it, without pybind11's
    signature line; "" when it has none beyond the signature."""
    doc = obj.__doc__ or ""
    first = doc.split("\n", 1)[0]
    if re.match(r"^\w+\(.*\)( -> .*)?$", first):  # pybind11's signature line
        doc = doc[len(first):]
    return inspect.cleandoc(doc)


def stub_drift(text):
    """Where the stub (its text) differs from the module: every public function,
    class, method and property must carry the module's docstring, word for word,
    and the module's parameters, with a default where the module has one.
    Returns one line per difference."""
    problems = []
    tree = ast.parse(text)
    defs = {n.name: n for n in tree.body if isinstance(n, (ast.FunctionDef, ast.ClassDef))}

    def compare(label, node, obj):
        stub_doc = ast.get_docstring(node) or ""
        want = module_docstring(obj)
        if stub_doc != want:
            problems.append(f"{label}: the stub's docstring is not the module's:\n--- stub\n{stub_doc}\n--- module\n{want}")
        if isinstance(node, ast.FunctionDef) and not any(
                isinstance(d, ast.Name) and d.id == "property" for d in node.decorator_list):
            args = node.args.args
            defaults = [False] * (len(args) - len(node.args.defaults)) + [True] * len(node.args.defaults)
            stub_params = [(a.arg, d) for a, d in zip(args, defaults) if a.arg != "self"]
            have = module_parameters(obj)
            # pybind11 calls a parameter bound without a name argN (positional only): any name will do in the stub.
            same = len(stub_params) == len(have) and all(
                (a == b or re.fullmatch(r"arg\d+", b)) and a_default == b_default
                for (a, a_default), (b, b_default) in zip(stub_params, have))
            if not same:
                problems.append(f"{label}: parameters {stub_params} in the stub, {have} in the module")

    for name in ascorr.__all__:
        if name not in defs:
            problems.append(f"{name}: not in the stub")
            continue
        obj = getattr(ascorr, name)
        compare(name, defs[name], obj)
        if isinstance(obj, type):
            for member in defs[name].body:
                if isinstance(member, ast.FunctionDef) and member.name in vars(obj):
                    compare(f"{name}.{member.name}", member, getattr(obj, member.name))
    return problems


def test_stub_docstrings_and_signatures_are_the_modules():
    """python/ascorr/__init__.pyi repeats the module's docstrings (written once,
    in python/src/docstrings.hpp and ascorr/__init__.py) for editors and type
    checkers: they must not drift apart."""
    problems = stub_drift(STUB.read_text())
    assert not problems, "\n".join(problems)


def test_stub_drift_is_found():
    """Mutation check: a changed word, a lost docstring, a lost default and a
    renamed parameter in the stub are each reported, naming the function."""
    stub = STUB.read_text()
    mutations = {
        "correct": stub.replace("Every row comes back", "Every row returns", 1),
        "read_model": re.sub(r'(def read_model\(path: _Path\) -> Model:\n)\s+""".*?"""\n', r"\1    ...\n", stub,
                             count=1, flags=re.S),
        "earth_velocity": stub.replace("exact: bool = ...", "exact: bool", 1),
        "Model.write": stub.replace("def write(self, path: _Path)", "def write(self, file: _Path)", 1),
        "Model.heads": stub.replace("The heads with coefficients", "The heads with models", 1),
    }
    for name, text in mutations.items():
        assert text != stub, f"mutation of {name} did not apply"
        problems = stub_drift(text)
        assert any(p.startswith(f"{name}:") for p in problems), (name, problems)


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
