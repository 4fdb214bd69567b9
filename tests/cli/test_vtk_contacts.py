# SPDX-License-Identifier: MIT
"""Contact state as VTK point data (ParaView colours stick/slip by `mode`): on every
contact node the state files hold `passages`, `passage`, `mode`, `flow`,
`tension_min`, `tension_max`, `critical_tension` and `wrap_angle`, read back with meshio
(binary and ASCII files) and compared with the rows of contacts.csv of the same step;
at a node with two passages the one shown is the slipping one (the rule: slip before
locked before stick, then the larger tension_max)."""
from __future__ import annotations

import sys
from pathlib import Path

import meshio
import numpy as np
import pytest

TOP = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(TOP / "tests" / "verification"))
from scenes import group, scene  # noqa: E402
from test_hysteresis import CASES, hysteresis_scene  # noqa: E402
from yarnfort import read_contacts, read_curve  # noqa: E402

MODE_CODES = {"stick": 1, "forward": 2, "backward": 3, "locked": 4}
RANK = {1: 1, 4: 2, 2: 3, 3: 3}
VALUE_COLUMNS = ["flow", "tension_min", "tension_max", "critical_tension", "wrap_angle"]


def cross_scene(vtk_format: str) -> str:
    """Two yarns through one free node 5 (a = 1-5-2 along x, b = 3-5-4 along y), a
    load on node 5 that wraps both, and the end 2 of yarn a pulled along x: yarn a
    slides through node 5 while yarn b sticks (two passages at one node)."""
    text = scene(
        nodes=[[-1.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 1.0, 0.0],
               [0.0, 0.0, -0.3]],
        materials=[dict(name="a", law="linear", stiffness=10.0),
                   dict(name="b", law="linear", stiffness=10.0)],
        yarns=[dict(material="a", nodes=[1, 5, 2]), dict(material="b", nodes=[3, 5, 4])],
        supports=[dict(name="ends", nodes=[1, 3, 4]),
                  dict(name="pull", nodes=[2], displacement=[0.4, 0.0, 0.0])],
        loads=[dict(nodes=[5], force=[0.0, 0.0, -1.0])],
        path=dict(time=[0.0, 1.0], p_force=[1.0, 1.0], p_disp=[0.0, 1.0]),
        output=dict(folder="out", progress=False, vtk_format=vtk_format))
    return text + group("contact", materials=["a", "b"], law="coulomb",
                        friction_coefficient=0.02)


def check_states_against_contacts(out: Path) -> dict[int, set[int]]:
    """Every state's passage point data against contacts.csv; returns, per step, the
    modes shown at the nodes with two or more passages."""
    table = read_contacts(out)
    steps = np.asarray(table["step"], int)
    shown_modes: dict[int, set[int]] = {}
    states = sorted(out.glob("state_*.vtu"))
    assert states
    for path in states:
        mesh = meshio.read(path)
        data = mesh.point_data
        step = int(np.ravel(mesh.field_data["step"])[0])
        rows = np.flatnonzero(steps == step)
        assert len(rows) > 0
        nodes = np.asarray(table["node"], int)[rows]
        count = np.asarray(data["passages"]).ravel()
        passage = np.asarray(data["passage"]).ravel()
        mode = np.asarray(data["mode"]).ravel()
        # Nodes without a passage: zeros everywhere, contact_state 0.
        without = np.setdiff1d(np.arange(len(count)), nodes - 1)
        assert np.all(count[without] == 0) and np.all(passage[without] == 0)
        assert np.all(mode[without] == 0)
        for column in VALUE_COLUMNS:
            assert np.all(np.asarray(data[column]).ravel()[without] == 0.0), column
        for node in set(nodes):
            at = rows[nodes == node]
            assert count[node - 1] == len(at)
            codes = np.array([MODE_CODES[m] for m in np.asarray(table["mode"])[at]])
            t_max = np.asarray(table["tension_max"])[at]
            # The rule: highest rank, then the largest tension_max, then the first.
            best = max(range(len(at)), key=lambda i: (RANK[codes[i]], t_max[i], -i))
            row = at[best]
            assert passage[node - 1] == int(table["passage"][row])
            assert mode[node - 1] == codes[best]
            for column in VALUE_COLUMNS:
                # Both files carry 17 significant digits (or the bits): the same double.
                assert np.ravel(data[column])[node - 1] == table[column][row], column
            state = np.asarray(data["contact_state"]).ravel()[node - 1]
            assert state == (2 if any(c in (2, 3) for c in codes) else 1)
            if len(at) > 1:
                shown_modes.setdefault(step, set()).update(codes.tolist())
    return shown_modes


@pytest.mark.parametrize("vtk_format", ["binary", "ascii"])
def test_one_pin_point_data_match_contacts_csv(run_yarnfort, tmp_path, vtk_format):
    text = hysteresis_scene(CASES["coulomb"]).replace(
        "&output", f"&output vtk_format = '{vtk_format}',")
    done = run_yarnfort(text, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    check_states_against_contacts(tmp_path / "out")
    # The run slips both ways and sticks: ParaView sees every mode over the states.
    modes = set()
    for path in (tmp_path / "out").glob("state_*.vtu"):
        modes.update(np.asarray(meshio.read(path).point_data["mode"]).ravel().tolist())
    assert {1, 2, 3} <= modes


@pytest.mark.parametrize("vtk_format", ["binary", "ascii"])
def test_two_passages_at_a_node_show_the_slipping_one(run_yarnfort, tmp_path, vtk_format):
    done = run_yarnfort(cross_scene(vtk_format), cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    shown = check_states_against_contacts(tmp_path / "out")
    # Some step has a slipping and a sticking passage at node 5 (the rule was used).
    assert any({1} <= modes and modes & {2, 3} for modes in shown.values()), shown
    curve = read_curve(tmp_path / "out")
    # The pulled end's displacement column is the prescribed one: p_disp * 0.4 along x.
    np.testing.assert_allclose(curve["pull_ux"], 0.4 * curve["p_disp"], rtol=0,
                               atol=1e-15)
    assert np.all(curve["pull_uy"] == 0.0) and np.all(curve["ends_ux"] == 0.0)
