# SPDX-License-Identifier: MIT
"""Exact answers with the default settings (issue 10, "Must have" 6).

Every scene here is run with NO ``&solver`` group at all, as a new user would, and is
compared with a closed form or with an independent solution computed in this file (never
with a run of the code under test): 1e-8 relative on forces, 1e-8 of the scene size on
positions. The reference critical tensions come from test_friction.py and the one-pin
play operator from test_hysteresis.py, both checked there against integrations of the
laws' ODEs and against the unreduced slip relations.
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
            if excess(0.0) <= 0.0:
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
        """(L0, tensions, zone size) at d, reached over a monotone step in `direction`."""
        if direction != self.direction:
            self.zone, self.direction = 0, direction
        lengths, alphas = self.geometry(d)
        old, k = self.length0, self.k
        n = self.zone
        while True:
            length0, tension = self._zone_state(n, lengths, alphas, old, direction)
            if n == k or self.violation(k - n, tension, alphas, direction) <= STICK_SLACK:
                break
            n += 1
        for p in range(1, k + 1):                        # every passage admissible
            for way in (1, -1):
                assert self.violation(p, tension, alphas, way) <= 10 * STICK_SLACK, (d, p)
        for p in range(k - n + 1, k + 1):                # zone flows go the half's way
            flow = length0[p:].sum() - old[p:].sum()
            assert direction * flow >= -1e-13 * old.sum(), (d, p, flow)
        self.length0, self.zone = length0, n
        return length0, tension, n, alphas


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
                units=(1.0, 1.0)):
    net, materials = capstan_net(k, peg_stiffness, units)
    text = defaults_namelist(net["nodes"], net["yarns"], net["supports"], net["loads"],
                             materials, CAPSTAN_PATH,
                             [dict(materials=["yarn", "peg"],
                                   **scaled_law(LAWS[law_name], units[1]))])
    run, curve, states = run_scene(run_yarnfort, tmp_path, name, text, ok=False)
    assert run.returncode == 0, run.stderr
    assert len(states) == len(curve["step"])
    return net, curve, states


def check_capstan(net, k, law_name, curve, states) -> dict:
    """Compare a capstan run with CapstanReference at every converged step; returns the
    worst errors (and asserts them)."""
    law = LAWS[law_name]
    reference = CapstanReference(net, k, law)
    yarn = element_ranges(net)[0]
    directions = np.where(curve["time"] <= 1.0, 1, -1)
    exact = [reference.advance(float(d), int(w)) for d, w in zip(curve["p_disp"], directions)]
    peak = max(e[1].max() for e in exact)
    errors = dict(tension=0.0, length0=0.0, reaction=0.0, gross_slip=0.0)
    flags, gross, onsets = [], 0, 0
    previous = (0, 1)
    for i, (state, (length0, tension, zone, alphas)) in enumerate(zip(states, exact)):
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
        margins = [abs(reference.violation(p, tension, alphas, direction)) for p in
                   range(1, k + 1) if p <= k - zone]
        if i > 0 and (not margins or min(margins) > CLOSE_CALL):
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
    return errors


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
