# SPDX-License-Identifier: MIT
"""contacts.csv (&output contact_state) on the one-pin hysteresis scene of
test_hysteresis: the mode column agrees with the run's `slipping` column of curve.csv,
stick rows keep T_max <= T_crit, slip rows have T_max = T_crit, and the flow is the
reference length element a (before the pin) gave up. A restart keeps the rows up to its
step and appends the rest as an uninterrupted run writes them."""
from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
import pytest

from test_hysteresis import CASES, Case, hysteresis_scene
from yarnfort import read_curve, read_states
from yarnfort.results import read_contacts as read_contacts_table

#: Slack of the stick test (&solver friction_tolerance 1e-9, plus its band) and the
#: agreement of a slipping passage with its law at residual_tolerance = 1e-13.
FRICTION_RTOL = 1e-8
COLUMNS = ["step", "passage", "node", "yarn", "flow", "mode", "tension_min",
           "tension_max", "critical_tension", "wrap_angle"]


def read_contacts(folder: Path) -> list[dict[str, str]]:
    with open(folder / "contacts.csv", newline="") as stream:
        rows = list(csv.DictReader(stream))
    assert rows and list(rows[0]) == COLUMNS
    return rows


def run(run_yarnfort, folder: Path, text: str):
    result = run_yarnfort(text, cwd=folder)
    assert result.returncode == 0, result.stderr
    return result


@pytest.mark.parametrize("scheme", ["monolithic", "staggered"])
@pytest.mark.parametrize("name", list(CASES))
def test_contact_state_on_the_hysteresis_scene(run_yarnfort, tmp_path, name, scheme):
    case = Case(**{**CASES[name].__dict__, "scheme": scheme})
    run(run_yarnfort, tmp_path, hysteresis_scene(case))
    out = tmp_path / "out"
    rows = read_contacts(out)
    curve = read_curve(out)
    states = read_states(out)
    # One passage: the yarn (1) through the pin (node 2), one row per converged step.
    assert [int(r["step"]) for r in rows] == [int(s) for s in curve["step"]]
    assert {(r["passage"], r["node"], r["yarn"]) for r in rows} == {("1", "2", "1")}
    modes = [r["mode"] for r in rows]
    assert set(modes) >= {"stick", "forward", "backward"}
    assert [m != "stick" for m in modes] == [n > 0 for n in curve["slipping"]]
    t_max = np.array([float(r["tension_max"]) for r in rows])
    t_min = np.array([float(r["tension_min"]) for r in rows])
    critical = np.array([float(r["critical_tension"]) for r in rows])
    angle = np.array([float(r["wrap_angle"]) for r in rows])
    stick = np.array([m == "stick" for m in modes])
    assert np.all(t_min <= t_max)
    assert np.all(t_max[stick] <= critical[stick] * (1 + FRICTION_RTOL))
    slip_error = np.abs(t_max[~stick] - critical[~stick]) / critical[~stick]
    assert np.max(slip_error) <= FRICTION_RTOL
    np.testing.assert_allclose(angle, case.alpha, rtol=0, atol=1e-12)
    # Forward slip moves material towards B: element b (after the pin) is the taut one.
    for r, state in zip(rows, states):
        if r["mode"] == "forward":
            assert state.tension[1] == pytest.approx(float(r["tension_max"]), rel=1e-15)
    # flow = L0 given up by element a (A-C): it starts at |CA| and ends at a yarn end.
    flow = np.array([float(r["flow"]) for r in rows])
    length0_a = np.array([s.length0[0] for s in states])
    np.testing.assert_allclose(flow, case.length_a - length0_a, rtol=0,
                               atol=1e-14 * case.length_a)
    assert np.max(flow) > 0.01 * case.length_a
    # The package's reader gives the same table.
    table = read_contacts_table(out)
    assert table.names == COLUMNS and list(table["mode"]) == modes
    np.testing.assert_array_equal(table["flow"], flow)
    np.testing.assert_array_equal(table["step"], curve["step"])
    print(f"{name} {scheme}: {len(rows)} rows, modes {sorted(set(modes))}, "
          f"max slip error {np.max(slip_error):.1e}")


def test_contact_state_on_restart(run_yarnfort, tmp_path):
    text = hysteresis_scene(CASES["adhesion"])
    (tmp_path / "full").mkdir()
    (tmp_path / "parts").mkdir()
    run(run_yarnfort, tmp_path / "full", text)
    run(run_yarnfort, tmp_path / "parts", text.replace("&control", "&control max_steps = 17,"))
    assert max(int(r["step"]) for r in read_contacts(tmp_path / "parts" / "out")) == 17
    run(run_yarnfort, tmp_path / "parts", text.replace("&control", "&control restart = .true.,"))
    full, parts = (read_contacts(tmp_path / f / "out") for f in ("full", "parts"))
    assert [(r["step"], r["mode"]) for r in parts] == [(r["step"], r["mode"]) for r in full]
    for column in ("flow", "tension_min", "tension_max", "critical_tension"):
        a = np.array([float(r[column]) for r in full])
        b = np.array([float(r[column]) for r in parts])
        assert np.max(np.abs(a - b)) <= 1e-10 * np.max(np.abs(a)), column


def test_contact_state_can_be_switched_off(run_yarnfort, tmp_path):
    text = hysteresis_scene(CASES["coulomb"])
    run(run_yarnfort, tmp_path, text)
    assert (tmp_path / "out" / "contacts.csv").exists()
    run(run_yarnfort, tmp_path, text.replace("&output", "&output contact_state = .false.,"))
    assert not (tmp_path / "out" / "contacts.csv").exists()


def test_passages_held_by_chatter_damping_are_reported_and_within_their_limit(
        run_yarnfort, tmp_path):
    """curve.csv `held` and the progress line name the passages that chatter damping
    held in stick; each such step is admissible: every stick passage within its capstan
    limit, T_crit from the closed form of the adhesion law (paper eqs. 34-36), not from
    the code. The scene (inputs/knit_clamped.nml, staggered scheme, max_step 0.2) is one
    where damping holds 4 passages at t = 1.5 (found by a scan of clamped knits: 4 x 4,
    8 x 4, 8 x 8 cells, max_step 0.05-0.2, both schemes; no other case held any)."""
    from fabric_scenes import TOP, patched_scene
    from test_knit_inlay import adhesion_critical

    text = patched_scene("inputs/knit_clamped.nml",
                         {"solver.max_step": 0.2, "solver.scheme": "staggered",
                          "output.vtk_every": 0, "output.progress": True}, tmp_path)
    result = run_yarnfort(text, cwd=TOP)
    assert result.returncode == 0, result.stderr
    curve = read_curve(tmp_path)
    held = np.asarray(curve["held"], int)
    assert held.sum() > 0, ("the scene no longer triggers chatter damping: choose "
                            "another one for this test")
    assert np.all(held <= np.asarray(curve["passages"]) - np.asarray(curve["slipping"]))
    # The progress line names them, step by step.
    printed = {int(line.split()[1]): int(line.split("held")[1])
               for line in result.stderr.splitlines()
               if line.startswith("step") and " held " in line}
    assert printed == {int(s): int(h) for s, h in zip(curve["step"], held) if h > 0}
    table = read_contacts_table(tmp_path)
    steps = np.asarray(table["step"], int)
    for step in np.asarray(curve["step"], int)[held > 0]:
        rows = (steps == step) & (np.asarray(table["mode"]) == "stick")
        critical = adhesion_critical(table["tension_min"][rows], table["wrap_angle"][rows],
                                     0.3999, 0.015)
        assert rows.sum() >= held[np.asarray(curve["step"], int) == step][0]
        assert np.all(table["tension_max"][rows] <= critical * (1 + FRICTION_RTOL)), step
