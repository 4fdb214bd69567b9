# SPDX-License-Identifier: MIT
"""A slip instability: a jump to an equilibrium of the exact law instead of a stop.

The 32 x 32 free-sided clamped knit (inputs/knit.nml with inlay, stretched to 2x and
back, benchmarks/steps_table.py's scene) reaches, at strain 0.147 of the release
(t = 1.85276), a state from which the quasi-static path has no continuation: mirror
pairs of passages flip between stick and slip in every round at every step size down
to min_step (docs/decisions.md, 'Slip instabilities: a jump'). yarnfort used to stop
there with exit code 1. It now jumps (friction_stepper try_jump, inputs/REFERENCE.md
*Slip instabilities*): viscous slip steps relax the net at that load, and the exact
law's rounds solve it from there.

tests/data/slip_jump.tar.gz holds the run's restart point, its step 88 (restart.dat,
curve.csv up to that step, contacts.csv of that step, the folder's manifest; 660 kB),
and the scene. Made by running the scene from the start with `restart = .false.` and
`max_steps = 88` (about 5 minutes), then keeping those files (contacts.csv: its header
and the rows of step 88; curve.csv and contacts.csv need the columns of the build that
reads them). The restart refuses a file made for another input (the table files, the
generator's network), so a change there shows here as a failed restart, never as a
silent pass.

Checked on the jumped step, against references independent of the solver:
- the step is the restart's first, it was cut (the rounds failed at every step size)
  and curve.csv marks it `jumped`;
- every slipping passage's flow moved over the jump in its slip direction (or not);
- its passages are admissible against the closed form of the adhesion law: a stick
  passage within T_crit(T_min), a slipping one at it (those locked at their minimum
  length are held by that bound, not by the law);
- the reactions of the four support sets balance (no load acts on the sample);
- the force per width lies on the curve of the steps before it: a jump that went far
  (another branch of the equilibria) would leave it.
"""
from __future__ import annotations

import tarfile
from pathlib import Path

import numpy as np
import pytest

from fabric_scenes import TOP
from test_clamped_samples import BALANCE
from test_contact_output import FRICTION_RTOL
from test_knit_inlay import adhesion_critical
from yarnfort import read_curve
from yarnfort.results import read_contacts

FIXTURE = Path(__file__).resolve().parent.parent / "data" / "slip_jump.tar.gz"
#: The knit-knit and knit-inlay contacts of inputs/knit.nml.
MU, BETA = 0.3999, 0.015
#: The jumped step's force per width against the secant through the two steps before
#: it, relative to the force. Measured: 2.8e-10 at this step; at the five later jumps
#: of the release, 2.5e-7 to 2.1e-6 (force drops of stick-slip events), while the
#: force changes by 8e-6 to 1.5e-5 of itself per step there.
ON_CURVE = 1e-5


def restart_point(tmp_path, name="slip_jump"):
    """The fixture's folder, unpacked under tmp_path / name, and its scene (restart from
    step 88, one step)."""
    with tarfile.open(FIXTURE) as archive:
        archive.extractall(tmp_path / name, filter="data")
    folder = tmp_path / name / "slip_jump"
    return folder, (folder / "scene.nml").read_text().replace("@FOLDER@", str(folder))


def test_release_step_without_quasi_static_continuation_jumps(run_yarnfort, tmp_path):
    folder, scene = restart_point(tmp_path)
    result = run_yarnfort(scene, cwd=TOP)
    assert result.returncode == 0, result.stderr
    cuts = [line for line in result.stderr.splitlines() if "cut:" in line]
    assert cuts and all("stick/slip active set did not settle" in line for line in cuts)
    progress = [line for line in result.stderr.splitlines() if line.startswith("step")]
    assert len(progress) == 1 and "viscous steps)" in progress[0].split("jumped (")[1]
    assert "note: 1 step(s) ended in a jump after a slip instability" in result.stderr

    curve = read_curve(folder)
    assert list(curve["step"][-2:]) == [88, 89]
    assert list(curve["jumped"]) == [0] * 89 + [1]
    assert curve["step_cuts"][-1] == len(cuts)
    print(f"step 89 (t = {curve['time'][-1]:.7f}): jumped after {len(cuts)} cuts, "
          f"{curve['newton_iterations'][-1]} Newton iterations, "
          f"{curve['slipping'][-2]} -> {curve['slipping'][-1]} passages slipping")

    everything = read_contacts(folder)
    steps = np.asarray(everything["step"], int)
    assert set(steps) == {88, 89}
    before = {name: np.asarray(values)[steps == 88] for name, values in everything.columns.items()}
    table = {name: np.asarray(values)[steps == 89] for name, values in everything.columns.items()}
    assert np.array_equal(before["passage"], table["passage"])
    stick = table["mode"] == "stick"
    critical = adhesion_critical(table["tension_min"], table["wrap_angle"], MU, BETA)
    assert len(stick) == 8064
    # Over the jump, a slipping passage's flow moved its own way (or not at all).
    increment = table["flow"] - before["flow"]
    assert np.all(increment[table["mode"] == "forward"] >= 0.0)
    assert np.all(increment[table["mode"] == "backward"] <= 0.0)
    changed = np.sum(table["mode"] != before["mode"])
    print(f"{changed} passages changed mode; largest flow increment "
          f"{np.max(np.abs(increment)):.1e} m")
    slip = np.isin(table["mode"], ("forward", "backward"))
    assert np.all(table["tension_max"][stick] <= critical[stick] * (1 + FRICTION_RTOL))
    slip_error = np.abs(table["tension_max"][slip] - critical[slip]) / critical[slip]
    print(f"{np.sum(slip)} passages slipping, max slip error {np.max(slip_error):.1e}; "
          f"{np.sum(~(stick | slip))} locked at the minimum length")
    assert np.sum(slip) == curve["slipping"][-1]
    assert np.max(slip_error) <= FRICTION_RTOL

    scale = np.max(np.abs(curve["right_rx"]))
    for axis in ("rx", "ry", "rz"):
        total = sum(curve[f"{s}_{axis}"][-1] for s in ("left", "right", "edge_left",
                                                        "edge_right"))
        assert abs(total) <= BALANCE * scale, axis

    strain, force = curve["strain"][-3:], curve["force_per_width"][-3:]
    secant = force[1] + (force[1] - force[0]) / (strain[1] - strain[0]) * (strain[2] - strain[1])
    print(f"force per width {force[2]:.9g}, secant of the steps before {secant:.9g}: "
          f"{abs(force[2] - secant) / force[2]:.1e} of it")
    assert abs(force[2] - secant) <= ON_CURVE * force[2]


def test_restart_after_a_jump_takes_the_same_steps(run_yarnfort, tmp_path):
    """The step after a jump is predicted from the jumped state alone (no secant across
    the jump), so the jump's restart snapshot has no earlier state, as otherwise only
    step 0's has (inputs/REFERENCE.md, *Restart*: a restarted run takes the same steps).
    Steps 89 and 90 jump; a run restarted after step 90 must take steps 91 and 92 as
    the uninterrupted run does: the same times, Newton iterations, slip counts and
    step cuts, and reactions within 1e-8 of the largest."""
    folder, scene = restart_point(tmp_path, "through")
    result = run_yarnfort(scene.replace("max_steps = 1", "max_steps = 4"), cwd=TOP)
    assert result.returncode == 0, result.stderr
    through = read_curve(folder)
    folder, scene = restart_point(tmp_path, "restarted")
    for _ in range(2):
        result = run_yarnfort(scene.replace("max_steps = 1", "max_steps = 2"), cwd=TOP)
        assert result.returncode == 0, result.stderr
    restarted = read_curve(folder)
    assert list(through["step"][-4:]) == list(restarted["step"][-4:]) == [89, 90, 91, 92]
    assert list(through["jumped"][-4:]) == [1, 1, 0, 0]
    print("steps 91, 92: Newton iterations", list(through["newton_iterations"][-2:]))
    for name in ("time", "newton_iterations", "slipping", "step_cuts"):
        assert list(through[name][-2:]) == list(restarted[name][-2:]), name
    scale = np.max(np.abs(through["right_rx"]))
    for name in through.names:
        if name.endswith(("_rx", "_ry", "_rz")):
            assert np.max(np.abs(through[name][-2:] - restarted[name][-2:])) \
                <= BALANCE * scale, name


def test_python_run_warns_of_the_jump(tmp_path, monkeypatch):
    """yarnfort.run_scene (in process) runs the same restart and warns of the jump, as
    the program's last lines name it."""
    from yarnfort import run_scene

    folder, scene = restart_point(tmp_path)
    path = tmp_path / "scene.nml"
    path.write_text(scene)
    monkeypatch.chdir(TOP)
    with pytest.warns(RuntimeWarning, match=r"1 step\(s\) ended in a jump .*steps 89;"):
        result = run_scene(path)
    assert (result.outcome, result.n_steps) == ("max_steps", 1)
