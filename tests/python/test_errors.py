# SPDX-License-Identifier: MIT
"""Python-side error messages (issue 14 items 13 and 16): each names the file, line,
column or support at fault, and no traceback reaches the command line."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

import yarnfort
from yarnfort.calibrate import calibrate, read_measured

TOP = Path(__file__).resolve().parents[2]
CAPSTAN = TOP / "inputs" / "capstan.nml"
HEADER = "step,time,p_force,p_disp,pull_rx,pull_ry,pull_rz,direction\n"


def plot(folder: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "yarnfort", "plot", str(folder)],
                          capture_output=True, text=True, timeout=120,
                          env=dict(os.environ, MPLBACKEND="Agg"))


def test_plot_of_an_empty_curve_is_a_message(tmp_path):
    (tmp_path / "curve.csv").write_text("")
    run = plot(tmp_path)
    assert run.returncode == 2
    assert "empty file" in run.stderr and "Traceback" not in run.stderr


def test_plot_of_a_header_only_curve_is_a_message(tmp_path):
    (tmp_path / "curve.csv").write_text(HEADER)
    run = plot(tmp_path)
    assert run.returncode == 2
    assert "has no rows" in run.stderr and "zero-size" not in run.stderr
    assert "Traceback" not in run.stderr


def test_read_curve_rejects_a_text_cell_and_names_line_and_column(tmp_path):
    path = tmp_path / "curve.csv"
    path.write_text(HEADER + "0,0,0,0,0,0,0,0\n1,0.1,0,0.1,0,oops,0,1\n")
    with pytest.raises(yarnfort.ResultError, match=r"line 3, column 'pull_ry': 'oops'"):
        yarnfort.read_curve(path)
    path.write_text(HEADER + "0,0,0\n")
    with pytest.raises(yarnfort.ResultError, match="line 2: 3 cells, the header has 8"):
        yarnfort.read_curve(path)
    path.write_text("")
    with pytest.raises(yarnfort.ResultError, match="empty file"):
        yarnfort.read_curve(path)
    path.write_text(HEADER)
    assert len(yarnfort.read_curve(path)) == 0


def test_sweep_with_an_unknown_support_fails_before_any_run(tmp_path):
    with pytest.raises(ValueError, match="support 'nope': the scene's supports are fixed,"
                       " pull, pegs"):
        yarnfort.run_sweep(CAPSTAN, {"contact[0].friction_coefficient": [0.1, 0.2]},
                           support="nope", progress=False, work_dir=tmp_path)
    assert not list(tmp_path.iterdir())  # nothing was run
    with pytest.raises(ValueError, match="bad parameter address"):
        yarnfort.run_sweep(CAPSTAN, {"contact friction": [0.1]}, progress=False)


def test_sweep_of_a_fabric_with_an_unknown_support_raises(tmp_path, monkeypatch):
    monkeypatch.chdir(TOP)  # the knit's tables are relative to the repository root
    with pytest.raises(ValueError, match="support 'nope': the scene's runs have supports"):
        yarnfort.run_sweep("inputs/knit.nml", {"solver.max_step": [0.25]}, support="nope",
                           progress=False, workers=1)


def test_calibrate_errors_name_what_is_wrong(tmp_path):
    measured = tmp_path / "measured.csv"
    measured.write_text("strain,force\n0.1,1.0\n0.2,2.0\n0.3,3.0\n")
    bounds = {"contact[0].friction_coefficient": (0.3, 0.1, 0.5)}
    with pytest.raises(ValueError, match="support 'nope'"):
        calibrate(CAPSTAN, measured, bounds, support="nope")
    with pytest.raises(yarnfort.AddressError, match="bad parameter address"):
        calibrate(CAPSTAN, measured, {"mu": (0.3, 0.1, 0.5)}, support="pull")
    with pytest.raises(ValueError, match="component 'w'"):
        calibrate(CAPSTAN, measured, bounds, support="pull", component="w")


def test_non_numeric_measured_value_names_file_and_line(tmp_path):
    measured = tmp_path / "measured.csv"
    measured.write_text("# a comment\nstrain,force\n0.1,1.0\n0.2,two\n")
    with pytest.raises(ValueError, match=rf"{measured}, line 4: force 'two' is not a"
                       " number"):
        read_measured(measured)
