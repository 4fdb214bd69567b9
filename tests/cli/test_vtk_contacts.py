# SPDX-License-Identifier: MIT
"""Contact state for ParaView: every sliding passage is a point of its own in the
passages block (passages_NNNNN.vtu) at its node, with point data passage, node, yarn,
mode (ParaView colours stick/slip by it), flow, tension_min, tension_max,
critical_tension and wrap_angle, read back with meshio (binary and ASCII files) and
compared with every row of contacts.csv of the same step; two passages at one node (one
slipping, one sticking) both show. The yarns' file keeps per node `passages` (their
number) and `contact_state` (2 when one of them slips)."""
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
    """Every state's passages block against contacts.csv; returns, per step, the modes
    of the passages at nodes with two or more passages."""
    table = read_contacts(out)
    steps = np.asarray(table["step"], int)
    shared_modes: dict[int, set[int]] = {}
    states = sorted(out.glob("state_*.vtu"))
    assert states
    for path in states:
        yarns = meshio.read(path)
        step = int(np.ravel(yarns.field_data["step"])[0])
        rows = np.flatnonzero(steps == step)
        assert len(rows) > 0
        passages = meshio.read(out / ("passages_" + path.name[len("state_"):]))
        assert {c.type for c in passages.cells} == {"vertex"}
        assert int(np.ravel(passages.field_data["step"])[0]) == step
        data = {name: np.ravel(values) for name, values in passages.point_data.items()}
        # One point per row of the step, in passage order, at its node.
        assert len(passages.points) == len(rows)
        for column in ("passage", "node", "yarn"):
            np.testing.assert_array_equal(data[column], table[column][rows], err_msg=column)
        np.testing.assert_array_equal(passages.points, yarns.points[data["node"] - 1])
        np.testing.assert_array_equal(
            data["mode"], [MODE_CODES[m] for m in np.asarray(table["mode"])[rows]])
        for column in VALUE_COLUMNS:
            # Both files carry 17 significant digits (or the bits): the same double.
            np.testing.assert_array_equal(data[column], table[column][rows], err_msg=column)
        # Per node in the yarns' file: the number of passages, and whether one slips.
        count = np.bincount(data["node"] - 1, minlength=len(yarns.points))
        np.testing.assert_array_equal(np.ravel(yarns.point_data["passages"]), count)
        slips = np.bincount(data["node"] - 1, weights=np.isin(data["mode"], (2, 3)),
                            minlength=len(yarns.points))
        np.testing.assert_array_equal(np.ravel(yarns.point_data["contact_state"]),
                                      np.where(count == 0, 0, np.where(slips > 0, 2, 1)))
        for node in np.flatnonzero(count > 1) + 1:
            shared_modes.setdefault(step, set()).update(
                data["mode"][data["node"] == node].tolist())
    return shared_modes


@pytest.mark.parametrize("vtk_format", ["binary", "ascii"])
def test_one_pin_point_data_match_contacts_csv(run_yarnfort, tmp_path, vtk_format):
    text = hysteresis_scene(CASES["coulomb"]).replace(
        "&output", f"&output vtk_format = '{vtk_format}',")
    done = run_yarnfort(text, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    check_states_against_contacts(tmp_path / "out")
    # The run slips both ways and sticks: ParaView sees every mode over the states.
    modes = set()
    for path in (tmp_path / "out").glob("passages_*.vtu"):
        modes.update(np.asarray(meshio.read(path).point_data["mode"]).ravel().tolist())
    assert {1, 2, 3} <= modes


@pytest.mark.parametrize("vtk_format", ["binary", "ascii"])
def test_two_passages_at_a_node_both_show(run_yarnfort, tmp_path, vtk_format):
    done = run_yarnfort(cross_scene(vtk_format), cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    shown = check_states_against_contacts(tmp_path / "out")
    # Some step has a slipping and a sticking passage at node 5: both points show.
    assert any({1} <= modes and modes & {2, 3} for modes in shown.values()), shown
    curve = read_curve(tmp_path / "out")
    # The pulled end's displacement column is the prescribed one: p_disp * 0.4 along x.
    np.testing.assert_allclose(curve["pull_ux"], 0.4 * curve["p_disp"], rtol=0,
                               atol=1e-15)
    assert np.all(curve["pull_uy"] == 0.0) and np.all(curve["ends_ux"] == 0.0)
