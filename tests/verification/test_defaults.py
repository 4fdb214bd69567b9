# SPDX-License-Identifier: MIT
"""Exact answers with the default settings (issue 10, "Must have" 6).

Every scene here is run with NO ``&solver`` group at all, as a new user would, and is
compared with a closed form or with an independent solution computed in this file (never
with a run of the code under test): 1e-8 relative on forces, 1e-8 of the scene size on
positions. The reference critical tensions come from test_friction.py and the one-pin
play operator from test_hysteresis.py, both checked there against integrations of the
laws' ODEs and against the unreduced slip relations.

1. capstan over 1, 4, 16, 64 pins, three laws: exact progressive slip (CapstanReference)
   at every step, and knots bracketing every exact slip onset (K = 1, 4);
2. one pin loaded and unloaded twice: test_hysteresis's play operator;
3. frictionless ring: the ellipse closed form for an extensible yarn (soft, and EA = 1e6
   times the load);
4. friction ring: the admissible interval of splits and the play operator over it;
5. pretensioned 8 x 8 cable net, stuck and frictionless: an independent scipy solve;
6. the same scenes in four unit systems, and pins of stiffness 1 .. 1e12 N;
7. zero load on stress-free networks: nothing moves;
8. order of the &yarn groups at a node where two obstacle types meet, and a yarn that
   passes twice through a node.

Each reference was also checked against runs of the exact model (slack_stiffness = 0 or
1e-13, residual_tolerance 1e-13 .. 1e-14, outside this file): it agreed to 1e-12 or
better wherever those runs converge.
"""
from __future__ import annotations

import itertools
import re

import numpy as np
import pytest
from scipy import optimize

from scenes import group, scene
from test_friction import (LAWS, arc_pegs, critical, element_ranges, peg_net, run_scene,
                           wrap_angles)
from test_hysteresis import CASES, Case, compare, hysteresis_scene
from yarnfort import read_curve, read_states

#: Required agreement of forces (relative to the forces of the step) with the references.
FORCE_RTOL = 1e-8
#: Required agreement of positions and lengths, as a fraction of the scene size.
POSITION_RTOL = 1e-8
#: Relative slack of the references' own stick tests (a tension within this fraction of
#: T_crit sticks); the flags of the solver are compared only where a passage is farther
#: than CLOSE_CALL from its threshold.
STICK_SLACK = 1e-12
CLOSE_CALL = 1e-6
#: Output: every step written, no progress lines. There is deliberately no &solver.
OUTPUT = dict(folder="out", progress=False)


def defaults_namelist(nodes, yarns, supports, loads, materials, path, contacts=()) -> str:
    """Namelist text without any &solver group (the defaults)."""
    text = scene(nodes=nodes, yarns=yarns, supports=supports, loads=loads,
                 materials=materials, path=path, solver=None, output=OUTPUT)
    text += "".join(group("contact", **c) for c in contacts)
    assert "&solver" not in text
    return text


def relative_error(value, exact, scale) -> float:
    return float(np.max(np.abs(np.asarray(value) - np.asarray(exact))) / scale)


# ======================================================================================
# 1. Capstan over K fixed pins under displacement control.

#: Yarn stiffness EA (N); the pins are ends of 'peg' yarns whose both ends are held.
YARN_EA = 10.0
PULL = (0.0, -0.3, 0.0)
CAPSTAN_PATH = dict(time=[0.0, 1.0, 2.0], p_force=[0.0, 0.0, 0.0], p_disp=[0.0, 1.0, 0.0])


class CapstanReference:
    """Exact quasi-static tensions of a yarn over K fixed pins, its first end held, its
    last end moved by d * PULL, stress free at d = 0.

    Every node of the yarn is prescribed, so the element lengths l_j(d) and the wrap
    angles alpha_p(d) (pin p between elements p-1 and p) are known; the unknowns are the
    reference lengths L0_j, with T_j = EA max(0, l_j/L0_j - 1). Only element K (the
    pulled one) changes length, so a pin can only start to slide once its neighbour
    towards the pulled end slides: on a monotone half of the path the slipping passages
    form a zone next to the pulled end, passages K-n+1 .. K, that only grows. In the
    zone the slip conditions chain the tensions from a seed tension t:
      loading   (material flows towards the pulled end): T_j = T_crit(T_(j-1), alpha_j),
                seed t = T_(K-n), the zone's element farthest from the pulled end;
      unloading (material flows back):                  T_(j-1) = T_crit(T_j, alpha_j),
                seed t = T_K,
    and passage K-n sticks, so the zone's total reference length is that of the previous
    state: sum_zone l_j / (1 + T_j(t)/EA) = S, monotone in t and solved by brentq to
    round-off (t = 0 with a slack seed element when even t = 0 leaves length over). The
    zone grows while passage K-n violates its stick condition. Elements outside the zone
    keep their reference length, hence their tension. The state at the end of a step
    depends only on d and the zone, so it is the exact path's state whatever the step
    sizes, onsets inside a step included. Each step checks its own assumptions: every
    passage satisfies the stick test both ways, and the flow through every zone passage
    has the direction of the half path."""

    def __init__(self, net: dict, k: int, law: dict, stiffness: float = YARN_EA,
                 pull=PULL):
        self.k, self.law, self.ea = k, law, stiffness
        self.nodes0 = np.asarray(net["nodes"], float)[:k + 2]
        self.pull = np.asarray(pull, float)
        self.length0 = self.geometry(0.0)[0]
        self.zone, self.direction = 0, 0

    def geometry(self, d: float) -> tuple[np.ndarray, np.ndarray]:
        x = self.nodes0.copy()
        x[-1] += d * self.pull
        return np.linalg.norm(np.diff(x, axis=0), axis=1), wrap_angles(x, range(self.k + 2))

    def tensions(self, length0, lengths):
        return self.ea * np.maximum(0.0, lengths / length0 - 1.0)

    def _chain(self, t_seed: float, n: int, alphas: np.ndarray, direction: int):
        k, ts = self.k, np.empty(n + 1)
        if direction > 0:
            ts[0] = t_seed
            for i in range(1, n + 1):
                ts[i] = critical(self.law, ts[i - 1], alphas[k - n + i - 1])
        else:
            ts[n] = t_seed
            for i in range(n, 0, -1):
                ts[i - 1] = critical(self.law, ts[i], alphas[k - n + i - 1])
        return ts

    def _zone_state(self, n, lengths, alphas, old, direction):
        k = self.k
        length0 = old.copy()
        if n > 0:
            zone = slice(k - n, k + 1)
            total = old[zone].sum()
            excess = lambda t: float(np.sum(lengths[zone] / (       # noqa: E731
                1.0 + self._chain(t, n, alphas, direction) / self.ea)) - total)
            if excess(0.0) <= 4 * np.finfo(float).eps * total:      # slack to round-off
                ts = self._chain(0.0, n, alphas, direction)
                zone_l0 = lengths[zone] / (1.0 + ts / self.ea)
                seed = 0 if direction > 0 else n
                zone_l0[seed] = total - (zone_l0.sum() - zone_l0[seed])
            else:
                top = 1e-3 * self.ea
                while excess(top) > 0.0:
                    top *= 2.0
                t = optimize.brentq(excess, 0.0, top, xtol=1e-300, rtol=4 * np.finfo(float).eps,
                                    maxiter=500)
                ts = self._chain(t, n, alphas, direction)
                zone_l0 = lengths[zone] / (1.0 + ts / self.ea)
            length0[zone] = zone_l0
            tension = self.tensions(length0, lengths)
            tension[zone] = ts          # the chain's tensions, free of l/L0 - 1 round-off
            return length0, tension
        return length0, self.tensions(length0, lengths)

    def violation(self, p: int, tension, alphas, direction: int) -> float:
        """T_hi / T_crit(T_lo) - 1 at passage p for slip in `direction` (> 0: slips)."""
        hi, lo = (tension[p], tension[p - 1]) if direction > 0 else (tension[p - 1], tension[p])
        crit = float(critical(self.law, lo, alphas[p - 1]))
        floor = 1e-14 * self.ea          # round-off of EA (l/L0 - 1)
        return (hi - crit) / max(crit, floor)

    def advance(self, d: float, direction: int):
        """(L0, tensions, zone size, wrap angles, margin) at d, reached over a monotone
        step in `direction`; margin is the smallest |violation| of the stick tests that
        decided the zone (a passage that joined it in this step, the first one left out)."""
        if direction != self.direction:
            self.zone, self.direction = 0, direction
        lengths, alphas = self.geometry(d)
        old, k = self.length0, self.k
        n, margin = self.zone, np.inf
        while True:
            length0, tension = self._zone_state(n, lengths, alphas, old, direction)
            if n == k:
                break
            violation = self.violation(k - n, tension, alphas, direction)
            margin = min(margin, abs(violation))
            if violation <= STICK_SLACK:
                break
            n += 1
        for p in range(1, k + 1):                        # every passage admissible
            for way in (1, -1):
                assert self.violation(p, tension, alphas, way) <= 10 * STICK_SLACK, (d, p)
        for p in range(k - n + 1, k + 1):                # zone flows go the half's way
            flow = length0[p:].sum() - old[p:].sum()
            assert direction * flow >= -1e-13 * old.sum(), (d, p, flow)
        self.length0, self.zone = length0, n
        return length0, tension, n, alphas, margin


def capstan_net(k: int, peg_stiffness: float = YARN_EA, units=(1.0, 1.0)):
    """The pins of test_friction's peg_net (K pins on the unit circle from 150 to 30
    degrees, yarn from (-1,-1) to (1,-1)), scaled by units = (length, force) factors."""
    a, f = units
    net = peg_net(arc_pegs(k), [-1, -1, 0], [1, -1, 0], pull=PULL)
    net["nodes"] = (a * np.asarray(net["nodes"], float)).tolist()
    for s in net["supports"]:
        if "displacement" in s:
            s["displacement"] = [a * v for v in s["displacement"]]
    materials = [dict(name="yarn", law="linear", stiffness=f * YARN_EA),
                 dict(name="peg", law="linear", stiffness=f * peg_stiffness)]
    return net, materials


def scaled_law(law: dict, force: float) -> dict:
    """A friction law with its force parameters (beta, w_d, s_d) in other units."""
    return {key: (force * value if key in ("adhesion", "decay_start", "decay_end") else value)
            for key, value in law.items()}


def run_capstan(run_yarnfort, tmp_path, name, k, law_name, peg_stiffness=YARN_EA,
                units=(1.0, 1.0), path=None):
    net, materials = capstan_net(k, peg_stiffness, units)
    text = defaults_namelist(net["nodes"], net["yarns"], net["supports"], net["loads"],
                             materials, path or CAPSTAN_PATH,
                             [dict(materials=["yarn", "peg"],
                                   **scaled_law(LAWS[law_name], units[1]))])
    run, curve, states = run_scene(run_yarnfort, tmp_path, name, text, ok=False)
    assert run.returncode == 0, run.stderr
    assert len(states) == len(curve["step"])
    return net, curve, states


def check_capstan(net, k, law_name, curve, states, peak_time: float = 1.0):
    """Compare a capstan run with CapstanReference at every converged step (loading up
    to peak_time); asserts and returns the worst errors and the steps whose stick/slip
    flags were judged."""
    law = LAWS[law_name]
    reference = CapstanReference(net, k, law)
    yarn = element_ranges(net)[0]
    directions = np.where(curve["time"] <= peak_time, 1, -1)
    exact = [reference.advance(float(d), int(w)) for d, w in zip(curve["p_disp"], directions)]
    peak = max(e[1].max() for e in exact)
    errors = dict(tension=0.0, length0=0.0, reaction=0.0, gross_slip=0.0)
    flags, gross, onsets = [], 0, 0
    previous = (0, 1)
    for i, (state, (length0, tension, zone, alphas, margin)) in enumerate(zip(states, exact)):
        direction = directions[i]
        # Relative to the step's largest tension; to the run's where all are slack.
        scale = tension.max() if tension.max() > 0.0 else peak
        errors["tension"] = max(errors["tension"],
                                relative_error(state.tension[yarn], tension, scale))
        errors["length0"] = max(errors["length0"], relative_error(
            state.length0[yarn], length0, reference.length0.sum()))
        # Reaction of the pulling support: T_K along the last element, away from the pin.
        x = state.position
        u = (x[k + 1] - x[k]) / np.linalg.norm(x[k + 1] - x[k])
        errors["reaction"] = max(errors["reaction"], relative_error(
            curve.reaction("pull")[i], tension[k] * u, scale))
        # Gross slip: the solver's own end tensions obey the law over the summed angle.
        if zone == k and tension.max() > 0.0:
            t_lo, t_hi = state.tension[[0, k]] if direction > 0 else state.tension[[k, 0]]
            angle = wrap_angles(x, range(k + 2)).sum()
            errors["gross_slip"] = max(errors["gross_slip"],
                                       abs(t_hi - critical(law, t_lo, angle)) / t_hi)
            gross += 1
        # Stick/slip flags where no passage is within CLOSE_CALL of its threshold.
        if i > 0 and margin > CLOSE_CALL:
            flags.append((i, int(curve["slipping"][i]), zone))
        onsets += direction == previous[1] and zone > previous[0]
        previous = (zone, direction)
    mismatched = [f for f in flags if f[1] != f[2]]
    print(f"capstan K={k} {law_name}: {len(states)} steps, {gross} in gross slip, "
          f"{len(flags)} flags compared ({len(mismatched)} wrong: {mismatched[:4]}), "
          f"errors {', '.join(f'{n} {v:.1e}' for n, v in errors.items())}, "
          f"Newton iterations {int(curve['newton_iterations'].sum())}")
    assert gross >= 2 and onsets >= 1
    assert mismatched == []
    for name, value in errors.items():
        assert value <= (POSITION_RTOL if name == "length0" else FORCE_RTOL), (name, value)
    return errors, [f[0] for f in flags]


@pytest.mark.parametrize("law_name", list(LAWS))
def test_capstan_reference_is_consistent(law_name):
    """CapstanReference against what it must satisfy by construction, independently of
    its zone bookkeeping: before any slip the pulled element is the elastic closed form
    EA (l_K/L0_K - 1) with the others slack; in gross slip the end tensions compose over
    the summed wrap angle, T_K = T_crit(T_0, A) (checked for the laws in test_friction),
    the yarn's reference length is conserved, and the release ends back at d = 0."""
    law = LAWS[law_name]
    for k in (4, 16):
        net, _ = capstan_net(k)
        reference = CapstanReference(net, k, law)
        d = 1e-3
        length0, tension, zone, _, _ = reference.advance(d, 1)
        lengths = reference.geometry(d)[0]
        if law_name != "coulomb":
            assert zone == 0 and np.all(tension[:k] == 0.0)
            assert tension[k] == pytest.approx(
                YARN_EA * (lengths[k] / reference.geometry(0.0)[0][k] - 1), rel=1e-13)
        for d in (0.5, 1.0):
            length0, tension, zone, alphas, _ = reference.advance(d, 1)
            assert zone == k
            assert tension[k] == pytest.approx(critical(law, tension[0], alphas.sum()),
                                               rel=1e-12)
            assert length0.sum() == pytest.approx(reference.geometry(0.0)[0].sum(),
                                                  rel=1e-15)
        for d in (0.5, 0.0):
            length0, tension, zone, alphas, _ = reference.advance(d, -1)
        assert length0.sum() == pytest.approx(reference.geometry(0.0)[0].sum(), rel=1e-15)


@pytest.mark.parametrize("law_name", list(LAWS))
@pytest.mark.parametrize("k", [1, 4, 16, 64])
def test_capstan_full_curve_with_defaults(run_yarnfort, tmp_path, k, law_name):
    """Pull over K pins and release (d: 0 -> 0.3 -> 0), defaults. At every converged
    step, against CapstanReference (exact progressive slip, see its docstring): the
    tension and L0 of every yarn element, the pulling support's reaction, the number of
    slipping passages (so a slip onset must appear in the step where the exact onset
    falls; steps with a passage within 1e-6 of its threshold are not judged), and, at
    every gross-slip step, T_hi = T_crit(T_lo, sum of the wrap angles) from the run's
    own tensions and positions. Stick phases are the elastic closed form
    T = EA (l/L0 - 1) with L0 unchanged."""
    net, curve, states = run_capstan(run_yarnfort, tmp_path, "capstan", k, law_name)
    check_capstan(net, k, law_name, curve, states)


def test_capstan_over_many_pins_with_defaults(run_yarnfort, tmp_path):
    """The capstan of test_capstan_full_curve_with_defaults over 128 pins, Coulomb: the
    release's slip fronts cross tens of passages in one load step, which the rounds
    settle by marching the fronts along the yarn (one round per passage before). Every
    step against CapstanReference as there (tensions, L0, reaction, slip flags, gross
    slip over the summed angle), and the whole run within 3 Newton iterations per pin
    of the 4-pin run's count, so that no front goes a passage per round."""
    net, curve, states = run_capstan(run_yarnfort, tmp_path, "many", 128, "coulomb")
    check_capstan(net, 128, "coulomb", curve, states)
    _, few, _ = run_capstan(run_yarnfort, tmp_path, "few", 4, "coulomb")
    assert curve["newton_iterations"].sum() <= few["newton_iterations"].sum() + 3 * 128


#: Exact violation of the stick test T_max / T_crit(T_min) - 1 at the knots placed just
#: before (stick) and just after (slip) each slip onset: far above the solver's
#: friction_tolerance (1e-9) and CLOSE_CALL, far below a step of the path.
ONSET_MARGIN = 1e-5


def slip_onset_knots(net, k: int, law: dict) -> tuple[list, list]:
    """Loads d just before and just after every slip onset of the pull (0 -> 1) and of
    the release (1 -> 0), from CapstanReference: with n passages slipping, the state is
    a function of d alone (the zone's conserved length is that of the start of the
    half), so the onset of passage K-n is the root in d of its stick-test violation,
    and the knots are the roots of violation = -+ONSET_MARGIN (brentq). Onsets at d = 0+
    (Coulomb from a slack start: everything slips at once) get no knots."""
    reference = CapstanReference(net, k, law)
    tol = dict(xtol=1e-15, rtol=4 * np.finfo(float).eps, maxiter=500)

    def violation(d, n, direction, start):
        lengths, alphas = reference.geometry(d)
        tension = reference._zone_state(n, lengths, alphas, start, direction)[1]
        return reference.violation(k - n, tension, alphas, direction)

    halves = []
    for direction, start_d, end_d in ((1, 0.0, 1.0), (-1, 1.0, 0.0)):
        start = reference.length0.copy()
        knots, d_from = [], start_d
        for n in range(k):
            f = lambda d, m: violation(d, n, direction, start) - m     # noqa: E731
            step = 1e-9 * (end_d - start_d)
            if f(d_from + step, 0.0) > 0.0:
                continue                          # slips at once: no onset to bracket
            if f(end_d, ONSET_MARGIN) < 0.0:
                break                             # never slips on this half
            before = optimize.brentq(f, d_from + step, end_d, args=(-ONSET_MARGIN,), **tol)
            after = optimize.brentq(f, d_from + step, end_d, args=(ONSET_MARGIN,), **tol)
            knots += [before, after]
            d_from = after
        halves.append(knots)
        reference.advance(end_d, direction)       # the state the release starts from
    return halves[0], halves[1]


@pytest.mark.parametrize("law_name", list(LAWS))
@pytest.mark.parametrize("k", [1, 4])
def test_capstan_slip_onsets_with_defaults(run_yarnfort, tmp_path, k, law_name):
    """The capstan of test_capstan_full_curve_with_defaults with path knots just before
    and just after every exact slip onset (slip_onset_knots: stick-test violation
    -1e-5 and +1e-5 of T_crit), so that an onset that comes early or late shows as a
    wrong number of slipping passages at a knot. Everything of the full-curve test is
    checked at every step, and every knot step must be judged."""
    net, _ = capstan_net(k)
    load, release = slip_onset_knots(net, k, LAWS[law_name])
    p_disp = [0.0, *load, 1.0, *release, 0.0]
    path = dict(time=list(map(float, range(len(p_disp)))), p_force=[0.0] * len(p_disp),
                p_disp=p_disp)
    _, curve, states = run_capstan(run_yarnfort, tmp_path, "onsets", k, law_name, path=path)
    knot_steps = [i for i, t in enumerate(curve["time"])
                  if abs(t - round(t)) < 1e-9 and 0 < round(t) < len(p_disp) - 1
                  and round(t) != len(load) + 1]
    print(f"K={k} {law_name}: {len(load) // 2} onsets on the pull, {len(release) // 2} on "
          f"the release")
    _, judged = check_capstan(net, k, law_name, curve, states, peak_time=len(load) + 1)
    assert len(knot_steps) == len(load) + len(release) > 0
    assert set(knot_steps) <= set(judged)


# ======================================================================================
# 2. One pin loaded and unloaded twice (test_hysteresis's play operator), defaults.

def without_solver(text: str) -> str:
    """The namelist text with its &solver group taken out (defaults)."""
    out = re.sub(r"&solver\n(?:[^/\n][^\n]*\n)*/\n", "", text)
    assert "&solver" not in out and out.count("&") == text.count("&") - 1
    return out


@pytest.mark.parametrize("name", list(CASES))
def test_hysteresis_loops_with_defaults(run_yarnfort, tmp_path, name):
    """test_hysteresis's scene (one yarn over one pin, pulled and released twice) without
    any &solver group, against its piecewise closed form (the play operator
    s(d) = clip(s_old, s_f(d), s_r(d)) with exact quadratic / bisection roots of the
    slip relations, evaluated at the run's own d): the force at every step, both element
    tensions, the stick/slip flag at every step, the loop area of each cycle and the
    permanent sliding left after each release."""
    case = Case(**CASES[name].__dict__)
    run = run_yarnfort(without_solver(hysteresis_scene(case)), cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    cmp = compare(case, tmp_path / "out")
    area, area_exact = cmp.areas()
    scale = np.max(cmp.tension_exact)
    errors = dict(
        force=cmp.force_error(),
        tension=float(np.max(np.abs(cmp.tension - cmp.tension_exact)) / scale),
        area=float(np.max(np.abs(area - area_exact) / area_exact)),
        sliding=float(max(abs(cmp.s[i] - cmp.s_exact[i]) / cmp.s_exact[i]
                          for i in cmp.unload_steps)),
        length0=float(np.max(np.abs(cmp.s - cmp.s_exact)) / case.length_a))
    print(f"hysteresis {name}: {len(cmp.d)} steps, flag mismatches {cmp.flag_mismatches()}, "
          f"errors {', '.join(f'{n} {v:.1e}' for n, v in errors.items())}")
    for phase in ("stick", "forward", "reverse"):
        assert phase in cmp.phases[1:]
    assert np.all(area_exact > 0) and all(cmp.s_exact[i] > 0 for i in cmp.unload_steps)
    assert cmp.flag_mismatches() == []
    for key, value in errors.items():
        assert value <= (POSITION_RTOL if key == "length0" else FORCE_RTOL), (key, value)


# ======================================================================================
# 3-4. A ring on a yarn between two supports at different heights.

RING_A = np.array([-1.0, 0.4, 0.0])
RING_B = np.array([1.0, 0.0, 0.0])
#: Load P (N) hanging from the ring by a stub yarn of stiffness STUB_EA (N).
RING_LOAD = 1.0
STUB_EA = 10.0
STUB_LENGTH = 0.3
#: Yarn stiffness EA (N): soft (strains of a few per cent), stiff (strains of 1e-6 to
#: 2e-5) and nearly inextensible (1e-7 to 2e-6). The last two converge only through
#: Newton's softened predictor (README, Numerics): without it no ring from EA = 3e3 P up
#: converged from the stress-free start.
RING_STIFFNESS = {"soft": 10.0 * RING_LOAD, "stiff": 1e5 * RING_LOAD,
                  "inextensible": 1e6 * RING_LOAD}
#: The load ramps from 5 % of P (at the first state, solved from the stress-free
#: input) to P; the frictionless ring is also run from zero load.
FIRST_LOAD = 0.05
#: Scene size (m) for position tolerances: the span A-B.
RING_SIZE = float(np.linalg.norm(RING_B - RING_A))


def ring_namelist(start, stiffness: float, mu: float, units=(1.0, 1.0),
                  first_load: float = FIRST_LOAD, last_load: float = 1.0) -> str:
    """Nodes A = 1 and B = 3 held, the ring R = 2 (starting at `start`, stress free),
    S = 4 the far end of the stub R-S hanging below R, loaded by (0, -P, 0). The yarn
    1-2-3 passes through R, the stub ends there: R is a contact node, Coulomb with mu."""
    a, f = units
    start = np.asarray(start, float)
    nodes = a * np.array([RING_A, start, RING_B, start - [0.0, STUB_LENGTH, 0.0]])
    return defaults_namelist(
        nodes, [dict(material="yarn", nodes=[1, 2, 3]), dict(material="stub", nodes=[2, 4])],
        [dict(name="a", nodes=[1], fix="xyz"), dict(name="b", nodes=[3], fix="xyz")],
        [dict(nodes=[4], force=[0.0, -f * RING_LOAD, 0.0])],
        [dict(name="yarn", law="linear", stiffness=f * stiffness),
         dict(name="stub", law="linear", stiffness=f * STUB_EA)],
        dict(time=[0.0, 1.0], p_force=[first_load, last_load], p_disp=[0.0, 0.0]),
        [dict(materials=["yarn", "stub"], law="coulomb", friction_coefficient=mu)])


def frictionless_ring(length0: float, stiffness: float, load: float):
    """mu = 0: equal tensions T on both sides, so the load's line bisects the angle at
    the ring and both segments make the same angle theta with the vertical. Horizontal
    span b = L sin(theta), L = l1 + l2 the stretched length; heights: (l2 - l1) cos(theta)
    = h (B above A by h); vertical equilibrium 2 T cos(theta) = P; linear law
    L = L0 (1 + T/EA). So theta is the root of L0 (1 + P/(2 EA cos theta)) sin theta = b
    (increasing in theta), l1 = (L - h/cos theta)/2 and R = A + l1 (sin theta, -cos theta).
    For EA -> infinity R is the lowest point of the ellipse with foci A, B and major
    axis L0. Returns R, T, L."""
    b, h = RING_B[0] - RING_A[0], RING_B[1] - RING_A[1]
    total = lambda theta: length0 * (1.0 + load / (2.0 * stiffness * np.cos(theta)))  # noqa
    theta = optimize.brentq(lambda x: total(x) * np.sin(x) - b, 0.0, 0.5 * np.pi * (1 - 1e-12),
                            xtol=1e-300, rtol=4 * np.finfo(float).eps, maxiter=500)
    length = total(theta)
    l1 = 0.5 * (length - h / np.cos(theta))
    ring = RING_A + l1 * np.array([np.sin(theta), -np.cos(theta), 0.0])
    return ring, load / (2.0 * np.cos(theta)), length



def frictionless_ring_path(length0: float, stiffness: float, p_force):
    """frictionless_ring at each load factor of a run: the ring positions and the two
    (equal) tensions per step."""
    rings, tensions = [], []
    for p in p_force:
        ring, t, _ = frictionless_ring(length0, stiffness, p * RING_LOAD)
        rings.append(ring)
        tensions.append(np.array([t, t]))
    return rings, tensions

def lower_intersection(l1: float, l2: float) -> np.ndarray:
    """The lower intersection of the circles of radius l1 about A and l2 about B."""
    e = RING_B - RING_A
    d = np.linalg.norm(e)
    e = e / d
    a = (l1 * l1 - l2 * l2 + d * d) / (2.0 * d)
    assert l1 * l1 >= a * a, "the circles do not meet"
    h = np.sqrt(l1 * l1 - a * a)
    normal = np.array([e[1], -e[0], 0.0])            # points downwards for A left of B
    return RING_A + a * e + h * normal


def stuck_ring(split: float, length0: float, stiffness: float, load: float):
    """The ring held at a fixed split of the reference length (L0 = split on the A side,
    length0 - split on the B side): an elastic V. Unknowns T1, T2: the segment lengths
    l_i = L0_i (1 + T_i/EA) place R at the circles' lower intersection, and R's
    equilibrium T1 u1 + T2 u2 = (0, P) closes the two equations (scipy root, started
    from the statics of the unstretched V). Returns R, (T1, T2), alpha."""
    def place(t):
        ring = lower_intersection(split * (1 + t[0] / stiffness),
                                  (length0 - split) * (1 + t[1] / stiffness))
        u = np.array([RING_A - ring, RING_B - ring])[:, :2]
        return ring, u / np.linalg.norm(u, axis=1)[:, None]

    def residual(t):
        u = place(t)[1]
        return (t[0] * u[0] + t[1] * u[1] - [0.0, load]) / load

    guess = np.linalg.solve(place([0.0, 0.0])[1].T, [0.0, load])
    sol = optimize.root(residual, guess, method="hybr", options=dict(xtol=1e-15))
    assert np.max(np.abs(residual(sol.x))) < 1e-13, sol
    ring, u = place(sol.x)
    alpha = np.pi - np.arctan2(abs(u[0, 0] * u[1, 1] - u[0, 1] * u[1, 0]), u[0] @ u[1])
    return ring, sol.x, alpha


def statics_at(ring: np.ndarray, load: float):
    """Tensions T1, T2 that hold a ring at `ring` under the load (2x2 statics) and alpha."""
    u = np.array([RING_A - ring, RING_B - ring])[:, :2]
    u = u / np.linalg.norm(u, axis=1)[:, None]
    t = np.linalg.solve(u.T, [0.0, load])
    return t, np.pi - np.arctan2(abs(u[0, 0] * u[1, 1] - u[0, 1] * u[1, 0]), u[0] @ u[1])


def admissible_splits(length0: float, stiffness: float, load: float, mu: float,
                      hint=None):
    """The splits s of the stuck ring where T_max <= T_min exp(mu alpha): an interval
    [s_lo, s_hi] (g1 = T1 - T2 e^(mu alpha) falls and g2 = T2 - T1 e^(mu alpha) rises
    with s), its ends found by brentq on g1 and g2 (s_lo = s_hi for mu = 0). Brackets
    come from a grid over the splits where the circles meet and the stuck V holds the
    load in tension on both sides, or from a window about `hint` (the ends at a nearby
    load) widened until g changes sign."""
    def g(s, side):
        _, t, alpha = stuck_ring(s, length0, stiffness, load)
        assert np.all(t > 0.0)
        return (t[0] - t[1] * np.exp(mu * alpha)) if side == 1 else \
            (t[1] - t[0] * np.exp(mu * alpha))

    def bracket(side):
        if hint is not None:
            width = 1e-6 * length0
            for _ in range(12):
                a, b = hint[side - 1] - width, hint[side - 1] + width
                try:
                    if g(a, side) * g(b, side) <= 0.0:
                        return a, b
                except AssertionError:
                    break
                width *= 8.0
        d = np.linalg.norm(RING_B - RING_A)
        grid = []
        for s in np.linspace(0.5 * (length0 - d), 0.5 * (length0 + d), 42)[1:-1]:
            try:
                grid.append((s, g(s, side)))
            except AssertionError:
                continue
        change = [(a[0], b[0]) for a, b in zip(grid, grid[1:]) if a[1] * b[1] <= 0.0]
        assert len(change) == 1, (side, change)
        return change[0]

    tol = dict(xtol=1e-15, rtol=4 * np.finfo(float).eps, maxiter=500)
    return tuple(optimize.brentq(lambda s: g(s, side), *bracket(side), **tol)
                 for side in (1, 2))


def run_ring(run_yarnfort, tmp_path, name, start, stiffness, mu, units=(1.0, 1.0),
             first_load=FIRST_LOAD):
    folder = tmp_path / name
    folder.mkdir()
    run = run_yarnfort(ring_namelist(start, stiffness, mu, units, first_load), cwd=folder)
    assert run.returncode == 0, run.stderr
    curve, states = read_curve(folder / "out"), read_states(folder / "out")
    assert len(states) == len(curve["step"])
    return curve, states


def ring_errors(curve, states, rings, tensions) -> dict:
    """Worst errors over the loaded steps: ring and stub-end positions (fraction of the
    scene size), both tensions and both reactions (relative to the step's load)."""
    errors = dict(ring=0.0, stub_end=0.0, tension=0.0, reaction=0.0)
    for i in range(len(states)):
        load = curve["p_force"][i] * RING_LOAD
        if load == 0.0:
            continue                    # stress free: test_zero_load covers it
        x = states[i].position
        ring, t = rings[i], tensions[i]
        end = ring - [0.0, STUB_LENGTH * (1 + load / STUB_EA), 0.0]
        u = np.array([RING_A - ring, RING_B - ring])     # reaction on the net at A, B
        u /= np.linalg.norm(u, axis=1)[:, None]
        reactions = np.vstack([curve.reaction("a")[i], curve.reaction("b")[i]])
        errors["ring"] = max(errors["ring"], np.max(np.abs(x[1] - ring)) / RING_SIZE)
        errors["stub_end"] = max(errors["stub_end"], np.max(np.abs(x[3] - end)) / RING_SIZE)
        errors["tension"] = max(errors["tension"],
                                np.max(np.abs(states[i].tension[:2] - t)) / load)
        errors["reaction"] = max(errors["reaction"],
                                 np.max(np.abs(reactions - t[:, None] * u)) / load)
    return errors


def test_frictionless_ring_reference_is_the_ellipse():
    """The references of the ring against each other and against the ellipse: for mu = 0
    the admissible interval of the stuck-ring solve is one split, whose ring is the
    closed form's; and for EA -> infinity the closed form's ring lies on the ellipse
    |R - A| + |R - B| = L0 with equal angles to the vertical."""
    length0 = np.linalg.norm(RING_A - [0, -0.6, 0]) + np.linalg.norm(RING_B - [0, -0.6, 0])
    for stiffness in RING_STIFFNESS.values():
        ring, t, _ = frictionless_ring(length0, stiffness, RING_LOAD)
        s_lo, s_hi = admissible_splits(length0, stiffness, RING_LOAD, 0.0)
        assert s_hi == pytest.approx(s_lo, rel=1e-13)
        ring2, t2, _ = stuck_ring(s_lo, length0, stiffness, RING_LOAD)
        np.testing.assert_allclose(ring2, ring, rtol=0, atol=1e-13)
        np.testing.assert_allclose(t2, t, rtol=1e-12)
    ring, t, _ = frictionless_ring(length0, 1e300, RING_LOAD)
    u1, u2 = (RING_A - ring) / np.linalg.norm(RING_A - ring), \
        (RING_B - ring) / np.linalg.norm(RING_B - ring)
    assert np.linalg.norm(RING_A - ring) + np.linalg.norm(RING_B - ring) == \
        pytest.approx(length0, rel=1e-15)
    assert u1[1] == pytest.approx(u2[1], rel=1e-14) and u1[0] == pytest.approx(-u2[0],
                                                                             rel=1e-14)


#: Known limit (README, Numerics): on the nearly inextensible yarn (EA = 1e6 P, 1e7
#: times the tension at the first state) the run converges, but the stick test's dead
#: band, ten times the rounding allowance of the passage's tensions (8 eps r EA each),
#: is 2e-6 to 1e-7 of the tension: at three steps the ring stays stuck where the
#: frictionless one slides, off by up to 1.3e-7 of the span, above POSITION_RTOL
#: (test_inextensible_ring_converges_within_its_dead_band). Below the band the rows'
#: convergence allowance (the same rounding) leaves 4e-8, and at the first load the bare
#: rounding of a tension (eps r EA) is 1e-8 of the load: the tests' tolerance is the
#: arithmetic's there. Strict: the day it is within, these tests must become plain ones.
INEXTENSIBLE_RING_LIMIT = pytest.mark.xfail(
    strict=True, reason="known limit: with EA = 1e7 tension the stick test's dead band "
    "(rounding of the tensions) leaves the ring off by up to 1.3e-7 of the span")


@pytest.mark.parametrize("yarn, first_load", [
    ("soft", FIRST_LOAD), ("stiff", FIRST_LOAD),
    pytest.param("inextensible", FIRST_LOAD, marks=INEXTENSIBLE_RING_LIMIT),
    ("soft", 0.0)])
def test_frictionless_ring_with_defaults(run_yarnfort, tmp_path, yarn, first_load):
    """mu = 0 ring, stress free at (0, -0.6), the load ramped from first_load P to P:
    at every loaded step the ring, the stub's end, both tensions and both support
    reactions against frictionless_ring (the ellipse closed form solved for the
    extensible yarn)."""
    stiffness = RING_STIFFNESS[yarn]
    start = np.array([0.0, -0.6, 0.0])
    length0 = np.linalg.norm(RING_A - start) + np.linalg.norm(RING_B - start)
    curve, states = run_ring(run_yarnfort, tmp_path, "ring", start, stiffness, 0.0,
                             first_load=first_load)
    rings, tensions = frictionless_ring_path(length0, stiffness, curve["p_force"])
    errors = ring_errors(curve, states, rings, tensions)
    print(f"frictionless ring ({yarn}, from {first_load} P): {len(states)} steps, errors "
          f"{', '.join(f'{n} {v:.1e}' for n, v in errors.items())}; "
          f"final ring at {states[-1].position[1]}")
    for key, value in errors.items():
        assert value <= (FORCE_RTOL if key in ("tension", "reaction") else POSITION_RTOL), \
            (key, value)


#: Start of the friction ring: far to the A side (split 0.61 m, where the admissible
#: splits start at 1.17 m), so it slides from the first state on; there the lower end
#: s_lo(P) of the admissible interval rises with P for both yarns, so the ring keeps
#: sliding and the exact path is the clip at the run's own loads, whatever its steps.
FRICTION_START = np.array([-0.9, -0.2, 0.0])
RING_MU = 0.3


@pytest.mark.parametrize("yarn", [
    "soft", "stiff", pytest.param("inextensible", marks=INEXTENSIBLE_RING_LIMIT)])
def test_friction_ring_with_defaults(run_yarnfort, tmp_path, yarn):
    """Coulomb ring (mu = 0.3) from a stress-free start far on the A side, the load
    ramped from 5 % of P to P. One passage, so the exact quasi-static path is the play operator
    s(P) = clip(s_old, s_lo(P), s_hi(P)) over the admissible splits of the stuck ring
    (admissible_splits, each end a brentq over the elastic-V solve stuck_ring). Checked
    at every loaded step: ring, stub end, tensions and reactions against that reference;
    at the end, from the run's own ring position and load by statics alone, the ring lies
    in the admissible set T_max <= T_min exp(mu alpha) and, the load being monotone from
    a stress-free start, on its boundary (T_max = T_min exp(mu alpha))."""
    stiffness = RING_STIFFNESS[yarn]
    length0 = np.linalg.norm(RING_A - FRICTION_START) + np.linalg.norm(RING_B - FRICTION_START)
    curve, states = run_ring(run_yarnfort, tmp_path, "ring", FRICTION_START, stiffness,
                             RING_MU)
    split = np.linalg.norm(RING_A - FRICTION_START)
    rings, tensions, lower, ends = [], [], [], None
    for p in curve["p_force"]:
        ends = s_lo, s_hi = admissible_splits(length0, stiffness, p * RING_LOAD, RING_MU,
                                              hint=ends)
        lower.append(s_lo)
        at_boundary = not s_lo < split < s_hi
        split = min(max(split, s_lo), s_hi)
        ring, t, _ = stuck_ring(split, length0, stiffness, p * RING_LOAD)
        rings.append(ring)
        tensions.append(t)
    # The scene is what the test says (reference): sliding along a rising s_lo.
    assert at_boundary and np.all(np.diff(lower) > 0.0)
    errors = ring_errors(curve, states, rings, tensions)
    t, alpha = statics_at(states[-1].position[1], RING_LOAD)
    ratio = t.max() / (t.min() * np.exp(RING_MU * alpha))
    errors["boundary"] = abs(ratio - 1.0)
    print(f"friction ring ({yarn}): {len(states)} steps, errors "
          f"{', '.join(f'{n} {v:.1e}' for n, v in errors.items())}; T_max/(T_min e^(mu "
          f"alpha)) = {ratio:.12f} at the end (run's position)")
    assert ratio <= 1.0 + FORCE_RTOL
    for key, value in errors.items():
        assert value <= (POSITION_RTOL if key in ("ring", "stub_end") else FORCE_RTOL), \
            (key, value)


#: The stick test's dead band (contact/stepper/active_set.f90, dead_band_factor) in units of the
#: rounding allowance of a passage's tensions, and that allowance per element in units
#: of eps (|T| + r dT/dlambda) (truss.f90, rounding_factor).
DEAD_BAND_FACTOR = 10.0
ROUNDING_FACTOR = 8.0


@pytest.mark.parametrize("mu", [0.0, RING_MU])
def test_inextensible_ring_converges_within_its_dead_band(run_yarnfort, tmp_path, mu):
    """The nearly inextensible ring (the known limit above) converges with the defaults,
    and at every step its tensions are the closed form's to within the stick test's dead
    band: ten times the rounding allowance of the passage's two tensions, 8 eps (|T| +
    r EA) each with r = (|x1| + |x2| + l) / L0 (about 9e-8 N here, 2e-6 to 1e-7 of the
    tension). The mechanism (mu = 0): at loads 0.145-0.38 P the passage stays in stick
    with T_max / T_min - 1 = 6e-8 to 2.3e-7, inside the band, where the frictionless ring
    slides on. Positions: within 1e-6 of the span (measured 1.3e-7)."""
    stiffness = RING_STIFFNESS["inextensible"]
    start = np.array([0.0, -0.6, 0.0]) if mu == 0.0 else FRICTION_START
    length0 = np.linalg.norm(RING_A - start) + np.linalg.norm(RING_B - start)
    curve, states = run_ring(run_yarnfort, tmp_path, "ring", start, stiffness, mu)
    if mu == 0.0:
        rings, tensions = frictionless_ring_path(length0, stiffness, curve["p_force"])
    else:
        rings, tensions, split, ends = [], [], np.linalg.norm(RING_A - start), None
        for p in curve["p_force"]:
            ends = admissible_splits(length0, stiffness, p * RING_LOAD, mu, hint=ends)
            split = min(max(split, ends[0]), ends[1])
            ring, t, _ = stuck_ring(split, length0, stiffness, p * RING_LOAD)
            rings.append(ring)
            tensions.append(t)
    assert len(states) == len(curve["p_force"]) >= 2
    eps = np.finfo(float).eps
    worst = 0.0
    for state, t_ref in zip(states, tensions):
        x = state.position
        band = 0.0
        for e, (a, b) in enumerate([(0, 1), (1, 2)]):     # the yarn's elements A-R, R-B
            length = np.linalg.norm(x[b] - x[a])
            r = (np.linalg.norm(x[a]) + np.linalg.norm(x[b]) + length) / state.length0[e]
            band += ROUNDING_FACTOR * eps * (abs(state.tension[e]) + r * stiffness)
        band *= DEAD_BAND_FACTOR
        error = np.max(np.abs(state.tension[:2] - t_ref))
        worst = max(worst, error / band)
        assert error <= band, (state.step, error, band)
    errors = ring_errors(curve, states, rings, tensions)
    print(f"inextensible ring (mu {mu}): {len(states)} steps, errors "
          f"{', '.join(f'{n} {v:.1e}' for n, v in errors.items())}; tension error up to "
          f"{worst:.2f} of the dead band")
    assert errors["ring"] <= 1e-6 and errors["stub_end"] <= 1e-6, errors


# ======================================================================================
# 5. A pretensioned 8 x 8 cable net under a centre load, stuck and frictionless.

NET_N = 8                    #: crossings per side
NET_EA = 100.0               #: cable stiffness EA (N), linear law
NET_PULL = 0.05              #: pretension: each boundary end moved outwards (m)
NET_LOAD = 2.0               #: total load (N) on the four centre crossings, along -z
NET_SIZE = float(NET_N + 1)  #: span (m), unit spacing


def cable_net_scene(frictionless: bool):
    """Warp cables along x (y = 1..8) and weft cables along y (x = 1..8) through the
    64 crossings, ends on the boundary (0 and 9) moved outwards by NET_PULL at
    p_disp = 1; then the load on the crossings (4,4), (5,4), (4,5), (5,5). Stuck: one
    material, no &contact (the crossings are plain shared nodes). Frictionless: warp
    and weft materials with a mu = 0 &contact, so both cables slide through every
    crossing. Returns (namelist text, nodes, elements [(a, b, yarn)], free node ids,
    boundary displacement per node, load per node, node ids of each support)."""
    n = NET_N
    keys = [(i, j) for j in range(1, n + 1) for i in range(1, n + 1)]
    keys += [(0, j) for j in range(1, n + 1)] + [(n + 1, j) for j in range(1, n + 1)]
    keys += [(i, 0) for i in range(1, n + 1)] + [(i, n + 1) for i in range(1, n + 1)]
    index = {key: k for k, key in enumerate(keys)}
    nodes = np.array([[i, j, 0.0] for i, j in keys], float)
    warp = [[index[(i, j)] for i in range(n + 2)] for j in range(1, n + 1)]
    weft = [[index[(i, j)] for j in range(n + 2)] for i in range(1, n + 1)]
    names = ("warp", "weft") if frictionless else ("cable", "cable")
    yarns = [dict(material=names[0], nodes=[v + 1 for v in w]) for w in warp]
    yarns += [dict(material=names[1], nodes=[v + 1 for v in w]) for w in weft]
    elements = [(a, b, y) for y, w in enumerate(warp + weft) for a, b in zip(w, w[1:])]
    sides = {"west": ([(0, j) for j in range(1, n + 1)], [-NET_PULL, 0.0, 0.0]),
             "east": ([(n + 1, j) for j in range(1, n + 1)], [NET_PULL, 0.0, 0.0]),
             "south": ([(i, 0) for i in range(1, n + 1)], [0.0, -NET_PULL, 0.0]),
             "north": ([(i, n + 1) for i in range(1, n + 1)], [0.0, NET_PULL, 0.0])}
    displacement = np.zeros_like(nodes)
    supports, side_nodes = [], {}
    for name, (side, d) in sides.items():
        ids = side_nodes[name] = [index[key] for key in side]
        displacement[ids] = d
        supports.append(dict(name=name, nodes=[v + 1 for v in ids], fix="xyz", displacement=d))
    centre = [index[key] for key in ((4, 4), (5, 4), (4, 5), (5, 5))]
    load = np.zeros_like(nodes)
    load[centre, 2] = -NET_LOAD / 4
    materials = [dict(name=m, law="linear", stiffness=NET_EA) for m in sorted(set(names))]
    contacts = [dict(materials=["warp", "weft"], law="coulomb",
                     friction_coefficient=0.0)] if frictionless else []
    text = defaults_namelist(
        nodes, yarns, supports, [dict(nodes=[v + 1 for v in centre],
                                      force=[0.0, 0.0, -NET_LOAD / 4])],
        materials, dict(time=[0.0, 1.0, 2.0], p_disp=[0.0, 1.0, 1.0], p_force=[0.0, 0.0, 1.0]),
        contacts)
    return text, nodes, elements, np.arange(n * n), displacement, load, side_nodes


class NetReference:
    """Independent equilibrium of the cable net (numpy residual and analytic Jacobian,
    scipy.optimize.root 'hybr', continued from step to step). Unknowns: the 64 free
    crossings; frictionless also one tension per cable.
    - stuck: element tension T = EA max(0, l/L0 - 1), L0 = 1 (the exact tension-only
      law), tangent (T/l)(I - u u^T) + (EA/L0) u u^T for taut elements;
    - frictionless (mu = 0): one tension T_y along each cable y (the capstan condition
      with mu = 0 at every crossing), and each cable keeps its reference length:
      sum_e l_e / (1 + T_y/EA) = 9 m; then L0_e = l_e / (1 + T_y/EA).
    The stress-free start (p = 0) is its own solution. The first pretensioned solve
    starts from the uniformly stretched flat net."""

    def __init__(self, nodes, elements, free, displacement, load, frictionless):
        self.nodes0, self.free, self.disp, self.load = nodes, free, displacement, load
        self.a = np.array([e[0] for e in elements])
        self.b = np.array([e[1] for e in elements])
        self.yarn = np.array([e[2] for e in elements])
        self.n_yarns = int(self.yarn.max()) + 1
        self.frictionless = frictionless
        self.unknowns = None

    def _unpack(self, z, p_disp):
        x = self.nodes0 + p_disp * self.disp
        nf = 3 * len(self.free)
        x[self.free] = z[:nf].reshape(-1, 3)
        return x, z[nf:]

    def residual(self, z, p_disp, p_force):
        x, t_yarn = self._unpack(z, p_disp)
        vec = x[self.b] - x[self.a]
        length = np.linalg.norm(vec, axis=1)
        u = vec / length[:, None]
        nf, ne = len(self.free), len(self.a)
        if self.frictionless:
            t = t_yarn[self.yarn]
            axial = np.zeros(ne)
        else:
            t = NET_EA * np.maximum(0.0, length - 1.0)
            axial = np.where(length > 1.0, NET_EA, 0.0)
        force = p_force * self.load.copy()
        np.add.at(force, self.a, t[:, None] * u)
        np.add.at(force, self.b, -t[:, None] * u)
        position = -np.ones(len(x), int)
        position[self.free] = np.arange(nf)
        n_unknowns = 3 * nf + (self.n_yarns if self.frictionless else 0)
        jac = np.zeros((n_unknowns, n_unknowns))
        uu = u[:, :, None] * u[:, None, :]
        k = (t / length)[:, None, None] * (np.eye(3) - uu) + axial[:, None, None] * uu
        three = np.arange(3)
        for row_node, sign_row in ((self.a, 1.0), (self.b, -1.0)):
            for col_node, sign_col in ((self.a, -1.0), (self.b, 1.0)):
                keep = (position[row_node] >= 0) & (position[col_node] >= 0)
                rows = 3 * position[row_node][keep][:, None, None] + three[None, :, None]
                cols = 3 * position[col_node][keep][:, None, None] + three[None, None, :]
                np.add.at(jac, (np.broadcast_to(rows, k[keep].shape),
                                np.broadcast_to(cols, k[keep].shape)),
                          sign_row * sign_col * k[keep])
        rows = [force[self.free].ravel()]
        if self.frictionless:
            stretch = 1.0 + t_yarn / NET_EA
            lengths = np.zeros(self.n_yarns)
            np.add.at(lengths, self.yarn, length)
            rows.append(lengths / stretch - NET_SIZE)
            for node, sign in ((self.a, 1.0), (self.b, -1.0)):
                keep = position[node] >= 0
                r = 3 * position[node][keep][:, None] + three[None, :]
                y = np.broadcast_to(3 * nf + self.yarn[keep][:, None], r.shape)
                np.add.at(jac, (r, y), sign * u[keep])          # force rows, d/dT_y
                np.add.at(jac, (y, r), -sign * u[keep] / stretch[self.yarn[keep]][:, None])
            jac[3 * nf:, 3 * nf:] = np.diag(-lengths / NET_EA / stretch ** 2)
        return np.concatenate(rows), jac

    def solve(self, p_disp: float, p_force: float):
        """(positions, element tensions, element L0) at the load factors."""
        if p_disp == 0.0 and p_force == 0.0:
            return self.nodes0.copy(), np.zeros(len(self.a)), np.ones(len(self.a))
        if self.unknowns is None:                  # uniformly stretched flat net
            x = self.nodes0 + p_disp * NET_PULL * (2 * self.nodes0 / NET_SIZE - 1) \
                * [1.0, 1.0, 0.0]
            z = [x[self.free].ravel()]
            if self.frictionless:
                x = self.nodes0[self.free].ravel()
                z = [x, np.full(self.n_yarns, NET_EA * 2 * p_disp * NET_PULL / NET_SIZE)]
            self.unknowns = np.concatenate(z)
        sol = optimize.root(self.residual, self.unknowns, args=(p_disp, p_force), jac=True,
                            method="hybr", options=dict(xtol=1e-15))
        scale = max(NET_LOAD, NET_EA * NET_PULL / NET_SIZE)
        assert np.max(np.abs(self.residual(sol.x, p_disp, p_force)[0])) < 1e-12 * scale, sol
        self.unknowns = sol.x
        x, t_yarn = self._unpack(sol.x, p_disp)
        length = np.linalg.norm(x[self.b] - x[self.a], axis=1)
        if self.frictionless:
            t = t_yarn[self.yarn]
            return x, t, length / (1.0 + t / NET_EA)
        return x, NET_EA * np.maximum(0.0, length - 1.0), np.ones(len(self.a))


@pytest.mark.parametrize("crossings", ["stuck", "frictionless"])
def test_cable_net_with_defaults(run_yarnfort, tmp_path, crossings):
    """Pretension (p_disp 0 -> 1), then the centre load (p_force 0 -> 1). At every step:
    all node positions, element tensions and reference lengths against NetReference
    (an independent numpy/scipy equilibrium solve of the same truss: tension-only
    linear law for the stuck net; one tension per cable and conserved cable length for
    the frictionless one); and the reaction of each side's supports, the sum of
    -T u over the elements that start there (u pointing into the net)."""
    frictionless = crossings == "frictionless"
    text, nodes, elements, free, displacement, load, sides = cable_net_scene(frictionless)
    run, curve, states = run_scene(run_yarnfort, tmp_path, "net", text, ok=False)
    assert run.returncode == 0, run.stderr
    assert len(states) == len(curve["step"])
    reference = NetReference(nodes, elements, free, displacement, load, frictionless)
    n_elements = len(elements)
    errors = dict(position=0.0, tension=0.0, length0=0.0, reaction=0.0)
    ends = {name: [(e, 1.0 if a in ids else -1.0) for e, (a, b, _) in enumerate(elements)
                   if a in ids or b in ids] for name, ids in sides.items()}
    for i, state in enumerate(states):
        x, t, length0 = reference.solve(float(curve["p_disp"][i]), float(curve["p_force"][i]))
        u = x[[e[1] for e in elements]] - x[[e[0] for e in elements]]
        u /= np.linalg.norm(u, axis=1)[:, None]
        for name, list_ in ends.items():
            exact = -sum(sign * t[e] * u[e] for e, sign in list_)
            scale = t.max() if t.max() > 0.0 else 1.0
            errors["reaction"] = max(errors["reaction"],
                                     relative_error(curve.reaction(name)[i], exact, scale))
        errors["position"] = max(errors["position"],
                                 np.max(np.abs(state.position - x)) / NET_SIZE)
        if t.max() > 0.0:
            errors["tension"] = max(errors["tension"], relative_error(
                state.tension[:n_elements], t, t.max()))
        errors["length0"] = max(errors["length0"],
                                np.max(np.abs(state.length0[:n_elements] - length0)) / NET_SIZE)
    sag = -x[free, 2].min()
    print(f"cable net ({crossings}): {len(states)} steps, sag {sag:.4f} m, errors "
          f"{', '.join(f'{n} {v:.1e}' for n, v in errors.items())}, Newton iterations "
          f"{int(curve['newton_iterations'].sum())}")
    assert sag > 0.1
    for key, value in errors.items():
        assert value <= (FORCE_RTOL if key in ("tension", "reaction") else POSITION_RTOL), \
            (key, value)


# ======================================================================================
# 6. Unit scaling and stiff obstacles.

#: (length, force) factors from m and N: the same scenes in mm/N, um/cN and m/kN.
UNITS = {"mm/N": (1e3, 1.0), "um/cN": (1e6, 1e2), "m/kN": (1.0, 1e-3)}


def unit_run(run_yarnfort, tmp_path, scene_name, name, units):
    """(curve, states, scene size) of one of the scenes in the given units."""
    if scene_name == "capstan":
        _, curve, states = run_capstan(run_yarnfort, tmp_path, name, 4, "adhesion",
                                       units=units)
        return curve, states, 2.0 * units[0]
    curve, states = run_ring(run_yarnfort, tmp_path, name, FRICTION_START,
                             RING_STIFFNESS["soft"], RING_MU, units=units)
    return curve, states, RING_SIZE * units[0]


@pytest.mark.parametrize("scene_name", ["capstan", "friction_ring"])
def test_unit_scaling_with_defaults(run_yarnfort, tmp_path, scene_name):
    """The capstan over 4 pins with adhesion, and the friction ring (soft yarn, load
    from a force node: every position free), in m/N, mm/N, um/cN and m/kN (every
    length, stiffness, load and adhesion parameter converted). Exact invariance: the
    same steps, the same stick/slip flags, and positions, L0 (over the scene size),
    tensions and reactions (over the step's largest tension) equal to 1e-8 after
    conversion back to m and N."""
    base_curve, base_states, base_size = unit_run(run_yarnfort, tmp_path, scene_name, "m_N",
                                                  (1.0, 1.0))
    worst, same_steps = {}, {}
    for label, (a, f) in UNITS.items():
        curve, states, size = unit_run(run_yarnfort, tmp_path, scene_name,
                                       label.replace("/", "_"), (a, f))
        same_steps[label] = len(curve["time"]) == len(base_curve["time"]) and \
            np.allclose(curve["time"], base_curve["time"], rtol=0, atol=1e-12)
        pairs = [(i, int(np.argmin(np.abs(base_curve["time"] - t))))
                 for i, t in enumerate(curve["time"])]
        pairs = [(i, j) for i, j in pairs if abs(base_curve["time"][j] - curve["time"][i]) < 1e-12]
        errors = dict(position=0.0, length0=0.0, tension=0.0, reaction=0.0, flags=0)
        supports = [n[:-3] for n in curve.names if n.endswith("_rx")]
        for i, j in pairs:
            b, s = base_states[j], states[i]
            scale = max(b.tension.max(), 1e-300)
            errors["position"] = max(errors["position"],
                                     np.max(np.abs(s.position / a - b.position)) / base_size)
            errors["length0"] = max(errors["length0"],
                                    np.max(np.abs(s.length0 / a - b.length0)) / base_size)
            errors["tension"] = max(errors["tension"],
                                    np.max(np.abs(s.tension / f - b.tension)) / scale)
            for name in supports:
                errors["reaction"] = max(errors["reaction"], np.max(np.abs(
                    curve.reaction(name)[i] / f - base_curve.reaction(name)[j])) / scale)
            errors["flags"] += int(curve["slipping"][i] != base_curve["slipping"][j])
        worst[label] = errors
        print(f"{scene_name} in {label}: {len(curve['time'])} steps (m/N: "
              f"{len(base_curve['time'])}), same steps {same_steps[label]}, {len(pairs)} "
              f"compared, errors {', '.join(f'{n} {v:.1e}' for n, v in errors.items())}")
    for label, errors in worst.items():
        assert same_steps[label], label
        assert errors["flags"] == 0, label
        for key in ("position", "length0"):
            assert errors[key] <= POSITION_RTOL, (label, key, errors[key])
        for key in ("tension", "reaction"):
            assert errors[key] <= FORCE_RTOL, (label, key, errors[key])


@pytest.mark.parametrize("peg_stiffness", [1.0, 1e6, 1e12])
@pytest.mark.parametrize("law_name", ["coulomb", "adhesion"])
def test_stiff_pins_change_nothing(run_yarnfort, tmp_path, law_name, peg_stiffness):
    """The capstan over 4 pins whose peg yarns (both ends held, so inert) have EA from
    1 to 1e12 N (the yarn 10 N): the same exact progressive-slip reference as
    test_capstan_full_curve_with_defaults must hold at every step."""
    net, curve, states = run_capstan(run_yarnfort, tmp_path, "capstan", 4, law_name,
                                     peg_stiffness=peg_stiffness)
    check_capstan(net, 4, law_name, curve, states)


# ======================================================================================
# 7. Zero load on a stress-free network.

def zero_load_scene(kind: str) -> str:
    """Stress-free scenes, every load factor zero:
    - 'v': a V-shaped yarn A-C-B with its middle node C free (a slack yarn);
    - 'ring': the friction ring (a contact node in a slack yarn, its stub end free);
    - 'dangling': a yarn hanging from A with two free nodes (a slack chain)."""
    if kind == "ring":
        return ring_namelist(FRICTION_START, RING_STIFFNESS["soft"], RING_MU,
                             first_load=0.0, last_load=0.0)
    nodes = {"v": [[-1.0, 0.4, 0.0], [-0.3, -0.5, 0.0], [1.0, 0.0, 0.0]],
             "dangling": [[0.0, 0.0, 0.0], [0.3, -0.7, 0.1], [0.9, -1.1, -0.2]]}[kind]
    supports = [dict(name="a", nodes=[1], fix="xyz")]
    if kind == "v":
        supports.append(dict(name="b", nodes=[3], fix="xyz"))
    return defaults_namelist(nodes, [dict(material="yarn", nodes=[1, 2, 3])], supports,
                             [dict(nodes=[2], force=[0.0, -1.0, 0.0])],
                             [dict(name="yarn", law="linear", stiffness=10.0)],
                             dict(time=[0.0, 1.0], p_force=[0.0, 0.0], p_disp=[0.0, 0.0]))


@pytest.mark.parametrize("kind", ["v", "ring", "dangling"])
def test_zero_load_keeps_a_stress_free_network(run_yarnfort, tmp_path, kind):
    """Exact model: with no load and no prescribed motion a stress-free network is in
    equilibrium where it is (every tension zero); it must stay there, positions to
    1e-12 of the scene size, at every step."""
    text = zero_load_scene(kind)
    nodes = np.array(re.search(r"xyz = ([^\n]*)", text).group(1).split(", "), float)
    nodes = nodes.reshape(-1, 3)
    size = np.ptp(nodes, axis=0).max()
    run, curve, states = run_scene(run_yarnfort, tmp_path, kind, text, ok=False)
    moved = max(np.max(np.abs(s.position - nodes)) for s in states) / size if states else None
    tension = max(np.max(np.abs(s.tension)) for s in states) if states else None
    print(f"zero load ({kind}): exit {run.returncode}, {len(states)} states, largest move "
          f"{moved} of the scene size, largest tension {tension} N; "
          f"{run.stderr.strip().splitlines()[-1] if run.returncode else ''}")
    assert run.returncode == 0, run.stderr
    assert moved <= 1e-12


# ======================================================================================
# 8. Friction laws at shared nodes do not depend on the order of the &yarn groups.

def permuted(yarns: list, order) -> list:
    return [yarns[i] for i in order]


def order_runs(run_yarnfort, tmp_path, nodes, yarns, supports, materials, contacts, path):
    """Run every order of the &yarn groups; returns [(order, run, curve, states)]."""
    out = []
    for order in itertools.permutations(range(len(yarns))):
        name = "order_" + "".join(map(str, order))
        text = defaults_namelist(nodes, permuted(yarns, order), supports, [], materials, path,
                                 contacts)
        folder = tmp_path / name
        folder.mkdir()
        run = run_yarnfort(text, cwd=folder)
        if run.returncode == 0:
            out.append((order, run, read_curve(folder / "out"), read_states(folder / "out")))
        else:
            out.append((order, run, None, None))
    return out


def main_yarn(states, yarns, order, main: int = 0):
    """Tensions and L0 of the yarn `main` (an index into the unpermuted list) per state."""
    ranges = element_ranges(dict(yarns=permuted(yarns, order)))
    r = ranges[list(order).index(main)]
    return np.array([s.tension[r] for s in states]), np.array([s.length0[r] for s in states])


def test_two_obstacle_types_at_one_node(run_yarnfort, tmp_path):
    """A yarn over a pin N where two obstacle yarns of different types end (pin types
    'pega', mu = 0.1 with the yarn, and 'pegb', mu = 0.9; bonded to each other). The
    yarn's law at N is ambiguous. Over all 6 orders of the &yarn groups either every run
    stops with exit code 2, a message naming node 2 and no curve written, or every run
    gives the same results (the yarn's tensions and L0, positions and the pull reaction
    at every step, to round-off)."""
    nodes = [[-1, -1, 0], [0, 0, 0], [1, -1, 0], [-0.2, 0.2, 0], [0.2, 0.2, 0]]
    yarns = [dict(material="yarn", nodes=[1, 2, 3]), dict(material="pega", nodes=[2, 4]),
             dict(material="pegb", nodes=[2, 5])]
    supports = [dict(name="first", nodes=[1], fix="xyz"),
                dict(name="pull", nodes=[3], fix="xyz", displacement=[0.0, -0.3, 0.0]),
                dict(name="pins", nodes=[2, 4, 5], fix="xyz")]
    materials = [dict(name=m, law="linear", stiffness=10.0) for m in ("yarn", "pega", "pegb")]
    contacts = [dict(materials=["yarn", "pega"], law="coulomb", friction_coefficient=0.1),
                dict(materials=["yarn", "pegb"], law="coulomb", friction_coefficient=0.9),
                dict(materials=["pega", "pegb"], law="bonded")]
    runs = order_runs(run_yarnfort, tmp_path, nodes, yarns, supports, materials, contacts,
                      dict(time=[0.0, 1.0], p_disp=[0.0, 1.0]))
    codes = {order: run.returncode for order, run, _, _ in runs}
    finals = {order: (float(curve.reaction("pull")[-1, 1]) if run.returncode == 0 else None)
              for order, run, curve, _ in runs}
    print(f"two obstacle types: exit codes {codes}; final pull reactions (y) {finals}")
    if all(c == 2 for c in codes.values()):
        for order, run, _, _ in runs:
            assert re.search(r"\bnode 2\b", run.stderr), run.stderr
            assert len(run.stderr.strip().splitlines()) <= 3
            assert not (tmp_path / ("order_" + "".join(map(str, order))) / "out"
                        / "curve.csv").exists()
        return
    assert all(c == 0 for c in codes.values()), codes
    (order0, _, curve0, states0) = runs[0]
    t0, l0 = main_yarn(states0, yarns, order0)
    for order, _, curve, states in runs[1:]:
        t, l = main_yarn(states, yarns, order)
        np.testing.assert_array_equal(curve["p_disp"], curve0["p_disp"])
        np.testing.assert_allclose(t, t0, rtol=1e-12, atol=0)
        np.testing.assert_allclose(l, l0, rtol=1e-14, atol=0)
        np.testing.assert_allclose(curve.reaction("pull"), curve0.reaction("pull"),
                                   rtol=1e-12, atol=0)
        for a, b in zip(states, states0):
            np.testing.assert_array_equal(a.position, b.position)


def test_yarn_revisiting_a_node_keeps_its_passages(run_yarnfort, tmp_path):
    """A yarn A-N-C1-C2-N-B passes twice through the pin N, where a 'peg' yarn ends
    (all nodes held, B pulled down; one &contact, yarn-peg Coulomb mu = 0.3). Its second
    passage at N (elements C2-N, N-B) is a one-pin capstan that slips from the start
    (T_min = 0): CapstanReference over the nodes C2, N, B gives its tensions at every
    step, and the first passage, with both sides slack, carries nothing. Both orders of
    the &yarn groups must run and agree with it."""
    nodes = [[-1, -1, 0], [0, 0, 0], [-0.5, 1, 0], [0.5, 1, 0], [1, -1, 0], [0, 0, 0.3]]
    yarns = [dict(material="yarn", nodes=[1, 2, 3, 4, 2, 5]),
             dict(material="peg", nodes=[2, 6])]
    supports = [dict(name="held", nodes=[1, 2, 3, 4, 6], fix="xyz"),
                dict(name="pull", nodes=[5], fix="xyz", displacement=list(PULL))]
    materials = [dict(name=m, law="linear", stiffness=YARN_EA) for m in ("yarn", "peg")]
    law = LAWS["coulomb"]
    contacts = [dict(materials=["yarn", "peg"], **law)]
    runs = order_runs(run_yarnfort, tmp_path, nodes, yarns, supports, materials, contacts,
                      dict(time=[0.0, 1.0], p_disp=[0.0, 1.0]))
    results = {}
    for order, run, curve, states in runs:
        if run.returncode != 0:
            results[order] = (run.returncode, run.stderr.strip().splitlines()[-1])
            continue
        tension, length0 = main_yarn(states, yarns, order)
        reference = CapstanReference(dict(nodes=[nodes[3], nodes[1], nodes[4]]), 1, law)
        error, slid = 0.0, 0.0
        for i, d in enumerate(curve["p_disp"]):
            exact = reference.advance(float(d), 1)[1]
            scale = exact.max() if exact.max() > 0 else 1.0
            error = max(error, np.max(np.abs(tension[i, 3:5] - exact)) / scale,
                        np.max(np.abs(tension[i, :3])) / scale)
            slid = max(slid, abs(length0[i, 4] - length0[0, 4]))
        results[order] = (run.returncode, error, slid, int(curve["slipping"].max()))
    print(f"yarn revisiting a node: (exit code, max rel. error of the tensions, L0 slid "
          f"through the second passage, most slipping passages) per order {results}")
    for order, result in results.items():
        assert result[0] == 0, (order, result)
        _, error, slid, slipping = result
        assert slid > 1e-3 and slipping >= 1, order
        assert error <= FORCE_RTOL, (order, error)
