# SPDX-License-Identifier: MIT
"""Stability at the extremes: every case converges to the right answer, checked against
a closed form or a limit written here, or stops cleanly (exit code 1, one
"error (solve)" line on stderr, every converged step kept in curve.csv). In every case
no output (curve.csv, VTK states, input.nml) holds NaN or Inf, and no run may take more
than RUN_TIMEOUT seconds (subprocess timeout: a hang fails the test).

Scenes
------
pin      one yarn A -> C -> B over one fixed pin C (test_hysteresis.py's scene): every
         node prescribed, the wrap angle alpha at C constant, the only unknown the flow
         s through C. slack_stiffness = 0 (the exact tension-only law). Pulled along
         C->B by d over a piecewise monotone path; the exact answer is the play operator
         s(d) = clip(s_old, s_f(d), s_r(d)) of test_hysteresis.py, with s_f, s_r solved
         here by bisection to adjacent floats for ANY force law f and any T_crit
         (`PinClosedForm`), and a minimum reference length as a bound on s.
capstan  one yarn over three fixed pegs (inputs/capstan.nml, test_friction.peg_net),
         pulled by 0.3 and released. In gross slip (every passage slipping) the end
         tensions obey T_hi = T_crit(T_lo, A), A the summed wrap angle.
chain    two strings in series along x, the shared node free along x; displacement
         controlled: a table law then a linear one, or two neo-Hookean strings.

T_crit closed forms (`critical_tension`) are solved from each law's ODE here, overflow
to inf instead of a float error, and are checked against numerical quadrature of the ODE
(test_friction.angle_to_reach) and the flow property of the ODE in
test_closed_forms_at_extreme_parameters.

Accuracy. CLOSED_FORM_RTOL = 1e-8 relative, plus TENSION_ATOL = 1e-11 N (the Newton
tolerance, residual_tolerance * force_scale) where a tension is zero or where it enters
T_crit: a low-side tension known to +-TENSION_ATOL gives T_crit only within
[T_crit(T - atol), T_crit(T + atol)], an interval that is exp(mu alpha) times wider (the
capstan's gross slip is checked in that interval form, as tight as the data allow).
Flows s are compared to LENGTH_ATOL = 1e-15 m besides (a reference length of 1 m is
stored to 1.1e-16).

Matrix (m+s: both schemes, monolithic and staggered)
------------------------------------------------------------------------------------------
case                                   scene    checks
------------------------------------------------------------------------------------------
mu = 0, 1e-8, 0.3, 10, 1e4             pin      every step against the closed form (force,
  coulomb and adhesion (beta=0.1), m+s          s, both tensions); mu = 0 coulomb: T_a =
                                                T_b while slipping (frictionless); mu =
                                                1e4: sticks (|s| <= 1e-15, T_b = EA d/l_b)
mu = 0, 1e-8, 0.3, 10, 1e4             capstan  gross slip T_hi = T_crit(T_lo, A) (interval
  coulomb and adhesion (beta=0.05),             form); mu = 0 coulomb: one tension along
  exact law (starts at zero tension)            the yarn, EA (l/L - 1) of its polyline
                                                length; mu = 1e4: no L0 changes, first
                                                tension 0, last one elastic
beta = 0, 1e-12, 0.1, 1e3 (mu = 0.3)   pin      closed form; beta = 0: also the coulomb
  adhesion, m+s                                 closed form; beta = 1e3: never slips,
                                                s = 0 exactly, T_b = EA d / l_b
decaying: s_d - w_d = 1e-9, 1e-14      pin      closed form of the decaying law
decaying: w_d = 0                      pin      closed form of the decaying law
decaying: mu w_d > beta, mu w_d = beta pin      closed form of the PLAIN adhesion law
slack start: pushed 0.3 up, then       capstan  tensions at the regularisation's level
  pulled 0.3 down (default slack_stiffness)     while slack; then gross slip obeys T_crit
stretch to 3x: neo-Hookean, coulomb    pin      closed form with f = S1 C (lambda -
                                                lambda^-2) at every step, lambda_b > 3
table law with flat (1e-3 N) and       chain    at every table knot: reaction = the knot's
  steep (1e4 N) slopes, up to 3x                force, node at 1 + the knot's strain
minimum length: mu = 0, ratio 0.9      pin      closed form with the lock s <= 0.1 l_a;
                                                L0_a never below 0.9 l_a, locked a while
minimum length: ratio 0.05 (default),  pin      closed form; element a down to 5 % of its
  coulomb pulled to d = 80                      length (stretch 20), then released
alpha = 0 (collinear), 1e-9            pin      closed form; |T_b - T_a| <= T_crit(T_a) -
  (coulomb mu = 1e4; adhesion beta=1e3)         T_a, i.e. no friction resistance
alpha = pi (folded back), pi - 1e-9    pin      closed form (adhesion: every phase)
stiff yarn: EA = 1e5 P, a ring from   ring     every step against test_defaults.py's
  the stress-free start far from its            play-operator reference (1e-8 of span
  place, coulomb mu = 0.3, m+s                  and load)
hundreds of step cuts, finishing:      pin      > 200 cuts (410 measured), every step at
  3x in one step, max_iterations = 2,           the closed form
  step_cut = 0.99
hundreds of step cuts, giving up:      chain    exit 1 after exactly 301 cuts, one
  max_iterations = 1, max_step_cuts =           "error (solve)" line saying so, the
  300, step_cut = 0.99                          converged steps kept
------------------------------------------------------------------------------------------

Bugs these cases exposed, fixed in the code:
- Kink of max(T, 0) (contact/friction_problem.f90): with the exact law (slack_stiffness
  = 0) every string of the stress-free start sits at stretch 1; the slip row's Jacobian
  took the flat side's slope 0 there, so T_crit lost its dependence on the low-side
  tension and the first Newton step overshot the flow by exp(mu alpha): coulomb mu = 10
  and 1e4 on the pin stopped ("line search ... unable to find an iterate", resp. an
  element "has length" error after the flow ran away).
- Ill-conditioned slip rows (contact/friction_problem.f90, solver/newton.f90): a slip
  row T_crit(T_min) - T_max cannot reach residual_tolerance once exp(mu alpha) is
  large, since T_min = EA (lambda - 1) carries a rounding error of EA epsilon that
  T_crit multiplies by exp(mu alpha) (mu alpha = 20: stalled at 5.7e-8 * force_scale).
  Slip rows are now divided by max(1, dT_crit/dT_min), fixed per Newton solve.
- Spurious solutions with L0 <= 0 (contact/friction_problem.f90, solver/newton.f90):
  pulled hard (pin, d = 4 -> 8), Newton overshot the flow to L0_a = -7 m, where a
  string counts as slack, and "converged" there (T = 0 = T_crit(0)); the stepper then
  locked the passage at its minimum length, 16 % off in force for 8 steps. Newton now
  rejects a solution with any L0 <= 0, and the step is retried.
- Step cuts undone (solver/continuation.f90): a cut step ending within a quarter step
  of the next knot was stretched back to the knot, so with step_cut > 0.8 a failing
  step was retried unchanged until max_step_cuts. Only uncut steps are stretched now.
"""
from __future__ import annotations

import math
import re
import sys
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Callable

import numpy as np
import pytest

from scenes import group, scene
from test_defaults import (FORCE_RTOL, FRICTION_START, POSITION_RTOL, RING_A, RING_B,
                           RING_LOAD, RING_MU, RING_STIFFNESS, admissible_splits,
                           ring_errors, ring_namelist, stuck_ring)
from test_friction import angle_to_reach, arc_pegs, namelist, peg_net, wrap_angles
from yarnfort import read_curve, read_states

#: No single run may take longer (seconds); a hang fails the test.
RUN_TIMEOUT = 60.0
#: Agreement required with closed forms (relative).
CLOSED_FORM_RTOL = 1e-8
#: Absolute accuracy of a computed tension (N): the Newton tolerance of these scenes,
#: residual_tolerance * force_scale = 1e-12 * 10 N (pin: 1e-13 * 10 N).
TENSION_ATOL = 1e-11
#: Absolute accuracy of a flow (m): a reference length of 1 m is stored to 1.1e-16.
LENGTH_ATOL = 1e-15
#: Relative slack of the solver's stick test (&solver friction_tolerance default).
STICK_SLACK = 1e-9
#: Largest exponent whose exp() is a finite double.
MAX_LOG = math.log(sys.float_info.max)
PI = math.pi


# --------------------------------------------------------------------------------------
# Closed forms of T_crit(T0, alpha), overflow-safe (inf when the true value is beyond
# the largest double).

def scaled_exp(scale: float, exponent: float) -> float:
    """scale * exp(exponent) for scale >= 0; inf when it overflows a double."""
    if scale <= 0.0:
        return 0.0
    if exponent < MAX_LOG:
        return scale * math.exp(exponent)       # inf if the product overflows
    x = exponent + math.log(scale)
    return math.exp(x) if x < MAX_LOG else math.inf


def critical_tension(law: dict, t0: float, alpha: float) -> float:
    """T_crit(T0, alpha) of a &contact law (dict as in the namelist), from the ODE
    T' = g(T), T(0) = T0:
    - coulomb, g = mu T: T0 exp(mu alpha);
    - adhesion, g = max(mu T, beta): T0 exp(mu alpha) if mu T0 >= beta; else
      T0 + beta alpha up to alpha* = 1/mu - T0/beta, then (beta/mu) exp(mu (alpha -
      alpha*)); mu = 0: T0 + beta alpha;
    - decaying_adhesion, g = max(beta min(1, (s_d - T)/(s_d - w_d)), mu T): plain
      adhesion if mu w_d >= beta; else linear T0 + beta alpha up to w_d, relaxation
      T = s_d - (s_d - T) exp(-k a) (k = beta/(s_d - w_d)) up to T* = s_d - gap*,
      gap* = s_d mu (s_d - w_d)/(mu (s_d - w_d) + beta) (where it meets mu T; the gap is
      formed directly, not as a difference of nearby numbers), then Coulomb from T*.
      Each piece starts where the last one stopped (the ODE is autonomous)."""
    mu = law.get("friction_coefficient", 0.0)
    beta = law.get("adhesion", 0.0)
    kind = law["law"]
    if kind == "coulomb" or beta == 0.0:
        return scaled_exp(t0, mu * alpha)
    if kind == "decaying_adhesion" and mu * law["decay_start"] < beta:
        w, s = law["decay_start"], law["decay_end"]
        if t0 > s and mu == 0.0:
            return t0                           # g = 0 above s_d
        k = beta / (s - w)
        gap_star = s * (mu * (s - w) / (mu * (s - w) + beta))
        t_star = s - gap_star
        if t0 > t_star:
            return scaled_exp(t0, mu * alpha)
        t, left = t0, alpha
        if t < w:
            used = (w - t) / beta
            if left <= used:
                return t + beta * left
            t, left = w, left - used
        gap = s - t
        to_star = math.log(gap / gap_star) / k if gap_star > 0.0 else math.inf
        if left <= to_star:
            return t - gap * math.expm1(-k * left)     # s - gap e^(-k left), no cancellation
        return scaled_exp(t_star, mu * (left - to_star))
    # adhesion (also decaying_adhesion with mu w_d >= beta)
    if mu == 0.0:
        return t0 + beta * alpha
    if mu * t0 >= beta:
        return scaled_exp(t0, mu * alpha)
    alpha_star = 1.0 / mu - t0 / beta
    if alpha <= alpha_star:
        return t0 + beta * alpha
    return scaled_exp(beta / mu, mu * alpha - 1.0 + mu * t0 / beta)


def kinks(law: dict) -> list[float]:
    """Tensions where the law's rate g has a kink (quadrature breakpoints)."""
    mu, beta = law.get("friction_coefficient", 0.0), law.get("adhesion", 0.0)
    if law["law"] == "decaying_adhesion" and mu * law["decay_start"] < beta:
        w, s = law["decay_start"], law["decay_end"]
        return [w, s - s * (mu * (s - w) / (mu * (s - w) + beta))]
    return [beta / mu] if mu > 0 and beta > 0 else []


def adhesion_law(mu: float, beta: float) -> dict:
    return dict(law="adhesion", friction_coefficient=mu, adhesion=beta)


def coulomb_law(mu: float) -> dict:
    return dict(law="coulomb", friction_coefficient=mu)


def decaying_law(mu: float, beta: float, w: float, s: float) -> dict:
    return dict(law="decaying_adhesion", friction_coefficient=mu, adhesion=beta,
                decay_start=w, decay_end=s)


def test_closed_forms_at_extreme_parameters():
    """critical_tension for the parameter sets of the matrix:
    - against quadrature of its ODE (test_friction.angle_to_reach: the angle the ODE
      needs from T0 to the closed form's value must be alpha), where that is well
      conditioned (growth T1/T0 between 1.001 and 100, or T0 = 0 < T1 <= 1 N: the
      quadrature of 1/g loses the digits of T1 - T0 below, and resolves 1/g = 1/(mu T)
      over many decades only with very many pieces above);
    - everywhere, also where it overflows: the flow property of an autonomous ODE,
      T_crit(T_crit(T0, a), b) = T_crit(T0, a + b), and T_crit(T0, 0) = T0;
    - the reductions (beta = 0 is Coulomb, mu w_d >= beta is plain adhesion); overflow
      is inf, never an exception or NaN."""
    laws = [coulomb_law(1e-8), coulomb_law(10.0), coulomb_law(1e4), adhesion_law(0.0, 0.1),
            adhesion_law(1e-8, 0.1), adhesion_law(10.0, 0.1), adhesion_law(1e4, 0.1),
            adhesion_law(0.3, 1e-12), adhesion_law(0.3, 1e3),
            decaying_law(0.3, 0.2, 0.5, 0.5 + 1e-9), decaying_law(0.3, 0.2, 0.5, 0.5 + 1e-14),
            decaying_law(0.3, 0.1, 0.0, 0.3), decaying_law(0.0, 0.1, 0.2, 0.4)]
    tensions = (0.0, 1e-6, 0.05, 0.3, 0.5, 0.5 + 5e-15, 0.5 + 1e-9, 1.0, 3.0)
    angles = (1e-9, 0.1, 0.7, 1.0, 2.0, PI)
    worst_quadrature, worst_flow, quadratures = 0.0, 0.0, 0
    for law in laws:
        for t0 in tensions:
            assert critical_tension(law, t0, 0.0) == t0
            for alpha in angles:
                t1 = critical_tension(law, t0, alpha)
                assert t1 >= t0 and not math.isnan(t1)
                for split in (0.25, 0.5):
                    t_half = critical_tension(law, t0, split * alpha)
                    t2 = critical_tension(law, t_half, (1 - split) * alpha)
                    if math.isinf(t1):
                        assert math.isinf(t2) or t2 > 1e300
                    else:
                        worst_flow = max(worst_flow, abs(t2 - t1) / t1 if t1 > 0 else t2)
                conditioned = (1.001 * t0 <= t1 <= 100 * t0) if t0 > 0 else (0 < t1 <= 1.0)
                if conditioned:
                    angle = angle_to_reach(law, t0, t1, kinks(law), pieces=64)
                    worst_quadrature = max(worst_quadrature, abs(angle - alpha) / alpha)
                    quadratures += 1
    print(f"closed forms at extreme parameters: {quadratures} against quadrature, max "
          f"relative angle error {worst_quadrature:.1e}; flow property max relative "
          f"error {worst_flow:.1e}")
    assert quadratures >= 100
    assert worst_quadrature < 1e-9
    assert worst_flow < 1e-12
    for t0 in (0.0, 0.1, 2.0):
        for alpha in (0.5, 2.0):
            assert critical_tension(adhesion_law(0.3, 0.0), t0, alpha) == \
                critical_tension(coulomb_law(0.3), t0, alpha)
            for w in (0.5, 0.2):           # mu w_d = 0.15 > 0.1 and mu w_d = beta exactly
                mu = 0.3 if w == 0.5 else 0.5
                assert critical_tension(decaying_law(mu, 0.1, w, 0.8), t0, alpha) == \
                    critical_tension(adhesion_law(mu, 0.1), t0, alpha)
    assert critical_tension(coulomb_law(1e4), 1.0, 2.0) == math.inf
    assert critical_tension(coulomb_law(1e4), 0.0, 2.0) == 0.0
    assert critical_tension(adhesion_law(1e4, 0.1), 0.0, 2.0) == math.inf
    assert critical_tension(coulomb_law(0.0), 0.7, 2.0) == 0.7


# --------------------------------------------------------------------------------------
# Running a case and checking its outputs.

@dataclass
class Outcome:
    returncode: int
    stderr: str
    folder: Path
    curve: object
    states: list


def run_case(run_yarnfort, tmp_path: Path, name: str, text: str) -> Outcome:
    """Run a scene in tmp_path/name (made if missing; output folder 'out', a VTK state
    per step) within RUN_TIMEOUT; the run must succeed or stop cleanly, and every output
    must be finite."""
    folder = tmp_path / name
    folder.mkdir(exist_ok=True)
    run = run_yarnfort(text, cwd=folder, timeout=RUN_TIMEOUT)
    out = folder / "out"
    assert run.returncode in (0, 1), run.stderr
    if run.returncode == 1:
        errors = [line for line in run.stderr.splitlines()
                  if line.startswith("yarnfort: error")]
        assert len(errors) == 1 and errors[0].startswith("yarnfort: error (solve): "), \
            run.stderr
    curve = read_curve(out)
    states = read_states(out)
    assert_finite_outputs(out, curve, states)
    return Outcome(run.returncode, run.stderr, folder, curve, states)


def assert_finite_outputs(out: Path, curve, states) -> None:
    """No NaN or Inf in curve.csv, the VTK states or input.nml; one state per row."""
    for name in curve.names:
        assert np.all(np.isfinite(curve[name])), f"curve.csv column {name}"
    assert len(states) == len(curve["step"]) >= 1
    for s in states:
        for values in (s.position, s.tension, s.stretch, s.length0):
            assert np.all(np.isfinite(values))
    text = (out / "input.nml").read_text()
    assert not re.search(r"\b(nan|inf|infinity)\b", text, re.IGNORECASE)
    for path in out.glob("*.vtu"):
        # The XML text only: the appended base64 data (checked as numbers above) may
        # hold "+nan/" or "/inf+" by chance.
        markup = path.read_text().split("<AppendedData", 1)[0]
        assert not re.search(r"\b(nan|inf|infinity)\b|\*\*\*", markup,
                             re.IGNORECASE), path.name


def ok(outcome: Outcome) -> None:
    assert outcome.returncode == 0, outcome.stderr


# --------------------------------------------------------------------------------------
# The pin scene and its closed form.

def linear_force(stiffness: float) -> Callable[[float], float]:
    return lambda stretch: stiffness * (stretch - 1.0) if stretch > 1.0 else 0.0


def neo_hookean_force(modulus: float, area: float) -> Callable[[float], float]:
    return lambda stretch: (modulus * area * (stretch - stretch**-2) if stretch > 1.0
                            else 0.0)


@dataclass(frozen=True)
class Pin:
    """Yarn A -> C -> B over a fixed pin C (nodes A=1, C=2, B=3, peg anchor 4)."""

    contact: dict
    alpha: float = 2.0
    length_a: float = 1.0
    length_b: float = 1.0
    knots: tuple = (0.0, 0.2, 0.05, 0.2, 0.05)     #: pull d at the path knots (m)
    step: float = 0.1                              #: pseudo-time step (1 per knot)
    material: dict = field(default_factory=lambda: dict(law="linear", stiffness=10.0))
    min_length_ratio: float | None = None
    scheme: str = "monolithic"
    solver: dict = field(default_factory=dict)    #: more &solver settings

    @property
    def force(self) -> Callable[[float], float]:
        m = self.material
        if m["law"] == "linear":
            return linear_force(m["stiffness"])
        return neo_hookean_force(m["modulus"], m["area"])

    @property
    def force_scale(self) -> float:
        m = self.material
        return m["stiffness"] if m["law"] == "linear" else 3 * m["modulus"] * m["area"]

    def directions(self) -> tuple[np.ndarray, np.ndarray]:
        theta_a = math.radians(200.0)
        theta_b = theta_a + (PI - self.alpha)
        return (np.array([math.cos(theta_a), math.sin(theta_a), 0.0]),
                np.array([math.cos(theta_b), math.sin(theta_b), 0.0]))

    def text(self) -> str:
        e_a, e_b = self.directions()
        n = len(self.knots)
        solver = dict(scheme=self.scheme, residual_tolerance=1e-13, max_step=self.step,
                      initial_step=self.step, slack_stiffness=0.0)
        if self.min_length_ratio is not None:
            solver["min_length_ratio"] = self.min_length_ratio
        solver.update(self.solver)
        body = scene(
            nodes=[self.length_a * e_a, [0.0, 0.0, 0.0], self.length_b * e_b, [0.0, 0.0, -0.3]],
            materials=[dict(name="yarn", **self.material),
                       dict(name="peg", law="linear", stiffness=10.0)],
            yarns=[dict(material="yarn", nodes=[1, 2, 3]), dict(material="peg", nodes=[2, 4])],
            supports=[dict(name="end", nodes=[1], fix="xyz"),
                      dict(name="pin", nodes=[2, 4], fix="xyz"),
                      dict(name="pull", nodes=[3], fix="xyz", displacement=list(e_b))],
            path=dict(time=[float(i) for i in range(n)], p_force=[0.0] * n,
                      p_disp=list(self.knots)),
            solver=solver, output=dict(folder="out", progress=False))
        return body + group("contact", materials=["yarn", "peg"], **self.contact)


class PinClosedForm:
    """Exact flow s of the pin scene along a path of monotone steps (module notes):
    T_a(s) = f(l_a / (l_a - s)), T_b(s, d) = f((l_b + d) / (l_b + s)); forward slip
    where T_b = T_crit(T_a), reverse where T_a = T_crit(T_b), else stick; a minimum
    reference length bounds s <= (1 - ratio) l_a. The roots are found by bisection to
    adjacent floats (g_f decreasing, g_r increasing in s), so any force law and any
    T_crit (also one that overflows to inf) can be used."""

    def __init__(self, pin: Pin):
        self.pin = pin
        self.f = pin.force
        ratio = pin.min_length_ratio if pin.min_length_ratio is not None else 0.05
        self.s_max = (1.0 - ratio) * pin.length_a
        # The solver's absolute slack of the stick test: 10 * residual_tolerance * scale.
        self.abs_slack = 10 * 1e-13 * max(pin.force_scale, 10.0)
        self.alpha = pin.alpha

    def crit(self, t: float) -> float:
        return critical_tension(self.pin.contact, t, self.alpha)

    def tension_a(self, s: float) -> float:
        return self.f(self.pin.length_a / (self.pin.length_a - s))

    def tension_b(self, s: float, d: float) -> float:
        return self.f((self.pin.length_b + d) / (self.pin.length_b + s))

    @staticmethod
    def bisect(g, lo: float, hi: float) -> float:
        """Root of a decreasing g with g(lo) >= 0 >= g(hi), to adjacent floats."""
        while True:
            mid = 0.5 * (lo + hi)
            if not lo < mid < hi:
                return lo if abs(g(lo)) <= abs(g(hi)) else hi
            if g(mid) > 0.0:
                lo = mid
            else:
                hi = mid

    def advance(self, s: float, d: float) -> tuple[float, str]:
        t_a, t_b = self.tension_a(s), self.tension_b(s, d)
        if t_b > self.crit(t_a) * (1 + STICK_SLACK) + self.abs_slack and s < self.s_max:
            g = lambda x: self.tension_b(x, d) - self.crit(self.tension_a(x))   # noqa: E731
            hi = min(d, self.s_max)
            if g(hi) > 0.0:
                return hi, "locked"
            return self.bisect(g, s, hi), "forward"
        if t_a > self.crit(t_b) * (1 + STICK_SLACK) + self.abs_slack:
            g = lambda x: self.crit(self.tension_b(x, d)) - self.tension_a(x)   # noqa: E731
            return self.bisect(g, 0.0, s), "reverse"
        return s, "stick"

    def follow(self, d: np.ndarray) -> tuple[np.ndarray, list[str]]:
        s, flows, phases = 0.0, [], []
        for di in d:
            s, phase = self.advance(s, float(di))
            flows.append(s)
            phases.append(phase)
        return np.array(flows), phases


@dataclass
class PinResult:
    outcome: Outcome
    d: np.ndarray
    force: np.ndarray            #: reaction at B along e_B
    s: np.ndarray                #: l_a - L0_a
    tension: np.ndarray          #: (steps, 2): T_a, T_b
    s_exact: np.ndarray
    tension_exact: np.ndarray
    phases: list[str]
    alpha: np.ndarray            #: wrap angle at C from the written positions

    def errors(self) -> tuple[float, float]:
        """Max relative force error (absolute TENSION_ATOL allowed) and max flow error."""
        scale = np.maximum(np.abs(self.tension_exact[:, 1]), TENSION_ATOL / CLOSED_FORM_RTOL)
        force = np.max(np.abs(self.force - self.tension_exact[:, 1]) / scale)
        flow = np.max(np.abs(self.s - self.s_exact))
        return float(force), float(flow)


def run_pin(run_yarnfort, tmp_path: Path, pin: Pin, name: str = "pin") -> PinResult:
    """Run the pin scene and evaluate the closed form at its steps."""
    outcome = run_case(run_yarnfort, tmp_path, name, pin.text())
    ok(outcome)
    curve, states = outcome.curve, outcome.states
    _, e_b = pin.directions()
    d = curve["p_disp"]
    closed = PinClosedForm(pin)
    # The closed form at the wrap angle the solver saw (the written positions).
    alpha = np.array([wrap_angles(s.position, [0, 1, 2])[0] for s in states])
    np.testing.assert_allclose(alpha, pin.alpha, rtol=0, atol=1e-12)
    closed.alpha = float(alpha[0])
    s_exact, phases = closed.follow(d)
    tension_exact = np.array([[closed.tension_a(s), closed.tension_b(s, di)]
                              for s, di in zip(s_exact, d)])
    result = PinResult(outcome, d, curve.reaction("pull") @ e_b,
                       np.array([pin.length_a - s.length0[0] for s in states]),
                       np.array([s.tension[:2] for s in states]), s_exact, tension_exact,
                       phases, alpha)
    return result


def assert_matches_closed_form(result: PinResult, label: str) -> None:
    force_error, flow_error = result.errors()
    iterations = int(result.outcome.curve["newton_iterations"].sum())
    print(f"{label}: {len(result.d)} steps, phases "
          f"{ {p: result.phases.count(p) for p in set(result.phases)} }, max force error "
          f"{force_error:.1e} (rel.), max flow error {flow_error:.1e} m, Newton iterations "
          f"{iterations}")
    assert force_error <= CLOSED_FORM_RTOL
    np.testing.assert_allclose(result.s, result.s_exact, rtol=CLOSED_FORM_RTOL,
                               atol=LENGTH_ATOL)
    np.testing.assert_allclose(result.tension, result.tension_exact, rtol=CLOSED_FORM_RTOL,
                               atol=TENSION_ATOL)


# --------------------------------------------------------------------------------------
# 1. Friction coefficient from 0 to 1e4 on the pin.

MUS = [0.0, 1e-8, 0.3, 10.0, 1e4]


@pytest.mark.parametrize("scheme", ["monolithic", "staggered"])
@pytest.mark.parametrize("mu", MUS)
@pytest.mark.parametrize("law", ["coulomb", "adhesion"])
def test_friction_coefficient_on_a_pin(run_yarnfort, tmp_path, law, mu, scheme):
    """Pull 0.2, release to 0.05, twice. Every step against the closed form. Limits:
    mu = 0 coulomb is frictionless (T_a = T_b once it slips); mu = 1e4 sticks (exp(2e4)
    overflows: T_crit is capped, the yarn keeps its reference lengths and T_b is the
    elastic EA d / l_b)."""
    contact = coulomb_law(mu) if law == "coulomb" else adhesion_law(mu, 0.1)
    pin = Pin(contact, scheme=scheme)
    result = run_pin(run_yarnfort, tmp_path, pin)
    assert_matches_closed_form(result, f"pin {law} mu={mu:g} {scheme}")
    if law == "coulomb" and mu == 0.0:
        slipping = result.outcome.curve["slipping"][1:] > 0
        assert np.all(slipping)
        np.testing.assert_allclose(result.tension[1:, 0], result.tension[1:, 1],
                                   rtol=STICK_SLACK, atol=TENSION_ATOL)
    if mu == 1e4:
        assert np.max(np.abs(result.s)) <= LENGTH_ATOL
        np.testing.assert_allclose(result.force, 10.0 * result.d / pin.length_b,
                                   rtol=CLOSED_FORM_RTOL, atol=TENSION_ATOL)


# --------------------------------------------------------------------------------------
# 2. Friction coefficient on the capstan (three pegs): gross slip.

def polyline_length(points: np.ndarray) -> float:
    return float(np.sum(np.linalg.norm(np.diff(points, axis=0), axis=1)))


@pytest.mark.parametrize("mu", MUS)
@pytest.mark.parametrize("law", ["coulomb", "adhesion"])
def test_friction_coefficient_on_the_capstan(run_yarnfort, tmp_path, law, mu):
    """Pull by 0.3 and release to 0.05 (exact law, slack_stiffness = 0, so the yarn starts
    at zero tension: T_crit(0) = 0 for coulomb, which must slip at once). Gross slip
    steps obey T_hi = T_crit(T_lo, A) in interval form. mu = 0: frictionless, one tension
    all along the yarn, EA (l/L - 1) with l the yarn's polyline length and L its
    reference length. mu = 1e4: it sticks: reference lengths unchanged, first element
    at zero tension, last one at its elastic tension."""
    contact = coulomb_law(mu) if law == "coulomb" else adhesion_law(mu, 0.05)
    net = peg_net(arc_pegs(3), [-1, -1, 0], [1, -1, 0])
    text = namelist(net, [dict(materials=["yarn", "peg"], **contact)],
                    path=dict(time=[0, 1, 2], p_disp=[0, 1, 0.05]),
                    solver=dict(slack_stiffness=0.0))
    outcome = run_case(run_yarnfort, tmp_path, "capstan", text)
    ok(outcome)
    curve, states = outcome.curve, outcome.states
    yarn = slice(0, 4)
    initial = states[0].length0.copy()
    checked = 0
    for i, s in enumerate(states):
        if curve["slipping"][i] != 3 or curve["direction"][i] == 0:
            continue
        total = wrap_angles(s.position, range(5)).sum()     # the last one moves with B
        first, last = s.tension[0], s.tension[3]
        lo, hi = (first, last) if curve["direction"][i] > 0 else (last, first)
        low = critical_tension(contact, max(lo - TENSION_ATOL, 0.0), total)
        high = critical_tension(contact, lo + TENSION_ATOL, total)
        assert low * (1 - CLOSED_FORM_RTOL) <= hi <= high * (1 + CLOSED_FORM_RTOL), \
            (i, lo, hi, low, high)
        checked += 1
    moved = max(np.max(np.abs(s.length0 - initial)) for s in states)
    print(f"capstan {law} mu={mu:g}: {len(states)} steps, {checked} in gross slip "
          f"(checked), largest change of an L0 {moved:.1e} m, Newton iterations "
          f"{int(curve['newton_iterations'].sum())}")
    if mu <= 0.3:
        assert checked >= 10
    if mu == 0.0 and law == "coulomb":
        for s in states:
            points = s.position[:5]
            expected = 10.0 * (polyline_length(points) / s.length0[yarn].sum() - 1.0)
            np.testing.assert_allclose(s.tension[yarn], max(expected, 0.0),
                                       rtol=CLOSED_FORM_RTOL, atol=TENSION_ATOL)
    if mu == 1e4:
        assert moved <= LENGTH_ATOL
        for s in states:
            assert abs(s.tension[0]) <= TENSION_ATOL
            l_last = np.linalg.norm(s.position[4] - s.position[3])
            expected = 10.0 * max(l_last / initial[3] - 1.0, 0.0)
            assert s.tension[3] == pytest.approx(expected, rel=CLOSED_FORM_RTOL,
                                                 abs=TENSION_ATOL)


# --------------------------------------------------------------------------------------
# 3. Adhesion from 0 to 1e3 on the pin.

@pytest.mark.parametrize("scheme", ["monolithic", "staggered"])
@pytest.mark.parametrize("beta", [0.0, 1e-12, 0.1, 1e3])
def test_adhesion_on_a_pin(run_yarnfort, tmp_path, beta, scheme):
    """mu = 0.3. beta = 0 is Coulomb: checked against the Coulomb closed form. beta =
    1e-12: Coulomb up to 1e-12 N. beta = 1e3: T_crit(0) = beta alpha = 2000 N (mu alpha
    < 1), so a load of 2 N never slips: s = 0 exactly and T_b = EA d / l_b."""
    pin = Pin(adhesion_law(0.3, beta), scheme=scheme)
    result = run_pin(run_yarnfort, tmp_path, pin)
    assert_matches_closed_form(result, f"pin adhesion beta={beta:g} {scheme}")
    if beta == 0.0:
        coulomb = PinClosedForm(replace(pin, contact=coulomb_law(0.3)))
        coulomb.alpha = float(result.alpha[0])
        s_coulomb, _ = coulomb.follow(result.d)
        np.testing.assert_allclose(result.s, s_coulomb, rtol=CLOSED_FORM_RTOL,
                                   atol=LENGTH_ATOL)
    if beta == 1e3:
        assert np.all(result.outcome.curve["slipping"] == 0)
        assert np.all(result.s == 0.0)
        np.testing.assert_allclose(result.force, 10.0 * result.d / pin.length_b,
                                   rtol=CLOSED_FORM_RTOL, atol=TENSION_ATOL)


# --------------------------------------------------------------------------------------
# 4. Decaying adhesion at its boundaries.

DECAYING = {
    # beta > mu w_d: the decay is used; tensions (up to 1.3 N) pass w_d and T*.
    "gap_1e-9": decaying_law(0.3, 0.2, 0.5, 0.5 + 1e-9),
    "gap_1e-14": decaying_law(0.3, 0.2, 0.5, 0.5 + 1e-14),
    # The decay starts at zero tension.
    "start_0": decaying_law(0.3, 0.1, 0.0, 0.3),
    # mu w_d >= beta: the plain adhesion law (compared with ITS closed form).
    "mu_w_above_beta": decaying_law(0.3, 0.1, 0.5, 0.8),
    "mu_w_equals_beta": decaying_law(0.5, 0.1, 0.2, 0.4),
}


@pytest.mark.parametrize("name", list(DECAYING))
def test_decaying_adhesion_at_its_boundaries(run_yarnfort, tmp_path, name):
    """Decaying adhesion on the pin, every step against the closed form: with the decay
    squeezed into 1e-9 or 1e-14 N above w_d (k = beta/(s_d - w_d) up to 2e13 per radian:
    the relaxation is a jump from w_d to T*), starting at zero tension, and where it
    reduces to plain adhesion (mu w_d above or exactly at beta), there against the
    adhesion law's closed form."""
    law = DECAYING[name]
    reduces = law["friction_coefficient"] * law["decay_start"] >= law["adhesion"]
    reference = adhesion_law(law["friction_coefficient"], law["adhesion"]) if reduces else law
    pin = Pin(law)
    result = run_pin(run_yarnfort, tmp_path, pin)
    # The solver ran the decaying law; the closed form is the reference law's.
    closed = PinClosedForm(replace(pin, contact=reference))
    closed.alpha = float(result.alpha[0])
    result.s_exact, result.phases = closed.follow(result.d)
    result.tension_exact = np.array([[closed.tension_a(s), closed.tension_b(s, d)]
                                     for s, d in zip(result.s_exact, result.d)])
    assert_matches_closed_form(result, f"pin decaying {name}")
    assert {"forward", "reverse", "stick"} <= set(result.phases)
    if not reduces:     # the tensions reach the decay
        assert np.max(result.tension) > law["decay_end"]


# --------------------------------------------------------------------------------------
# 5. Slack start on the capstan.

def test_slack_start_then_taut(run_yarnfort, tmp_path):
    """The pulled end starts 0.3 above its stress-free place (the last element at 80 % of
    its length: slack), comes down through it and is pulled 0.3 below (default
    slack_stiffness, adhesion law of inputs/capstan.nml). While slack every tension stays
    at the regularisation's level (slack_stiffness * EA * stretch <= 1e-5 N); once taut,
    gross slip obeys T_crit."""
    contact = adhesion_law(0.3, 0.05)
    net = peg_net(arc_pegs(3), [-1, -1, 0], [1, -1, 0])
    text = namelist(net, [dict(materials=["yarn", "peg"], **contact)],
                    path=dict(time=[0, 1, 2], p_disp=[-1, 0, 1]))
    outcome = run_case(run_yarnfort, tmp_path, "slack", text)
    ok(outcome)
    curve, states = outcome.curve, outcome.states
    slack = [s for s, p in zip(states, curve["p_disp"]) if p <= 0.0]
    assert slack[0].stretch[3] < 0.85
    assert max(np.max(s.tension[:4]) for s in slack) <= 1e-6 * 10.0 * 1.0
    gross = 0
    for i, s in enumerate(states):
        if curve["slipping"][i] == 3 and curve["p_disp"][i] > 0:
            total = wrap_angles(s.position, range(5)).sum()
            assert s.tension[3] == pytest.approx(critical_tension(contact, s.tension[0], total),
                                                 rel=CLOSED_FORM_RTOL)
            gross += 1
    print(f"slack start: {len(states)} steps, {len(slack)} slack, {gross} in gross slip, "
          f"Newton iterations {int(curve['newton_iterations'].sum())}")
    assert gross >= 5


# --------------------------------------------------------------------------------------
# 6. Stretch to three times the length.

def test_stretch_to_three_times_the_length(run_yarnfort, tmp_path):
    """Neo-Hookean yarn (S1 C = 10 N) over the pin with Coulomb friction, pulled until
    the yarn is three times its length (d = 4 for l_a + l_b = 2), released to d = 1 and
    pulled again: every step against the closed form with f = S1 C (lambda - lambda^-2)."""
    pin = Pin(coulomb_law(0.3), knots=(0.0, 4.0, 1.0, 4.0),
              material=dict(law="neo_hookean", modulus=1e6, area=1e-5), step=0.05)
    result = run_pin(run_yarnfort, tmp_path, pin)
    assert_matches_closed_form(result, "pin neo-Hookean stretched 3x")
    peak = result.outcome.states[int(np.argmax(result.d))]
    assert peak.stretch[1] > 3.0 and peak.length0[:2].sum() == pytest.approx(2.0, rel=1e-15)
    assert (np.linalg.norm(peak.position[0] - peak.position[1])
            + np.linalg.norm(peak.position[2] - peak.position[1])) == pytest.approx(6.0)


#: Newton tolerance of the table chain (N): residual_tolerance 1e-10 * force_scale 1 N.
TABLE_ATOL = 1e-10
TABLE = np.array([      # strain, force (N): flat (slope 1e-3) and steep (slope 1e4) parts
    [0.0, 0.0],
    [0.1, 1e-4],
    [0.1001, 1.0],
    [1.0, 1.0009],
    [1.0001, 2.0],
    [2.0, 2.001],
])


def test_table_law_with_steep_and_flat_parts(run_yarnfort, tmp_path):
    """Chain: node 1 fixed, node 2 free along x, node 3 pulled along x; string 1-2 of a
    table law whose slope jumps between 1e-3 and 1e4 N (ratio 1e7), string 2-3 linear
    (EA = 1 N); both 1 m long. Node 3's displacement e_k + F_k puts the table string
    exactly at knot k (strain e_k, force F_k; then the linear string is at strain F_k):
    whatever the interpolant does in between, there the reaction must be F_k and node
    2 at x = 1 + e_k. The last knot stretches the table string to 3x its length. The
    path starts at the first knot (with the exact law a stress-free chain has no
    stiffness). Newton tolerance 1e-10 relative to the forces at node 2 (the knot's force
    F_k), plus the residual's rounding (on a slope of 1e4 N a residual is only defined
    to about 1e4 * ulp(1.1) = 2e-12 N). Hence reaction to 1e-8 relative plus TABLE_ATOL
    = 1e-10 N, and position (the linear string's stiffness is 1 N) to 1e-10 m times
    max(1, F_k / 1 N)."""
    folder = tmp_path / "table"
    folder.mkdir()
    (folder / "steep.csv").write_text("strain,force\n" + "".join(
        f"{float(e)!r},{float(f)!r}\n" for e, f in TABLE))
    targets = TABLE[1:, 0] + TABLE[1:, 1]
    text = scene(
        nodes=[[0, 0, 0], [1, 0, 0], [2, 0, 0]],
        materials=[dict(name="steep", law="table", table_file="steep.csv"),
                   dict(name="soft", law="linear", stiffness=1.0)],
        yarns=[dict(material="steep", nodes=[1, 2]), dict(material="soft", nodes=[2, 3])],
        supports=[dict(name="fixed", nodes=[1], fix="xyz"),
                  dict(name="line", nodes=[2], fix="yz"),
                  dict(name="pull", nodes=[3], fix="xyz", displacement=[1.0, 0, 0])],
        path=dict(time=[float(i) for i in range(len(targets))],
                  p_force=[0.0] * len(targets), p_disp=targets.tolist()),
        solver=dict(residual_tolerance=1e-10, slack_stiffness=0.0, max_step=0.1,
                    initial_step=0.1),
        output=dict(folder="out", progress=False))
    outcome = run_case(run_yarnfort, tmp_path, "table", text)
    ok(outcome)
    curve, states = outcome.curve, outcome.states
    worst_force = worst_x = 0.0
    for k, (strain, force) in enumerate(TABLE[1:]):
        i = int(np.argmin(np.abs(curve["time"] - k)))
        assert curve["time"][i] == pytest.approx(k, abs=1e-12)
        reaction = curve.reaction("pull")[i, 0]
        worst_force = max(worst_force, abs(reaction - force) / force)
        worst_x = max(worst_x, abs(states[i].position[1, 0] - (1 + strain)))
        assert reaction == pytest.approx(force, rel=CLOSED_FORM_RTOL, abs=TABLE_ATOL)
        assert states[i].position[1, 0] == pytest.approx(1 + strain, rel=0,
                                                         abs=TABLE_ATOL * max(1.0, force))
    print(f"table law steep/flat: {len(states)} steps, {int(curve['step_cuts'].sum())} cuts,"
          f" max force error at knots {worst_force:.1e} (rel.), max position error "
          f"{worst_x:.1e} m, Newton iterations {int(curve['newton_iterations'].sum())}")
    assert states[-1].stretch[0] == pytest.approx(3.0)
    assert np.all(np.diff(curve.reaction("pull")[:, 0]) > 0)


# --------------------------------------------------------------------------------------
# 7. Elements at the minimum reference length.

def test_minimum_length_lock_without_friction(run_yarnfort, tmp_path):
    """mu = 0 with min_length_ratio = 0.9: the yarn slides freely (T_a = T_b, s = d l_a /
    (l_a + l_b + d)) until element a is down to 0.9 l_a (at d = 0.222), then the passage
    locks forward (s = 0.1 l_a) while b keeps stretching; released, it slides back as
    soon as T_a exceeds T_b. Closed form: s = min(d l_a / (l_a + l_b + d), 0.1 l_a)."""
    ratio = 0.9
    pin = Pin(coulomb_law(0.0), knots=(0.0, 0.4, 0.05, 0.4), min_length_ratio=ratio,
              step=0.05)
    result = run_pin(run_yarnfort, tmp_path, pin)
    assert_matches_closed_form(result, "pin mu=0 min_length_ratio=0.9")
    d = result.d
    np.testing.assert_allclose(result.s_exact, np.minimum(d / (2 + d), 1 - ratio), rtol=1e-12)
    length0_a = np.array([s.length0[0] for s in result.outcome.states])
    assert np.min(length0_a) >= ratio * (1 - 1e-12)
    assert np.sum(length0_a <= ratio * (1 + 1e-12)) >= 10       # locked for a while
    assert "locked" in result.phases


def test_element_run_down_to_the_default_minimum_length(run_yarnfort, tmp_path):
    """Coulomb mu = 0.3 with the default min_length_ratio = 0.05, pulled to d = 80: the
    yarn slides until element a is at 5 % of its length (stretch 20, T_a = 190 N), where
    the passage locks; released to d = 1 it slides back. Every step against the closed
    form (with the lock)."""
    pin = Pin(coulomb_law(0.3), knots=(0.0, 80.0, 1.0), step=0.05)
    result = run_pin(run_yarnfort, tmp_path, pin)
    assert_matches_closed_form(result, "pin coulomb pulled to d = 80 (min length 0.05)")
    length0_a = np.array([s.length0[0] for s in result.outcome.states])
    assert np.min(length0_a) >= 0.05 * (1 - 1e-12)
    assert np.any(length0_a <= 0.05 * (1 + 1e-12))
    assert max(s.stretch[0] for s in result.outcome.states) == pytest.approx(20.0, rel=1e-9)


# --------------------------------------------------------------------------------------
# 8. Wrap angles near 0 (straight yarn) and near pi (folded back).

@pytest.mark.parametrize("alpha", [0.0, 1e-9])
@pytest.mark.parametrize("law", ["coulomb", "adhesion"])
def test_nearly_straight_yarn_has_no_friction_resistance(run_yarnfort, tmp_path, law, alpha):
    """A (nearly) straight yarn through the pin (alpha = 0: A, C, B collinear) with a
    huge friction coefficient (coulomb mu = 1e4) or adhesion (beta = 1e3, mu = 0.3):
    no resistance, T_b - T_a <= T_crit(T_a, alpha) - T_a (at most 1e-5 T_a resp.
    1e-6 N), and every step as in the closed form at the written angle."""
    contact = coulomb_law(1e4) if law == "coulomb" else adhesion_law(0.3, 1e3)
    pin = Pin(contact, alpha=alpha)
    result = run_pin(run_yarnfort, tmp_path, pin)
    assert_matches_closed_form(result, f"pin straight alpha={alpha:g} {law}")
    angle = float(np.max(result.alpha))
    assert angle <= alpha + 1e-12
    resistance = [critical_tension(contact, t_a, angle) - t_a for t_a in result.tension[:, 0]]
    gap = np.abs(result.tension[:, 1] - result.tension[:, 0])
    assert np.all(gap <= np.array(resistance) * (1 + 1e-6) + TENSION_ATOL)
    assert np.max(gap) <= 2e-5 * np.max(result.tension)


@pytest.mark.parametrize("alpha", [PI, PI - 1e-9])
def test_yarn_folded_back_over_the_pin(run_yarnfort, tmp_path, alpha):
    """alpha = pi: B lies on the ray from C through A (l_b = 1.5 so that B is not A); the
    yarn folds back at C. Adhesion mu = 0.3, beta = 0.1 (mu alpha < 1 ... > 1 branches
    of eq. 35): every step against the closed form."""
    pin = Pin(adhesion_law(0.3, 0.1), alpha=alpha, length_b=1.5)
    result = run_pin(run_yarnfort, tmp_path, pin)
    assert_matches_closed_form(result, f"pin folded alpha=pi-{PI - alpha:.0e}")
    assert {"forward", "reverse", "stick"} <= set(result.phases)


# --------------------------------------------------------------------------------------
# 9. Hundreds of step cuts.

def neo_hookean_chain(solver: dict, path: dict) -> str:
    """Two neo-Hookean strings in series along x, 1 m each: 'soft' (S1 C = 10 N) from
    node 1 (fixed) to node 2 (free along x), 'stiff' (S1 C = 30 N) on to node 3, pulled
    along x by 4 m at p_disp = 1 (the chain then is 3x its length). Exact law."""
    return scene(
        nodes=[[0, 0, 0], [1, 0, 0], [2, 0, 0]],
        materials=[dict(name="soft", law="neo_hookean", modulus=1e6, area=1e-5),
                   dict(name="stiff", law="neo_hookean", modulus=3e6, area=1e-5)],
        yarns=[dict(material="soft", nodes=[1, 2]), dict(material="stiff", nodes=[2, 3])],
        supports=[dict(name="fixed", nodes=[1], fix="xyz"),
                  dict(name="line", nodes=[2], fix="yz"),
                  dict(name="pull", nodes=[3], fix="xyz", displacement=[4.0, 0, 0])],
        path=path,
        solver=dict(residual_tolerance=1e-13, slack_stiffness=0.0, **solver),
        output=dict(folder="out", progress=True))


def test_hundreds_of_step_cuts_then_finish(run_yarnfort, tmp_path):
    """The neo-Hookean yarn over the pin (coulomb mu = 0.3) pulled to d = 4 (3x its
    length) in one go (initial_step = max_step = 1) with max_iterations = 1, step_cut =
    0.99, no step growth and plain Newton steps (line_search = .false.: no fallback
    attempts): the first step is cut hundreds of times (1 % each) until one Newton
    iteration suffices; within max_step_cuts = 1000 the run finishes, every
    step at the closed form. (With max_iterations = 2 the friction solves' chord steps
    (one Newton step, then a step with its factors) reach the tolerance at full length:
    no cut at all.) (The elastic chain below cannot be used here: from its
    stress-free start, where both strings sit at the kink of the tension-only law, the
    first step needs 5 or more iterations at any step length.)"""
    pin = Pin(coulomb_law(0.3), knots=(0.0, 4.0), step=1.0,
              material=dict(law="neo_hookean", modulus=1e6, area=1e-5))
    pin = replace(pin, solver=dict(max_iterations=1, step_cut=0.99, max_step_cuts=1000,
                                   step_growth=1.0, line_search=False))
    result = run_pin(run_yarnfort, tmp_path, pin)
    curve = result.outcome.curve
    cuts = int(curve["step_cuts"].sum())
    assert_matches_closed_form(result, f"pin pulled to 3x with max_iterations = 1: {cuts} "
                               f"cuts (at most {int(curve['step_cuts'].max())} in a row)")
    assert cuts >= 200
    assert curve["time"][-1] == 1.0 and result.d[-1] == 4.0


def test_hundreds_of_step_cuts_then_a_clean_stop(run_yarnfort, tmp_path):
    """The chain with max_iterations = 1 (plain Newton steps, line_search = .false.: no
    fallback attempts), step_cut = 0.99, max_step_cuts = 300: the path
    holds still up to time 1 (steps that converge at once), then stretches the chain
    to 3x, which no step of length >= 0.5 * 0.99^300 = 0.025 does in one Newton
    iteration. The run must stop after exactly 301 consecutive cuts, within
    RUN_TIMEOUT, with exit code 1, one "error (solve)" line that says so, and the
    converged steps up to time 1 kept in curve.csv and as VTK states."""
    text = neo_hookean_chain(dict(max_iterations=1, step_cut=0.99, max_step_cuts=300,
                                  initial_step=0.5, max_step=1.0, step_growth=1.0,
                                  min_step=1e-12, line_search=False),
                             dict(time=[0.0, 1.0, 2.0], p_force=[0.0, 0.0, 0.0],
                                  p_disp=[0.0, 0.0, 1.0]))
    outcome = run_case(run_yarnfort, tmp_path, "give_up", text)
    assert outcome.returncode == 1
    lines = outcome.stderr.splitlines()
    message = [line for line in lines if "error (solve)" in line][0]
    print(f"clean stop: {len(outcome.curve['step'])} converged steps kept; {message}")
    assert "step from time 1.00000 failed after 301 cuts" in message
    assert "Newton did not converge" in message
    assert sum("cut:" in line for line in lines) == 301
    np.testing.assert_array_equal(outcome.curve["time"], [0.0, 0.5, 1.0])


@pytest.mark.parametrize("scheme", ["monolithic", "staggered"])
def test_ring_sliding_far_on_a_stiff_yarn(run_yarnfort, tmp_path, scheme):
    """test_defaults.py's friction ring on its stiff yarn (EA = 1e5 P) with each scheme:
    from the stress-free start far on the A side the ring must slide about 0.5 m at the
    first state, where Newton's steps along the yarn are limited to about sqrt(l T / EA).
    It converges through Newton's softened-yarn predictor (the monolithic scheme), and
    through the staggered scheme's last monolithic finish with every Newton fallback
    (its rounds alone creep: residual 7e-4 falling by 1e-10 per round). Every step
    against the play-operator reference, as in test_friction_ring_with_defaults."""
    stiffness = RING_STIFFNESS["stiff"]
    text = ring_namelist(FRICTION_START, stiffness, RING_MU)
    text = text.replace("&output", group("solver", scheme=scheme) + "&output", 1)
    outcome = run_case(run_yarnfort, tmp_path, scheme, text)
    assert outcome.returncode == 0, outcome.stderr
    length0 = np.linalg.norm(RING_A - FRICTION_START) + np.linalg.norm(RING_B - FRICTION_START)
    split, ends, rings, tensions = np.linalg.norm(RING_A - FRICTION_START), None, [], []
    for p in outcome.curve["p_force"]:
        ends = admissible_splits(length0, stiffness, p * RING_LOAD, RING_MU, hint=ends)
        split = min(max(split, ends[0]), ends[1])
        ring, t, _ = stuck_ring(split, length0, stiffness, p * RING_LOAD)
        rings.append(ring)
        tensions.append(t)
    errors = ring_errors(outcome.curve, outcome.states, rings, tensions)
    print(f"ring on a stiff yarn ({scheme}): {len(outcome.states)} steps, errors "
          f"{', '.join(f'{n} {v:.1e}' for n, v in errors.items())}")
    for key, value in errors.items():
        assert value <= (POSITION_RTOL if key in ("ring", "stub_end") else FORCE_RTOL), \
            (key, value)
