# SPDX-License-Identifier: MIT
"""Sliding at contact nodes (capstan friction) against closed forms and limits.

The reference critical tensions are computed here, independently of the Fortran laws:
Coulomb and adhesion in closed form (paper eqs. 20 and 35, with alpha* = 1/mu - T0/beta
as in the design notes), decaying adhesion by a fine Runge-Kutta integration of its ODE;
the closed forms are themselves checked against that integration.
"""
from __future__ import annotations

import numpy as np
import pytest

from scenes import group, scene
from yarnfort import read_curve, read_states

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


def critical_rk4(law: dict, t0, angle, n: int = 4000):
    """Classical RK4 with n fixed steps per integration. g has kinks (w_d, T*, beta/mu):
    a step across one loses the fourth order there (local error O(h^3)), so n is chosen
    from the convergence check in test_reference_critical_tensions."""
    g = rate(law)
    t = np.array(t0, dtype=float)
    h = np.asarray(angle, dtype=float) / n
    for _ in range(n):
        k1 = g(t)
        k2 = g(t + 0.5 * h * k1)
        k3 = g(t + 0.5 * h * k2)
        k4 = g(t + h * k3)
        t = t + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    return t


def critical_closed_form(law: dict, t0, angle):
    """Coulomb: T0 exp(mu alpha) (eq. 20). Adhesion (eq. 35): T0 + beta alpha up to
    alpha* = 1/mu - T0/beta, (beta/mu) exp(mu (alpha - alpha*)) after; the pure
    exponential when T0 >= beta/mu."""
    t0, angle = np.broadcast_arrays(np.asarray(t0, float), np.asarray(angle, float))
    mu = law["friction_coefficient"]
    if law["law"] == "coulomb":
        return t0 * np.exp(mu * angle)
    assert law["law"] == "adhesion"
    beta = law["adhesion"]
    alpha_star = 1 / mu - t0 / beta
    return np.where(t0 >= beta / mu, t0 * np.exp(mu * angle),
                    np.where(angle <= alpha_star, t0 + beta * angle,
                             beta / mu * np.exp(mu * (angle - alpha_star))))


def critical(law: dict, t0, angle):
    if law["law"] == "decaying_adhesion":
        return critical_rk4(law, t0, angle)
    return critical_closed_form(law, t0, angle)


def test_reference_critical_tensions():
    """The references used below: closed forms against RK4, and RK4 converged (halving
    its step changes the result by far less than CLOSED_FORM_RTOL)."""
    t0, angle = np.meshgrid(np.r_[0.0, np.geomspace(1e-3, 1.0, 30)], np.linspace(0, 8, 25))
    for name in ("coulomb", "adhesion"):
        np.testing.assert_allclose(critical_closed_form(LAWS[name], t0, angle),
                                   critical_rk4(LAWS[name], t0, angle), rtol=1e-11, atol=0)
    law = LAWS["decaying_adhesion"]
    coarse, fine = critical_rk4(law, t0, angle), critical_rk4(law, t0, angle, n=8000)
    change = np.max(np.abs(coarse - fine) / fine[angle > 0].min())
    print("decaying adhesion RK4, change on halving the step:", change)
    assert change < 1e-3 * CLOSED_FORM_RTOL
    # Spot values of the decaying law by hand: linear up to w_d, T < s_d, T* then Coulomb.
    mu, beta, w, s = (law[k] for k in ("friction_coefficient", "adhesion", "decay_start",
                                       "decay_end"))
    assert critical_rk4(law, 0.0, 0.5 * w / beta) == pytest.approx(0.5 * w, rel=1e-13)
    star = beta * s / (mu * (s - w) + beta)
    assert critical_rk4(law, star, 2.0) == pytest.approx(star * np.exp(2 * mu), rel=1e-13)


# --------------------------------------------------------------------------------------
# Scenes

def with_contacts(text: str, *contacts: dict) -> str:
    """Append &contact groups (groups may come in any order)."""
    return text + "".join(group("contact", **c) for c in contacts)


def run_scene(run_yarnfort, tmp_path, name: str, text: str, ok: bool = True):
    folder = tmp_path / name
    folder.mkdir()
    run = run_yarnfort(text, cwd=folder)
    if ok:
        assert run.returncode == 0, run.stderr
    return run, read_curve(folder / "out"), read_states(folder / "out")


def wrap_angles(position: np.ndarray, path: list[int]) -> np.ndarray:
    """alpha = pi - gamma at each interior node of `path` (0-based node indices)."""
    a = position[path[:-2]] - position[path[1:-1]]
    b = position[path[2:]] - position[path[1:-1]]
    cos_gamma = np.sum(a * b, axis=1) / np.linalg.norm(a, axis=1) / np.linalg.norm(b, axis=1)
    return np.pi - np.arccos(np.clip(cos_gamma, -1.0, 1.0))


def peg_scene(pegs, first, last, contact: dict | None, scheme: str = "monolithic",
              first_fix: str = "xyz", first_force=(0.0, 0.0, 0.0), pull=(0.0, -0.3, 0.0),
              path=None, solver=None, peg_offset=0.2):
    """One yarn first -> pegs -> last over fixed pegs. A peg is a contact node held in
    place, which makes it the end of a short 'peg' yarn to a fixed anchor (a node only
    becomes a contact node where two yarns meet). The last node is pulled by `pull`
    (displacement control); the first is held in `first_fix` and loaded by `first_force`
    (force control). Nodes: 1 = first, 2..K+1 = pegs, K+2 = last, then the anchors."""
    pegs = np.asarray(pegs, float)
    k = len(pegs)
    anchors = pegs * (1 - peg_offset)
    if np.allclose(anchors, pegs):
        anchors = pegs + [0.0, peg_offset, 0.0]
    nodes = [first, *pegs, last, *anchors]
    yarns = [dict(material="yarn", nodes=list(range(1, k + 3)))]
    yarns += [dict(material="peg", nodes=[2 + i, k + 3 + i]) for i in range(k)]
    supports = [dict(name="first", nodes=[1], fix=first_fix),
                dict(name="pull", nodes=[k + 2], fix="xyz", displacement=list(pull)),
                dict(name="pegs", nodes=list(range(2, k + 2)) + list(range(k + 3, 2 * k + 3)),
                     fix="xyz")]
    loads = [dict(nodes=[1], force=list(first_force))] if any(first_force) else []
    text = scene(nodes=nodes, yarns=yarns, supports=supports, loads=loads,
                 materials=[dict(name="yarn", law="linear", stiffness=YARN_EA),
                            dict(name="peg", law="linear", stiffness=YARN_EA)],
                 path=path or dict(time=[0, 1, 2], p_force=[0, 0, 0], p_disp=[0, 1, 0]),
                 solver={**TIGHT, "max_step": 0.05, "initial_step": 0.05, "scheme": scheme,
                         **(solver or {})},
                 output=dict(folder="out", progress=False))
    if contact is None:
        return text
    return with_contacts(text, dict(materials=["yarn", "peg"], **contact))


def arc_pegs(k: int, start: float = 150.0, stop: float = 30.0):
    theta = np.radians(np.linspace(start, stop, k)) if k > 1 else np.array([np.pi / 2])
    return np.column_stack([np.cos(theta), np.sin(theta), np.zeros(k)])


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
    text = peg_scene(arc_pegs(k), [-1, -1, 0], [1, -1, 0], LAWS[law], scheme)
    run, curve, states = run_scene(run_yarnfort, tmp_path, "capstan", text)
    scale = max(np.max(s.tension) for s in states)
    errors, directions = [], set()
    for i, state in enumerate(states):
        if curve["slipping"][i] != k or curve["direction"][i] == 0:
            continue
        angle = wrap_angles(state.position, list(range(k + 2))).sum()
        t_first, t_last = np.maximum(state.tension[[0, k]], 0.0)
        t_lo, t_hi = (t_first, t_last) if curve["direction"][i] > 0 else (t_last, t_first)
        if t_hi < 1e-3 * scale:     # everything slack: 0 = 0 says nothing
            continue
        errors.append(abs(t_hi - critical(LAWS[law], t_lo, angle)) / t_hi)
        directions.add(int(curve["direction"][i]))
    print(f"K={k} {law} {scheme}: {len(errors)} gross-slip steps, max rel. error "
          f"{max(errors):.2e}, Newton iterations {int(curve['newton_iterations'].sum())}")
    assert 1 in directions and len(errors) >= 5
    assert max(errors) <= CLOSED_FORM_RTOL
