# SPDX-License-Identifier: MIT
"""The woven examples' titles name the yarns by the direction they run in the solved
cell: the generator lays the warp along x and the weft along y (REFERENCE.md, *Woven
geometry*), so a cell stretched or pulled along x loads the warp and n22 is held by the
weft. The direction of each yarn type is read from the written state, not from the
docs; the titles once said the opposite (and plot-membrane prints the title)."""
from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import f90nml
import numpy as np
import pytest

import yarnfort
from yarnfort.results import read_state

TOP = Path(__file__).resolve().parents[2]


def yarn_along(state, axis: int) -> set[int]:
    """Materials (1-based) whose elements run along `axis` (x 0, y 1) at step 0."""
    ends = state.position[state.elements]
    run = np.abs(ends[:, 1] - ends[:, 0])
    along = run[:, axis] > 10.0 * run[:, 1 - axis]
    return {int(m) for m in np.asarray(state.cell_data["material"])[along]}


@pytest.mark.parametrize("name, verb", [("weave_biaxial", "stretched"),
                                        ("weave_force", "pulled"),
                                        ("weave_shear", None)])
def test_woven_titles_name_the_yarn_along_each_axis(tmp_path, name, verb):
    shutil.copytree(TOP / "inputs", tmp_path / "inputs")
    with open(tmp_path / "inputs" / f"{name}.nml") as scene:
        done = subprocess.run([str(yarnfort.program_path())], stdin=scene, cwd=tmp_path,
                              capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr
    folder = tmp_path / "out" / name
    scene = f90nml.read(str(folder / "input.nml"))
    materials = [m["name"] for m in scene["material"]]
    state = read_state(folder / "state_00000.vtu")
    along_x, along_y = yarn_along(state, 0), yarn_along(state, 1)
    assert len(along_x) == 1 and len(along_y) == 1 and along_x != along_y
    x_yarn, y_yarn = materials[along_x.pop() - 1], materials[along_y.pop() - 1]
    title = scene["control"]["title"]
    assert f"{y_yarn} held at" in title  # n22: the force carried along y
    if verb is not None:
        assert f"{x_yarn} {verb}" in title  # e11 or n11: along x
