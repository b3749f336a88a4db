"""The notebook examples/mission.ipynb: committed without outputs, and executed
as written (Debian's `jupyter nbconvert --execute`) into the build tree, where
it shows the Table 3 layout with the thermal stage at the simulator's noise
floor and draws its two figures."""

import base64
import json
import os
import pathlib
import shutil
import struct
import subprocess
import sys

import pytest

from conftest import SOURCE

NOTEBOOK = SOURCE / "examples" / "mission.ipynb"


def test_committed_notebook_has_no_outputs():
    nb = json.loads(NOTEBOOK.read_text())
    code = [c for c in nb["cells"] if c["cell_type"] == "code"]
    assert len(code) >= 5
    for c in code:
        assert c["outputs"] == [] and c["execution_count"] is None, "".join(c["source"])[:60]
        assert set(c["metadata"]) <= {"tags"}, c["metadata"]


@pytest.fixture(scope="module")
def executed(exe, tmp_path_factory):
    """The executed copy (its working directory: ASCORR_NOTEBOOK_DIR, in the build tree under CTest)."""
    given = os.environ.get("ASCORR_NOTEBOOK_DIR")
    work = pathlib.Path(given) if given else tmp_path_factory.mktemp("notebook")
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    shutil.copy(NOTEBOOK, work / NOTEBOOK.name)
    jupyter = pathlib.Path(sys.executable).with_name("jupyter")
    assert jupyter.exists(), f"{jupyter}: not found (Debian's jupyter-nbconvert)"
    p = subprocess.run([jupyter, "nbconvert", "--to", "notebook", "--execute", "--output", "executed.ipynb",
                        "--ExecutePreprocessor.timeout=900", NOTEBOOK.name],
                       cwd=work, env={**os.environ, "ASCORR_EXE": exe}, capture_output=True, text=True)
    assert p.returncode == 0, p.stderr[-4000:]
    return json.loads((work / "executed.ipynb").read_text())


def text_of(cell):
    return "".join("".join(o.get("text", "")) for o in cell["outputs"] if o["output_type"] == "stream")


def test_notebook_prints_table_3_with_the_thermal_stage_at_the_noise_floor(executed):
    (cell,) = [c for c in executed["cells"] if "table3.to_string" in "".join(c["source"])]
    lines = text_of(cell).splitlines()
    assert "whole mission" in lines[0] and "modelling period" in lines[0] and "prediction" in lines[0]
    rows = {line.split()[0]: [float(x) for x in line.split()[1:]]
            for line in lines if line[:3] in ("A-B", "A-C", "B-C")}
    assert rows.keys() == {"A-B", "A-C", "B-C"}
    for pair, v in rows.items():
        assert len(v) == 10, (pair, v)  # 3 periods x 3 stages, and the floor
        floor = v[9]
        for k in range(3):
            original, aberration, thermal = v[3 * k:3 * k + 3]
            assert original > 3 * aberration and aberration >= thermal, (pair, k, v)
            assert abs(thermal / floor - 1) < 0.02, (pair, k, thermal, floor)


def png_size(data):
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    return struct.unpack(">II", data[16:24])


def test_notebook_draws_the_iba_and_temperature_figures(executed):
    images = [(("".join(c["source"])), base64.b64decode(o["data"]["image/png"]))
              for c in executed["cells"] for o in c.get("outputs", []) if "image/png" in o.get("data", {})]
    assert [("ascorr.iba" in src, "T_CHU" in src) for src, _ in images] == [(True, False), (False, True)]
    for _, png in images:
        width, height = png_size(png)
        assert width > 500 and height > 300 and len(png) > 20000, (width, height, len(png))


def test_notebook_compares_the_self_calibrated_model_with_the_ground_fit(executed):
    (cell,) = [c for c in executed["cells"] if "comparison.to_string" in "".join(c["source"])]
    lines = text_of(cell).splitlines()
    assert "models adopted" in lines[0], lines[0]
    rows = {line.split()[0]: [float(x) for x in line.split()[1:]]
            for line in lines if line[:3] in ("A-B", "A-C", "B-C")}
    assert rows.keys() == {"A-B", "A-C", "B-C"}
    for pair, (fitted, learnt, floor) in rows.items():
        # Learnt on board from nothing, it reaches the floor as the ground fit does.
        assert abs(fitted / floor - 1) < 0.02 and abs(learnt / floor - 1) < 0.03, (pair, fitted, learnt, floor)
