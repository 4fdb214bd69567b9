# SPDX-License-Identifier: MIT
"""Sliding at contact nodes (capstan friction) against closed forms and limits.

The reference critical tensions are computed here, independently of the Fortran laws, in
closed forms solved from each law's ODE (paper eqs. 20; 35, read with alpha* = 1/mu -
T0/beta, not T1; 40-44, their "w" read as w_d), and those are checked against a numerical
integration of the ODE.
"""
from __future__ import annotations

import numpy as np
import pytest

from scenes import group, scene
from yarnfort import read_curve, read_states
from yarnfort.results import read_contacts

#: Agreement required with closed forms at convergence.
CLOSED_FORM_RTOL = 1e-8
#: Newton tolerance of these runs: the residual is 1e-12 * force_scale (EA = 10 N) at
#: most, i.e. 1e-11 N against tensions of 1e-2 N and more.
TIGHT = dict(residual_tolerance=1e-12)
MU = 0.3
LAWS = {
    "coulomb": dict(law="coulomb", friction_coefficient=MU),
    # beta/mu = 0.167 N lies inside the range of tensions: both branches of eq. 35.
    "adhesion": dict(law="adhesion", friction_coefficient=MU, adhesion=0.05),
    # mu*w_d = 0.015 < beta: the adhesion decays; T* = beta*s_d/(mu*(s_d-w_d)+beta) = 0.23,
    # and the tensions pass w_d and T*, so every regime of the law is used.
    "decaying_adhesion": dict(law="decaying_adhesion", friction_coefficient=MU, adhesion=0.1,
                              decay_start=0.05, decay_end=0.6),
}
YARN_EA = 10.0


# --------------------------------------------------------------------------------------
# Reference critical tensions T_crit(T0, alpha), vectorised over T0 and alpha.

def rate(law: dict):
    """g(T) of the law's ODE dT/dalpha = g(T) (reference table of inputs/REFERENCE.md)."""
    mu = law.get("friction_coefficient", 0.0)
    beta = law.get("adhesion", 0.0)
    if law["law"] == "coulomb":
        return lambda t: mu * t
    if law["law"] == "adhesion":
        return lambda t: np.maximum(mu * t, beta)
    w, s = law["decay_start"], law["decay_end"]
    return lambda t: np.maximum(beta * np.minimum(1.0, (s - t) / (s - w)), mu * t)


def angle_to_reach(law: dict, t0, t1, kinks=(), pieces: int = 8, order: int = 20):
    """The wrap angle over which the law's ODE takes T from t0 to t1 > t0: the integral
    of dT/g(T) (the flow's inverse), by Gauss-Legendre on pieces that end at the kinks
    of g, where 1/g is analytic and the quadrature converges exponentially."""
    g = rate(law)
    nodes, weights = np.polynomial.legendre.leggauss(order)
    points = np.unique(np.r_[t0, t1, [k for k in kinks if t0 < k < t1]])
    points = np.unique(np.concatenate([np.linspace(a, b, pieces + 1)
                                       for a, b in zip(points, points[1:])]))
    total = 0.0
    for a, b in zip(points, points[1:]):
        t = 0.5 * (a + b) + 0.5 * (b - a) * nodes
        total += 0.5 * (b - a) * np.sum(weights / g(t))
    return total


def critical(law: dict, t0, angle):
    """T_crit(T0, alpha) in closed form, solved here from the ODE piece by piece.
    - Coulomb (eq. 20): T0 exp(mu alpha).
    - Adhesion (eq. 35): T0 + beta alpha up to alpha* = 1/mu - T0/beta, then
      (beta/mu) exp(mu (alpha - alpha*)); the pure exponential when T0 >= beta/mu.
    - Decaying adhesion with beta > mu w_d (k = beta/(s_d - w_d)): g = beta below w_d,
      k (s_d - T) from w_d up to T* = beta s_d/(mu (s_d - w_d) + beta) where it meets
      mu T, and mu T above T*. The ODE is autonomous: each piece starts where the last
      one left off, after the angle the last one took to reach its end tension."""
    t0, angle = np.broadcast_arrays(np.asarray(t0, float), np.asarray(angle, float))
    mu = law["friction_coefficient"]
    if law["law"] == "coulomb":
        return t0 * np.exp(mu * angle)
    beta = law["adhesion"]
    if law["law"] == "adhesion":
        alpha_star = 1 / mu - t0 / beta
        return np.where(t0 >= beta / mu, t0 * np.exp(mu * angle),
                        np.where(angle <= alpha_star, t0 + beta * angle,
                                 beta / mu * np.exp(mu * (angle - alpha_star))))
    w, s = law["decay_start"], law["decay_end"]
    assert beta > mu * w
    k = beta / (s - w)
    t_star = beta * s / (mu * (s - w) + beta)
    t, left = t0.copy(), angle.copy()
    # Piece 1, T < w_d: linear.
    used = np.where(t < w, np.minimum(left, (w - t) / beta), 0.0)
    t, left = t + beta * used, left - used
    # Piece 2, w_d <= T < T* (a round-off below w_d is harmless): relaxation to s_d.
    gap = s - np.minimum(t, t_star)
    used = np.minimum(left, np.log(gap / (s - t_star)) / k)
    t, left = np.where(t < t_star, s - gap * np.exp(-k * used), t), left - used
    # Piece 3, T >= T*: Coulomb.
    return t * np.exp(mu * left)


def test_reference_critical_tensions():
    """The closed forms used below against numerical integration of each law's ODE: the
    angle the ODE needs from T0 to the closed form's T_crit(T0, alpha) must be alpha."""
    worst = {}
    for name, law in LAWS.items():
        mu, beta = law["friction_coefficient"], law.get("adhesion", 0.0)
        kinks = [beta / mu]
        if "decay_start" in law:
            w, s = law["decay_start"], law["decay_end"]
            kinks = [w, beta * s / (mu * (s - w) + beta)]
        errors = []
        for t0 in np.r_[0.0, np.geomspace(1e-3, 1.0, 13), kinks]:
            for angle in np.linspace(0.1, 8.0, 12):
                t1 = float(critical(law, t0, angle))
                if name == "coulomb" and t0 == 0.0:
                    assert t1 == 0.0     # T = 0 is an equilibrium of T' = mu T
                    continue
                errors.append(abs(angle_to_reach(law, t0, t1, kinks) - angle) / angle)
        worst[name] = max(errors)
    print("closed forms vs integration, max relative error of the angle:", worst)
    assert max(worst.values()) < 1e-12
    # Spot values of the decaying law by hand: linear up to w_d, Coulomb above T*.
    law = LAWS["decaying_adhesion"]
    mu, beta, w, s = (law[k] for k in ("friction_coefficient", "adhesion", "decay_start",
                                       "decay_end"))
    assert critical(law, 0.0, 0.5 * w / beta) == pytest.approx(0.5 * w, rel=1e-14)
    star = beta * s / (mu * (s - w) + beta)
    assert critical(law, star, 2.0) == pytest.approx(star * np.exp(2 * mu), rel=1e-14)


# --------------------------------------------------------------------------------------
# Scenes: a net is a dict of nodes (list of xyz), yarns, supports and loads as for
# scenes.scene; contact nodes held in place are the ends of short 'peg' yarns to fixed
# anchors (a node only becomes a contact node where two yarns meet).

#: Stiffness EA (N) of the yarn types used below.
STIFFNESS = {"yarn": YARN_EA, "peg": YARN_EA, "cord": YARN_EA, "post": 3.0}


def peg_net(pegs, first, last, pull=(0.0, -0.3, 0.0), first_fix="xyz", first_force=None,
            yarn="yarn", peg="peg", elements_per_segment=1, anchor_offset=(0.0, 0.2, 0.0)):
    """One yarn first -> pegs -> last over fixed pegs; `last` is pulled by `pull`
    (displacement control), `first` held in `first_fix` and loaded by `first_force`.
    Nodes: 1 = first, 2..K+1 = pegs, K+2 = last, then the anchors."""
    pegs = np.atleast_2d(np.asarray(pegs, float))
    k = len(pegs)
    nodes = [list(first), *pegs.tolist(), list(last), *(pegs + anchor_offset).tolist()]
    yarns = [dict(material=yarn, nodes=list(range(1, k + 3)),
                  elements_per_segment=elements_per_segment)]
    yarns += [dict(material=peg, nodes=[2 + i, k + 3 + i]) for i in range(k)]
    supports = [dict(name="first", nodes=[1], fix=first_fix),
                dict(name="pull", nodes=[k + 2], fix="xyz", displacement=list(pull)),
                dict(name="pegs", nodes=list(range(2, k + 2)) + list(range(k + 3, 2 * k + 3)),
                     fix="xyz")]
    loads = [dict(nodes=[1], force=list(first_force))] if first_force is not None else []
    return dict(nodes=nodes, yarns=yarns, supports=supports, loads=loads)


def arc_pegs(k: int, start: float = 150.0, stop: float = 30.0) -> np.ndarray:
    """k pegs on the unit circle between the polar angles start and stop (degrees)."""
    theta = np.radians(np.linspace(start, stop, k)) if k > 1 else np.array([np.pi / 2])
    return np.column_stack([np.cos(theta), np.sin(theta), np.zeros(k)])


def free_node_net(pull=(0.2, -0.3, 0.0), peg_length: float = 0.05, yarn="yarn",
                  peg="post"):
    """Yarn A-C1-C2-B through two FREE contact nodes C1, C2, each the end of an elastic
    'post' yarn (EA = 3 N, length `peg_length`) anchored at D1, D2; A held, B pulled.
    Nodes 1-6: A, C1, C2, B, D1, D2. All in the z = 0 plane (C1, C2 are held in z: a
    planar net has almost no stiffness out of its plane)."""
    c1, c2 = np.array([-0.4, 0.8, 0.0]), np.array([0.4, 0.8, 0.0])
    up = np.array([0.3, 1.0, 0.0]) / np.hypot(0.3, 1.0)
    nodes = [[-1, 0, 0], c1, c2, [1, 0, 0], c1 + peg_length * up * [-1, 1, 1],
             c2 + peg_length * up]
    yarns = [dict(material=yarn, nodes=[1, 2, 3, 4]),
             dict(material=peg, nodes=[2, 5]), dict(material=peg, nodes=[3, 6])]
    supports = [dict(name="a", nodes=[1], fix="xyz"),
                dict(name="pull", nodes=[4], fix="xyz", displacement=list(pull)),
                dict(name="anchors", nodes=[5, 6], fix="xyz"),
                dict(name="plane", nodes=[2, 3], fix="z")]
    return dict(nodes=[list(map(float, n)) for n in nodes], yarns=yarns, supports=supports,
                loads=[])


def merge(a: dict, b: dict, shift=(5.0, 0.0, 0.0), suffix: str = "2") -> dict:
    """Two disjoint nets in one scene: b's nodes shifted and renumbered after a's."""
    offset = len(a["nodes"])
    renumber = lambda ids: [i + offset for i in ids]   # noqa: E731
    return dict(
        nodes=a["nodes"] + (np.asarray(b["nodes"]) + shift).tolist(),
        yarns=a["yarns"] + [{**y, "nodes": renumber(y["nodes"])} for y in b["yarns"]],
        supports=a["supports"] + [{**s, "name": s["name"] + suffix,
                                   "nodes": renumber(s["nodes"])} for s in b["supports"]],
        loads=a["loads"] + [{**ld, "nodes": renumber(ld["nodes"])} for ld in b["loads"]])


def namelist(net: dict, contacts=(), scheme: str = "monolithic", path=None, solver=None,
             step: float = 0.05) -> str:
    """Namelist text of a net with one &contact per dict of `contacts`, fixed steps of
    `step` (initial_step = max_step) unless a step has to be cut."""
    names = sorted({y["material"] for y in net["yarns"]})
    text = scene(nodes=net["nodes"], yarns=net["yarns"], supports=net["supports"],
                 loads=net["loads"],
                 materials=[dict(name=m, law="linear", stiffness=STIFFNESS[m]) for m in names],
                 path=path or dict(time=[0, 1, 2], p_force=[0, 0, 0], p_disp=[0, 1, 0]),
                 solver={**TIGHT, "max_step": step, "initial_step": step, "scheme": scheme,
                         **(solver or {})},
                 output=dict(folder="out", progress=False))
    return text + "".join(group("contact", **c) for c in contacts)


def contact(a: str, b: str, law: dict) -> dict:
    return dict(materials=[a, b], **law)


def run_scene(run_yarnfort, tmp_path, name: str, text: str, ok: bool = True):
    folder = tmp_path / name
    folder.mkdir()
    run = run_yarnfort(text, cwd=folder)
    if ok:
        assert run.returncode == 0, run.stderr
    return run, read_curve(folder / "out"), read_states(folder / "out")


def wrap_angles(position: np.ndarray, path) -> np.ndarray:
    """alpha = pi - gamma at each interior node of `path` (0-based node indices)."""
    path = list(path)
    a = position[path[:-2]] - position[path[1:-1]]
    b = position[path[2:]] - position[path[1:-1]]
    # atan2 of |a x b| and a.b, accurate at gamma = 0 and pi (an arccos of the cosine
    # loses half the digits there: it would give alpha only to ~1e-8).
    return np.pi - np.arctan2(np.linalg.norm(np.cross(a, b), axis=1), np.sum(a * b, axis=1))


def initial_length0(net: dict) -> np.ndarray:
    """Reference lengths of all elements as built from the input: the lengths of the
    segments split evenly."""
    nodes = np.asarray(net["nodes"], float)
    lengths = []
    for y in net["yarns"]:
        n = y.get("elements_per_segment", 1)
        for a, b in zip(y["nodes"], y["nodes"][1:]):
            lengths += [np.linalg.norm(nodes[b - 1] - nodes[a - 1]) / n] * n
    return np.array(lengths)


def element_ranges(net: dict) -> list[slice]:
    """Elements of each yarn (they are numbered yarn by yarn)."""
    ranges, start = [], 0
    for y in net["yarns"]:
        count = (len(y["nodes"]) - 1) * y.get("elements_per_segment", 1)
        ranges.append(slice(start, start + count))
        start += count
    return ranges


# --------------------------------------------------------------------------------------
# 1. Capstan over K pegs: gross slip follows the law over the summed wrap angle.

@pytest.mark.parametrize("scheme", ["monolithic", "staggered"])
@pytest.mark.parametrize("law", list(LAWS))
@pytest.mark.parametrize("k", [1, 3, 8])
def test_capstan_gross_slip(run_yarnfort, tmp_path, k, law, scheme):
    """Pull the last end down by 0.3 and back (the first end held, yarn initially at zero
    tension). Whenever every passage slips, the tensions of the first and last element
    obey T_hi = T_crit(T_lo, A), A the wrap angles summed over the pegs (the node laws
    compose exactly): T_lo = first element while loading, last one while unloading."""
    net = peg_net(arc_pegs(k), [-1, -1, 0], [1, -1, 0])
    text = namelist(net, [contact("yarn", "peg", LAWS[law])], scheme)
    run, curve, states = run_scene(run_yarnfort, tmp_path, "capstan", text)
    scale = max(np.max(s.tension) for s in states)
    errors, directions, lows = [], set(), []
    for i, state in enumerate(states):
        if curve["slipping"][i] != k or curve["direction"][i] == 0:
            continue
        angle = wrap_angles(state.position, range(k + 2)).sum()
        t_first, t_last = state.tension[[0, k]]
        t_lo, t_hi = (t_first, t_last) if curve["direction"][i] > 0 else (t_last, t_first)
        if t_hi < 1e-3 * scale:     # all slack: 0 = 0 says nothing
            continue
        errors.append(abs(t_hi - critical(LAWS[law], t_lo, angle)) / t_hi)
        directions.add(int(curve["direction"][i]))
        lows.append(t_lo)
    print(f"K={k} {law} {scheme}: {len(errors)} gross-slip steps (directions "
          f"{sorted(directions)}), max rel. error {max(errors):.1e}, Newton iterations "
          f"{int(curve['newton_iterations'].sum())}")
    assert 1 in directions and len(errors) >= 5
    assert max(errors) <= CLOSED_FORM_RTOL
    if law == "decaying_adhesion":      # gross slip from each regime of the law
        w, s, beta = (LAWS[law][key] for key in ("decay_start", "decay_end", "adhesion"))
        t_star = beta * s / (MU * (s - w) + beta)
        lows = np.array(lows)
        assert np.any(lows < w) and np.any((lows > w) & (lows < t_star)) \
            and np.any(lows > t_star), lows


# --------------------------------------------------------------------------------------
# 2. No friction: free sliding, no hysteresis.

@pytest.mark.parametrize("net_name", ["pegs", "free_nodes"])
@pytest.mark.parametrize("scheme", ["monolithic", "staggered"])
def test_frictionless_passages_carry_equal_tensions(run_yarnfort, tmp_path, scheme,
                                                    net_name):
    """mu = 0: T_crit(T_min, alpha) = T_min, so at every step the tensions on both sides
    of every passage agree (up to the stick test's relative slack friction_tolerance =
    1e-9), and loading then unloading retraces the same curve: at equal p_disp the
    reactions up and down agree to 1e-8. Over three fixed pegs, and through the two free
    contact nodes of free_node_net."""
    if net_name == "pegs":
        net, posts, low = peg_net(arc_pegs(3), [-1, -1, 0], [1, -1, 0]), "peg", 0.0
    else:
        # Unloaded, a frictionless yarn through free nodes is a mechanism that only the
        # slack regularisation holds (Newton does not converge there): start and end
        # the cycle at 5 % of the pull.
        net, posts, low = free_node_net(), "post", 0.05
    frictionless = dict(law="coulomb", friction_coefficient=0.0)
    text = namelist(net, [contact("yarn", posts, frictionless)], scheme,
                    path=dict(time=[0, 1, 2], p_disp=[low, 1, low]),
                    solver=dict(max_friction_iterations=1000))
    run, curve, states = run_scene(run_yarnfort, tmp_path, "free", text)
    main = element_ranges(net)[0]
    scale = max(np.max(s.tension) for s in states)
    worst = max(np.max(np.abs(np.diff(s.tension[main]))) for s in states) / scale
    p_disp, reaction = curve["p_disp"], curve.reaction("pull")
    up = np.flatnonzero(curve["direction"] > 0)
    down = np.flatnonzero(curve["direction"] < 0)
    pairs = [(i, j) for i in up for j in down if abs(p_disp[i] - p_disp[j]) < 1e-12]
    gap = max(np.max(np.abs(reaction[i] - reaction[j])) for i, j in pairs)
    peak = np.max(np.abs(reaction))
    print(f"mu = 0, {net_name}, {scheme}: max tension jump at a passage {worst:.1e} "
          f"(relative), {len(pairs)} up/down pairs, max reaction difference "
          f"{gap / peak:.1e} (relative), Newton iterations "
          f"{int(curve['newton_iterations'].sum())}")
    assert worst <= 1e-9
    assert len(pairs) >= 10
    assert gap <= 1e-8 * peak


# --------------------------------------------------------------------------------------
# 3. Bonded contacts are plain shared nodes.

def test_bonded_contacts_are_plain_shared_nodes(run_yarnfort, tmp_path):
    """law = 'bonded' for every pair: no passage at all, so the run is the elastic run of
    the same net without &contact, bit for bit."""
    net = free_node_net()
    runs = {name: run_scene(run_yarnfort, tmp_path, name, namelist(net, contacts))
            for name, contacts in (("plain", []),
                                   ("bonded", [contact("yarn", "post", dict(law="bonded"))]))}
    (_, c0, s0), (_, c1, s1) = runs["plain"], runs["bonded"]
    assert len(s0) == len(s1) > 10
    np.testing.assert_array_equal(c0["p_disp"], c1["p_disp"])
    for a, b in zip(s0, s1):
        np.testing.assert_array_equal(a.position, b.position)
        np.testing.assert_array_equal(a.tension, b.tension)


@pytest.mark.parametrize("scheme", ["monolithic", "staggered"])
def test_bonded_contacts_inside_a_sliding_net(run_yarnfort, tmp_path, scheme):
    """A bonded part solved by the friction stepper (a sliding capstan in the same scene,
    disjoint from it, makes the run use that stepper) against the same scene without any
    &contact. The bonded part is elastic, hence path independent, so its states at equal
    p_disp agree to the Newton tolerance (residual 1e-12 * force_scale) whatever steps
    the sliding part made the continuation take."""
    net = merge(free_node_net(), peg_net(arc_pegs(3), [-1, -1, 0], [1, -1, 0], yarn="cord"))
    bonded = namelist(net, [contact("yarn", "post", dict(law="bonded")),
                            contact("cord", "peg", LAWS["coulomb"])], scheme)
    _, c0, s0 = run_scene(run_yarnfort, tmp_path, "plain", namelist(net))
    _, c1, s1 = run_scene(run_yarnfort, tmp_path, "bonded", bonded)
    assert np.max(c1["slipping"]) > 0       # the friction stepper did slide
    part = element_ranges(net)[:3]
    elements = np.r_[tuple(np.arange(r.start, r.stop) for r in part)]
    nodes = np.arange(6)
    pairs = [(i, j) for i in range(len(s0)) for j in range(len(s1))
             if abs(c0["p_disp"][i] - c1["p_disp"][j]) < 1e-12
             and c0["direction"][i] == c1["direction"][j]]
    assert len(pairs) >= 20
    dx = max(np.max(np.abs(s0[i].position[nodes] - s1[j].position[nodes])) for i, j in pairs)
    dt = max(np.max(np.abs(s0[i].tension[elements] - s1[j].tension[elements]))
             for i, j in pairs)
    t_scale = max(np.max(s.tension[elements]) for s in s0)
    print(f"bonded inside a sliding net ({scheme}): {len(pairs)} states compared, max "
          f"position difference {dx:.1e} m, max tension difference {dt / t_scale:.1e} (rel.)")
    assert dx <= 1e-11 and dt <= 1e-11 * t_scale


# --------------------------------------------------------------------------------------
# 4. Sliding moves reference length between elements and never creates or loses any.

@pytest.mark.parametrize("scheme", ["monolithic", "staggered"])
def test_yarn_length_is_conserved(run_yarnfort, tmp_path, scheme):
    """Two load/unload cycles 0 -> 1 -> 0 -> 1 -> 0 on the free-node net (decaying
    adhesion, so that the slack ends of the cycles still hold): the sum of L0 over each
    yarn stays at its initial value to 1e-12, while single elements change by percents."""
    net = free_node_net()
    text = namelist(net, [contact("yarn", "post", LAWS["decaying_adhesion"])], scheme,
                    path=dict(time=[0, 1, 2, 3, 4], p_disp=[0, 1, 0, 1, 0]),
                    solver=dict(max_friction_iterations=1000))
    run, curve, states = run_scene(run_yarnfort, tmp_path, "cycle", text)
    initial = initial_length0(net)
    np.testing.assert_allclose(states[0].length0, initial, rtol=1e-15)
    drift = max(abs(s.length0[r].sum() - initial[r].sum()) / initial[r].sum()
                for s in states for r in element_ranges(net))
    moved = max(np.max(np.abs(s.length0 - initial) / initial) for s in states)
    print(f"{scheme}: {len(states)} states, {int(np.sum(curve['slipping'] > 0))} with "
          f"slipping passages; max relative drift of a yarn's length {drift:.1e}, largest "
          f"relative change of one element's L0 {moved:.1e}")
    assert np.sum(curve["slipping"] > 0) >= 10 and moved > 1e-2
    assert drift <= 1e-12


# --------------------------------------------------------------------------------------
# 5. Partial slip: the slip front of the bollard.

def test_partial_slip_front_over_many_pegs(run_yarnfort, tmp_path):
    """A yarn over K = 12 pegs on a half circle, ends hanging straight down. Phase 1: a
    force F on the far end (free to move vertically), the near end held: the yarn slides
    towards F until T_e = F exp(-mu C_(e-1)) (C_j = wrap angle summed over the first j
    pegs). Phase 2: pull the near end down. A passage p is then held by its far-side
    tension, which does not change while the passages before it stick, and slips once the
    pulled tension tau exceeds F exp(mu (A - 2 C_(p-1))) (the slip zone between it and
    the pulled end composes exactly). So early in phase 2 the passages near the pulled
    end slip, the far ones stick, and their elements keep their tensions exactly: the
    classic bollard result, with the number of slipping passages predicted from tau."""
    k, force = 12, 0.5
    # The far end starts under 2 % of F: unloaded, the slack regularisation (a weak
    # zero-rest-length spring) would pull that free end onto the first peg.
    start = 0.02
    theta = np.linspace(np.pi, 0.0, k)
    pegs = np.column_stack([np.cos(theta), np.sin(theta), np.zeros(k)])
    net = peg_net(pegs, [-1, -1, 0], [1, -1, 0], pull=(0.0, -0.3, 0.0), first_fix="xz",
                  first_force=(0.0, -force, 0.0), anchor_offset=(0.0, 0.0, 0.2))
    text = namelist(net, [contact("yarn", "peg", LAWS["coulomb"])],
                    path=dict(time=[0, 1, 2], p_force=[start, 1, 1], p_disp=[0, 0, 1]),
                    step=0.02)
    run, curve, states = run_scene(run_yarnfort, tmp_path, "bollard", text)
    path = [0, *range(1, k + 1), k + 1]
    alphas = wrap_angles(states[0].position, path)
    cumulative = np.r_[0.0, np.cumsum(alphas)]              # C_0 .. C_K
    total = cumulative[-1]
    assert total == pytest.approx(np.pi, rel=1e-12)
    end_of_phase1 = int(np.flatnonzero(curve["time"] <= 1.0 + 1e-12)[-1])
    t0 = states[end_of_phase1].tension[:k + 1]
    np.testing.assert_allclose(t0, force * np.exp(-MU * cumulative[:k + 1]), rtol=1e-9)
    thresholds = force * np.exp(MU * (total - 2 * cumulative[:k]))   # passage p = 1..K
    partial, checked, gross = 0, 0, 0
    for i in range(end_of_phase1 + 1, len(states)):
        tension = states[i].tension[:k + 1]
        tau = tension[k]
        if curve["slipping"][i] == k:
            # Gross slip: the far end gives way, tau stays at F exp(mu A).
            assert tau == pytest.approx(force * np.exp(MU * total), rel=CLOSED_FORM_RTOL)
            gross += 1
            continue
        if np.min(np.abs(tau / thresholds - 1)) < 1e-6:
            continue                                    # too close to call
        n_slip = int(np.sum(tau > thresholds))
        assert curve["slipping"][i] == n_slip, (i, tau, curve["slipping"][i], n_slip)
        checked += 1
        if 0 < n_slip < k:
            partial += 1
            first = k - n_slip      # elements 0..first-1 lie behind sticking passages
            np.testing.assert_allclose(tension[:first], t0[:first], rtol=1e-12, atol=0)
            # The slip zone composes: tau = T_(first) exp(mu (A - C_(first))).
            slip_zone = cumulative[k] - cumulative[first]
            assert tau == pytest.approx(tension[first] * np.exp(MU * slip_zone),
                                        rel=CLOSED_FORM_RTOL)
    fronts = curve["slipping"][end_of_phase1 + 1:]
    print(f"bollard K={k}: {checked} pull steps checked, {partial} with a stick zone, "
          f"{gross} in gross slip; "
          f"slipping passages along the pull: {fronts.astype(int).tolist()}")
    assert partial >= 5 and gross >= 1
    assert np.all(np.diff(fronts) >= 0)                 # the front only advances


# --------------------------------------------------------------------------------------
# 6. Both schemes solve the same discrete problem.

def test_schemes_agree_with_free_contact_nodes(run_yarnfort, tmp_path):
    """The free-node net (contact nodes held by elastic posts, so positions and sliding
    are coupled) through a load/unload cycle 0 -> 1 -> 0.3 with Coulomb friction and the
    same fixed steps; slip forward while loading, backward while unloading. Each step of
    either scheme solves the same equations for the same active set, so they may differ
    only by how far each stops from the exact solution of a step:
    - monolithic: Newton to residual_tolerance (1e-12 * force_scale);
    - staggered: the alternation stops when the equilibrium residual after a sliding
      step is below the same tolerance, but it is a fixed-point iteration contracting
      at a rate r ~ 1 - O(T/EA) (the elastic step moves a free contact node along the
      yarn and so undoes most of the sliding step), so its error is ~1/(1 - r) ~ 1e2
      times that residual;
    - the stick test's relative slack (friction_tolerance = 1e-9) lets a passage stick
      with T_max up to 1e-9 above T_crit in either scheme.
    Hence ~1e-10 relative; the tolerance 1e-8 leaves a factor 100 and is 1e6 below the
    effect of one step of slip (1e-2 on the reactions). The cycle stops at 0.3: towards
    zero load the tensions fall to the slack regularisation's level, the staggered rate
    tends to 1 and it no longer converges (a property of the scheme, measured)."""
    net = free_node_net()
    results = {}
    for scheme in ("monolithic", "staggered"):
        text = namelist(net, [contact("yarn", "post", LAWS["coulomb"])], scheme,
                        path=dict(time=[0, 1, 2], p_disp=[0, 1, 0.3]),
                        solver=dict(max_friction_iterations=1000))
        results[scheme] = run_scene(run_yarnfort, tmp_path, scheme, text)[1:]
    (cm, sm), (cs, ss) = results["monolithic"], results["staggered"]
    np.testing.assert_array_equal(cm["p_disp"], cs["p_disp"])
    np.testing.assert_array_equal(cm["slipping"], cs["slipping"])
    assert np.max(cm["slipping"]) == 2 and np.any((cm["direction"] < 0) & (cm["slipping"] > 0))
    reaction_m, reaction_s = cm.reaction("pull"), cs.reaction("pull")
    scale = np.max(np.abs(reaction_m))
    curve_error = np.max(np.abs(reaction_m - reaction_s)) / scale
    position_error = np.max(np.abs(sm[-1].position - ss[-1].position))
    length_error = np.max(np.abs(sm[-1].length0 - ss[-1].length0) / sm[-1].length0)
    tension_error = np.max(np.abs(sm[-1].tension - ss[-1].tension)) / np.max(sm[-1].tension)
    print(f"schemes: reactions differ by {curve_error:.1e} (relative), final positions by "
          f"{position_error:.1e} m, L0 by {length_error:.1e}, tensions by {tension_error:.1e}; "
          f"Newton iterations monolithic {int(cm['newton_iterations'].sum())}, staggered "
          f"{int(cs['newton_iterations'].sum())}")
    for error in (curve_error, position_error, length_error, tension_error):
        assert error <= 1e-8


# --------------------------------------------------------------------------------------
# 7. Hard cases.

def assert_finite(states):
    for s in states:
        for field in (s.position, s.tension, s.stretch, s.length0):
            assert np.all(np.isfinite(field))


@pytest.mark.parametrize("scheme", ["monolithic", "staggered"])
def test_slack_side_lets_the_yarn_slide(run_yarnfort, tmp_path, scheme):
    """Coulomb friction with T_min = 0: a yarn over two pegs (90 degrees each) whose far
    end is pushed up towards its peg by 0.8 while the near end is pulled down by 0.8. The
    far side is slack, so T_crit = T_min exp(mu alpha) = 0: nothing holds the yarn, it
    slides round the pegs, and both sides keep the slack regularisation's tension only
    (a zero-rest-length spring, slack_stiffness * EA * stretch = 1e-5 N * stretch)."""
    travel = 0.8
    net = peg_net([[-0.5, 1, 0], [0.5, 1, 0]], [-0.5, 0, 0], [0.5, 0, 0],
                  pull=(0.0, -travel, 0.0))
    net["supports"][0]["displacement"] = [0.0, travel, 0.0]
    text = namelist(net, [contact("yarn", "peg", LAWS["coulomb"])], scheme,
                    path=dict(time=[0, 1], p_disp=[0, 1]), step=0.05)
    run, curve, states = run_scene(run_yarnfort, tmp_path, "slack", text)
    assert_finite(states)
    far = np.array([s.tension[0] for s in states])
    near = np.array([s.tension[2] for s in states])
    spring = 1e-6 * YARN_EA * np.array([s.stretch[0] for s in states])
    slid = states[0].length0[0] - states[-1].length0[0]
    print(f"T_min = 0 ({scheme}): far tension <= {np.max(far):.2e} N, near <= "
          f"{np.max(near):.2e} N, slack spring <= {np.max(spring):.2e} N; material slid "
          f"round the pegs {slid:.6f} m; Newton iterations "
          f"{int(curve['newton_iterations'].sum())}")
    assert np.all(curve["slipping"][1:] == 2)
    assert np.all(far <= 1.001 * spring + 1e-15)
    assert np.all(near <= np.exp(MU * np.pi) * 1.001 * spring + 1e-15)
    assert slid == pytest.approx(travel, rel=1e-3)
    np.testing.assert_allclose(states[-1].length0.sum(), states[0].length0.sum(), rtol=1e-14)


@pytest.mark.parametrize("scheme", ["monolithic", "staggered"])
def test_material_running_out_of_an_element(run_yarnfort, tmp_path, scheme):
    """The same two pegs; the far end is moved up to 5e-4 m below its peg while the near
    end hangs under a small force (1 % of F = 1 N), then F is applied in full. The far
    element's reference length runs down towards zero: sliding must stop at
    min_length_ratio * its initial length (the passage locks, and stays locked in the
    following steps), the yarn then carries F, and no step may produce NaN. Were the run
    to stop, it must say why in one line and keep its converged steps (checked first);
    with the lock it must complete."""
    ratio, travel = 1e-3, 0.9995
    net = peg_net([[-0.5, 1, 0], [0.5, 1, 0]], [-0.5, 0, 0], [0.5, 0, 0],
                  pull=(0.0, 0.0, 0.0))
    net["supports"][0]["displacement"] = [0.0, travel, 0.0]
    net["supports"][1]["fix"] = "xz"                 # near end: force controlled
    net["loads"] = [dict(nodes=[4], force=[0.0, -1.0, 0.0])]
    text = namelist(net, [contact("yarn", "peg", LAWS["coulomb"])], scheme,
                    path=dict(time=[0, 1, 2], p_disp=[0, 1, 1], p_force=[0.01, 0.01, 1]),
                    step=0.02, solver=dict(min_length_ratio=ratio))
    run, curve, states = run_scene(run_yarnfort, tmp_path, "run_out", text, ok=False)
    assert len(states) >= 2
    assert_finite(states)
    if run.returncode != 0:       # a clear message, and the converged steps kept
        assert "error" in run.stderr and len(run.stderr.strip().splitlines()) <= 3
    initial = initial_length0(net)      # states[0] has slid already (F > 0 at time 0)
    shortest = np.array([np.min(s.length0 / initial) for s in states])
    far_l0 = np.array([s.length0[0] for s in states]) / initial[0]
    locked = np.flatnonzero(far_l0 <= ratio * (1 + 1e-9))
    print(f"material running out ({scheme}): return code {run.returncode}, "
          f"{len(states)} states, far L0 / initial reaches {far_l0.min():.6e} "
          f"(first at time {curve['time'][locked[0]] if len(locked) else None}), "
          f"shortest L0 / initial {shortest.min():.6e}, near tension at the end "
          f"{states[-1].tension[2]:.4f} N, Newton iterations "
          f"{int(curve['newton_iterations'].sum())}")
    assert run.returncode == 0, run.stderr
    assert shortest.min() >= ratio * (1 - 1e-12)
    assert len(locked) > 0 and curve["time"][locked[0]] <= 1.0 + 1e-12
    assert np.all(far_l0[locked[0]:] == pytest.approx(ratio, rel=1e-9))
    assert states[-1].tension[2] == pytest.approx(1.0, rel=1e-9)   # the yarn carries F
    # contacts.csv reports the lock: passage 1 (at the far peg, node 2) is 'locked' from
    # the step its element ran out on, and never before.
    contacts = read_contacts(tmp_path / "run_out" / "out")
    first = contacts["passage"] == 1
    assert np.array_equal(contacts["step"][first], curve["step"])
    modes = contacts["mode"][first]
    assert np.all(modes[locked[0]:] == "locked")
    assert not np.any(modes[:locked[0]] == "locked")
    assert not np.any(contacts["mode"][~first] == "locked")


@pytest.mark.parametrize("scheme", ["monolithic", "staggered"])
def test_slip_towards_a_lock_not_reached(run_yarnfort, tmp_path, scheme):
    """The scene of test_material_running_out_of_an_element on its way to the lock (far
    end moved up by half its travel, the near end under 1 % of F). The yarn slides
    towards the near end over both pegs all the way: both passages slip forward and the
    tensions are those of the capstan relation, wrap pi/2 at each peg (the ends hang
    straight below their pegs): T_near = F, T_middle = F exp(-mu pi/2), T_far = F
    exp(-mu pi), at every step. The first step's rounds meet states in which the far
    element runs out (a lock far past anything the step reaches); a slip judged from
    such a lock took the far passage backward while its flow went forward, with
    T_far = T_middle exp(+mu pi/2)."""
    ratio, travel, force = 1e-3, 0.9995, 0.01
    net = peg_net([[-0.5, 1, 0], [0.5, 1, 0]], [-0.5, 0, 0], [0.5, 0, 0],
                  pull=(0.0, 0.0, 0.0))
    net["supports"][0]["displacement"] = [0.0, travel, 0.0]
    net["supports"][1]["fix"] = "xz"
    net["loads"] = [dict(nodes=[4], force=[0.0, -1.0, 0.0])]
    text = namelist(net, [contact("yarn", "peg", LAWS["coulomb"])], scheme,
                    path=dict(time=[0, 1], p_disp=[0, 0.5], p_force=[force, force]),
                    step=0.02, solver=dict(min_length_ratio=ratio))
    run, curve, states = run_scene(run_yarnfort, tmp_path, "towards_lock", text)
    expected = force * np.exp(-MU * np.pi / 2 * np.arange(3)[::-1])  # far, middle, near
    worst = max(np.max(np.abs(s.tension[:3] - expected) / force) for s in states)
    contacts = read_contacts(tmp_path / "towards_lock" / "out")
    later = contacts["step"] > 0
    flows = {p: contacts["flow"][contacts["passage"] == p] for p in (1, 2)}
    print(f"slip towards a lock ({scheme}): {len(states)} states, tensions off the "
          f"capstan relation by {worst:.1e} of F, modes {set(contacts['mode'][later])}, "
          f"Newton iterations {int(curve['newton_iterations'].sum())}")
    assert worst <= CLOSED_FORM_RTOL
    assert np.all(contacts["mode"][later] == "forward")
    for flow in flows.values():
        assert np.all(np.diff(flow) > 0.0)


@pytest.mark.parametrize("offset", [0.0, 1e-10, 1e-7])
@pytest.mark.parametrize("scheme", ["monolithic", "staggered"])
def test_nearly_straight_passage(run_yarnfort, tmp_path, scheme, offset):
    """A yarn through a contact node that is (nearly) on the line of its ends, with two
    elements per segment, so the wrap angle at the node depends on free midpoints (its
    gradient does not exist at alpha = 0). Pulled along its axis it must converge, and
    the tensions on both sides must agree: T_after = T_before exp(mu alpha), alpha
    measured from the output, nearly 1."""
    net = peg_net([[0.0, offset, 0.0]], [-1, 0, 0], [1, 0, 0], pull=(0.1, 0.0, 0.0),
                  elements_per_segment=2)
    text = namelist(net, [contact("yarn", "peg", LAWS["coulomb"])], scheme,
                    path=dict(time=[0, 1], p_disp=[0, 1]), step=0.1)
    run, curve, states = run_scene(run_yarnfort, tmp_path, "straight", text)
    assert_finite(states)
    errors, angles = [], []
    for s in states[1:]:
        angle = wrap_angles(s.position, [4, 1, 5])[0]    # midpoint, peg, midpoint
        t_lo, t_hi = s.tension[1], s.tension[2]
        errors.append(abs(t_hi - t_lo * np.exp(MU * angle)) / t_hi)
        angles.append(angle)
    print(f"straight passage offset {offset:g} ({scheme}): alpha <= {max(angles):.1e}, "
          f"T ratio - 1 <= {max(s.tension[2] / s.tension[1] - 1 for s in states[1:]):.1e},"
          f" max rel. error {max(errors):.1e}, Newton iterations "
          f"{int(curve['newton_iterations'].sum())}")
    assert np.all(curve["slipping"][1:] == 1)
    assert max(angles) < 1e-5
    assert max(errors) <= CLOSED_FORM_RTOL


@pytest.mark.parametrize("offset", [0.0, 1e-3])
@pytest.mark.parametrize("scheme", ["monolithic", "staggered"])
def test_yarn_folded_back_around_a_peg(run_yarnfort, tmp_path, scheme, offset):
    """A yarn folded back around a peg (alpha = pi - 2 atan(offset), exactly pi for
    offset 0, where the wrap angle has a cone-shaped maximum), two elements per segment
    so that free midpoints set the angle. Pulling one leg: gross slip with
    T_hi = T_lo exp(mu alpha)."""
    net = peg_net([[0.0, 0.0, 0.0]], [-offset, -1, 0], [offset, -1.2, 0],
                  pull=(0.0, -0.2, 0.0), elements_per_segment=2,
                  anchor_offset=(0.0, 0.2, 0.0))
    text = namelist(net, [contact("yarn", "peg", LAWS["coulomb"])], scheme,
                    path=dict(time=[0, 1], p_disp=[0, 1]), step=0.1)
    run, curve, states = run_scene(run_yarnfort, tmp_path, "folded", text)
    assert_finite(states)
    errors = []
    for i, s in enumerate(states):
        if curve["slipping"][i] != 1:
            continue
        angle = wrap_angles(s.position, [4, 1, 5])[0]
        errors.append(abs(s.tension[2] - s.tension[1] * np.exp(MU * angle)) / s.tension[2])
    print(f"folded offset {offset:g} ({scheme}): {len(errors)} slipping steps, alpha = pi - "
          f"{np.pi - wrap_angles(states[-1].position, [4, 1, 5])[0]:.1e}, max rel. error "
          f"{max(errors):.1e}, Newton iterations {int(curve['newton_iterations'].sum())}")
    assert len(errors) >= 5
    assert max(errors) <= CLOSED_FORM_RTOL


# --------------------------------------------------------------------------------------
# The general law T' = g(T) from a rate table (paper eqs. 37-39).

#: A rate table (T in N, g in N/rad) with a falling piece, a steep rise and a last piece
#: that the law continues beyond the table: g > 0 everywhere, kinks at every row.
RATE_TABLE = np.array([[0.0, 0.03], [0.05, 0.045], [0.1, 0.04], [0.2, 0.07], [0.4, 0.15],
                       [0.8, 0.3]])


def table_critical(t0: float, angle: float) -> float:
    """T_crit(T0, alpha) of the table law by integrating T' = g(T) with scipy's DOP853,
    g linear between the rows of RATE_TABLE and with the last slope beyond the last row.
    The integration restarts at each row (a kink of g, which an embedded error estimate
    does not see) by a terminal event, and each stretch integrates the smooth extension
    of its own piece, so that no stage samples g across a kink."""
    from scipy.integrate import solve_ivp
    tension, rate = RATE_TABLE.T
    slope = np.diff(rate) / np.diff(tension)
    start, t = 0.0, t0
    while start < angle:
        i = min(np.searchsorted(tension, t, side="right") - 1, len(slope) - 1)
        end = tension[i + 1] if i + 1 < len(tension) - 1 else np.inf

        def event(_, y):
            return y[0] - end
        event.terminal, event.direction = True, 1
        sol = solve_ivp(lambda _, y: [rate[i] + slope[i] * (y[0] - tension[i])],
                        (start, angle), [t], method="DOP853", rtol=1e-13, atol=1e-16,
                        events=event)
        assert sol.status >= 0, sol.message
        if sol.status == 1:     # on the row (the event's root, up to its tolerance)
            start, t = sol.t_events[0][0], end
        else:
            start, t = angle, sol.y[0, -1]
    return t


def test_table_reference_integration():
    """The reference integrator on a piece where g is linear has the exact solution
    T = T_a + g_a (exp(m alpha) - 1) / m, and passes kinks: over the first two pieces
    the angle is the sum of the two exact piece angles log(g_b / g_a) / m."""
    (t_a, g_a), (t_b, g_b), (t_c, g_c) = RATE_TABLE[:3]
    m = (g_b - g_a) / (t_b - t_a)
    angle = 0.3
    assert table_critical(t_a, angle) == pytest.approx(
        t_a + g_a * np.expm1(m * angle) / m, rel=1e-12)
    m2 = (g_c - g_b) / (t_c - t_b)
    to_c = np.log(g_b / g_a) / m + np.log(g_c / g_b) / m2
    assert table_critical(0.0, to_c) == pytest.approx(t_c, rel=1e-12)


@pytest.mark.parametrize("scheme", ["monolithic", "staggered"])
@pytest.mark.parametrize("k", [1, 3])
def test_capstan_gross_slip_general_law(run_yarnfort, tmp_path, k, scheme):
    """As test_capstan_gross_slip, with law = 'general' and its rate table from a CSV
    file: whenever every passage slips, T_hi = T_crit(T_lo, A) with A the summed wrap
    angle, T_crit from the test's own integration of T' = g(T)."""
    table = tmp_path / "rate.csv"
    table.write_text("# T (N), g (N/rad)\nT,g\n"
                     + "".join(f"{t!r},{g!r}\n" for t, g in RATE_TABLE.tolist()))
    net = peg_net(arc_pegs(k), [-1, -1, 0], [1, -1, 0])
    law = dict(law="general", rate_table=str(table))
    text = namelist(net, [contact("yarn", "peg", law)], scheme)
    run, curve, states = run_scene(run_yarnfort, tmp_path, "capstan", text)
    scale = max(np.max(s.tension) for s in states)
    errors, directions, lows, highs = [], set(), [], []
    for i, state in enumerate(states):
        if curve["slipping"][i] != k or curve["direction"][i] == 0:
            continue
        angle = wrap_angles(state.position, range(k + 2)).sum()
        t_first, t_last = state.tension[[0, k]]
        t_lo, t_hi = (t_first, t_last) if curve["direction"][i] > 0 else (t_last, t_first)
        if t_hi < 1e-3 * scale:
            continue
        errors.append(abs(t_hi - table_critical(t_lo, angle)) / t_hi)
        directions.add(int(curve["direction"][i]))
        lows.append(t_lo)
        highs.append(t_hi)
    print(f"K={k} general {scheme}: {len(errors)} gross-slip steps (directions "
          f"{sorted(directions)}), T_lo {min(lows):.3g}..{max(lows):.3g}, T_hi up to "
          f"{max(highs):.3g}, max rel. error {max(errors):.1e}")
    assert 1 in directions and len(errors) >= 5
    assert max(errors) <= CLOSED_FORM_RTOL
    # The tensions pass several rows of the table (several kinks of g are used).
    assert np.sum((RATE_TABLE[:, 0] > min(lows)) & (RATE_TABLE[:, 0] < max(highs))) >= 2
