# SPDX-License-Identifier: MIT
"""Independent load channels (`&path channels`, `factors`; `&load channel`, `&support
channel`):

- a two-stage load (stage 1 on channel 'down', stage 2 on channel 'side') run in one go
  and the same input run in two pieces chained by restart (stopped at the knot between
  the stages) give the same states, to the restart's round-off;
- a friction ring (Coulomb, the stub-yarn ring of test_defaults) pulled down and then
  pushed sideways back and forth shows path dependence (hysteresis of the ring's
  position) that matches an independent return-mapping solution of the ring, written
  here: the play operator s = clip(s_old, s_lo(F), s_hi(F)) over the admissible
  interval of splits of the stuck ring under the load vector F (capstan law);
- without channels the two default channels keep today's columns and behaviour;
- bad channel input is a named error (exit 2, nothing written)."""
from __future__ import annotations

import numpy as np
import pytest
from scipy import optimize

from scenes import group, scene
from yarnfort import read_curve, read_states

# The ring: A and B held, the yarn A-R-B through the ring R, a stub R-S hangs from R
# (S loaded). The numbers are those of test_defaults' friction ring.
RING_A = np.array([-1.0, 0.4, 0.0])
RING_B = np.array([1.0, 0.0, 0.0])
START = np.array([-0.9, -0.2, 0.0])           # stress free, far on the A side
STUB_LENGTH = 0.3
YARN_EA = 10.0                                 # N
#: A stiff yarn (the ring node's test): 1e4 N, 1e5 times the first load; from the
#: stress-free start it converges only through Newton's softened predictor (README,
#: Numerics: before, no ring run with EA >= 3e3 times its load did).
STIFF_YARN_EA = 1.0e4
STUB_EA = 10.0
MU = 0.3
LOAD = 1.0                                     # N, downwards at p_down = 1
SIDE = 0.3                                     # N, along +x at p_side = 1
LENGTH0 = float(np.linalg.norm(RING_A - START) + np.linalg.norm(RING_B - START))
SIZE = float(np.linalg.norm(RING_B - RING_A))
#: Agreement with the reference: the ring's position as a fraction of the span, the
#: tensions relative to the load (Newton's residual tolerance is 1e-10 of the forces).
POSITION_RTOL = 1e-8
FORCE_RTOL = 1e-8
#: The restarted run against the uninterrupted one, relative to each column's scale:
#: the same operations from the same bits except the linear solvers' pivot order
#: (see tests/cli/test_restart.py); measured: equal to the last bit here.
RESTART_RTOL = 1e-10

#: Stage 1 (t 0 -> 1): the load P from 5 % to 100 % on channel 'down'. Stage 2: the
#: sideways force cycled on channel 'side': 0 -> +1 -> 0 -> -1 -> 0 -> +1.
TIMES = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0]
DOWN = [0.05, 1.0, 1.0, 1.0, 1.0, 1.0, 1.0]
SIDEWAYS = [0.0, 0.0, 1.0, 0.0, -1.0, 0.0, 1.0]


def ring_text(folder: str = "out", control: str = "", path=None, loads=None) -> str:
    nodes = np.array([RING_A, START, RING_B, START - [0.0, STUB_LENGTH, 0.0]])
    loads = loads if loads is not None else [
        dict(nodes=[4], force=[0.0, -LOAD, 0.0], channel="down"),
        dict(nodes=[4], force=[SIDE, 0.0, 0.0], channel="side")]
    path = path if path is not None else dict(
        time=TIMES, channels=["down", "side"],
        factors=np.column_stack([DOWN, SIDEWAYS]))
    text = scene(nodes=nodes,
                 yarns=[dict(material="yarn", nodes=[1, 2, 3]),
                        dict(material="stub", nodes=[2, 4])],
                 supports=[dict(name="a", nodes=[1]), dict(name="b", nodes=[3])],
                 loads=loads,
                 materials=[dict(name="yarn", law="linear", stiffness=YARN_EA),
                            dict(name="stub", law="linear", stiffness=STUB_EA)],
                 path=path,
                 output=dict(folder=folder, progress=False, vtk_format="ascii"))
    text += group("contact", materials=["yarn", "stub"], law="coulomb",
                  friction_coefficient=MU)
    if control:
        text += f"&control {control} /\n"
    return text.replace("&control\n    title = 'verification scene'\n/\n", "", 1) \
        if control else text


# ------------------------------------------------------------------ the reference
def lower_intersection(l1: float, l2: float) -> np.ndarray:
    """The lower intersection of the circles of radius l1 about A and l2 about B."""
    e = RING_B - RING_A
    d = np.linalg.norm(e)
    e = e / d
    a = (l1 * l1 - l2 * l2 + d * d) / (2.0 * d)
    assert l1 * l1 >= a * a, "the circles do not meet"
    h = np.sqrt(l1 * l1 - a * a)
    return RING_A + a * e + h * np.array([e[1], -e[0], 0.0])


def stuck_ring(split: float, force: np.ndarray, yarn_ea: float = YARN_EA):
    """The ring held at reference length `split` on the A side (LENGTH0 - split on the B
    side) under the force `force` (x, y) that the stub passes on: the segment lengths
    l_i = L0_i (1 + T_i / EA) place R at the circles' lower intersection, and R's
    equilibrium T1 u1 + T2 u2 + F = 0 closes the two equations (yarn stiffness
    `yarn_ea`). Returns R, (T1, T2), the wrap angle alpha."""
    def place(t):
        ring = lower_intersection(split * (1 + t[0] / yarn_ea),
                                  (LENGTH0 - split) * (1 + t[1] / yarn_ea))
        u = np.array([RING_A - ring, RING_B - ring])[:, :2]
        return ring, u / np.linalg.norm(u, axis=1)[:, None]

    scale = np.linalg.norm(force)

    def residual(t):
        return (t[0] * place(t)[1][0] + t[1] * place(t)[1][1] + force) / scale

    guess = np.linalg.solve(place([0.0, 0.0])[1].T, -force)
    sol = optimize.root(residual, guess, method="hybr", options=dict(xtol=1e-15))
    assert np.max(np.abs(residual(sol.x))) < 1e-13, sol
    ring, u = place(sol.x)
    alpha = np.pi - np.arctan2(abs(u[0, 0] * u[1, 1] - u[0, 1] * u[1, 0]), u[0] @ u[1])
    return ring, sol.x, alpha


def admissible_interval(force: np.ndarray, hint, yarn_ea: float = YARN_EA):
    """[s_lo, s_hi]: the splits where the stuck ring obeys the capstan law, T_max <=
    T_min exp(mu alpha). At s_lo the A side is the taut one (T1 = T2 e^(mu alpha)), at
    s_hi the B side; each end a brentq in a window about `hint` (the ends at a nearby
    load), widened until the sign changes."""
    def g(s, side):
        _, t, alpha = stuck_ring(s, force, yarn_ea)
        assert np.all(t > 0.0)
        return (t[0] - t[1] * np.exp(MU * alpha)) if side == 0 else \
            (t[1] - t[0] * np.exp(MU * alpha))

    ends = []
    for side in (0, 1):
        width = 1e-4 * LENGTH0
        while True:
            a, b = hint[side] - width, hint[side] + width
            if g(a, side) * g(b, side) <= 0.0:
                break
            width *= 2.0
            assert width < LENGTH0, "no end of the admissible interval found"
        ends.append(optimize.brentq(lambda s: g(s, side), a, b, xtol=1e-15,
                                    rtol=4 * np.finfo(float).eps, maxiter=500))
    return ends


def return_mapping(loads: np.ndarray, yarn_ea: float = YARN_EA):
    """The ring's split at each of the run's loads (rows (Fx, Fy)): the play operator
    from the stress-free start, s_k = clip(s_{k-1}, s_lo(F_k), s_hi(F_k)). Exact for a
    path whose interval ends move monotonically between the steps, as here."""
    split = float(np.linalg.norm(RING_A - START))
    # First ends: a scan of the splits where the circles meet and both sides are taut,
    # for the sign change of each end's condition at the first load.
    span = np.linalg.norm(RING_B - RING_A)
    rows = []
    for s in np.linspace(0.5 * (LENGTH0 - span), 0.5 * (LENGTH0 + span), 82)[1:-1]:
        try:
            _, t, alpha = stuck_ring(s, loads[0], yarn_ea)
        except AssertionError:
            continue
        if np.all(t > 0.0):
            rows.append((s, t[0] - t[1] * np.exp(MU * alpha), t[1] - t[0] * np.exp(MU * alpha)))
    rows = np.array(rows)
    hint = []
    for side in (0, 1):
        k = np.flatnonzero(np.diff(np.sign(rows[:, 1 + side])))
        assert len(k) == 1, (side, k)
        hint.append(0.5 * (rows[k[0], 0] + rows[k[0] + 1, 0]))
    splits, rings, tensions = [], [], []
    for force in loads:
        hint = admissible_interval(force, hint, yarn_ea)
        split = min(max(split, hint[0]), hint[1])
        ring, t, _ = stuck_ring(split, force, yarn_ea)
        splits.append(split)
        rings.append(ring)
        tensions.append(t)
    return np.array(splits), np.array(rings), np.array(tensions)


# ------------------------------------------------------------------ tests
def run_ring(run_yarnfort, tmp_path, name: str, **kwargs):
    folder = tmp_path / name
    folder.mkdir()
    done = run_yarnfort(ring_text(**kwargs), cwd=folder)
    assert done.returncode == 0, done.stderr
    return folder / "out"


def test_sideways_cycle_on_a_friction_ring_follows_the_return_mapping(run_yarnfort, tmp_path):
    out = run_ring(run_yarnfort, tmp_path, "ring")
    curve, states = read_curve(out), read_states(out)
    assert len(states) == len(curve)
    assert curve.names[:4] == ["step", "time", "down", "side"]
    loads = np.column_stack([SIDE * curve["side"], -LOAD * curve["down"]])
    splits, rings, tensions = return_mapping(loads)
    position_error = max(np.max(np.abs(s.position[1] - r)) for s, r in zip(states, rings))
    tension_error = max(np.max(np.abs(s.tension[:2] - t)) / np.linalg.norm(f)
                        for s, t, f in zip(states, tensions, loads))
    # The stub's end: the ring plus the stretched stub along the force.
    ends = rings + (STUB_LENGTH * (1 + np.linalg.norm(loads, axis=1) / STUB_EA)
                    / np.linalg.norm(loads, axis=1))[:, None] * np.column_stack(
                        [loads, np.zeros(len(loads))])
    end_error = max(np.max(np.abs(s.position[3] - e)) for s, e in zip(states, ends))
    # The mean displacement of the loaded node in curve.csv is the stub end's.
    load_u = np.column_stack([curve[f"load_1_u{k}"] for k in "xyz"])
    moved = ends - (START - [0.0, STUB_LENGTH, 0.0])
    end_column_error = np.max(np.abs(load_u - moved))
    print(f"ring cycled sideways: {len(states)} steps; errors: ring {position_error / SIZE:.1e}"
          f", stub end {end_error / SIZE:.1e}, curve load_1_u {end_column_error / SIZE:.1e} "
          f"(of the span), tensions {tension_error:.1e} (of the load)")
    assert position_error <= POSITION_RTOL * SIZE
    assert end_error <= POSITION_RTOL * SIZE
    assert end_column_error <= POSITION_RTOL * SIZE
    assert tension_error <= FORCE_RTOL
    # Path dependence: at the three states without a sideways force after stage 1
    # (t = 1, 3, 5) the ring sits at three different places, the reference's too.
    at = {t: int(np.flatnonzero(np.isclose(curve["time"], t, rtol=0, atol=1e-12))[0])
          for t in (1.0, 3.0, 5.0)}
    x = {t: states[i].position[1][0] for t, i in at.items()}
    print("ring x at no sideways force: " + ", ".join(f"t={t:g}: {v:.6f}"
                                                       for t, v in x.items()))
    assert abs(x[3.0] - x[1.0]) > 1e-3 * SIZE and abs(x[5.0] - x[3.0]) > 1e-3 * SIZE
    # The hysteresis loop: the split on the way out (+) and back differs at equal force.
    assert splits[at[3.0]] != pytest.approx(splits[at[5.0]], rel=1e-3)


def ring_kind_text(folder: str = "out", yarn_ea: float = YARN_EA) -> str:
    """The same ring as a `&ring` node (no stub yarn): the loads act on the ring's node."""
    text = scene(nodes=np.array([RING_A, START, RING_B]),
                 yarns=[dict(material="yarn", nodes=[1, 2, 3])],
                 supports=[dict(name="a", nodes=[1]), dict(name="b", nodes=[3])],
                 loads=[dict(nodes=[2], force=[0.0, -LOAD, 0.0], channel="down"),
                        dict(nodes=[2], force=[SIDE, 0.0, 0.0], channel="side")],
                 materials=[dict(name="yarn", law="linear", stiffness=yarn_ea)],
                 path=dict(time=TIMES, channels=["down", "side"],
                           factors=np.column_stack([DOWN, SIDEWAYS])),
                 output=dict(folder=folder, progress=False))
    text += group("ring", name="ring", nodes=[2])
    text += group("contact", at="ring", law="coulomb", friction_coefficient=MU)
    return text


@pytest.mark.parametrize("yarn_ea", [YARN_EA, STIFF_YARN_EA])
def test_sideways_cycle_on_a_ring_node_follows_the_return_mapping(run_yarnfort, tmp_path,
                                                                  yarn_ea):
    """The `&ring` kind on two channels: the same play operator as the stub-yarn ring
    (the stub only passes the force on), and the load columns are the ring's own
    displacement; with the soft yarn and with a stiff one."""
    folder = tmp_path / "ring_kind"
    folder.mkdir()
    done = run_yarnfort(ring_kind_text(yarn_ea=yarn_ea), cwd=folder)
    assert done.returncode == 0, done.stderr
    curve, states = read_curve(folder / "out"), read_states(folder / "out")
    loads = np.column_stack([SIDE * curve["side"], -LOAD * curve["down"]])
    _, rings, tensions = return_mapping(loads, yarn_ea)
    position_error = max(np.max(np.abs(s.position[1] - r)) for s, r in zip(states, rings))
    tension_error = max(np.max(np.abs(s.tension[:2] - t)) / np.linalg.norm(f)
                        for s, t, f in zip(states, tensions, loads))
    load_u = np.column_stack([curve[f"load_1_u{k}"] for k in "xyz"])
    column_error = np.max(np.abs(load_u - (rings - START)))
    print(f"&ring (EA {yarn_ea:g} N) cycled sideways: {len(states)} steps; errors: ring "
          f"{position_error / SIZE:.1e}"
          f", load_1_u {column_error / SIZE:.1e} (of the span), tensions "
          f"{tension_error:.1e} (of the load)")
    assert position_error <= POSITION_RTOL * SIZE
    assert column_error <= POSITION_RTOL * SIZE
    assert tension_error <= FORCE_RTOL
    x = [states[int(np.flatnonzero(np.isclose(curve["time"], t, rtol=0, atol=1e-12))[0])]
         .position[1][0] for t in (1.0, 3.0, 5.0)]
    assert abs(x[1] - x[0]) > 1e-3 * SIZE and abs(x[2] - x[1]) > 1e-3 * SIZE


def test_two_stages_chained_by_restart_equal_one_run(run_yarnfort, tmp_path):
    whole = run_ring(run_yarnfort, tmp_path, "whole")
    curve = read_curve(whole)
    # Stop at the knot between the stages (t = 1): that many steps after step 0.
    knot_step = int(curve["step"][np.flatnonzero(np.isclose(curve["time"], 1.0, rtol=0,
                                                            atol=1e-12))[0]])
    folder = tmp_path / "pieces"
    folder.mkdir()
    first = run_yarnfort(ring_text(control=f"max_steps = {knot_step}"), cwd=folder)
    assert first.returncode == 0, first.stderr
    part = read_curve(folder / "out")
    assert part["time"][-1] == pytest.approx(1.0, abs=1e-12) and part["side"][-1] == 0.0
    second = run_yarnfort(ring_text(control="restart = .true."), cwd=folder)
    assert second.returncode == 0, second.stderr
    pieces = read_curve(folder / "out")
    assert pieces.names == curve.names and len(pieces) == len(curve)
    worst = 0.0
    for name in curve.names:
        if name in ("wall_time", "residual"):
            continue
        scale = max(np.max(np.abs(curve[name])), 1e-300)
        worst = max(worst, np.max(np.abs(pieces[name] - curve[name])) / scale)
    states_whole, states_pieces = read_states(whole), read_states(folder / "out")
    assert len(states_whole) == len(states_pieces)
    position = max(np.max(np.abs(a.position - b.position))
                   for a, b in zip(states_whole, states_pieces)) / SIZE
    print(f"two stages chained by restart at step {knot_step}: curve columns differ by "
          f"{worst:.1e} of their scale, positions by {position:.1e} of the span")
    assert worst <= RESTART_RTOL and position <= RESTART_RTOL


def test_channels_named_p_force_and_p_disp_equal_the_default(run_yarnfort, tmp_path):
    """The defaults are two channels, 'p_force' and 'p_disp': spelled out, the same run."""
    path = dict(time=[0.0, 1.0], p_force=[0.05, 1.0])
    loads = [dict(nodes=[4], force=[0.1, -LOAD, 0.0])]
    default = run_ring(run_yarnfort, tmp_path, "default", path=path, loads=loads)
    named = run_ring(run_yarnfort, tmp_path, "named",
                     path=dict(time=[0.0, 1.0], channels=["p_force", "p_disp"],
                               factors=[0.05, 0.0, 1.0, 0.0]),
                     loads=[dict(nodes=[4], force=[0.1, -LOAD, 0.0], channel="p_force")])
    a, b = read_curve(default), read_curve(named)
    assert a.names == b.names and a.names[:4] == ["step", "time", "p_force", "p_disp"]
    for name in a.names:
        if name != "wall_time":
            assert np.array_equal(a[name], b[name]), name
    for x, y in zip(read_states(default), read_states(named)):
        assert np.array_equal(x.position, y.position)


BAD = [
    (dict(loads=[dict(nodes=[4], force=[0.0, -1.0, 0.0], channel="dwn")]),
     "&load #1: channel = 'dwn' is not a channel of &path (channels: 'down', 'side'); "
     "did you mean 'down'?"),
    (dict(loads=[dict(nodes=[4], force=[0.0, -1.0, 0.0])]),
     "&load #1: channel is not set, and &path names its channels"),
    (dict(path=dict(time=[0.0, 1.0], channels=["down", "side"], factors=[0.0, 0.0, 1.0])),
     "&path: factors has 3 values but the 2 channels ('down', 'side') at 2 knots need 4"),
    (dict(path=dict(time=[0.0, 1.0], channels=["down", "down"], factors=[0.0] * 4)),
     "&path: channel 'down' is named twice"),
    (dict(path=dict(time=[0.0, 1.0], channels=["down", "time"], factors=[0.0] * 4)),
     "&path: channels(2) = 'time' is the name of another column of curve.csv"),
    (dict(path=dict(time=[0.0, 1.0], channels=["down", "side"], factors=[0.0] * 4,
                    p_force=[0.0, 1.0])),
     "&path: p_force or p_disp is set together with channels"),
    (dict(path=dict(time=[0.0, 1.0], factors=[0.0, 1.0])),
     "&path: factors is given but channels is not"),
    (dict(path=dict(time=[0.0, 1.0], channels=["down", "a_rx"], factors=[0.0] * 4),
          loads=[dict(nodes=[4], force=[0.0, -1.0, 0.0], channel="down")]),
     "curve.csv would have two columns 'a_rx' (the factor of channel a_rx and &support 'a')"),
    (dict(path=dict(time=[0.0, 1.0], p_force=[0.0, 1.0]),
          loads=[dict(nodes=[4], force=[0.0, -1.0, 0.0], channel="down")]),
     "&load #1: channel = 'down' is not a channel of &path (channels: 'p_force', 'p_disp')"),
]


@pytest.mark.parametrize("change, message", BAD, ids=[m[:40] for _, m in BAD])
def test_bad_channels_are_named_errors(run_yarnfort, tmp_path, change, message):
    done = run_yarnfort(ring_text(**change), cwd=tmp_path)
    assert done.returncode == 2, done.stderr
    assert message in done.stderr, done.stderr
    assert not (tmp_path / "out").exists()


def test_channels_with_many_names_and_spaces(run_yarnfort, tmp_path):
    """channels(3) after an empty channels(2) is an error (names one after another)."""
    text = ring_text().replace("channels = 'down', 'side'", "channels(1) = 'down', "
                               "channels(3) = 'side'")
    done = run_yarnfort(text, cwd=tmp_path)
    assert done.returncode == 2, done.stderr
    assert "&path: channels(3) = 'side' follows the empty channels(2)" in done.stderr
