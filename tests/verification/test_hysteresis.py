# SPDX-License-Identifier: MIT
"""Hysteresis of one yarn over one frictional pin, against a piecewise closed form.

Scene
-----
A yarn of linear law f(lambda) = EA (lambda - 1) runs A -> C -> B. A is fixed, C is a
fixed pin (the end of a short 'peg' yarn to a fixed anchor, so C is a contact node and
only the yarn slides there), and B is pulled along the ray from C through B:
x_B = C + (l_b0 + d) e_B. A, C and the direction of CB never change, so the wrap angle
alpha = pi - angle(CA, CB) is constant and every node position is prescribed: the only
unknown is the flow s, the reference length moved from element a = A-C to element
b = C-B (passage flow, paper eq. 22). Both strings start stress free (L0 = length):

    L0_a = l_a - s,           l_a fixed,         T_a(s)    = EA s / (l_a - s),
    L0_b = l_b0 + s,          l_b = l_b0 + d,    T_b(s, d) = EA (d - s) / (l_b0 + s).

The reaction of the support at B on the net, along e_B, is T_b (the string pulls B
toward C). String a never goes slack (s >= 0). String b goes slack (T_b = 0) when
s >= d, which only a release to small d brings about (the main cases release to
d = 0.05 m and stay taut; a full release to d = 0 is tested separately).

Friction law at C (T_min, T_max the smaller and larger tension; stick iff
T_max <= T_crit(T_min, alpha)):
- coulomb: T_crit = T_min exp(mu alpha);
- adhesion, T' = max(mu T, beta) (paper eq. 35 with alpha* = 1/mu - T0/beta, T0 =
  T_min: the wrap angle at which T' = beta brings T0 to beta/mu), three branches of T0:
    (L) T0 <= tau_1 = (beta/mu)(1 - mu alpha):  T_crit = T0 + beta alpha,
    (M) tau_1 < T0 < tau_2 = beta/mu:          T_crit = (beta/mu) exp(mu alpha - 1 + mu T0/beta),
    (E) T0 >= tau_2:                           T_crit = T0 exp(mu alpha).
  (tau_1 < 0 when mu alpha > 1: no L branch, even at T0 = 0.)

Stick and slip as a play operator
---------------------------------
Increasing s lowers T_b and raises T_a, and T_crit is increasing in T_min, so
g_f(s, d) = T_b - T_crit(T_a) is strictly decreasing and g_r(s, d) = T_a - T_crit(T_b)
strictly increasing in s. Forward slip (material a -> b, T_b = T_crit(T_a)) holds at
s = s_f(d), the root of g_f; reverse slip (b -> a, T_a = T_crit(T_b)) at s = s_r(d),
the root of g_r. The yarn sticks iff s_f(d) <= s <= s_r(d) (non-empty since
T_crit(T) >= T). Both s_f and s_r increase with d. Quasi-statically, on any interval of
monotone d the sliding is therefore the play operator

    s(d) = clip(s(d_0), s_f(d), s_r(d)),

and for a piecewise-monotone path the clip is applied knot after knot. Phases:
1. stick: s frozen, T_b = EA (d - s)/(l_b0 + s) linear in d, T_a constant;
2. forward slip (loading): s = s_f(d) > s_old;
3. stick after the reversal: T_b falls linearly until T_a = T_crit(T_b);
4. reverse slip (unloading): s = s_r(d) < s_old;
then again 1-4 for the second cycle (its loading sticks until s_f(d) reaches the
s left by the first unloading). With Coulomb and no pre-tension, phase 1 of the first
loading has zero length (T_min = 0 gives T_crit = 0).

Exact s on the affine branches (Coulomb, adhesion E and L): T_max = c1 T_min + c0 with
(c1, c0) = (exp(mu alpha), 0) or (1, beta alpha). Multiplying out the denominators
(l_a - s)(l_b0 + s) > 0 gives a quadratic a s^2 + b s + c = 0, with k = EA:
- forward (T_b = c1 T_a + c0):
    a = k (1 - c1) + c0,
    b = -k (d + l_a + c1 l_b0) + c0 (l_b0 - l_a),
    c = l_a (k d - c0 l_b0);
- reverse (T_a = c1 T_b + c0):
    a = k (1 - c1) + c0,
    b = k (l_b0 + c1 (d + l_a)) - c0 (l_a - l_b0),
    c = -l_a (c1 k d + c0 l_b0).
It has exactly one root in the search interval (forward: s_old <= s <= min(d, l_a);
reverse: 0 <= s <= s_old), asserted; it is taken in the cancellation-free form
q = -(b + sign(b) sqrt(b^2 - 4ac))/2, s = q/a or c/q.
Reverse slip into a slack b (T_b = 0, when T_a(d) <= T_crit(0)): T_a = T_crit(0), so
s = tau l_a/(k + tau) with tau = T_crit(0): beta alpha for adhesion with mu alpha <= 1,
and 0 for Coulomb (everything slides back). Then the relations above apply with s <= d.
The branch is found first: T_min(s) is monotone in s, so the branch thresholds tau_1,
tau_2 map to explicit s (forward: T_a = tau -> s = tau l_a/(k + tau); reverse:
T_b = tau -> s = (k d - tau l_b0)/(k + tau)), and the sign of g there tells which
branch holds the root. On branch M the relation is transcendental (exp of a rational
function of s); there s is the root of the monotone g by bisection to adjacent floats.

Steps. The continuation lands exactly on every path knot (it never steps over a
reversal), so each solver step goes over monotone d. The clip above is then exact over
any step, including a step where stick turns into slip or back: the closed form is
evaluated at the solver's own d of every converged step, with no path error at all, and
EVERY step is compared, transitions included (no step is left out). A coarse run with
one step per half cycle checks this claim. The closed form's stick test has the solver's
relative slack (friction_tolerance = 1e-9) so that a step ending exactly on a transition
gets one phase label; the force it changes is below that fraction.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from scenes import group, scene
from yarnfort import read_curve, read_states

#: Agreement required with the closed form (force at every step, loop areas, sliding).
CLOSED_FORM_RTOL = 1e-6
#: Relative slack of the closed form's stick test (the solver's friction_tolerance).
STICK_SLACK = 1e-9


# --------------------------------------------------------------------------- case
@dataclass(frozen=True)
class Case:
    """One pull/release scene: geometry, yarn, friction law and load path."""

    law: str = "coulomb"             #: 'coulomb' or 'adhesion'
    mu: float = 0.3                  #: friction coefficient
    beta: float = 0.0                #: adhesion (N), 'adhesion' only
    stiffness: float = 10.0          #: EA (N)
    alpha: float = 2.0               #: wrap angle at C (rad)
    length_a: float = 1.0            #: l_a = |CA| (m)
    length_b: float = 1.0            #: l_b0 = |CB| at d = 0 (m)
    pull: float = 0.2                #: largest pull d_max (m)
    release: float = 0.05            #: d after each release (m), > 0: strings stay taut
    max_step: float = 0.1            #: continuation step (pseudo-time, 1 per half cycle)
    scheme: str = "monolithic"
    #: &solver slack_stiffness. The regularisation adds slack_stiffness * EA * lambda to
    #: every string's tension, taut ones too (a relative change ~ slack_stiffness/strain,
    #: 2e-4 here with the default 1e-6), so the exact law needs 0. Every node is
    #: prescribed, so even a slack string b leaves no singular tangent.
    slack_stiffness: float = 0.0

    @property
    def knots(self) -> list[float]:
        """Pulled and released twice: d = 0 -> max -> release -> max -> release."""
        return [0.0, self.pull, self.release, self.pull, self.release]

    def directions(self) -> tuple[np.ndarray, np.ndarray]:
        """Unit vectors C->A and C->B (in the x-y plane, no axis-aligned shortcut)."""
        theta_a = math.radians(200.0)
        theta_b = theta_a + (math.pi - self.alpha)
        return (np.array([math.cos(theta_a), math.sin(theta_a), 0.0]),
                np.array([math.cos(theta_b), math.sin(theta_b), 0.0]))


def hysteresis_scene(case: Case, folder: str = "out") -> str:
    """Namelist text: nodes A=1, C=2, B=3, peg anchor 4; yarn 1-2-3, peg 2-4."""
    e_a, e_b = case.directions()
    nodes = [case.length_a * e_a, [0.0, 0.0, 0.0], case.length_b * e_b, [0.0, 0.0, -0.3]]
    contact = dict(materials=["yarn", "peg"], law=case.law, friction_coefficient=case.mu)
    if case.law == "adhesion":
        contact["adhesion"] = case.beta
    text = scene(
        nodes=nodes,
        materials=[dict(name="yarn", law="linear", stiffness=case.stiffness),
                   dict(name="peg", law="linear", stiffness=case.stiffness)],
        yarns=[dict(material="yarn", nodes=[1, 2, 3]), dict(material="peg", nodes=[2, 4])],
        supports=[dict(name="end", nodes=[1], fix="xyz"),
                  dict(name="pin", nodes=[2, 4], fix="xyz"),
                  dict(name="pull", nodes=[3], fix="xyz", displacement=list(e_b))],
        path=dict(time=[0.0, 1.0, 2.0, 3.0, 4.0], p_force=[0.0] * 5, p_disp=case.knots),
        solver=dict(scheme=case.scheme, residual_tolerance=1e-13, max_step=case.max_step,
                    initial_step=case.max_step, slack_stiffness=case.slack_stiffness),
        output=dict(folder=folder, progress=False))
    return text.replace("&path", group("contact", **contact) + "&path")


# -------------------------------------------------------------------- closed form
class ClosedForm:
    """Exact quasi-static sliding s and tensions of the one-pin scene (module docstring)."""

    def __init__(self, case: Case):
        self.case = case
        self.k = case.stiffness
        self.la = case.length_a
        self.lb = case.length_b
        self.exp_mu_alpha = math.exp(case.mu * case.alpha)
        #: Branches of T_crit met by the slip solutions so far ('L', 'M', 'E').
        self.branches: set[str] = set()
        if case.law == "adhesion" and case.beta > 0.0:
            ma = case.mu * case.alpha
            self.tau2 = case.beta / case.mu
            self.tau1 = self.tau2 * (1.0 - ma)   # < 0 when mu alpha > 1: no branch L
        else:
            self.tau1 = self.tau2 = 0.0          # Coulomb: branch E only

    # tensions and law
    def tension_a(self, s: float) -> float:
        return self.k * s / (self.la - s)

    def tension_b(self, s: float, d: float) -> float:
        return self.k * max(d - s, 0.0) / (self.lb + s)      # zero when slack (s >= d)

    def critical(self, t_min: float) -> float:
        c = self.case
        if t_min >= self.tau2:
            return t_min * self.exp_mu_alpha
        if t_min <= self.tau1:
            return t_min + c.beta * c.alpha      # t_min >= 0 > tau1 never gets here
        return self.tau2 * math.exp(c.mu * c.alpha - 1.0 + t_min / self.tau2)

    def g_forward(self, s: float, d: float) -> float:
        return self.tension_b(s, d) - self.critical(self.tension_a(s))

    def g_reverse(self, s: float, d: float) -> float:
        return self.tension_a(s) - self.critical(self.tension_b(s, d))

    # exact roots
    def _affine(self) -> list[tuple[str, float, float]]:
        c = self.case
        out = [("E", self.exp_mu_alpha, 0.0)]
        if c.law == "adhesion" and c.beta > 0.0:
            out.append(("L", 1.0, c.beta * c.alpha))
        return out

    def _quadratic_root(self, a: float, b: float, cc: float, lo: float, hi: float) -> float:
        disc = b * b - 4.0 * a * cc
        assert disc >= 0.0, "no real root"
        q = -0.5 * (b + math.copysign(math.sqrt(disc), b))
        roots = [cc / q] if q != 0.0 else []
        if a != 0.0:
            roots.append(q / a)
        inside = [r for r in roots if lo <= r <= hi]
        assert len(inside) == 1, (roots, lo, hi)
        return inside[0]

    def _bisect(self, g, lo: float, hi: float) -> float:
        """Root of a decreasing g on [lo, hi] (g(lo) >= 0 >= g(hi)) to adjacent floats."""
        while True:
            mid = 0.5 * (lo + hi)
            if not lo < mid < hi:
                return lo if abs(g(lo)) <= abs(g(hi)) else hi
            if g(mid) > 0.0:
                lo = mid
            else:
                hi = mid

    def _branch(self, t_min_root: float) -> str:
        if t_min_root >= self.tau2:
            return "E"
        return "L" if t_min_root <= self.tau1 else "M"

    def s_forward(self, d: float, s_old: float) -> float:
        """s_f(d): root of T_b = T_crit(T_a), searched above s_old (g_f(s_old) > 0)."""
        k, la, lb = self.k, self.la, self.lb
        # Branch: evaluate g_f at the s where T_a crosses tau1, tau2 (g_f decreasing).
        s_tau = lambda tau: tau * la / (k + tau)
        lo, hi = s_old, min(d, la)          # g_f(d) <= 0: T_b(d) = 0
        if self.tau2 > 0.0:
            s2 = s_tau(self.tau2)
            s1 = s_tau(self.tau1) if self.tau1 >= 0.0 else -math.inf
            if s2 <= lo or self.g_forward(s2, d) > 0.0:
                branch = "E"
            elif s1 <= lo or self.g_forward(s1, d) > 0.0:
                branch, lo, hi = "M", max(lo, s1), s2
            else:
                branch = "L"
        else:
            branch = "E"
        if branch == "M":
            s = self._bisect(lambda x: self.g_forward(x, d), lo, hi)
        else:
            c1, c0 = dict((n, (a1, a0)) for n, a1, a0 in self._affine())[branch]
            a = k * (1.0 - c1) + c0
            b = -k * (d + la + c1 * lb) + c0 * (lb - la)
            cc = la * (k * d - c0 * lb)
            s = self._quadratic_root(a, b, cc, s_old, hi)
        assert self._branch(self.tension_a(s)) == branch or self.tau2 == 0.0
        self.branches.add(branch)
        return s

    def s_reverse(self, d: float, s_old: float) -> float:
        """s_r(d): root of T_a = T_crit(T_b), searched below s_old (g_r(s_old) > 0)."""
        k, la, lb = self.k, self.la, self.lb
        if s_old > d and self.g_reverse(d, d) <= 0.0:
            # The root lies where b is slack (s >= d): T_a = T_crit(0) alone.
            tau = self.critical(0.0)
            self.branches.add("slack")
            return tau * la / (k + tau)
        s_tau = lambda tau: (k * d - tau * lb) / (k + tau)   # T_b(s) = tau, decreasing
        lo, hi = 0.0, min(s_old, d)                          # g_r(0) <= 0: T_a(0) = 0
        g = lambda x: -self.g_reverse(x, d)                  # decreasing in s
        if self.tau2 > 0.0:
            s2 = s_tau(self.tau2)
            s1 = s_tau(self.tau1) if self.tau1 >= 0.0 else math.inf
            if s2 >= hi or g(s2) < 0.0:
                branch = "E"
            elif s1 >= hi or g(s1) < 0.0:
                branch, lo, hi = "M", max(lo, s2), min(hi, s1)
            else:
                branch = "L"
        else:
            branch = "E"
        if branch == "M":
            s = self._bisect(g, lo, hi)
        else:
            c1, c0 = dict((n, (a1, a0)) for n, a1, a0 in self._affine())[branch]
            a = k * (1.0 - c1) + c0
            b = k * (lb + c1 * (d + la)) - c0 * (la - lb)
            cc = -la * (c1 * k * d + c0 * lb)
            s = self._quadratic_root(a, b, cc, lo, hi)
        assert self._branch(self.tension_b(s, d)) == branch or self.tau2 == 0.0
        self.branches.add(branch)
        return s

    def advance(self, s_old: float, d: float) -> tuple[float, str]:
        """Clip s_old into the stick interval at d: (s, 'stick'|'forward'|'reverse').

        A violation within STICK_SLACK of T_crit counts as stick, like the solver's
        stick test with its default friction_tolerance (it changes T_b by less than that
        fraction). It keeps the phase label well defined when a step ends exactly on a
        transition (here d = 0.02 m for the adhesion case: T_b = beta alpha = 0.2 N).
        """
        t_a, t_b = self.tension_a(s_old), self.tension_b(s_old, d)
        if t_b > self.critical(t_a) * (1.0 + STICK_SLACK):
            return self.s_forward(d, s_old), "forward"
        if t_a > self.critical(t_b) * (1.0 + STICK_SLACK):
            return self.s_reverse(d, s_old), "reverse"
        return s_old, "stick"

    def follow(self, d: np.ndarray) -> tuple[np.ndarray, np.ndarray, list[str]]:
        """s, T_b and phase at each d of a path of monotone steps (starts at s = 0)."""
        s, out_s, out_t, phases = 0.0, [], [], []
        for di in d:
            s, phase = self.advance(s, float(di))
            assert 0.0 <= s < self.la
            out_s.append(s)
            out_t.append(self.tension_b(s, float(di)))
            phases.append(phase)
        return np.array(out_s), np.array(out_t), phases


# ------------------------------------------------------------------- comparison
@dataclass
class Comparison:
    d: np.ndarray                #: pull d at every converged step
    force: np.ndarray            #: solver: reaction at B along e_B
    force_exact: np.ndarray
    s: np.ndarray                #: solver: l_a - L0_a
    s_exact: np.ndarray
    tension: np.ndarray          #: solver: (n_steps, 2) tensions of a and b (VTK states)
    tension_exact: np.ndarray
    phases: list[str]
    slipping: np.ndarray         #: solver's slipping passages per step
    alpha: np.ndarray            #: wrap angle at C from the written positions
    unload_steps: list[int]      #: step indices at the end of each release
    branches: set[str]           #: branches of T_crit the closed form's slips met
    on_surface: np.ndarray       #: closed form sticks with T_max = T_crit (zero flow)

    def flag_mismatches(self) -> list[int]:
        """Steps (after the first) where the solver's slipping flag differs from the
        closed form's phase. A stick step that sits exactly on the slip surface (only
        after a release into a slack string b: T_b = 0, T_a = T_crit(0), zero flow) is
        either; the solver may keep its slip mode there with a zero flow increment."""
        return [i for i in range(1, len(self.d))
                if int(self.slipping[i] > 0) != int(self.phases[i] != "stick")
                and not self.on_surface[i]]

    def force_error(self) -> float:
        """Max relative error of the force (absolute at the zero-force first step)."""
        scale = np.where(self.force_exact > 0.0, self.force_exact, 1.0)
        return float(np.max(np.abs(self.force - self.force_exact) / scale))

    def cycles(self) -> list[slice]:
        return [slice(0, self.unload_steps[0] + 1),
                slice(self.unload_steps[0], self.unload_steps[1] + 1)]

    def areas(self) -> tuple[np.ndarray, np.ndarray]:
        """Integral of force d(d) over each cycle (trapezoid on the step points)."""
        trap = lambda f, x: float(np.sum(0.5 * (f[1:] + f[:-1]) * np.diff(x)))
        solver = [trap(self.force[c], self.d[c]) for c in self.cycles()]
        exact = [trap(self.force_exact[c], self.d[c]) for c in self.cycles()]
        return np.array(solver), np.array(exact)


def compare(case: Case, folder: Path) -> Comparison:
    """Read a finished run and evaluate the closed form at its steps."""
    curve = read_curve(folder)
    states = read_states(folder)
    assert len(states) == len(curve["step"]), "need a VTK state for every step"
    e_a, e_b = case.directions()
    d = curve["p_disp"]
    force = curve.reaction("pull") @ e_b
    closed_form = ClosedForm(case)
    s_exact, t_exact, phases = closed_form.follow(d)
    for st in states:                    # element 0 is a = A-C, element 1 is b = C-B
        assert st.elements[:2].tolist() == [[0, 1], [1, 2]]
    s = np.array([case.length_a - st.length0[0] for st in states])
    tension = np.array([st.tension[:2] for st in states])
    tension_exact = np.column_stack([[closed_form.tension_a(x) for x in s_exact], t_exact])
    alpha = []
    for st in states:
        ca = st.position[0] - st.position[1]
        cb = st.position[2] - st.position[1]
        cos_g = ca @ cb / np.linalg.norm(ca) / np.linalg.norm(cb)
        alpha.append(math.pi - math.acos(max(-1.0, min(1.0, cos_g))))
    # The last step at each release knot (time 2 and 4).
    unload = [int(np.argmin(np.abs(curve["time"] - t))) for t in (2.0, 4.0)]
    ratio = 1.0 - STICK_SLACK
    on_surface = np.array([
        phase == "stick" and (ta >= closed_form.critical(tb) * ratio
                              or tb >= closed_form.critical(ta) * ratio)
        for phase, (ta, tb) in zip(phases, tension_exact)])
    return Comparison(d.copy(), force, t_exact, s, s_exact, tension, tension_exact, phases,
                      curve["slipping"], np.array(alpha), unload, closed_form.branches,
                      on_surface)


def run_case(run, case: Case, folder: Path) -> Comparison:
    result = run(hysteresis_scene(case), cwd=folder)
    assert result.returncode == 0, result.stderr
    return compare(case, folder / "out")


# ------------------------------------------------------------------------ tests
CASES = {
    "coulomb": Case(law="coulomb", mu=0.3),
    # beta/mu = 1/3 N and (beta/mu)(1 - mu alpha) = 0.133 N: the loading visits the
    # linear, the mixed and the exponential branch of T_crit.
    "adhesion": Case(law="adhesion", mu=0.3, beta=0.1),
}


def test_closed_form_quadratic_roots_satisfy_the_slip_relations():
    """The quadratic (and bisection) roots are zeros of the unreduced relations."""
    for case in CASES.values():
        cf = ClosedForm(case)
        for d in np.linspace(case.release, 0.3, 17):   # taut strings only
            s = cf.s_forward(d, 0.0)
            assert cf.tension_b(s, d) == pytest.approx(cf.critical(cf.tension_a(s)),
                                                       rel=1e-13)
            s_top = cf.s_forward(0.3, 0.0)
            if cf.g_reverse(s_top, d) > 0.0:
                s = cf.s_reverse(d, s_top)
                assert cf.tension_a(s) == pytest.approx(cf.critical(cf.tension_b(s, d)),
                                                        rel=1e-13)


@pytest.mark.parametrize("scheme", ["monolithic", "staggered"])
@pytest.mark.parametrize("name", list(CASES))
def test_hysteresis_loop_matches_closed_form(run_yarnfort, tmp_path, name, scheme):
    case = Case(**{**CASES[name].__dict__, "scheme": scheme})
    cmp = run_case(run_yarnfort, case, tmp_path)

    # The scene is what the closed form assumes: constant wrap angle, every phase.
    np.testing.assert_allclose(cmp.alpha, case.alpha, rtol=0, atol=1e-12)
    for phase in ("stick", "forward", "reverse"):
        assert phase in cmp.phases[1:]
    assert cmp.branches == ({"L", "M", "E"} if case.law == "adhesion" else {"E"})
    assert np.all(cmp.force_exact[1:] > 0)              # taut: relative errors defined
    # Stick/slip of the solver agrees with the closed form's phase at every step.
    assert cmp.flag_mismatches() == []

    # Force at every converged step, transitions included; element tensions too.
    assert cmp.force_error() <= CLOSED_FORM_RTOL
    np.testing.assert_allclose(cmp.tension, cmp.tension_exact, rtol=CLOSED_FORM_RTOL,
                               atol=1e-15)
    # Loop area of each cycle, on the same points.
    area, area_exact = cmp.areas()
    np.testing.assert_allclose(area, area_exact, rtol=CLOSED_FORM_RTOL)
    assert np.all(area_exact > 0)
    # Permanent sliding left after each release (L0 of element a).
    for i in cmp.unload_steps:
        assert cmp.s_exact[i] > 0
        assert cmp.s[i] == pytest.approx(cmp.s_exact[i], rel=CLOSED_FORM_RTOL)
    np.testing.assert_allclose(cmp.s, cmp.s_exact, rtol=CLOSED_FORM_RTOL, atol=1e-15)


def test_hysteresis_coarse_steps_still_exact(run_yarnfort, tmp_path):
    """One step per half cycle jumps over every stick/slip transition: the one-node play
    operator is exact over any monotone step, so the knots still match exactly."""
    case = Case(law="adhesion", mu=0.3, beta=0.1, max_step=1.0)
    cmp = run_case(run_yarnfort, case, tmp_path)
    assert len(cmp.d) == 5
    assert cmp.force_error() <= CLOSED_FORM_RTOL
    np.testing.assert_allclose(cmp.s, cmp.s_exact, rtol=CLOSED_FORM_RTOL, atol=1e-15)


@pytest.mark.parametrize("name", list(CASES))
def test_full_release_with_slack_string(run_yarnfort, tmp_path, name):
    """Released to d = 0: string b goes slack. Adhesion then holds T_a = beta alpha with
    T_b = 0 and keeps s = beta alpha l_a / (EA + beta alpha); Coulomb slides back to
    s = 0. Forces are compared absolutely where the closed form gives zero."""
    case = Case(**{**CASES[name].__dict__, "release": 0.0})
    cmp = run_case(run_yarnfort, case, tmp_path)
    assert "slack" in cmp.branches
    assert cmp.force_error() <= CLOSED_FORM_RTOL
    np.testing.assert_allclose(cmp.tension, cmp.tension_exact, rtol=CLOSED_FORM_RTOL,
                               atol=1e-12)
    area, area_exact = cmp.areas()
    np.testing.assert_allclose(area, area_exact, rtol=CLOSED_FORM_RTOL)
    assert cmp.flag_mismatches() == []
    if case.law == "adhesion":
        hold = case.beta * case.alpha          # T_crit(0), mu alpha = 0.6 <= 1
        s_left = hold * case.length_a / (case.stiffness + hold)
    else:
        s_left = 0.0
    for i in cmp.unload_steps:
        assert cmp.force_exact[i] == 0.0 and abs(cmp.force[i]) <= 1e-12
        assert cmp.s_exact[i] == pytest.approx(s_left, rel=1e-14, abs=1e-15)
        assert cmp.s[i] == pytest.approx(s_left, rel=CLOSED_FORM_RTOL, abs=1e-12)
