# SPDX-License-Identifier: MIT
"""read_run says when a folder's run stopped before the end of its load path (a failed
step, Ctrl-C, max_steps, a kill): outcome 'incomplete' and a warning naming where the
curve ends; a run that reached the end, in one piece or after a restart, reads 'read'."""
from __future__ import annotations

import warnings
from pathlib import Path

import pytest

import yarnfort
from yarnfort import read_scene, set_parameter, write_scene

VNET = Path(__file__).resolve().parents[2] / "inputs" / "vnet.nml"


def _vnet(tmp_path: Path, **settings) -> Path:
    scene = read_scene(VNET)  # path 0 -> 2, steps of 0.1
    set_parameter(scene, "output.folder", str(tmp_path / "out"))
    for address, value in settings.items():
        set_parameter(scene, address.replace("__", "."), value)
    return write_scene(scene, tmp_path / "scene.nml")


def test_a_run_stopped_by_max_steps_reads_incomplete_then_whole_after_restart(tmp_path):
    yarnfort.run_scene(_vnet(tmp_path, control__max_steps=3))
    with pytest.warns(RuntimeWarning, match=r"incomplete run: the curve ends at step 3,"
                      r" time 0\.3, the load path at 2"):
        read = yarnfort.read_run(tmp_path / "out")
    assert read.outcome == "incomplete" and read.n_steps == 4  # steps 0..3
    yarnfort.run_scene(_vnet(tmp_path, control__restart=True))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        read = yarnfort.read_run(tmp_path / "out")
    assert read.outcome == "read" and read.n_steps == 21  # 0..2 in steps of 0.1
    assert read.curve["time"][-1] == pytest.approx(2.0, rel=1e-12)


def test_a_last_row_cut_short_by_a_kill_is_left_out_with_a_warning(tmp_path):
    # Cut inside the exponent, '2.5E-05' reads as the valid number 2.5.
    (tmp_path / "curve.csv").write_text("step,time,p_force,pull_ry\n"
                                        "0,0.0,0.0,0.0\n"
                                        "1,0.1,0.1,1.5E-05\n"
                                        "2,0.2,0.2,2.5E-0")
    with pytest.warns(RuntimeWarning, match=r"line 4: the last row has no line end"):
        curve = yarnfort.read_curve(tmp_path)
    assert list(curve["step"]) == [0, 1] and curve["pull_ry"][-1] == 1.5e-5
    (tmp_path / "curve.csv").write_text("step,time\n0,0.0\n1,0.1\n")
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # whole rows: no warning
        assert list(yarnfort.read_curve(tmp_path)["step"]) == [0, 1]
