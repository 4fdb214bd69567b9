# SPDX-License-Identifier: MIT
"""TexGen import (&fabric kind = 'texgen'): contact counts from the pattern, and the
imported weaves against the built-in generator of the same parameters.

(a) A woven cell of nx x ny crossings has nx * ny yarn-yarn contacts (one per crossing),
    whatever the pattern; TexGen's weft knit cell (one loop) has 2: the loop's head
    around the feet of the loop above (the same count as the built-in planar knit, two
    contacts per loop).
(b) TexGen's plain weave and 2/2 twill of spacing s and thickness t place the yarn
    centres at the crossings, t / 2 apart, with master-node tangents in the plane: the
    import makes the network of the built-in generator with spacing s and gap t / 2
    (up to a translation), so the two curves agree to the Newton tolerance. Tolerance
    1e-10 of the largest force per width (Newton's residual tolerance, 1e-10 of the
    force scale); measured 8e-15 (plain 2 x 2 and twill 4 x 4, with friction).

The shipped examples (inputs/texgen_*.nml) run without pytexgen; the tests that make
models need pytexgen in .venv-texgen (tools/bootstrap installs it where it can) and
skip with a message where it is missing.
"""
from __future__ import annotations

import re
import subprocess
from pathlib import Path

import numpy as np
import pytest

from fabric_scenes import TOP, patched_scene
from yarnfort import read_curve

WEAVE, KNIT = "inputs/texgen_weave.nml", "inputs/texgen_knit.nml"
TEXGEN_PYTHON = TOP / ".venv-texgen" / "bin" / "python"
MODELS = Path(__file__).with_name("texgen_models.py")
#: Imported against built-in weave: Newton's tolerance bounds the difference.
SAME_NETWORK = 1e-10
#: TexGen parameters (mm) of the weaves below: spacing, thickness, yarn width.
SPACING, THICKNESS, WIDTH = 1.0, 0.4, 0.8
UNIFORM = {"solver.max_step": 0.1, "solver.initial_step": 0.1}
LOADING_CYCLE = {"path.time": [0.0, 1.0, 2.0], "path.p_disp": [0.0, 1.0, 0.0]}


def needs_pytexgen():
    if not TEXGEN_PYTHON.exists():
        pytest.skip("pytexgen is not installed (.venv-texgen is missing: tools/bootstrap "
                    "installs it from PyPI where it can); the shipped examples are still "
                    "tested")
    probe = subprocess.run([str(TEXGEN_PYTHON), "-c", "import pytexgen.Core"],
                           capture_output=True, text=True)
    if probe.returncode != 0:
        pytest.skip(f"pytexgen cannot be imported in .venv-texgen: {probe.stderr[-300:]}")


def make_model(kind: str, path: Path, *values: float) -> Path:
    proc = subprocess.run([str(TEXGEN_PYTHON), str(MODELS), kind, str(path),
                           *map(str, values)], capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0 and path.exists(), proc.stderr[-2000:]
    return path


def run(run_yarnfort, base: str, values: dict, folder: Path):
    result = run_yarnfort(patched_scene(base, {"output.vtk_every": 0, **values}, folder),
                          cwd=TOP)
    assert result.returncode == 0, result.stderr
    found = re.search(r"TexGen model: (\d+) yarns, (\d+) contacts", result.stderr)
    counts = (int(found[1]), int(found[2])) if found else None
    return read_curve(folder), counts


def builtin_weave(kind: str, cells: tuple[int, int]) -> dict:
    """texgen_weave.nml's scene with the built-in generator of the same parameters."""
    return {"fabric.kind": kind, "fabric.cells": list(cells),
            "fabric.spacing": [SPACING * 1e-3] * 2, "fabric.gap": 0.5 * THICKNESS * 1e-3,
            "fabric.warp_material": "warp", "fabric.weft_material": "weft",
            "fabric.texgen_file": None, "fabric.texgen_materials": None}


def assert_same_curve(imported, builtin):
    assert np.array_equal(imported["time"], builtin["time"])
    assert np.allclose(imported["strain"], builtin["strain"], rtol=1e-14, atol=0)
    scale = builtin["force_per_width"].max()
    assert np.max(np.abs(imported["force_per_width"] - builtin["force_per_width"])) \
        < SAME_NETWORK * scale


def test_weave_example_equals_builtin_plain_weave(run_yarnfort, tmp_path):
    imported, counts = run(run_yarnfort, WEAVE, UNIFORM, tmp_path / "texgen")
    assert counts == (4, 4)
    builtin, _ = run(run_yarnfort, WEAVE, {**UNIFORM, **builtin_weave("plain", (2, 2))},
                     tmp_path / "builtin")
    assert_same_curve(imported, builtin)


def test_knit_example_finds_two_contacts_per_loop_and_hysteresis(run_yarnfort, tmp_path):
    curve, counts = run(run_yarnfort, KNIT, {}, tmp_path / "knit")
    assert counts == (1, 2)
    strain, force = curve["strain"], curve["force_per_width"]
    peak = int(np.argmax(strain))
    grid = np.linspace(0.2, 0.8, 7)
    loading = np.interp(grid, strain[:peak + 1], force[:peak + 1])
    unloading = np.interp(grid, strain[peak:][::-1], force[peak:][::-1])
    assert np.all(unloading < loading)  # friction at work: the yarn slides


@pytest.mark.parametrize("kind, cells", [("plain", (2, 2)), ("plain", (4, 2)),
                                         ("twill", (4, 4)), ("twill", (8, 4))])
def test_pytexgen_weave_equals_builtin(run_yarnfort, tmp_path, kind, cells):
    needs_pytexgen()
    model = make_model(kind, tmp_path / f"{kind}.tg3", *cells, SPACING, THICKNESS, WIDTH)
    n_yarns = cells[0] + cells[1]
    materials = ["warp"] * cells[1] + ["weft"] * cells[0]
    values = {**UNIFORM, "fabric.texgen_file": str(model),
              "fabric.texgen_materials": materials}
    imported, counts = run(run_yarnfort, WEAVE, values, tmp_path / "texgen")
    assert counts == (n_yarns, cells[0] * cells[1])
    builtin, _ = run(run_yarnfort, WEAVE, {**UNIFORM, **builtin_weave(kind, cells)},
                     tmp_path / "builtin")
    assert_same_curve(imported, builtin)


@pytest.mark.parametrize("sizes", [(1.0, 1.0, 1.2, 0.2), (1.2, 1.0, 1.5, 0.25)])
def test_pytexgen_weft_knit_has_two_contacts_per_loop(run_yarnfort, tmp_path, sizes):
    needs_pytexgen()
    model = make_model("knit", tmp_path / "knit.tg3", *sizes)
    _, counts = run(run_yarnfort, KNIT, {"fabric.texgen_file": str(model),
                                         "path.time": [0.0, 1.0],
                                         "path.p_disp": [0.0, 0.5]}, tmp_path / "run")
    assert counts == (1, 2)
