# SPDX-License-Identifier: MIT
"""Elastic string networks against closed forms (no friction)."""
from __future__ import annotations

import numpy as np
import pytest

from scenes import scene
from yarnfort import read_curve, read_states

#: Agreement required with closed forms at convergence (issue: rel. error <= 1e-8).
CLOSED_FORM_RTOL = 1e-8
TIGHT = dict(residual_tolerance=1e-13)


def v_scene(law: dict, load: float, depth0: float = 0.2, solver=None, **extra):
    """Two strings from (-1,0,0) and (1,0,0) meeting at C = (0,-depth0,0)."""
    return scene(
        nodes=[[-1, 0, 0], [0, -depth0, 0], [1, 0, 0]],
        materials=[dict(name="yarn", **law)],
        yarns=[dict(material="yarn", nodes=[1, 2, 3])],
        supports=[dict(name="ends", nodes=[1, 3], fix="xyz"),
                  dict(name="plane", nodes=[2], fix="z")],
        loads=[dict(nodes=[2], force=[0.0, -load, 0.0])],
        path=dict(time=[0.0, 1.0], p_force=[0.0, 1.0], p_disp=[0.0, 0.0]),
        solver={**TIGHT, "max_step": 0.25, **(solver or {})},
        **extra)


def test_v_shape_linear_law_matches_closed_form(run_yarnfort):
    ea, load = 10.0, 0.5
    run = run_yarnfort(v_scene(dict(law="linear", stiffness=ea), load))
    assert run.returncode == 0, run.stderr
    state = read_states(run.folder / "out")[-1]
    w = -state.position[1, 1]
    length = np.hypot(1.0, w)
    stretch = length / np.hypot(1.0, 0.2)
    predicted = 2 * ea * (stretch - 1) * w / length
    assert predicted == pytest.approx(load, rel=CLOSED_FORM_RTOL)
    # The supports carry the load: sum of their vertical reactions balances P.
    curve = read_curve(run.folder / "out")
    assert curve.reaction("ends")[-1, 1] == pytest.approx(load, rel=CLOSED_FORM_RTOL)
    assert state.position[1, 0] == pytest.approx(0.0, abs=1e-12)  # symmetry


def test_v_shape_table_law_matches_closed_form_at_a_knot(run_yarnfort, tmp_path):
    """Displacement control puts both strings exactly at a table knot, where the
    interpolant must return the measured force: P = 2 F_k w / l."""
    strain = np.array([0.0, 0.01, 0.03, 0.06, 0.1])
    force = np.array([0.0, 0.02, 0.09, 0.25, 0.6])
    (tmp_path / "yarn.csv").write_text("strain,force\n" + "".join(
        f"{e},{f}\n" for e, f in zip(strain, force)))
    length0 = np.hypot(1.0, 0.2)
    knot = 3
    length = length0 * (1 + strain[knot])
    w = np.sqrt(length**2 - 1)
    text = scene(
        nodes=[[-1, 0, 0], [0, -0.2, 0], [1, 0, 0]],
        materials=[dict(name="yarn", law="table", table_file="yarn.csv")],
        yarns=[dict(material="yarn", nodes=[1, 2, 3])],
        supports=[dict(name="ends", nodes=[1, 3], fix="xyz"),
                  dict(name="pull", nodes=[2], fix="yz",
                       displacement=[0.0, -(w - 0.2), 0.0])],
        path=dict(time=[0.0, 1.0], p_force=[0.0, 0.0], p_disp=[0.0, 1.0]),
        solver={**TIGHT, "max_step": 0.25})
    run = run_yarnfort(text)
    assert run.returncode == 0, run.stderr
    curve = read_curve(run.folder / "out")
    state = read_states(run.folder / "out")[-1]
    np.testing.assert_allclose(state.stretch, 1 + strain[knot], rtol=1e-12)
    predicted = 2 * force[knot] * w / length
    assert -curve.reaction("pull")[-1, 1] == pytest.approx(predicted, rel=CLOSED_FORM_RTOL)


def test_strings_in_series_carry_equal_tension(run_yarnfort):
    """Two yarn types in series (stiffness 5 N and 20 N), split into several elements
    each, pulled at one end: one tension everywhere, strains in ratio 4:1."""
    text = scene(
        nodes=[[0, 0, 0], [1, 0, 0], [2, 0, 0]],
        materials=[dict(name="soft", law="linear", stiffness=5.0),
                   dict(name="stiff", law="linear", stiffness=20.0)],
        yarns=[dict(material="soft", nodes=[1, 2], elements_per_segment=3),
               dict(material="stiff", nodes=[2, 3], elements_per_segment=2)],
        supports=[dict(name="fixed", nodes=[1], fix="xyz"),
                  dict(name="pull", nodes=[3], fix="xyz", displacement=[0.3, 0, 0]),
                  dict(name="line", nodes=[2], fix="yz")],
        path=dict(time=[0.0, 1.0], p_force=[0.0, 0.0], p_disp=[0.0, 1.0]),
        solver={**TIGHT, "max_step": 0.5})
    run = run_yarnfort(text)
    assert run.returncode == 0, run.stderr
    state = read_states(run.folder / "out")[-1]
    curve = read_curve(run.folder / "out")
    tension = state.tension
    np.testing.assert_allclose(tension, tension[0], rtol=1e-12)
    # Closed form: T = 0.3 / (1/5 + 1/20) with L0 = 1 for each yarn.
    assert tension[0] == pytest.approx(0.3 / (1 / 5 + 1 / 20), rel=CLOSED_FORM_RTOL)
    assert curve.reaction("pull")[-1, 0] == pytest.approx(tension[0], rel=CLOSED_FORM_RTOL)


def test_initially_slack_straight_string_under_transverse_load(run_yarnfort):
    """A straight string at zero tension has no transverse stiffness (paper 2.6): Newton
    must still converge, to P = 2 EA (l - 1) w / l with l = sqrt(1 + w^2)."""
    ea, load = 10.0, 0.01
    text = scene(
        nodes=[[0, 0, 0], [1, 0, 0], [2, 0, 0]],
        materials=[dict(name="yarn", law="linear", stiffness=ea)],
        yarns=[dict(material="yarn", nodes=[1, 2, 3])],
        supports=[dict(name="ends", nodes=[1, 3], fix="xyz"),
                  dict(name="plane", nodes=[2], fix="z")],
        loads=[dict(nodes=[2], force=[0.0, -load, 0.0])],
        path=dict(time=[0.0, 1.0], p_force=[0.0, 1.0], p_disp=[0.0, 0.0]),
        solver=TIGHT)
    run = run_yarnfort(text)
    assert run.returncode == 0, run.stderr
    state = read_states(run.folder / "out")[-1]
    w = -state.position[1, 1]
    length = np.hypot(1.0, w)
    assert 2 * ea * (length - 1) * w / length == pytest.approx(load, rel=CLOSED_FORM_RTOL)
