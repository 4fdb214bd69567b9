# SPDX-License-Identifier: MIT
"""tools/plot_membrane: the picture of a periodic-cell run's membrane forces, and clear
answers for a call without a run (usage, a folder with no curve, a run that is not a
periodic cell)."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

from fabric_scenes import patched_scene
from test_axial_force import run_knit_file

TOP = Path(__file__).resolve().parents[2]
TOOL = TOP / "tools" / "plot_membrane"
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def plot(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(TOOL), *args], capture_output=True,
                          text=True, cwd=TOP, timeout=300)


def test_help_prints_the_usage():
    done = plot("--help")
    assert done.returncode == 0
    assert "tools/plot_membrane OUTPUT_FOLDER [PNG]" in done.stdout


def test_a_folder_without_a_curve_is_named(tmp_path):
    done = plot(str(tmp_path / "nowhere"))
    assert done.returncode == 2
    assert str(tmp_path / "nowhere" / "curve.csv") in done.stderr
    assert "Traceback" not in done.stderr


def test_a_run_that_is_not_a_cell_is_refused(run_yarnfort, tmp_path):
    folder = tmp_path / "capstan"
    run = run_yarnfort(patched_scene("inputs/capstan.nml", {"output.vtk_every": 0}, folder),
                       cwd=TOP)
    assert run.returncode == 0, run.stderr
    done = plot(str(folder))
    assert done.returncode == 1
    assert "not a periodic-cell run" in done.stderr


def test_the_biaxial_knit_is_drawn(run_yarnfort, tmp_path):
    folder = tmp_path / "biaxial"
    run_knit_file(run_yarnfort, folder, "inputs/knit_biaxial.nml")
    png = tmp_path / "membrane.png"
    done = plot(str(folder), str(png))
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == str(png)
    assert png.read_bytes()[:8] == PNG_SIGNATURE
