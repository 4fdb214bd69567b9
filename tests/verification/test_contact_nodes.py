# SPDX-License-Identifier: MIT
"""Contact nodes of their own kind (issue 11, item 1): fixed obstacles (&obstacle) and
free rings (&ring), with the default settings (no &solver group), against closed forms
and the independent references of test_defaults.py (never against a run of this code).

1. a yarn over K = 1, 4, 16 pins of one &obstacle, no dummy yarns: CapstanReference
   (exact progressive slip) at every step, for the three laws; the same steps and
   results as the peg version of test_defaults.py to round-off; the pins never move and
   the scene has no element but the yarn's;
2. a pin moved by a &support that lists it, frictionless: the closed form of a yarn of
   conserved length through a prescribed point;
3. a frictionless ring loaded directly (a &load on its node, no stub yarn): the ellipse
   closed form of test_defaults.frictionless_ring;
4. a Coulomb ring: the play operator over the admissible interval of test_defaults, and
   the run's own ring inside that interval (from statics alone) at every step;
5. contacts.csv and the VTK point data contact_state at the new kinds.
"""
from __future__ import annotations

import numpy as np
import pytest

from scenes import group
from test_defaults import (FIRST_LOAD, FORCE_RTOL, POSITION_RTOL, PULL, RING_A, RING_B,
                           RING_LOAD, RING_MU, RING_SIZE, RING_STIFFNESS, YARN_EA,
                           CAPSTAN_PATH, FRICTION_START, admissible_splits, capstan_net,
                           check_capstan, defaults_namelist, frictionless_ring, run_capstan,
                           statics_at, stuck_ring)
from test_friction import LAWS, critical, run_scene
from yarnfort.results import read_contacts

#: Agreement of the pin and peg versions of the capstan (same steps, same equations:
#: only the rounding of the peg yarns' share of the residual scales differs).
SAME_RTOL = 1e-12


def pin_net(k: int) -> dict:
    """test_defaults' capstan net without its peg yarns: nodes 1 (held), 2..K+1 (the
    pins), K+2 (pulled); the pins are the nodes of one &obstacle 'pins'."""
    net, _ = capstan_net(k)
    nodes = net["nodes"][:k + 2]
    supports = [s for s in net["supports"] if s["name"] != "pegs"]
    return dict(nodes=nodes, yarns=net["yarns"][:1], supports=supports, loads=[])


def pin_namelist(net: dict, k: int, law: dict, specific: bool = False) -> str:
    """The pin scene; the law at the pins for every yarn type, or (specific) for 'yarn'
    with a different law for every other type (which must not be taken)."""
    materials = [dict(name="yarn", law="linear", stiffness=YARN_EA),
                 dict(name="other", law="linear", stiffness=YARN_EA)]
    if specific:
        contacts = [dict(at="pins", law="coulomb", friction_coefficient=5.0),
                    dict(at="pins", materials=["yarn", ""], **law)]
    else:
        contacts = [dict(at="pins", **law)]
    text = defaults_namelist(net["nodes"], net["yarns"], net["supports"], net["loads"],
                             materials, CAPSTAN_PATH, contacts)
    return text + group("obstacle", name="pins", nodes=list(range(2, k + 2)))


@pytest.mark.parametrize("law_name", list(LAWS))
@pytest.mark.parametrize("k", [1, 4, 16])
def test_capstan_over_pins_with_defaults(run_yarnfort, tmp_path, k, law_name):
    """Pull over K pins and release, the pins an &obstacle: CapstanReference at every
    step (tensions, L0, the pull's reaction, slip onsets and gross slip, as in
    test_defaults); the pins stay exactly where they are; the obstacle's reaction is
    minus the sum of the supports' (it holds the rest); and the peg version (dummy peg
    yarns held at both ends) takes the same steps with the same results."""
    net = pin_net(k)
    run, curve, states = run_scene(run_yarnfort, tmp_path, "pins",
                                   pin_namelist(net, k, LAWS[law_name], specific=k == 4))
    assert len(states) == len(curve["step"])
    errors, _ = check_capstan(net, k, law_name, curve, states)
    x0 = np.asarray(net["nodes"], float)
    for state in states:
        assert state.tension.shape == (k + 1,)          # the yarn's elements only
        np.testing.assert_array_equal(state.position[1:k + 1], x0[1:k + 1])
    total = curve.reaction("first") + curve.reaction("pull") + curve.reaction("pins")
    scale = np.max(np.abs(curve.reaction("pull")))
    assert np.max(np.abs(total)) <= FORCE_RTOL * scale
    # The peg version: the same scene with a peg yarn to an anchor at every pin.
    pegs, peg_curve, peg_states = run_capstan(run_yarnfort, tmp_path, "pegs", k, law_name)
    np.testing.assert_array_equal(peg_curve["time"], curve["time"])
    tension = max(np.max(np.abs(p.tension[:k + 1] - s.tension)) for p, s in
                  zip(peg_states, states)) / max(np.max(s.tension) for s in states)
    length0 = max(np.max(np.abs(p.length0[:k + 1] - s.length0)) for p, s in
                  zip(peg_states, states)) / float(np.sum(states[0].length0))
    reaction = np.max(np.abs(peg_curve.reaction("pegs") - curve.reaction("pins"))) / scale
    print(f"pins K={k} {law_name}: against the pegs: tension {tension:.1e}, L0 "
          f"{length0:.1e}, reaction {reaction:.1e}")
    assert max(tension, length0, reaction) <= SAME_RTOL
    assert list(peg_curve["slipping"]) == list(curve["slipping"])


def test_moving_pin(run_yarnfort, tmp_path):
    """A frictionless pin moved up by a &support that lists it only in y (the obstacle
    holds its x and z), both yarn ends held. mu = 0: one tension T along the yarn, whose
    length is conserved: T = EA (|A - P| + |P - B|) / L0 - EA with P the prescribed pin.
    The moving support carries the y reaction T (u_A + u_B)_y and the obstacle the x one."""
    a, b, pin = np.array([-1.0, 0.0, 0.0]), np.array([1.5, 0.2, 0.0]), np.array([0.2, 0.5, 0.0])
    lift = np.array([0.0, 0.8, 0.0])
    ea = 7.0
    text = defaults_namelist(
        [a, pin, b], [dict(material="yarn", nodes=[1, 2, 3])],
        [dict(name="ends", nodes=[1, 3]),
         dict(name="lift", nodes=[2], fix="y", displacement=lift)],
        [], [dict(name="yarn", law="linear", stiffness=ea)],
        dict(time=[0.0, 1.0], p_disp=[0.0, 1.0]),
        [dict(at="guide", law="coulomb", friction_coefficient=0.0)])
    text += group("obstacle", name="guide", nodes=[2])
    _, curve, states = run_scene(run_yarnfort, tmp_path, "moving", text)
    length0 = np.linalg.norm(pin - a) + np.linalg.norm(b - pin)
    worst = dict(position=0.0, tension=0.0, reaction=0.0)
    for i, state in enumerate(states):
        p = pin + curve["p_disp"][i] * lift
        worst["position"] = max(worst["position"],
                                np.max(np.abs(state.position[1] - p)) / RING_SIZE)
        if curve["p_disp"][i] == 0.0:
            continue                    # stress free
        u = np.array([a - p, b - p])
        length = np.linalg.norm(u, axis=1)
        t = ea * (length.sum() / length0 - 1.0)
        force = t * (u / length[:, None]).sum(axis=0)      # of the yarn on the pin
        worst["tension"] = max(worst["tension"], np.max(np.abs(state.tension - t)) / t)
        reaction = curve.reaction("lift")[i] + curve.reaction("guide")[i]
        worst["reaction"] = max(worst["reaction"], np.max(np.abs(reaction + force)) / t)
        assert curve.reaction("lift")[i][0] == 0.0 and curve.reaction("guide")[i][1] == 0.0
    print(f"moving pin: {len(states)} steps, errors "
          f"{', '.join(f'{n} {v:.1e}' for n, v in worst.items())}")
    assert worst["position"] <= 4 * np.finfo(float).eps
    assert worst["tension"] <= FORCE_RTOL and worst["reaction"] <= FORCE_RTOL
    assert curve["p_disp"][-1] == 1.0 and states[-1].tension[0] > 0.1 * ea


def ring_scene(start, stiffness: float, mu: float, first_load: float = FIRST_LOAD,
               loads=(1.0,)) -> str:
    """test_defaults' ring scene with the ring a &ring node loaded directly: A = 1 and
    B = 3 held, the ring R = 2 (stress free at `start`) pulled by (0, -P, 0), P from
    first_load to each of `loads` in turn (times 0, 1, 2, ...)."""
    return defaults_namelist(
        [RING_A, np.asarray(start, float), RING_B], [dict(material="yarn", nodes=[1, 2, 3])],
        [dict(name="a", nodes=[1]), dict(name="b", nodes=[3])],
        [dict(nodes=[2], force=[0.0, -RING_LOAD, 0.0])],
        [dict(name="yarn", law="linear", stiffness=stiffness)],
        dict(time=list(range(len(loads) + 1)), p_force=[first_load, *loads],
             p_disp=[0.0] * (len(loads) + 1)),
        [dict(at="ring", materials=["yarn", ""], law="coulomb", friction_coefficient=mu)]
    ) + group("ring", name="ring", nodes=[2])


def ring_errors(curve, states, rings, tensions) -> dict:
    """Worst errors over the loaded steps: the ring's position (fraction of the span),
    both tensions and both support reactions (relative to the step's load)."""
    errors = dict(ring=0.0, tension=0.0, reaction=0.0)
    for i, state in enumerate(states):
        load = curve["p_force"][i] * RING_LOAD
        if load == 0.0:
            continue
        ring, t = rings[i], tensions[i]
        u = np.array([RING_A - ring, RING_B - ring])
        u /= np.linalg.norm(u, axis=1)[:, None]
        reactions = np.vstack([curve.reaction("a")[i], curve.reaction("b")[i]])
        errors["ring"] = max(errors["ring"],
                             np.max(np.abs(state.position[1] - ring)) / RING_SIZE)
        errors["tension"] = max(errors["tension"], np.max(np.abs(state.tension - t)) / load)
        errors["reaction"] = max(errors["reaction"],
                                 np.max(np.abs(reactions - t[:, None] * u)) / load)
    return errors


@pytest.mark.parametrize("first_load", [FIRST_LOAD, 0.0])
def test_frictionless_ring_with_defaults(run_yarnfort, tmp_path, first_load):
    """mu = 0 ring at a &ring node, stress free at (0, -0.6), the load on the ring ramped
    to P: ring, tensions and reactions at every loaded step against the ellipse closed
    form for the extensible yarn (test_defaults.frictionless_ring)."""
    stiffness = RING_STIFFNESS["soft"]
    start = np.array([0.0, -0.6, 0.0])
    length0 = np.linalg.norm(RING_A - start) + np.linalg.norm(RING_B - start)
    _, curve, states = run_scene(run_yarnfort, tmp_path, "ring",
                                 ring_scene(start, stiffness, 0.0, first_load))
    rings, tensions = [], []
    for p in curve["p_force"]:
        ring, t, _ = frictionless_ring(length0, stiffness, p * RING_LOAD)
        rings.append(ring)
        tensions.append(np.array([t, t]))
    errors = ring_errors(curve, states, rings, tensions)
    print(f"frictionless &ring (from {first_load} P): {len(states)} steps, errors "
          f"{', '.join(f'{n} {v:.1e}' for n, v in errors.items())}")
    assert errors["ring"] <= POSITION_RTOL
    assert errors["tension"] <= FORCE_RTOL and errors["reaction"] <= FORCE_RTOL


def test_friction_ring_with_defaults(run_yarnfort, tmp_path):
    """Coulomb ring (mu = 0.3) at a &ring node from a stress-free start far on the A
    side, the load ramped from 5 % of P to P (the ring slides: the lower end s_lo(P) of
    the admissible interval rises) and back to P/2 (the interval moves down past the
    ring, which sticks inside it): at every step the play operator
    s(P) = clip(s_old, s_lo(P), s_hi(P)) over the admissible splits (test_defaults), and
    the run's own ring, judged by statics alone from its position and load, inside the
    admissible set T_max <= T_min exp(mu alpha): on its boundary at P, strictly inside
    at P/2."""
    stiffness = RING_STIFFNESS["soft"]
    length0 = np.linalg.norm(RING_A - FRICTION_START) + np.linalg.norm(RING_B - FRICTION_START)
    _, curve, states = run_scene(run_yarnfort, tmp_path, "ring",
                                 ring_scene(FRICTION_START, stiffness, RING_MU,
                                            loads=(1.0, 0.5)))
    split = np.linalg.norm(RING_A - FRICTION_START)
    rings, tensions, ends, ratios = [], [], None, []
    for i, p in enumerate(curve["p_force"]):
        ends = s_lo, s_hi = admissible_splits(length0, stiffness, p * RING_LOAD, RING_MU,
                                              hint=ends)
        split = min(max(split, s_lo), s_hi)
        ring, t, _ = stuck_ring(split, length0, stiffness, p * RING_LOAD)
        rings.append(ring)
        tensions.append(t)
        t_run, alpha = statics_at(states[i].position[1], p * RING_LOAD)
        ratios.append(t_run.max() / (t_run.min() * np.exp(RING_MU * alpha)))
    errors = ring_errors(curve, states, rings, tensions)
    print(f"friction &ring: {len(states)} steps, errors "
          f"{', '.join(f'{n} {v:.1e}' for n, v in errors.items())}; T_max/(T_min e^(mu "
          f"alpha)) from {min(ratios):.12f} to {max(ratios):.12f}")
    assert max(ratios) <= 1.0 + FORCE_RTOL
    peak = int(np.flatnonzero(curve["time"] == 1.0)[0])
    assert abs(ratios[peak] - 1.0) <= FORCE_RTOL and ratios[-1] < 1.0 - 1e-3
    assert list(curve["slipping"][peak + 1:]) == [0] * (len(states) - peak - 1)
    assert errors["ring"] <= POSITION_RTOL
    assert errors["tension"] <= FORCE_RTOL and errors["reaction"] <= FORCE_RTOL


def test_contact_output_at_pins_and_rings(run_yarnfort, tmp_path):
    """contacts.csv and the VTK point data contact_state at the new kinds: one row per
    pin and step with the pin's node and the yarn, modes that agree with curve.csv's
    slipping count, slip rows on the law, stick rows inside it, wrap angles those of the
    fixed geometry; contact_state 1 (stick) or 2 (slip) at the pins, 0 elsewhere; and at
    a ring, its one passage with the flow that moved the ring's split."""
    k = 4
    net = pin_net(k)
    law = LAWS["adhesion"]
    _, curve, states = run_scene(run_yarnfort, tmp_path, "pins", pin_namelist(net, k, law))
    table = read_contacts(tmp_path / "pins" / "out")
    steps = np.asarray(table["step"], int)
    assert len(steps) == k * len(curve["step"])
    for i, step in enumerate(curve["step"]):
        rows = np.flatnonzero(steps == int(step))
        assert list(np.asarray(table["node"], int)[rows]) == list(range(2, k + 2))
        assert set(np.asarray(table["yarn"], int)[rows]) == {1}
        modes = [table["mode"][r] for r in rows]
        assert sum(m != "stick" for m in modes) == curve["slipping"][i]
        t_min, t_max = table["tension_min"][rows], table["tension_max"][rows]
        crit, angle = table["critical_tension"][rows], table["wrap_angle"][rows]
        np.testing.assert_allclose(crit, critical(law, t_min, angle), rtol=1e-13)
        slip = np.array([m != "stick" for m in modes])
        scale = max(float(np.max(t_max)), 1e-300)
        assert np.all(t_max[~slip] <= crit[~slip] * (1 + 1e-9) + FORCE_RTOL * scale)
        assert np.all(np.abs(t_max[slip] - crit[slip]) <= FORCE_RTOL * scale)
        x = np.asarray(net["nodes"], float)
        x[-1] += curve["p_disp"][i] * np.asarray(PULL)
        u, v = x[:-2] - x[1:-1], x[2:] - x[1:-1]
        exact = np.pi - np.arctan2(np.linalg.norm(np.cross(u, v), axis=1),
                                   np.sum(u * v, axis=1))
        np.testing.assert_allclose(angle, exact, rtol=0, atol=1e-13)
        state = states[i].point_data["contact_state"]
        expected = np.zeros(k + 2)
        expected[1:k + 1] = np.where(slip, 2, 1)
        np.testing.assert_array_equal(state, expected)
    assert {"stick", "forward", "backward"} <= set(table["mode"])
    # A ring: one passage at node 2; its flow is the L0 that the A side gave up.
    stiffness = RING_STIFFNESS["soft"]
    _, curve, states = run_scene(run_yarnfort, tmp_path, "ring",
                                 ring_scene(FRICTION_START, stiffness, RING_MU))
    table = read_contacts(tmp_path / "ring" / "out")
    assert len(table["step"]) == len(curve["step"])
    assert set(np.asarray(table["node"], int)) == {2}
    length_a = np.linalg.norm(RING_A - FRICTION_START)
    flow = np.asarray(table["flow"])
    np.testing.assert_allclose(flow, [length_a - s.length0[0] for s in states], rtol=0,
                               atol=1e-14 * length_a)
    assert flow[-1] < -0.1 * length_a                   # towards A: the ring slid to B
    assert set(table["mode"][1:]) == {"backward"}
    assert all(s.point_data["contact_state"][1] == 2 for s in states[1:])
