#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Clamped samples of many repeats and their convergence towards the periodic cell
(issue 13 item 4, issue 16 item 2).

1. Newton iterations per step of clamped knits (inputs/knit.nml, with inlay, free sides:
   the cast-on and bind-off threads; and rollers) against periodic cells of the same
   size, one loading to strain 1 (20 steps of max_step 0.05).
2. Clamped samples of many repeats from the built-in routes, curve per width (force per
   unit width against strain): the knit with inlay up to 20 x 20 loops, plain weave and
   2/2 twill (inputs/belt.nml's yarns and gap table) up to 40 x 40 crossings.
3. Convergence of the sample's curve per width against its size n (n x n repeats,
   rollers on the sides, the periodic cell's boundary in y) towards the periodic cell:
   error e(n) = max over the common strains of |F_n - F_cell| / max F_cell, the fitted
   exponent p of e ~ C / n**p, and the sizes where the fit gives 5 % and 1 %.

NO MEASURED DATA: the yarn tables in inputs/data are illustrative; every curve is
computed.

Run:  nice .venv/bin/python verification/clamped/run_study.py   (after ./yarnfort once)
Writes the README's tables to results.txt, clamped_curves.png and clamped_convergence.png
next to this script; runs go to out/clamped_study/ (git-ignored), two at a time. A run
whose scene text is unchanged and newer than build/yarnfort is reused (its wall time is
then the sum of its steps'); REUSE=0 runs everything again.
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
from fabric_scenes import LOADING, patched_scene, run_scene  # noqa: E402
from yarnfort import read_curve  # noqa: E402

EXE = Path(os.environ.get("YARNFORT_EXE", TOP / "build" / "yarnfort"))
OUT = TOP / "out" / "clamped_study"
WORKERS = 2
#: Reuse a run whose scene text is unchanged and newer than the program (REUSE=0: all).
REUSE = os.environ.get("REUSE", "1")
REUSE = "" if REUSE == "0" else REUSE
NOTE = "computed with illustrative yarn tables; no measured data"
KNIT, BELT, TEXGEN = "inputs/knit.nml", "inputs/belt.nml", "inputs/texgen_weave.nml"
#: Sizes (n x n repeats) of each route; the woven ones need even counts for the cell.
KNIT_SIZES = (2, 4, 8, 16, 20)
WOVEN_SIZES = (4, 8, 16, 24, 40)
#: Copies of inputs/texgen_weave.tg3's 2 x 2 cell (n x n copies: 2n x 2n crossings).
TEXGEN_COPIES = (1, 2, 4, 8, 12)
#: Sizes of the iteration table (item 1).
TABLE_SIZES = (4, 8, 16)
#: A holding thread pulled taut (the knit yarn's table, 1 N prestress) for the free
#: sides of the knit samples (edge_material); the default thread is the knit yarn itself.
THREAD = """
&material
    name = 'thread'
    law = 'table'
    table_file = 'inputs/data/knit_yarn.csv'
    prestress = 1.0
/
"""
LINES: list[str] = []
REUSED: list[str] = []
#: Route, sizes, and the periodic cell it is compared with.
ROUTES = (("knit", KNIT_SIZES, "knit_periodic_2"), ("plain", WOVEN_SIZES, "plain_periodic_4"),
          ("twill", WOVEN_SIZES, "twill_periodic_4"),
          ("texgen", TEXGEN_COPIES, "texgen_periodic_1"))


def say(line: str = "") -> None:
    LINES.append(line)
    print(line, flush=True)


def knit_values(n: int, boundary: str, sides: str | None = None,
                thread: bool = False) -> dict:
    values = {**LOADING, "output.vtk_every": 0, "fabric.cells": [n, n],
              "fabric.boundary": boundary}
    if boundary == "clamped":
        values.update({"fabric.lateral_strain": None, "fabric.sides": sides})
    if thread:
        values["fabric.edge_material"] = "thread"
    return values


def woven_values(kind: str, n: int, boundary: str) -> dict:
    values = {**LOADING, "output.vtk_every": 0, "fabric.kind": kind, "fabric.cells": [n, n],
              "fabric.boundary": boundary}
    if boundary == "periodic":
        values["fabric.sides"] = None
    return values


def run(case: tuple[str, str, dict]):
    name, base, values = case
    folder = OUT / name
    text = patched_scene(base, values, folder)
    if values.get("fabric.edge_material") == "thread":
        text += THREAD
    scene = folder / "scene.nml"
    if REUSE and scene.exists() and scene.read_text() == text and (REUSE == "any" or (
            folder / "curve.csv").stat().st_mtime > EXE.stat().st_mtime):
        curve = read_curve(folder)
        REUSED.append(name)
        return name, curve, float(np.sum(curve["wall_time"])), []
    proc, wall = run_scene(text, EXE, timeout=900)
    if proc.returncode != 0:
        return name, None, wall, proc.stderr.strip().splitlines()[-1:]
    scene.write_text(text)
    return name, read_curve(folder), wall, []


def run_all(cases):
    results = {}
    with cf.ThreadPoolExecutor(WORKERS) as pool:
        for name, curve, wall, error in pool.map(run, cases):
            results[name] = (curve, wall)
            if curve is None:
                say(f"  {name}: FAILED {error}")
    return results


def iterations(curve) -> tuple[int, int, int, float]:
    """Steps after the initial state, their Newton iterations, the initial state's."""
    it = np.asarray(curve["newton_iterations"], int)
    return len(it) - 1, int(it[1:].sum()), int(it[0]), float(it[1:].mean())


def error_against(curve, cell) -> float:
    """max |F - F_cell| / max F_cell at the sample's strains (cell interpolated)."""
    strain, force = curve["strain"], curve["force_per_width"]
    reference = np.interp(strain, cell["strain"], cell["force_per_width"])
    return float(np.max(np.abs(force - reference)) / np.max(np.abs(cell["force_per_width"])))


def fit(sizes, errors) -> tuple[float, float]:
    """C, p of e = C / n**p, least squares in logs over the given sizes."""
    slope, intercept = np.polyfit(np.log(sizes), np.log(errors), 1)
    return float(np.exp(intercept)), float(-slope)


def main() -> None:
    if not EXE.exists():
        sys.exit(f"{EXE} not found: run ./yarnfort --version once to build it")
    OUT.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    cpu0 = os.times()
    cases = [(f"knit_periodic_2", KNIT, knit_values(2, "periodic"))]
    for n in sorted(set(KNIT_SIZES) | set(TABLE_SIZES)):
        cases.append((f"knit_rollers_{n}", KNIT, knit_values(n, "clamped", "rollers")))
        cases.append((f"knit_free_{n}", KNIT, knit_values(n, "clamped", "free", True)))
    for n in TABLE_SIZES:
        cases.append((f"knit_periodic_{n}", KNIT, knit_values(n, "periodic")))
        cases.append((f"knit_default_{n}", KNIT, knit_values(n, "clamped", "free")))
    for kind in ("plain", "twill"):
        cases.append((f"{kind}_periodic_4", BELT, woven_values(kind, 4, "periodic")))
        for n in WOVEN_SIZES:
            cases.append((f"{kind}_rollers_{n}", BELT, woven_values(kind, n, "clamped")))
    cases.append(("texgen_periodic_1", TEXGEN, {**LOADING, "output.vtk_every": 0}))
    for n in TEXGEN_COPIES:
        cases.append((f"texgen_rollers_{n}", TEXGEN, {
            **LOADING, "output.vtk_every": 0, "fabric.boundary": "clamped",
            "fabric.cells": [n, n], "fabric.sides": "rollers"}))
    results = run_all(cases)
    curves = {name: curve for name, (curve, _) in results.items()}
    walls = {name: wall for name, (_, wall) in results.items()}

    say("# Clamped samples: iterations, curves per width, convergence to the cell")
    say(f"({NOTE}; {len(cases)} runs)")
    say()
    say("## 1. Newton iterations per step, clamped knits against periodic cells")
    say("(inputs/knit.nml with inlay, loading to strain 1, max_step 0.05)")
    say()
    say("| sample | steps | Newton iterations | per step | initial state | wall s |")
    say("|---|---:|---:|---:|---:|---:|")
    for n in TABLE_SIZES:
        for kind in ("periodic", "default", "free", "rollers"):
            name = f"knit_{kind}_{n}"
            if curves.get(name) is None:
                say(f"| {kind} {n} x {n} | failed | | | | {walls[name]:.1f} |")
                continue
            steps, total, first, per = iterations(curves[name])
            label = {"periodic": "periodic", "default": "clamped, free, knit-yarn threads",
                     "free": "clamped, free, taut thread", "rollers": "clamped, rollers"}[kind]
            say(f"| {label} {n} x {n} | {steps} | {total} | {per:.1f} | {first} | "
                f"{walls[name]:.2f} |")
    say()

    say("## 2-3. Curve per width against sample size")
    say()
    summary = {}
    for route, sizes, cell_name in ROUTES:
        cell = curves.get(cell_name)
        say(f"### {route}: periodic cell F(end) = "
            f"{cell['force_per_width'][-1]:.1f} N/m at strain {cell['strain'][-1]:.3g}")
        say()
        say("| sample (rollers) | F(end) N/m | e(n) = max \\|F - F_cell\\| / max F_cell | "
            "free sides (taut thread) F(end) | wall s |")
        say("|---|---:|---:|---:|---:|")
        ns, es = [], []
        for n in sizes:
            curve = curves.get(f"{route}_rollers_{n}")
            free = curves.get(f"{route}_free_{n}")
            free_text = f"{free['force_per_width'][-1]:.1f}" if free is not None else "-"
            if curve is None:
                say(f"| {n} x {n} | failed | | {free_text} | |")
                continue
            e = error_against(curve, cell)
            ns.append(n)
            es.append(e)
            say(f"| {n} x {n} | {curve['force_per_width'][-1]:.1f} | {e:.3g} | {free_text} | "
                f"{walls[f'{route}_rollers_{n}']:.1f} |")
        say()
        summary[route] = (np.array(ns), np.array(es))
        usable = [(n, e) for n, e in zip(ns, es) if n >= 4 and e > 1e-8]
        if len(usable) >= 2:
            c, p = fit(*zip(*usable))
            n5, n1 = (c / 0.05) ** (1 / p), (c / 0.01) ** (1 / p)
            say(f"fit over n >= 4: e = {c:.3g} / n^{p:.2f}; 5 % at n = {n5:.1f}, "
                f"1 % at n = {n1:.1f}")
        else:
            say("no fit: the error is at the Newton tolerance (exact) or too few sizes")
        say()
    cpu1 = os.times()
    cpu = (cpu1.children_user + cpu1.children_system) - (cpu0.children_user
                                                          + cpu0.children_system)
    say(f"total wall {time.perf_counter() - start:.0f} s, CPU of the runs {cpu:.0f} s "
        f"({len(REUSED)} of {len(cases)} runs reused from out/clamped_study; wall s of a "
        "reused run is the sum of its steps')")
    (HERE / "results.txt").write_text("\n".join(LINES) + "\n")
    plot(curves, summary)


def plot(curves, summary) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 4, figsize=(19, 4.6))
    for ax, (route, sizes, cell_name) in zip(axes, ROUTES):
        cell = curves[cell_name]
        ax.plot(cell["strain"], cell["force_per_width"], "k-", lw=2.5, label="periodic cell")
        for n in sizes:
            curve = curves.get(f"{route}_rollers_{n}")
            if curve is not None:
                ax.plot(curve["strain"], curve["force_per_width"], lw=1,
                        label=f"{n} x {n}, rollers")
            free = curves.get(f"{route}_free_{n}")
            if free is not None:
                ax.plot(free["strain"], free["force_per_width"], "--", lw=1,
                        label=f"{n} x {n}, free sides")
        ax.set_xlabel("strain")
        ax.set_ylabel("force per width (N/m)")
        unit = " copies of the 2 x 2 cell" if route == "texgen" else ""
        ax.set_title(f"{route}: clamped samples (n x n{unit})\n({NOTE})", fontsize=9)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(HERE / "clamped_curves.png", dpi=110)

    fig, ax = plt.subplots(figsize=(6, 4.6))
    for route, (ns, es) in summary.items():
        keep = es > 0
        if np.any(keep):
            ax.loglog(1.0 / ns[keep], es[keep], "o-", label=route)
    ax.set_xlabel("1 / n (n x n repeats)")
    ax.set_ylabel("max |F - F_cell| / max F_cell")
    ax.set_title(f"clamped (rollers) against the periodic cell\n({NOTE})", fontsize=9)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(HERE / "clamped_convergence.png", dpi=110)


if __name__ == "__main__":
    main()
