#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Fabric study: the knitted jersey with inlay (inputs/knit.nml) and the woven belt
(inputs/belt.nml) as in the paper's section 3 (Figs. 6-8 and 13), plus the numerics
behind them.

1. sensitivity of the knit's loading-unloading cycle to the knit-inlay friction
   coefficient ikmu (0.3333 - 0.4666, Fig. 6a) and adhesion ikbeta (0 - 0.05 N, Fig. 6b),
   and to the knit-knit kmu, kbeta over the same ranges (the ik pair turns out inert);
2. hysteresis loops (two cycles) for a wider range of kbeta and kmu (Figs. 7, 8), with
   the same values for the knit-inlay pair as a check;
3. the belt for constant gap factors and for the table of belt.nml (Fig. 13a, b);
4. discretisation (elements per segment 1, 2, 4, 8) and load step (max_step 0.2 ...
   0.0125) of the knit cycle, with the twill cell as a second step study;
5. periodic cell against clamped samples (sides = 'rollers') of growing size: plain
   weave (bonded and with friction) and 2/2 twill (with friction).

NO MEASURED DATA: the paper's measurements are not available and the yarn tables in
inputs/data are illustrative. Every curve here is computed; none is a measurement.

Run:  .venv/bin/python verification/fabrics/run_study.py   (after ./yarnfort once)
15-40 s on 2 cores (74 runs). Writes sensitivity.png, loops.png, belt.png,
convergence.png, periodic_vs_sample.png and results.txt next to this script; runs go to
out/fabrics_study/ (git-ignored).
"""
from __future__ import annotations

import concurrent.futures as cf
import os
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
TOP = HERE.parents[1]
sys.path.insert(0, str(TOP / "python"))
sys.path.insert(0, str(TOP / "tests" / "verification"))
from fabric_scenes import (LOADING, ONE_CYCLE, bonded, interior_measures,  # noqa: E402
                           patched_scene, run_scene)
from yarnfort import read_curve, read_states  # noqa: E402

EXE = Path(os.environ.get("YARNFORT_EXE", TOP / "build" / "yarnfort"))
OUT = TOP / "out" / "fabrics_study"
WORKERS = 2
NOTE = "computed with illustrative yarn tables; no measured data"
KNIT, BELT = "inputs/knit.nml", "inputs/belt.nml"
IK = "contact[1]"          # the knit-inlay &contact of knit.nml
WOVEN_SPACING = (1.0e-3, 0.5e-3)
LINES: list[str] = []


def say(line: str = "") -> None:
    LINES.append(line)
    print(line, flush=True)


class Run:
    """A finished run: curve, states (when written), wall time."""

    def __init__(self, name: str, base: str, values: dict, vtk: bool = False,
                 may_fail: bool = False) -> None:
        self.name, self.base, self.values, self.vtk = name, base, dict(values), vtk
        self.may_fail, self.error = may_fail, ""

    def __call__(self) -> "Run":
        folder = OUT / self.name
        values = dict(self.values)
        values["output.vtk_every"] = 1 if self.vtk else 0
        proc, self.seconds = run_scene(patched_scene(self.base, values, folder), EXE)
        if proc.returncode != 0:
            if not self.may_fail:
                raise RuntimeError(f"run {self.name} failed:\n{proc.stderr[-2000:]}")
            self.error = proc.stderr.strip().splitlines()[-1]
            return self
        self.curve = read_curve(folder)
        self.states = read_states(folder) if self.vtk else None
        return self


def run_all(runs: list[Run]) -> dict[str, Run]:
    """Run on WORKERS processes; results by name."""
    with cf.ThreadPoolExecutor(WORKERS) as pool:
        done = list(pool.map(lambda r: r(), runs))
    return {r.name: r for r in done}


def branches(curve) -> list[np.ndarray]:
    """Step indices of each monotone branch (loading / unloading) of the path, each
    starting at the step where the previous branch ended."""
    direction = curve["direction"]
    cuts = [0] + [k for k in range(1, len(direction))
                  if direction[k] != direction[k - 1] and direction[k - 1] != 0] \
        + [len(direction)]
    return [np.arange(max(a - 1, 0), b) for a, b in zip(cuts[:-1], cuts[1:])]


def loop_area(curve, first: int = 0, last: int | None = None) -> float:
    """Area of the force-per-width / strain loop (J/m^2: energy dissipated per unit area
    of fabric) between steps first and last, by the trapezoid rule."""
    e = curve["strain"][first:last]
    f = curve["force_per_width"][first:last]
    return float(np.sum(0.5 * (f[1:] + f[:-1]) * np.diff(e)))


def at_strain(curve, strain: float, direction: int, cycle: int = 0) -> float:
    """Force per width at `strain` on the loading (1) or unloading (-1) branch of a
    cycle, interpolated linearly between steps."""
    b = [idx for idx in branches(curve)][2 * cycle + (0 if direction == 1 else 1)]
    e, f = curve["strain"][b], curve["force_per_width"][b]
    order = np.argsort(e)
    return float(np.interp(strain, e[order], f[order]))


def draw_loop(ax, curve, colour, label, cycles=1):
    b = branches(curve)[: 2 * cycles]
    for k, idx in enumerate(b):
        ax.plot(curve["strain"][idx], curve["force_per_width"][idx], color=colour,
                ls="-" if k % 2 == 0 else "--", lw=1.3, label=label if k == 0 else None)


# ---------------------------------------------------------------------------------------
# 1 and 2: knit sensitivity and loops
# ---------------------------------------------------------------------------------------
IKMU = [0.3333, 0.3666, 0.3999, 0.4333, 0.4666]     # the paper's measured range
IKBETA = [0.0, 0.0075, 0.015, 0.03, 0.05]           # N
LOOP_BETA = [0.0, 0.015, 0.05, 0.1]
LOOP_MU = [0.1, 0.2, 0.3999, 0.8]
KK = "contact[0]"          # the knit-knit &contact of knit.nml
#: The paper's Fig. 6 varies the knit-inlay pair (ik); the knit-knit pair (k) is varied
#: over the same ranges because the ik pair turns out to be inert (see README).
SENSITIVITY = [("ikmu", IK, "friction_coefficient", IKMU, ""),
               ("ikbeta", IK, "adhesion", IKBETA, " N"),
               ("kmu", KK, "friction_coefficient", IKMU, ""),
               ("kbeta", KK, "adhesion", IKBETA, " N")]
#: knit.nml's values (the same for both pairs).
KNIT_NOMINAL = {"kmu": 0.3999, "kbeta": 0.015}
FRICTIONLESS_INLAY = {f"{IK}.friction_coefficient": 0.0, f"{IK}.adhesion": 0.0}


def knit_runs() -> list[Run]:
    runs = [Run(f"sens_{label}_{v}", KNIT, {**ONE_CYCLE, f"{group}.{variable}": v})
            for label, group, variable, values, _ in SENSITIVITY for v in values]
    runs.append(Run("sens_ik_frictionless", KNIT, {**ONE_CYCLE, **FRICTIONLESS_INLAY}))
    runs.append(Run("sens_ik_frictionless_offset0.3", KNIT, {
        **ONE_CYCLE, **FRICTIONLESS_INLAY, "fabric.inlay_offset": 0.3}))
    runs.append(Run("sens_offset0.3", KNIT, {**ONE_CYCLE, "fabric.inlay_offset": 0.3}))
    for label, group in (("kbeta", KK), ("ikbeta", IK)):
        runs += [Run(f"loop_{label}_{b}", KNIT, {f"{group}.adhesion": b}) for b in LOOP_BETA]
    for label, group in (("kmu", KK), ("ikmu", IK)):
        runs += [Run(f"loop_{label}_{m}", KNIT, {f"{group}.friction_coefficient": m})
                 for m in LOOP_MU]
    return runs


def loop_difference(c, ref, grid=np.linspace(0, 1, 101), cycle=0) -> float:
    """Largest |F - F_ref| over a cycle, compared at equal strain on each branch."""
    return max(abs(at_strain(c, e, d, cycle) - at_strain(ref, e, d, cycle))
               for e in grid for d in (1, -1))


def sensitivity(r: dict[str, Run]) -> None:
    import matplotlib.pyplot as plt
    say("## 1. knit sensitivity (one cycle to strain 1; paper Fig. 6 varies ikmu, ikbeta)")
    fig, axes = plt.subplots(2, 3, figsize=(15, 7.5))
    cmap = plt.get_cmap("viridis")
    nominal = r["sens_ikmu_0.3999"].curve
    say("parameter | value | F at strain 1 (N/m) | F unloading at 0.5 (N/m) | F after "
        "unloading (N/m) | loop area (J/m^2) | max |F - F(nominal)| over the cycle (N/m)")
    for col, (label, _, _, values, unit) in enumerate(SENSITIVITY):
        ax = axes[col // 2, col % 2]
        peaks, areas = [], []
        for k, v in enumerate(values):
            c = r[f"sens_{label}_{v}"].curve
            colour = cmap(k / (len(values) - 1))
            draw_loop(ax, c, colour, f"{label} = {v}{unit}")
            if label in ("kmu", "kbeta"):
                for d, ls in ((1, "-"), (-1, "--")):
                    grid = np.linspace(0, 1, 201)
                    diff = [at_strain(c, e, d) - at_strain(nominal, e, d) for e in grid]
                    axes[1, 2].plot(grid, diff, color=colour, ls=ls, lw=1,
                                    label=f"{label} = {v}" if d == 1 else None,
                                    alpha=1 if label == "kbeta" else 0.6,
                                    marker="" if label == "kbeta" else ".", markevery=20)
            peaks.append(c["force_per_width"].max())
            areas.append(loop_area(c))
            say(f"{label:7s} | {v:7.4f} | {peaks[-1]:8.2f} | {at_strain(c, 0.5, -1):7.2f} | "
                f"{c['force_per_width'][-1]:6.2f} | {areas[-1]:7.2f} | "
                f"{loop_difference(c, nominal):.2e}")
        say(f"  {label} over [{values[0]}, {values[-1]}]: peak force varies by "
            f"{100 * np.ptp(peaks) / nominal['force_per_width'].max():.3g} %, loop area by "
            f"{100 * np.ptp(areas) / loop_area(nominal):.3g} % of the nominal")
        pair = "knit-inlay" if label.startswith("ik") else "knit-knit"
        ax.set_title(f"({'abde'[col]}) {label} ({pair}) varied", fontsize=9)
        ax.legend(fontsize=7, title="solid loading, dashed unloading", title_fontsize=7)
        ax.set_xlabel("strain")
        ax.set_ylabel("force per width (N/m)")
    # Diagnostic: a frictionless inlay (ikmu = ikbeta = 0) at the inlay offset of knit.nml
    # (0.5, half way up the legs) and at 0.3.
    for name, ref, colour, text in (
            ("sens_ik_frictionless", nominal, "tab:blue", "inlay_offset 0.5 (knit.nml)"),
            ("sens_ik_frictionless_offset0.3", r["sens_offset0.3"].curve, "tab:red",
             "inlay_offset 0.3")):
        c = r[name].curve
        say(f"  frictionless inlay (ikmu = ikbeta = 0), {text}: max |F - F(ik as in "
            f"knit.nml)| = {loop_difference(c, ref):.3e} N/m")
        grid = np.linspace(0, 1, 201)
        for d, ls in ((1, "-"), (-1, "--")):
            axes[0, 2].plot(grid, [at_strain(c, e, d) - at_strain(ref, e, d) for e in grid],
                            color=colour, ls=ls, label=text if d == 1 else None)
    axes[0, 2].set_title("(c) frictionless inlay minus ikmu 0.3999, ikbeta 0.015 N",
                         fontsize=9)
    axes[0, 2].set_xlabel("strain")
    axes[0, 2].set_ylabel("force per width difference (N/m)")
    axes[0, 2].legend(fontsize=7)
    axes[1, 2].set_title("(f) difference to knit.nml (kmu 0.3999, kbeta 0.015 N)",
                         fontsize=9)
    fig.suptitle(f"Knit cell, one cycle to strain 1: sensitivity to friction and adhesion "
                 f"({NOTE})", fontsize=10)
    axes[1, 2].set_xlabel("strain")
    axes[1, 2].set_ylabel("force per width difference (N/m)")
    axes[1, 2].axhline(0, color="k", lw=0.5)
    axes[1, 2].legend(fontsize=7, ncol=2)
    for ax in axes.flat:
        ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(HERE / "sensitivity.png", dpi=110)
    plt.close(fig)


def loops(r: dict[str, Run]) -> None:
    import matplotlib.pyplot as plt
    say("")
    say("## 2. knit loops, two cycles to strain 1 (paper Figs. 7, 8)")
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.3), sharey=True)
    cmap = plt.get_cmap("plasma")
    for ax, (label, values, unit) in zip(axes, (("kbeta", LOOP_BETA, " N"),
                                                ("kmu", LOOP_MU, ""))):
        say(f"{label} | loop area cycle 1, 2 (J/m^2) | F at strain 1 (N/m) | "
            "F after each unloading (N/m) | the same with ik instead of k: max |dF| (N/m)")
        for k, v in enumerate(values):
            c = r[f"loop_{label}_{v}"].curve
            draw_loop(ax, c, cmap(0.85 * k / (len(values) - 1)), f"{label} = {v}{unit}",
                      cycles=2)
            ends = [i for i in range(1, len(c["strain"]))
                    if c["strain"][i] == 0.0 and c["direction"][i] == -1]
            a1, a2 = loop_area(c, 0, ends[0] + 1), loop_area(c, ends[0], ends[1] + 1)
            # The same value for the knit-inlay pair instead, against knit.nml as it is.
            ik, nominal = (r[f"loop_i{label}_{v}"].curve,
                           r[f"loop_{label}_{KNIT_NOMINAL[label]}"].curve)
            ik_change = max(loop_difference(ik, nominal, cycle=q) for q in (0, 1))
            say(f"{v:6.4f} | {a1:7.2f}, {a2:7.2f} | "
                f"{c['force_per_width'][np.argmax(c['strain'])]:8.2f} | "
                + ", ".join(f"{c['force_per_width'][i]:6.2f}" for i in ends)
                + f" | {ik_change:.1e}")
        ax.set_title(f"({'ab'[values is LOOP_MU]}) {label} (knit-knit) varied",
                     fontsize=9)
        ax.set_xlabel("strain")
        ax.legend(fontsize=8, title="solid loading, dashed unloading", title_fontsize=8)
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("force per width (N/m)")
    fig.suptitle(f"Knit cell, two cycles to strain 1 ({NOTE})", fontsize=10)
    fig.tight_layout()
    fig.savefig(HERE / "loops.png", dpi=110)
    plt.close(fig)


# ---------------------------------------------------------------------------------------
# 3: belt and gap factors
# ---------------------------------------------------------------------------------------
GAP = 0.2e-3
GAP_FACTORS = [1.0, 0.85, 0.7, 0.55]
NO_TABLE = {"fabric.gap_factor": None, "fabric.gap_factor_p_disp": None}


def belt_runs() -> list[Run]:
    # Constant factor f: the fabric generated with the gap f * 0.2 mm (its L0 set there
    # by the prestress). Scaling the holders of belt.nml's fabric by a constant f < 1
    # from the first state on instead makes the yarns slack (their paths get shorter
    # than their L0): its initial state does not converge for f <= 0.7 (see README).
    runs = [Run(f"belt_gap_{f}", BELT, {**NO_TABLE, "fabric.gap": f * GAP})
            for f in GAP_FACTORS]
    return runs + [Run("belt_table", BELT, {})]


def belt(r: dict[str, Run]) -> None:
    import matplotlib.pyplot as plt
    say("")
    say("## 3. belt, 2/2 twill 12 x 8 clamped, stretch to 15 % and release (Fig. 13)")
    say("f = constant gap factor: the fabric generated with gap f * 0.2 mm (prestress "
        "applied in that geometry); 'table': belt.nml (generated with 0.2 mm, holders "
        "scaled by 1.0, 0.8, 0.7 at p_disp 0, 0.5, 1 along the path, L0 kept)")
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.3))
    cmap = plt.get_cmap("cividis")
    say("case | F at 5 %, 10 %, 15 % (N/m) | max slipping passages | unloading - loading "
        "max |dF| (N/m)")
    for k, name in enumerate([f"belt_gap_{f}" for f in GAP_FACTORS] + ["belt_table"]):
        c = r[name].curve
        label = "table (belt.nml)" if name == "belt_table" else \
            f"f = {name.split('_')[-1]}"
        style = dict(color="crimson", lw=2.2) if name == "belt_table" else \
            dict(color=cmap(k / len(GAP_FACTORS)), lw=1.3)
        load = branches(c)[0]
        axes[0].plot(c["strain"][load], c["force_per_width"][load], label=label, **style)
        gap_loop = max(abs(at_strain(c, e, -1) - at_strain(c, e, 1))
                       for e in np.linspace(0, 0.15, 31))
        say(f"{label:17s} | " + ", ".join(f"{at_strain(c, e, 1):8.1f}" for e in
                                          (0.05, 0.10, 0.15))
            + f" | {int(c['slipping'].max())} of {int(c['passages'][0])} | {gap_loop:.2e}")
    axes[0].set_xlabel("strain")
    axes[0].set_ylabel("force per width (N/m)")
    axes[0].set_title("(a) loading; unloading retraces it (no passage slips)", fontsize=9)
    fig.suptitle(f"Belt, 2/2 twill 12 x 8 with gap-holders ({NOTE})", fontsize=10)
    axes[0].legend(fontsize=8)
    p = np.linspace(0, 1, 101)
    axes[1].plot(0.15 * p, np.interp(p, [0, 0.5, 1], [1.0, 0.8, 0.7]), color="crimson",
                 lw=2.2, label="adopted table (belt.nml)")
    for k, f in enumerate(GAP_FACTORS):
        axes[1].axhline(f, color=cmap(k / len(GAP_FACTORS)), lw=1, ls=":")
    axes[1].set_xlabel("strain (= 0.15 p_disp)")
    axes[1].set_ylabel("gap factor")
    axes[1].set_title("(b) gap factor along the path (illustrative, not fitted)",
                      fontsize=9)
    axes[1].legend(fontsize=8)
    for ax in axes:
        ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(HERE / "belt.png", dpi=110)
    plt.close(fig)


# ---------------------------------------------------------------------------------------
# 4: discretisation and load step
# ---------------------------------------------------------------------------------------
ELEMENTS = [1, 2, 4, 8]
STEPS = [0.2, 0.1, 0.05, 0.025, 0.0125]
TWILL_CELL = {"fabric.kind": "twill", "fabric.boundary": "periodic", "fabric.cells": [4, 4],
              "fabric.sides": None}


def convergence_runs() -> list[Run]:
    runs = [Run(f"elements_{n}", KNIT, {**ONE_CYCLE, "fabric.elements_per_segment": n},
                vtk=True) for n in ELEMENTS]
    runs += [Run(f"elements_{n}_lock0.001", KNIT,
                 {**ONE_CYCLE, "fabric.elements_per_segment": n,
                  "solver.min_length_ratio": 0.001}) for n in (4, 8)]
    uniform = lambda h: {"solver.max_step": h, "solver.initial_step": h}  # noqa: E731
    runs += [Run(f"step_{h}", KNIT, {**ONE_CYCLE, **uniform(h)}) for h in STEPS]
    runs += [Run(f"twill_step_{h}", BELT, {**TWILL_CELL, **uniform(h)}, may_fail=True)
             for h in STEPS]
    return runs


def common_points(curve, grid: float = 0.2) -> np.ndarray:
    """Force per width at the path times that are multiples of `grid` (every run with a
    uniform step that divides `grid` stops there, unless it had to cut a step)."""
    t = curve["time"]
    on = np.isclose(np.round(t / grid) * grid, t, rtol=0, atol=1e-9)
    return curve["force_per_width"][on]


def difference_at_shared_times(curve, reference) -> float:
    """Largest |force per width difference| at the path times both runs reached (a run
    that cut a step leaves the uniform grid; no interpolation across the gap)."""
    same = np.isclose(curve["time"][:, None], reference["time"][None, :], rtol=0,
                      atol=1e-9)
    i, j = np.nonzero(same)
    return float(np.max(np.abs(curve["force_per_width"][i]
                               - reference["force_per_width"][j])))


def orders(errors: list[float], ratio: float = 2.0) -> list[str]:
    out = []
    for a, b in zip(errors[:-1], errors[1:]):
        out.append(f"{np.log(a / b) / np.log(ratio):.2f}" if a > 0 and b > 0 else "-")
    return out


def convergence(r: dict[str, Run]) -> None:
    import matplotlib.pyplot as plt
    say("")
    say("## 4a. knit cycle against elements per segment (max_step 0.05, uniform path)")
    fig, axes = plt.subplots(2, 2, figsize=(11, 8))
    cmap = plt.get_cmap("viridis")
    finest, first = r[f"elements_{ELEMENTS[-1]}"].curve, r["elements_1"].curve
    say("elements | steps | max|F - F(8)| (N/m) | max|F - F(1)| (N/m) | rel. to max F | "
        "min L0/L0(0) | F at strain 1 (N/m) | same with min_length_ratio 0.001")
    for k, n in enumerate(ELEMENTS):
        run = r[f"elements_{n}"]
        c = run.curve
        ratio = min(np.min(s.length0 / run.states[0].length0) for s in run.states)
        draw_loop(axes[0, 0], c, cmap(k / len(ELEMENTS)), f"{n} per segment")
        d8, d1 = loop_difference(c, finest), loop_difference(c, first)
        unlocked = "-"
        if f"elements_{n}_lock0.001" in r:
            unlocked = f"{r[f'elements_{n}_lock0.001'].curve['force_per_width'].max():.1f}"
        say(f"{n:8d} | {len(c['strain']):5d} | {d8:10.3e} | {d1:10.3e} | "
            f"{d1 / first['force_per_width'].max():9.2e} | {ratio:6.3f} | "
            f"{c['force_per_width'].max():8.1f} | {unlocked}")
    axes[0, 0].set_title(f"(a) knit cycle, elements per segment ({NOTE})", fontsize=9)
    axes[0, 0].set_xlabel("strain")
    axes[0, 0].set_ylabel("force per width (N/m)")
    axes[0, 0].legend(fontsize=8)
    # L0 of the shortest element next to a passage, along the path.
    for k, n in enumerate(ELEMENTS):
        run = r[f"elements_{n}"]
        ratio = [np.min(s.length0 / run.states[0].length0) for s in run.states]
        axes[0, 1].plot(run.curve["time"], ratio, color=cmap(k / len(ELEMENTS)),
                        label=f"{n} per segment")
    axes[0, 1].axhline(0.05, color="k", ls=":", lw=1, label="min_length_ratio 0.05")
    axes[0, 1].set_xlabel("pseudo-time (0-1 loading, 1-2 unloading)")
    axes[0, 1].set_ylabel("min over elements of L0 / L0(initial)")
    axes[0, 1].set_title("(b) smallest L0 / L0(0) over the cycle", fontsize=9)
    axes[0, 1].legend(fontsize=8)

    say("")
    say("## 4b. load step (uniform steps, initial_step = max_step; compared at the 11 path "
        "points that are multiples of 0.2 in pseudo-time, no interpolation)")
    for scene, prefix, ax_colour in (("knit cycle", "step", "tab:blue"),
                                     ("twill 4x4 cell, belt yarns (woven with sliding)",
                                      "twill_step", "tab:red")):
        ref = common_points(r[f"{prefix}_{STEPS[-1]}"].curve)
        say(f"{scene}: max_step | steps | max|F - F(0.0125)| (N/m) | rel. to max F | "
            "wall (s)")
        errors = []
        for h in STEPS[:-1]:
            run = r[f"{prefix}_{h}"]
            if run.error:
                errors.append(np.nan)
                say(f"    {h:7.4f} | FAILED: {run.error}")
                continue
            errors.append(difference_at_shared_times(run.curve,
                                                     r[f"{prefix}_{STEPS[-1]}"].curve))
            say(f"    {h:7.4f} | {len(run.curve['strain']):4d} | {errors[-1]:10.3e} | "
                f"{errors[-1] / ref.max():9.2e} | {run.seconds:.2f}")
        say(f"    observed orders (h -> h/2): {', '.join(orders(errors))}")
        ok = np.isfinite(errors)
        axes[1, 1].loglog(np.array(STEPS[:-1])[ok],
                          np.maximum(np.array(errors)[ok] / ref.max(), 1e-17),
                          "o-", color=ax_colour, label=scene)
        c = r[f"{prefix}_{STEPS[0]}"].curve
        if prefix == "step":
            for k, h in enumerate(STEPS):
                c = r[f"{prefix}_{h}"].curve
                draw_loop(axes[1, 0], c, cmap(k / len(STEPS)), f"max_step {h}")
    axes[1, 0].set_title(f"(c) knit cycle, load step ({NOTE})", fontsize=9)
    axes[1, 0].set_xlabel("strain")
    axes[1, 0].set_ylabel("force per width (N/m)")
    axes[1, 0].legend(fontsize=8)
    axes[1, 1].set_xlabel("max_step (pseudo-time; one cycle = 2)")
    axes[1, 1].set_ylabel("max |F - F(max_step 0.0125)| / max F")
    axes[1, 1].set_title("(d) load step: difference to the finest run", fontsize=9)
    axes[1, 1].legend(fontsize=8)
    for ax in axes.flat:
        ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(HERE / "convergence.png", dpi=110)
    plt.close(fig)


# ---------------------------------------------------------------------------------------
# 5: periodic cell against clamped samples
# ---------------------------------------------------------------------------------------
PLAIN_SAMPLES = [(8, 4), (16, 4), (32, 4)]
TWILL_SAMPLES = [(8, 4), (16, 4), (32, 4), (16, 8), (32, 16)]
FINE = {"solver.max_step": 0.0125, "solver.initial_step": 0.0125}
COARSE = {"solver.max_step": 0.05, "solver.initial_step": 0.05}
#: Tolerance for the plain weave (relative to the largest force per width).
PLAIN_TOLERANCE = 1e-8


def sample_runs() -> list[Run]:
    runs = []
    for law, contact in (("bonded", bonded(1)), ("adhesion", {})):
        runs.append(Run(f"plain_cell_{law}", BELT, {
            **LOADING, **contact, **FINE, "fabric.kind": "plain", "fabric.boundary": "periodic",
            "fabric.cells": [4, 4], "fabric.sides": None}))
        runs += [Run(f"plain_sample_{law}_{nx}x{ny}", BELT, {
            **LOADING, **contact, **COARSE, "fabric.kind": "plain",
            "fabric.cells": [nx, ny]}, vtk=True)
            for nx, ny in PLAIN_SAMPLES]
    runs.append(Run("twill_cell", BELT, {**LOADING, **TWILL_CELL, **FINE}))
    runs += [Run(f"twill_sample_{nx}x{ny}", BELT, {
        **LOADING, **COARSE, "fabric.kind": "twill", "fabric.cells": [nx, ny]}, vtk=True)
        for nx, ny in TWILL_SAMPLES]
    return runs


def compare(cell, sample, cells):
    """A sample against the periodic cell, relative to the cell's largest force per
    width, per step: clamp force at clamp strain, clamp force at interior strain and
    interior (middle-warp) force at interior strain; and the interior strain."""
    from scipy.interpolate import CubicSpline
    periodic = CubicSpline(cell.curve["strain"], cell.curve["force_per_width"])
    scale = cell.curve["force_per_width"].max()
    strain, force = interior_measures(sample.states, cells, WOVEN_SPACING)
    c = sample.curve
    f = c["force_per_width"]
    return (np.abs(f - periodic(c["strain"])) / scale,
            np.abs(f - periodic(strain)) / scale,
            np.abs(force - periodic(strain)) / scale, strain)


def periodic_vs_sample(r: dict[str, Run]) -> None:
    import matplotlib.pyplot as plt
    say("")
    say("## 5. periodic 4x4 cell against clamped samples with rollers (nx wefts along the "
        "load x ny warps), stretch to 15 %")
    say("differences: max over all steps of |F_sample - F_cell| / max F_cell; interior "
        "strain from the crossings of wefts nx/4 and 3nx/4 of the middle warps; interior F "
        "from the middle warps' tensions at a section near the centre; cell curve "
        "interpolated by a cubic spline (exact at the sample's strains for the plain weave)")
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.6))
    say("case | steps | slipping (max) | clamp F @ clamp strain | clamp F @ interior "
        "strain | interior F @ interior strain | interior - clamp strain at 15 % | wall (s)")
    floor = 1e-16
    worst_plain = 0.0
    for law, marker in (("bonded", "o"), ("adhesion", "s")):
        cell = r[f"plain_cell_{law}"]
        for k, (nx, ny) in enumerate(PLAIN_SAMPLES):
            s = r[f"plain_sample_{law}_{nx}x{ny}"]
            d_clamp, d_int, d_force, strain = compare(cell, s, (nx, ny))
            worst = max(d_clamp.max(), d_int.max(), d_force.max())
            worst_plain = max(worst_plain, worst)
            say(f"plain {law:8s} {nx:2d}x{ny:<2d} | {len(strain):3d} | "
                f"{int(s.curve['slipping'].max()):3d} | {d_clamp.max():.1e} | "
                f"{d_int.max():.1e} | {d_force.max():.1e} | "
                f"{strain[-1] - s.curve['strain'][-1]:+.1e} | {s.seconds:.2f}")
            axes[0].semilogy(strain, np.maximum(d_int, floor), marker + "-", mfc="none",
                             ms=3 + k, lw=0.8, label=f"{law}, sample {nx}x{ny}")
    axes[0].axhline(PLAIN_TOLERANCE, color="k", ls="--", lw=1, label="tolerance 1e-8")
    say(f"plain weave: worst difference {worst_plain:.1e} (tolerance {PLAIN_TOLERANCE:.0e})"
        f" -> {'PASS' if worst_plain < PLAIN_TOLERANCE else 'FAIL'}")
    axes[0].set_xlabel("interior strain of the sample")
    axes[0].set_ylabel("|F_sample - F_cell| / max F_cell (clamp force)")
    axes[0].set_title("(a) plain weave, bonded and adhesion (no passage slips)",
                      fontsize=9)
    axes[0].legend(fontsize=7, ncol=2)

    cell = r["twill_cell"]
    rows = {}
    cmap = plt.get_cmap("viridis")
    for k, (nx, ny) in enumerate(TWILL_SAMPLES):
        s = r[f"twill_sample_{nx}x{ny}"]
        d_clamp, d_int, d_force, strain = compare(cell, s, (nx, ny))
        rows[(nx, ny)] = (d_clamp.max(), d_int.max(), d_force.max())
        say(f"twill adhesion {nx:2d}x{ny:<2d} | {len(strain):3d} | "
            f"{int(s.curve['slipping'].max()):3d} | {d_clamp.max():.1e} | {d_int.max():.1e} | "
            f"{d_force.max():.1e} | {strain[-1] - s.curve['strain'][-1]:+.1e} | "
            f"{s.seconds:.2f}")
        colour = cmap(k / len(TWILL_SAMPLES))
        axes[1].semilogy(s.curve["strain"], np.maximum(d_clamp, floor), "--", color=colour,
                         lw=1)
        axes[1].semilogy(strain, np.maximum(d_force, floor), "-", color=colour, lw=1.3,
                         label=f"sample {nx}x{ny}")
    axes[1].set_xlabel("strain (dashed: clamps; solid: interior)")
    axes[1].set_ylabel("|F_sample - F_cell| / max F_cell")
    axes[1].set_title("(b) 2/2 twill with adhesion: dashed clamp F at clamp strain,\n"
                      "solid middle-warp F at interior strain", fontsize=9)
    axes[1].legend(fontsize=7)
    for series, marker, name in (([(8, 4), (16, 4), (32, 4)], "o", "ny = 4"),
                                 ([(8, 4), (16, 8), (32, 16)], "s", "ny = nx/2")):
        nxs = [nx for nx, _ in series]
        for index, what, colour in ((0, "clamp F @ clamp strain", "tab:blue"),
                                    (1, "clamp F @ interior strain", "tab:orange"),
                                    (2, "interior F @ interior strain", "tab:green")):
            axes[2].loglog(nxs, [rows[key][index] for key in series], marker=marker,
                           color=colour, ls="-" if marker == "s" else ":",
                           label=f"{what}, {name}")
    first = rows[(8, 4)][0]
    axes[2].loglog([8, 32], [first, first / 4], "k-", lw=0.6, label="slope -1")
    axes[2].set_xlabel("wefts along the load nx")
    axes[2].set_ylabel("max |F_sample - F_cell| / max F_cell")
    axes[2].set_title("(c) twill: difference against sample size", fontsize=9)
    axes[2].legend(fontsize=6.5)
    for ax in axes:
        ax.grid(alpha=0.3, which="both")
    fig.suptitle(f"Periodic 4x4 cell vs clamped samples with rollers, stretch to 15 % "
                 f"({NOTE})", fontsize=10)
    fig.tight_layout()
    fig.savefig(HERE / "periodic_vs_sample.png", dpi=110)
    plt.close(fig)


def main() -> None:
    import matplotlib
    matplotlib.use("Agg")
    if not EXE.exists():
        sys.exit(f"{EXE} is missing: build first (./yarnfort --version)")
    start = time.perf_counter()
    say("# fabric study (verification/fabrics/run_study.py)")
    say(f"# {NOTE.upper()}: the paper's measurements are not available; every curve is "
        "computed")
    groups = {"knit": knit_runs(), "belt": belt_runs(), "convergence": convergence_runs(),
              "samples": sample_runs()}
    results: dict[str, Run] = {}
    for name, runs in groups.items():
        t = time.perf_counter()
        results.update(run_all(runs))
        print(f"[{name}: {len(runs)} runs in {time.perf_counter() - t:.1f} s]", flush=True)
    sensitivity(results)
    loops(results)
    belt(results)
    convergence(results)
    periodic_vs_sample(results)
    total = sum(r.seconds for r in results.values())
    say("")
    say(f"# {len(results)} runs, {total:.1f} s of run time, "
        f"{time.perf_counter() - start:.1f} s wall on {WORKERS} workers")
    (HERE / "results.txt").write_text("\n".join(LINES) + "\n")


if __name__ == "__main__":
    main()
