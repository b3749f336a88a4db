#!/usr/bin/env python3
"""The package as a ground user installs it (CTest `Python.venv_install`, not
collected by pytest):

    venv_install.py SOURCE_DIR WORK_DIR ASCORR_EXE

1. a fresh virtual environment from the interpreter that runs this (Debian's),
   with the system's site packages (NumPy), in WORK_DIR/venv;
2. `pip install --no-build-isolation --no-index SOURCE_DIR` in it, building in
   WORK_DIR/build (ASCORR_BUILD_DIR, kept between runs so that only what
   changed is rebuilt); nothing may appear in the source tree;
3. from WORK_DIR (outside the source tree, no PYTHONPATH): `import ascorr` is
   the environment's (its package and compiled module inside the venv), and it
   corrects the worked example (tests/data/solutions.csv with the Table 2
   model) to the same numbers and status bits as `ascorr correct`;
4. `pip wheel` gives a platform wheel holding the compiled module and the
   package's files.
"""

import os
import pathlib
import shutil
import subprocess
import sys
import zipfile

SRC, WORK, EXE = (pathlib.Path(a).resolve() for a in sys.argv[1:4])
VENV = WORK / "venv"
DATA = SRC / "tests" / "data"


def run(*args, **kw):
    print("+", " ".join("<script>" if "\n" in str(a) else str(a) for a in args), flush=True)
    return subprocess.run([str(a) for a in args], check=True, **kw)


def source_listing():
    """Every path in the source tree, except .git, __pycache__ (the pytest
    suite, maybe running meanwhile, writes there) and the contents of build/,
    where only the names count that are not CMake build directories (the
    presets', maybe configured meanwhile; setuptools' build/lib.*, bdist.*
    would count)."""
    paths = set()
    for dirpath, dirnames, filenames in os.walk(SRC):
        rel = pathlib.Path(dirpath).relative_to(SRC)
        dirnames[:] = [d for d in dirnames if d != "__pycache__"]
        if rel == pathlib.Path("."):
            dirnames[:] = [d for d in dirnames if d != ".git"]
            if "build" in dirnames:
                dirnames.remove("build")
                paths.update(f"build/{n}" for n in os.listdir(SRC / "build")
                             if not (SRC / "build" / n / "CMakeCache.txt").exists())
        paths.update(str(rel / n) for n in dirnames + filenames)
    return paths


CHECK = r"""
import pathlib, sys
import numpy as np
import ascorr, ascorr._ascorr

venv = pathlib.Path(sys.argv[1]).resolve()
for f in (ascorr.__file__, ascorr._ascorr.__file__):
    assert venv in pathlib.Path(f).resolve().parents, f"{f} is not inside {venv}"
print("module:", ascorr._ascorr.__file__)

d = ascorr.read_solutions(sys.argv[2])
q, status = ascorr.correct(d["t"], d["chu"], d["q"], d["temps"], d["v"], model=ascorr.read_model(sys.argv[3]))
lines = pathlib.Path(sys.argv[4]).read_text().splitlines()
header = lines[0].split(",")
rows = [line.split(",") for line in lines[1:] if line]
assert len(rows) == len(q) == len(status), (len(rows), len(q))
cols = [header.index(c) for c in ("qw", "qx", "qy", "qz")]
for i, row in enumerate(rows):
    assert int(row[header.index("status")]) == status[i], (i, row, status[i])
    if status[i] & 16:  # rejected: the input's numbers, unchanged
        assert q[i].tobytes() == d["q"][i].tobytes(), i
    else:
        mine = [f"{x:.15f}" for x in q[i]]
        assert mine == [row[c] for c in cols], (i, [row[c] for c in cols], mine)
print(f"{len(q)} rows as `ascorr correct`, status bits {sorted(set(int(s) for s in status))}")
"""


def main():
    before = source_listing()
    shutil.rmtree(VENV, ignore_errors=True)
    shutil.rmtree(WORK / "wheels", ignore_errors=True)
    WORK.mkdir(parents=True, exist_ok=True)
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME", "VIRTUAL_ENV")}
    env.update(ASCORR_BUILD_DIR=str(WORK / "build"),
               CMAKE_BUILD_PARALLEL_LEVEL=env.get("CMAKE_BUILD_PARALLEL_LEVEL", "2"),
               PIP_DISABLE_PIP_VERSION_CHECK="1", PIP_NO_CACHE_DIR="1")
    run(sys.executable, "-m", "venv", "--system-site-packages", VENV, env=env)
    python = VENV / "bin" / "python"
    run(python, "-m", "pip", "install", "--no-build-isolation", "--no-index", SRC, env=env, cwd=WORK)

    corrected = WORK / "corrected_cli.csv"
    run(EXE, "correct", "--in", DATA / "solutions.csv", "--model", DATA / "model_table2.csv", "--out", corrected)
    run(python, "-c", CHECK, VENV, DATA / "solutions.csv", DATA / "model_table2.csv", corrected, env=env, cwd=WORK)

    run(python, "-m", "pip", "wheel", "--no-build-isolation", "--no-index", "--no-deps", "-w", WORK / "wheels", SRC,
        env=env, cwd=WORK)
    (wheel,) = (WORK / "wheels").glob("ascorr-*.whl")
    names = zipfile.ZipFile(wheel).namelist()
    assert not wheel.name.endswith("-any.whl"), f"{wheel.name}: not a platform wheel"
    for want in ("ascorr/__init__.py", "ascorr/__init__.pyi", "ascorr/py.typed"):
        assert want in names, (want, names)
    assert any(n.startswith("ascorr/_ascorr.") and n.endswith(".so") for n in names), names
    print("wheel:", wheel.name)

    after = source_listing()
    assert after == before, f"written into the source tree: {sorted(after - before)}, removed: {sorted(before - after)}"
    print("venv install, import, worked example and wheel: all pass")


if __name__ == "__main__":
    main()
