# SPDX-License-Identifier: MIT
"""Elastic string networks against closed forms (no friction)."""
from __future__ import annotations

import numpy as np
import pytest

from scenes import scene
from yarnfort import read_curve, read_states

#: Agreement required with closed forms at convergence (issue: rel. error <= 1e-8).
CLOSED_FORM_RTOL = 1e-8
#: Tight Newton tolerance (relative to the forces at each node).
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


def cable_net(n: int = 3, pretension_pull: float = 0.05, load: float = 0.5):
    """An n x n pretensioned cable net in the xy plane (unit spacing, cables along x
    and y through interior nodes, ends held by the boundary supports) under a
    transverse point load at its centre: pretension first (p_disp 0 -> 1), then the
    load (p_force 0 -> 1)."""
    interior = {(i, j): None for i in range(1, n + 1) for j in range(1, n + 1)}
    nodes, index = [], {}
    for key in list(interior) + [(0, j) for j in range(1, n + 1)] \
            + [(n + 1, j) for j in range(1, n + 1)] + [(i, 0) for i in range(1, n + 1)] \
            + [(i, n + 1) for i in range(1, n + 1)]:
        index[key] = len(nodes) + 1
        nodes.append([key[0], key[1], 0.0])
    yarns = [dict(material="cable", nodes=[index[(i, j)] for i in range(n + 2)])
             for j in range(1, n + 1)]
    yarns += [dict(material="cable", nodes=[index[(i, j)] for j in range(n + 2)])
              for i in range(1, n + 1)]
    supports = [
        dict(name="west", nodes=[index[(0, j)] for j in range(1, n + 1)], fix="xyz",
             displacement=[-pretension_pull, 0, 0]),
        dict(name="east", nodes=[index[(n + 1, j)] for j in range(1, n + 1)], fix="xyz",
             displacement=[pretension_pull, 0, 0]),
        dict(name="south", nodes=[index[(i, 0)] for i in range(1, n + 1)], fix="xyz",
             displacement=[0, -pretension_pull, 0]),
        dict(name="north", nodes=[index[(i, n + 1)] for i in range(1, n + 1)], fix="xyz",
             displacement=[0, pretension_pull, 0])]
    centre = index[((n + 1) // 2, (n + 1) // 2)]
    return dict(nodes=nodes, yarns=yarns, supports=supports,
                materials=[dict(name="cable", law="neo_hookean", modulus=2e6, area=5e-6)],
                loads=[dict(nodes=[centre], force=[0.0, 0.0, -load])],
                path=dict(time=[0.0, 1.0, 2.0], p_disp=[0.0, 1.0, 1.0],
                          p_force=[0.0, 0.0, 1.0]))


def residual_histories(stderr: str) -> list[list[float]]:
    return [[float(v) for v in line.split()[1:]] for line in stderr.splitlines()
            if line.strip().startswith("residuals")]


def test_cable_net_newton_converges_quadratically(run_yarnfort):
    """Full Newton (a Jacobian at every iterate): once the residual is small, each
    iterate roughly squares it, until round-off."""
    net = cable_net()
    run = run_yarnfort(scene(**net, solver=dict(initial_step=1.0, max_step=1.0,
                                                residual_tolerance=1e-14),
                             output=dict(folder="out", residual_history=True)))
    assert run.returncode == 0, run.stderr
    history = residual_histories(run.stderr)[-1]   # the load step
    print("cable net, load step, scaled residual per Newton iterate:", history)
    # Observed order from three consecutive iterates above round-off:
    # p = log(e[k+1]/e[k]) / log(e[k]/e[k-1]), 2 for Newton's quadratic convergence.
    orders = [np.log(c / b) / np.log(b / a) for a, b, c in
              zip(history, history[1:], history[2:]) if c > 1e-14 and a < 1e-2]
    print("observed orders:", orders)
    assert orders, history
    assert max(orders) > 1.8, (orders, history)


def test_cable_net_answer_independent_of_load_steps(run_yarnfort, tmp_path):
    """Elastic, hence path independent: 1 step per knot and 40 steps give one answer."""
    net = cable_net()
    finals = []
    for name, step in (("coarse", 1.0), ("fine", 0.05)):
        folder = tmp_path / name
        folder.mkdir()
        run = run_yarnfort(scene(**net, solver=dict(initial_step=step, max_step=step,
                                                    residual_tolerance=1e-14)),
                           cwd=folder)
        assert run.returncode == 0, run.stderr
        finals.append(read_states(folder / "out")[-1].position)
        print(name, "steps:", len(read_curve(folder / "out")["step"]) - 1)
    assert np.max(np.abs(finals[0] - finals[1])) <= 1e-8


def test_slack_regularisation_leaves_the_answer_exact(run_yarnfort, tmp_path):
    """The V-shaped string plus a third string hanging from C to D = (0,-1,0): when C
    is pushed down by the load that string goes slack (compressed). The exact
    tension-only law gives it no tension. The regularisation (slack_stiffness) acts on
    the Newton tangent of slack strings and as a predictor only, so whatever its weight
    the converged C is that of the exact law (slack_stiffness = 0) to the Newton
    tolerance, and the slack string carries exactly zero."""
    depth = {}
    for ratio in (0.0, 1e-6, 1e-4):
        folder = tmp_path / f"r{ratio}"
        folder.mkdir()
        text = scene(
            nodes=[[-1, 0, 0], [0, -0.2, 0], [1, 0, 0], [0, -1, 0]],
            materials=[dict(name="yarn", law="linear", stiffness=10.0)],
            yarns=[dict(material="yarn", nodes=[1, 2, 3]), dict(material="yarn", nodes=[2, 4])],
            supports=[dict(name="west", nodes=[1], fix="xyz", displacement=[-0.05, 0, 0]),
                      dict(name="east", nodes=[3], fix="xyz", displacement=[0.05, 0, 0]),
                      dict(name="anchor", nodes=[4], fix="xyz"),
                      dict(name="plane", nodes=[2], fix="z")],
            loads=[dict(nodes=[2], force=[0.0, -0.5, 0.0])],
            # Pull the ends apart first so that the V is taut: with the exact
            # tension-only law a net at zero tension has no stiffness at all.
            path=dict(time=[0.0, 1.0, 2.0], p_force=[0.0, 0.0, 1.0], p_disp=[0.0, 1.0, 1.0]),
            solver=dict(slack_stiffness=ratio, residual_tolerance=1e-14))
        run = run_yarnfort(text, cwd=folder)
        assert run.returncode == 0, run.stderr
        state = read_states(folder / "out")[-1]
        assert state.stretch[2] < 1.0     # the hanging string is compressed (slack)
        assert state.tension[2] == 0.0
        depth[ratio] = -state.position[1, 1]
    for ratio in (1e-6, 1e-4):
        change = abs(depth[ratio] - depth[0.0]) / depth[0.0]
        print(f"slack_stiffness {ratio:g}: relative change of C's depth {change:.3e}")
        assert change <= 1e-12
