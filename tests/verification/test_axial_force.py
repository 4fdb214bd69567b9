# SPDX-License-Identifier: MIT
"""A force-controlled x period (&fabric axial_control = 'force'): n11 held at p_disp *
axial_force, e11 the unknown of an outer iteration (yarnfort_solver_force_control), alone
or around a force-controlled y period; and restarts under force control that repeat the
uninterrupted run bit for bit.

Checks independent of the iteration: the force held against its target at every step;
the strain-controlled run's (e11, n11) curve reproduced by force control to its forces
(a bonded cell has one state per strain, so the e11 found must be the one prescribed);
the work balance of test_membrane.py under force control; the collapse refused.
"""
from __future__ import annotations

import re

import numpy as np
import pytest

from fabric_scenes import TOP, patched_scene
from test_membrane import HOLD, membrane_work, run_cell, stored_energy
from yarnfort import read_curve

#: The knit example's cell (table laws, friction with adhesion) under axial force
#: control: `strain` left out, n11 ramped from 5 to 100 N/m and back (p_disp > 0
#: throughout: n11 = 0 would let the cell collapse along x).
AXIAL = {"fabric.axial_control": "force", "fabric.axial_force": 100.0, "fabric.strain": None,
         "path.time": [0.0, 1.0, 2.0], "path.p_disp": [0.05, 1.0, 0.05],
         "output.vtk_every": 0}


def run_knit(run_yarnfort, folder, values):
    result = run_yarnfort(patched_scene("inputs/knit.nml", values, folder), cwd=TOP)
    assert result.returncode == 0, result.stderr
    return read_curve(folder)


def test_axial_force_is_held_at_every_step(run_yarnfort, tmp_path):
    """n11 = p_disp * axial_force at every step, loaded and released, to the iteration's
    tolerance of the forces present; e11 is the axial channel's factor, and with the y
    period held (e22 = 0) n11 is force_per_width and e11 the fabric's strain. Friction
    makes the loop: released, the cell is longer than loaded at the same force."""
    curve = run_knit(run_yarnfort, tmp_path, AXIAL)
    p, e11, n11, n22 = (np.asarray(curve[c]) for c in ("p_disp", "e11", "n11", "n22"))
    target = 100.0 * p
    scale = np.maximum(target, np.abs(n22))
    assert np.all(np.abs(n11 - target) <= HOLD * scale), np.abs(n11 / target - 1).max()
    assert np.array_equal(curve["axial"], e11) and np.array_equal(curve["strain"], e11)
    assert np.all(np.asarray(curve["e22"]) == 0.0) and "lateral" not in curve.names
    assert np.allclose(curve["force_per_width"], n11, rtol=1e-12, atol=0)
    peak = int(np.argmax(p))
    assert e11[peak] > e11[0] + 0.1
    # The same force on the way down (p_disp 0.525 at steps 10 and 30 of 40: knots at
    # 0, 20, 40 and steps of 0.05 of the interval).
    loading = int(np.argmin(np.abs(p[:peak] - 0.525)))
    unloading = peak + int(np.argmin(np.abs(p[peak:] - 0.525)))
    assert p[loading] == pytest.approx(p[unloading], rel=1e-12)
    assert e11[unloading] > e11[loading] + 0.01, (e11[loading], e11[unloading])


def test_force_control_reproduces_the_strain_controlled_curve(run_yarnfort, tmp_path):
    """A bonded plain weave (one state per strain): the strain-controlled run's n11 at
    e11 = 0.09, 0.18, 0.3, held by force control, gives back those strains, to the error
    of the force held over the stiffness (bound about 1e-9, measured 7e-13)."""
    strained, _, _ = run_cell(run_yarnfort, tmp_path / "strain", "plain", "bonded", 0.1,
                              strain=0.3, lateral=0.0)
    steps = [3, 6, 10]
    e11, n11, n22 = (np.asarray(strained[c])[steps] for c in ("e11", "n11", "n22"))
    # dn11/de11 by the secant to the step before: the force held to HOLD of the forces
    # present moves e11 by at most that over this stiffness.
    slope = (n11 - np.asarray(strained["n11"])[np.subtract(steps, 1)]) / 0.03
    bound = HOLD * np.maximum(n11, np.abs(n22)) / slope
    assert np.allclose(e11, [0.09, 0.18, 0.3], rtol=1e-12)
    assert np.all(np.diff(n11) > 0) and n11[0] > 0
    forced, _, _ = run_cell(run_yarnfort, tmp_path / "force", "plain", "bonded", 0.5,
                            strain=0.3, lateral=0.0, extra={
                                "fabric.strain": None, "fabric.axial_control": "force",
                                "fabric.axial_force": 1.0, "path.time": [0.0, 1.0, 2.0],
                                "path.p_disp": list(n11)})
    knots = np.isin(np.asarray(forced["time"]), [0.0, 1.0, 2.0])
    assert knots.sum() == 3
    assert np.allclose(np.asarray(forced["n11"])[knots], n11, rtol=HOLD, atol=0)
    found = np.asarray(forced["e11"])[knots]
    assert np.all(np.abs(found - e11) <= bound), (found - e11, bound)


def test_held_x_force_turned_by_90_degrees_is_a_held_y_force(run_yarnfort, tmp_path):
    """The square bonded plain weave (its own image under a turn by 90 degrees, see
    test_membrane) with n11 held at 5 kN/m and e22 = 0.05, and with e11 = 0.05 and n22
    held at 5 kN/m: the two axes of the stepper give mirrored states (to the force held,
    2 * HOLD of it, over the secant stiffness F / e; measured 5e-12 in e, 6e-12 of F)."""
    force, strain = 5000.0, 0.05
    common = {"fabric.spacing": [1.0e-3, 1.0e-3], "path.p_disp": [0.2, 1.0]}
    x_held, _, _ = run_cell(run_yarnfort, tmp_path / "x", "plain", "bonded", 0.25,
                            lateral=strain, extra={
                                **common, "fabric.strain": None,
                                "fabric.axial_control": "force", "fabric.axial_force": force})
    y_held, _, _ = run_cell(run_yarnfort, tmp_path / "y", "plain", "bonded", 0.25,
                            strain=strain, extra={
                                **common, "fabric.lateral_strain": None,
                                "fabric.lateral_control": "force",
                                "fabric.lateral_force": force})
    a = {k: np.asarray(x_held[k])[-1] for k in ("e11", "e22", "n11", "n22")}
    b = {k: np.asarray(y_held[k])[-1] for k in ("e11", "e22", "n11", "n22")}
    assert a["e22"] == b["e11"] == pytest.approx(strain, rel=1e-15)
    assert a["e11"] > 2 * strain   # found, not trivially the prescribed strain
    assert abs(a["e11"] - b["e22"]) <= 2 * HOLD * a["e11"]
    assert abs(a["n22"] - b["n11"]) <= 2 * HOLD * force
    assert abs(a["n11"] - force) <= HOLD * force and abs(b["n22"] - force) <= HOLD * force


@pytest.mark.parametrize("kind", ["bonded", "frictionless"])
def test_work_balance_under_axial_force_control(run_yarnfort, tmp_path, kind):
    """The knit cell of linear yarns with n11 ramped from 1 to 10 kN/m (e22 = 0): the work of the membrane
    forces along the e11 the iteration finds equals the change of stored energy (no
    dissipation, bonded or frictionless), to the trapezoid rule's second order in the
    step."""
    residual = []
    for step in (0.2, 0.1):
        curve, states, periods = run_cell(
            run_yarnfort, tmp_path / f"{step}", "knit", kind, step, lateral=0.0,
            extra={"fabric.strain": None, "fabric.axial_control": "force",
                   "fabric.axial_force": 1.0e4, "path.p_disp": [0.1, 1.0]})
        e11 = np.asarray(curve["e11"])
        assert np.all(np.diff(e11) > 0) and e11[-1] - e11[0] > 0.05
        energy = np.array([stored_energy(s) for s in states])
        work = membrane_work(curve, periods)[-1]
        assert work > 0
        residual.append(abs(work - (energy[-1] - energy[0])) / work)
    assert 3.0 < residual[0] / residual[1] < 5.0, residual
    assert residual[1] < 1e-2, residual


def test_both_periods_force_controlled(run_yarnfort, tmp_path):
    """n11 ramped and n22 held at 20 N/m, or at half of n11: both held at every step,
    loaded and released (the x iteration around the y one)."""
    for name, lateral in (("force", {"fabric.lateral_control": "force",
                                     "fabric.lateral_force": 20.0}),
                          ("ratio", {"fabric.lateral_control": "ratio",
                                     "fabric.force_ratio": 0.5})):
        values = {**AXIAL, **lateral, "path.p_disp": [0.2, 0.6, 0.2]}
        curve = run_knit(run_yarnfort, tmp_path / name, values)
        p, n11, n22 = (np.asarray(curve[c]) for c in ("p_disp", "n11", "n22"))
        held = 20.0 if name == "force" else 0.5 * n11
        scale = np.maximum(np.abs(n11), np.abs(n22))
        assert np.all(np.abs(n11 - 100.0 * p) <= HOLD * scale)
        assert np.all(np.abs(n22 - held) <= HOLD * scale)
        assert curve.names.index("axial") + 1 == curve.names.index("lateral")
        assert np.ptp(curve["e11"]) > 0.02 and np.ptp(curve["e22"]) > 0.01


def test_steps_grow_back_after_a_cut_under_force_control(run_yarnfort, tmp_path):
    """inputs/knit_biaxial.nml (n22 held, e11 0 -> 0.6 -> 0) with max_step 0.2 of a knot
    interval: its step is cut (by step_cut 0.5) where the yarns start to slide; afterwards
    the steps grow by step_growth (1.5) per easy step, judged by the trial that held the
    force, back to max_step within 4 steps (1.5^3 > 2.67 = 0.2 / 0.075); 8 are allowed.
    Before, every trial's iterations counted, and after that cut the steps stayed at 0.05
    for the rest of the run (37 steps instead of 13)."""
    max_step = 0.2
    curve = run_knit_file(run_yarnfort, tmp_path, "inputs/knit_biaxial.nml",
                          {"solver.max_step": max_step})
    dt = np.diff(np.asarray(curve["time"]))
    cuts = np.flatnonzero(np.asarray(curve["step_cuts"])[1:])
    assert len(cuts) > 0
    for cut in cuts:
        after = dt[cut:cut + 8]
        assert np.any(after >= max_step * (1 - 1e-12)), (cut, after)
    held = np.abs(np.asarray(curve["n22"]) - 20.0)
    scale = np.maximum(np.abs(np.asarray(curve["n11"])), 20.0)
    assert np.all(held <= HOLD * scale)


def run_knit_file(run_yarnfort, folder, scene, values=None):
    result = run_yarnfort(patched_scene(scene, {"output.vtk_every": 0, **(values or {})},
                                        folder), cwd=TOP)
    assert result.returncode == 0, result.stderr
    return read_curve(folder)


def test_axial_collapse_is_refused(run_yarnfort, tmp_path):
    """n11 held at 0 (p_disp = 0): the yarns along x are slack and the x period is free
    to shrink: no state, so no curve (exit 1, the message names the mechanism). Released
    to p_disp = 0, the run keeps the steps before (exit 1)."""
    start = run_yarnfort(patched_scene("inputs/knit.nml", {
        **AXIAL, "path.time": [0.0, 1.0], "path.p_disp": [0.0, 1.0]}, tmp_path / "start"),
        cwd=TOP)
    assert start.returncode == 1
    assert "initial state" in start.stderr and "Axial collapse" in start.stderr
    assert "n11 would be held at p_disp * axial_force = 0" in start.stderr
    assert "carries no compression" in start.stderr
    assert len(read_curve(tmp_path / "start")) == 0
    end = run_yarnfort(patched_scene("inputs/knit.nml", {
        **AXIAL, "path.p_disp": [0.1, 0.3, 0.0]}, tmp_path / "end"), cwd=TOP)
    assert end.returncode == 1
    assert "Axial collapse" in end.stderr
    curve = read_curve(tmp_path / "end")
    assert len(curve) > 10 and np.asarray(curve["p_disp"])[-1] > 0


def assert_restart_is_bitwise(run_yarnfort, folder, values, stop):
    """A run stopped after `stop` steps and restarted writes the curve of the run that
    never stopped, byte for byte but the step times."""
    run_knit(run_yarnfort, folder / "whole", values)
    run_knit(run_yarnfort, folder / "pieces", {**values, "control.max_steps": stop})
    assert len(read_curve(folder / "pieces")) == stop + 1
    run_knit(run_yarnfort, folder / "pieces", {**values, "control.restart": True})
    a, b = read_curve(folder / "whole"), read_curve(folder / "pieces")
    assert a.names == b.names and len(a) == len(b) > stop + 1
    for name in a.names:
        if name != "wall_time":
            assert np.array_equal(a[name], b[name]), name


@pytest.mark.parametrize("case", ["axial", "both"])
def test_restart_under_force_control_is_bitwise(run_yarnfort, tmp_path, case):
    """The secant slopes of the outer iterations are in the restart file: the restarted
    run takes the trials of the uninterrupted one (the y period alone:
    test_membrane.test_restart_under_lateral_control). With both periods held the matrices
    of the first step after the restart are others than the first ones of the whole
    run, so the sparse solvers' pivot order (fixed at their first factorisation) could
    differ by round-off: that case uses the dense solver."""
    lateral = {"fabric.lateral_control": "force", "fabric.lateral_force": 20.0}
    values = {"axial": AXIAL, "both": {**AXIAL, **lateral, "path.p_disp": [0.2, 0.6, 0.2],
                                       "solver.linear_solver": "dense"}}[case]
    assert_restart_is_bitwise(run_yarnfort, tmp_path, values, 10)


def test_progress_lines_print_every_number(run_yarnfort, tmp_path):
    """The knit with both periods held, in steps of half the path, takes over 999 Newton
    iterations in a step (every trial and cut counts): its progress lines print the counts
    in full, as curve.csv has them, and no field of asterisks."""
    values = {**AXIAL, "fabric.lateral_control": "force", "fabric.lateral_force": 20.0,
              "solver.initial_step": 0.5, "solver.max_step": 0.5, "output.progress": True}
    result = run_yarnfort(patched_scene("inputs/knit.nml", values, tmp_path), cwd=TOP)
    assert result.returncode == 0, result.stderr
    lines = [line for line in result.stderr.splitlines() if line.startswith("step ")]
    assert lines and not any("*" in line for line in lines)
    printed = [int(re.search(r"  newton +(\d+)  ", line)[1]) for line in lines]
    curve = read_curve(tmp_path)
    assert printed == [int(n) for n in curve["newton_iterations"]]
    assert max(printed) > 999
