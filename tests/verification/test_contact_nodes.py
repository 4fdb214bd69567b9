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
                           check_capstan, defaults_namelist, frictionless_ring_path, run_capstan,
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


@pytest.mark.parametrize("yarn, first_load", [("soft", FIRST_LOAD), ("soft", 0.0),
                                              ("stiff", 0.0)])
def test_frictionless_ring_with_defaults(run_yarnfort, tmp_path, yarn, first_load):
    """mu = 0 ring at a &ring node, stress free at (0, -0.6), the load on the ring ramped
    to P: ring, tensions and reactions at every loaded step against the ellipse closed
    form for the extensible yarn (test_defaults.frictionless_ring). The stiff yarn (EA
    = 1e5 P) from zero load: its first loaded step must slide the ring far along a yarn
    1e6 times stiffer than that step's load (before Newton's softened-yarn predictor it
    failed after 17 step cuts)."""
    stiffness = RING_STIFFNESS[yarn]
    start = np.array([0.0, -0.6, 0.0])
    length0 = np.linalg.norm(RING_A - start) + np.linalg.norm(RING_B - start)
    _, curve, states = run_scene(run_yarnfort, tmp_path, "ring",
                                 ring_scene(start, stiffness, 0.0, first_load))
    rings, tensions = frictionless_ring_path(length0, stiffness, curve["p_force"])
    errors = ring_errors(curve, states, rings, tensions)
    print(f"frictionless &ring ({yarn}, from {first_load} P): {len(states)} steps, errors "
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


def test_law_rule_does_not_depend_on_the_input_order(run_yarnfort, tmp_path):
    """The law at the pins (a law for the yarn's type and one for every type) and the
    groups in either order: the same curve and contact table to the last digit; and the
    specific law is the one taken (its T_crit, not the other law's, in contacts.csv)."""
    k, law = 4, LAWS["adhesion"]
    net = pin_net(k)
    first = pin_namelist(net, k, law, specific=True)
    chunks = first.split("&contact")
    head, contacts = chunks[0], ["&contact" + c for c in chunks[1:]]
    obstacle = contacts[-1][contacts[-1].index("&obstacle"):]
    contacts[-1] = contacts[-1][:contacts[-1].index("&obstacle")]
    second = obstacle + head + "".join(reversed(contacts))
    assert second != first and sorted(second.splitlines()) == sorted(first.splitlines())
    tables = []
    for name, text in (("first", first), ("second", second)):
        _, curve, _ = run_scene(run_yarnfort, tmp_path, name, text)
        table = read_contacts(tmp_path / name / "out")
        tables.append((curve, table))
    (c1, t1), (c2, t2) = tables
    for column in c1.names:
        if column != "wall_time":
            np.testing.assert_array_equal(c1[column], c2[column])
    for column in t1.names:
        np.testing.assert_array_equal(t1[column], t2[column])
    np.testing.assert_allclose(t1["critical_tension"],
                               critical(law, t1["tension_min"], t1["wrap_angle"]), rtol=1e-13)


def test_pair_laws_do_not_apply_at_a_ring(run_yarnfort, tmp_path):
    """Two yarns of two types through one frictionless ring, and a pair &contact between
    the types with mu = 0.9: at the ring only the ring's law counts, so both yarns slide
    freely (T_crit = T_min, equal tensions on both sides of each yarn) and the ring's
    load is held by the four tensions."""
    nodes = [[-1.0, 0.3, 0.0], [0.0, -0.5, 0.0], [1.0, 0.0, 0.0],
             [0.0, 0.2, -1.0], [0.0, 0.4, 1.0]]
    text = defaults_namelist(
        nodes, [dict(material="line", nodes=[1, 2, 3]), dict(material="cord", nodes=[4, 2, 5])],
        [dict(name="ends", nodes=[1, 3, 4, 5])], [dict(nodes=[2], force=[0.0, -1.0, 0.0])],
        [dict(name="line", law="linear", stiffness=10.0),
         dict(name="cord", law="linear", stiffness=20.0)],
        dict(time=[0.0, 1.0], p_force=[FIRST_LOAD, 1.0]),
        [dict(materials=["line", "cord"], law="coulomb", friction_coefficient=0.9),
         dict(at="hook", law="coulomb", friction_coefficient=0.0)])
    text += group("ring", name="hook", nodes=[2])
    _, curve, states = run_scene(run_yarnfort, tmp_path, "hook", text)
    table = read_contacts(tmp_path / "hook" / "out")
    assert len(table["step"]) == 2 * len(states)
    assert set(np.asarray(table["node"], int)) == {2}
    np.testing.assert_array_equal(table["critical_tension"], table["tension_min"])
    for i, state in enumerate(states):
        load = curve["p_force"][i]
        t = state.tension
        assert abs(t[0] - t[1]) <= FORCE_RTOL * load and abs(t[2] - t[3]) <= FORCE_RTOL * load
        x = state.position
        pull = sum(t[e] * (x[n] - x[1]) / np.linalg.norm(x[n] - x[1])
                   for e, n in enumerate((0, 2, 3, 4)))
        assert np.max(np.abs(pull + [0.0, -load, 0.0])) <= FORCE_RTOL * load
    assert states[-1].tension.min() > 0.1


def test_pin_reactions_per_node(run_yarnfort, tmp_path):
    """&output node_reactions at an obstacle: one row per pin and step, each the force
    that holds the pin against the yarn's two tensions at it (from the run's own tensions
    and positions), and the rows adding up to the obstacle's columns in curve.csv."""
    k = 4
    net = pin_net(k)
    text = pin_namelist(net, k, LAWS["coulomb"]).replace(
        "folder = 'out'", "folder = 'out'\n    node_reactions = .true.")
    _, curve, states = run_scene(run_yarnfort, tmp_path, "pins", text)
    from yarnfort.results import read_reactions
    table = read_reactions(tmp_path / "pins" / "out")
    rows = [i for i, s in enumerate(table["support"]) if s == "pins"]
    assert len(rows) == k * len(states)
    force = np.column_stack([table["rx"], table["ry"], table["rz"]])
    worst = 0.0
    for i, state in enumerate(states):
        mine = [r for r in rows if int(table["step"][r]) == int(curve["step"][i])]
        assert [int(table["node"][r]) for r in mine] == list(range(2, k + 2))
        x, t = state.position, state.tension
        scale = max(float(t.max()), 1e-300)
        for p, r in enumerate(mine, start=1):
            u = [(x[p - 1] - x[p]) / np.linalg.norm(x[p - 1] - x[p]),
                 (x[p + 1] - x[p]) / np.linalg.norm(x[p + 1] - x[p])]
            held = -(t[p - 1] * u[0] + t[p] * u[1])
            worst = max(worst, np.max(np.abs(force[r] - held)) / scale)
        np.testing.assert_allclose(force[mine].sum(axis=0), curve.reaction("pins")[i],
                                   rtol=0, atol=1e-14 * scale)
    print(f"pin reactions: {len(rows)} rows, worst {worst:.1e} of the largest tension")
    assert worst <= FORCE_RTOL
