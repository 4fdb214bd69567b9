# SPDX-License-Identifier: MIT
"""``python -m yarnfort plot-membrane``: the picture of a periodic-cell run's membrane
forces, and clear answers for a folder without a run or with a run that is not a
periodic cell."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
from fabric_scenes import patched_scene
from test_axial_force import run_knit_file

from yarnfort import read_curve
from yarnfort.plots import plot_membrane

TOP = Path(__file__).resolve().parents[2]
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def plot(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "yarnfort", "plot-membrane", *args],
                          capture_output=True, text=True, cwd=TOP, timeout=300)


def test_a_folder_without_a_curve_is_named(tmp_path):
    done = plot(str(tmp_path / "nowhere"))
    assert done.returncode == 2
    assert "no output folder" in done.stderr and str(tmp_path / "nowhere") in done.stderr
    assert "Traceback" not in done.stderr


def test_a_run_that_is_not_a_cell_is_refused(run_yarnfort, tmp_path):
    folder = tmp_path / "capstan"
    run = run_yarnfort(patched_scene("inputs/capstan.nml", {"output.vtk_every": 0}, folder),
                       cwd=TOP)
    assert run.returncode == 0, run.stderr
    done = plot(str(folder))
    assert done.returncode == 2
    assert "not a periodic-cell run" in done.stderr


def test_the_biaxial_knit_is_drawn(run_yarnfort, tmp_path):
    """The three panels show the run's own columns: n11, n22 (held, a flat line) and e22
    against e11, forces from zero; the command writes the PNG it names."""
    folder = tmp_path / "biaxial"
    curve = run_knit_file(run_yarnfort, folder, "inputs/knit_biaxial.nml")
    figure = plot_membrane(read_curve(folder))
    panels = figure.axes
    assert [a.get_ylabel() for a in panels] == ["n11 (N/m)", "n22 (N/m)", "e22 (1)"]
    drawn = {a.get_ylabel(): np.concatenate([line.get_ydata() for line in a.get_lines()])
             for a in panels}
    assert np.isclose(drawn["n22 (N/m)"], 20.0, rtol=1e-6).all()
    assert set(np.round(drawn["e22 (1)"], 12)) <= set(np.round(curve["e22"], 12))
    assert panels[0].get_ylim()[0] == 0.0 and panels[1].get_ylim()[0] == 0.0
    png = tmp_path / "membrane.png"
    done = plot(str(folder), "--out", str(png))
    assert done.returncode == 0, done.stderr
    assert str(png) in done.stdout
    assert png.read_bytes()[:8] == PNG_SIGNATURE
