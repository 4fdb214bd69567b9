#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The speed-accuracy front of the &solver settings on fabric-scale scenes, and where the
presets lie on it (issue 42).

    .venv/bin/python benchmarks/presets_front.py                  # about 5 min CPU
    .venv/bin/python benchmarks/presets_front.py --cell 8 --clamped 8   # about 1 min

Scenes (one stretch-and-release cycle each, p_disp 0 -> 1 -> 0, no VTK output, the
scenes' own max_step removed): the periodic knit cell of inputs/knit.nml at --cell x
--cell loops (16), that knit clamped with rollers at --clamped x --clamped loops (24), the
belt (inputs/belt.nml) and the TexGen weave (inputs/texgen_weave.nml). Settings: the
defaults, the presets (values from src/yarnfort/input/variables.py), a grid of max_step
(= initial_step) 1, 0.5, 0.25, 0.1, 0.05 by residual_tolerance 1e-2 .. 1e-10 (1e-4 and
1e-6 only above 0.25, 1e-2 only at 0.25 and 0.1), a point a preset sets left out; the
staggered scheme at the defaults and at step 0.25, tolerance 1e-6. Cost: user CPU
seconds of the child processes (resource.getrusage), summed over the scenes; a run is
stopped at --limit times its scene's reference's CPU (slower than the reference, it is
not on the front). Curve error of a run: per branch (loading, release) the largest
difference of force_per_width from the reference at the run's times, over the branch's
largest |force_per_width| in the reference; per scene the worse branch. The reference is
the monolithic scheme at max_step = --reference-step (0.005), residual_tolerance =
REFERENCE_TOLERANCE; its own error, printed, is its difference from the run at twice its
step and 10x its tolerance. A run's times not on the reference's grid (after a step cut)
are left out and counted. A setting is on the front when no other is faster and at least
as accurate on every scene.

Prints a markdown table (setting, CPU, curve error per scene, worst, on the front or
dominated by which setting), the steps every setting takes (step 0 with the first load
step, the last load step: CPU and Newton iterations from the defaults' step trace), the
CPU per scene of the defaults and presets, and draws CPU against the worst scene's curve
error (--png, default docs/images/presets_front.png). Progress on stderr.
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
from pathlib import Path

TOP = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(TOP / "tests" / "verification"))
sys.path.insert(0, str(TOP / "benchmarks"))
from fabric_scenes import ONE_CYCLE, patched_scene  # noqa: E402
from steps_compare import read_curve as read_rows  # noqa: E402

import blas_env  # noqa: E402

PROGRAM = TOP / "build" / "yarnfort"
TRACE = TOP / "build" / "benchmarks" / "steps_trace"
#: The reference run: fine steps, tight tolerance (its own error is measured, above).
REFERENCE_STEP = 0.005
REFERENCE_TOLERANCE = 1e-12
#: Times of two runs are the same step when they differ by less than this (knot units).
TIME_MATCH = 1e-9
PRESETS = ("balanced", "accurate")
#: A run is stopped at this fraction of its scene's reference's CPU (a setting that slow
#: is not on the front: the reference is more accurate).
LIMIT = 1.0


def scenes(cell: int, clamped: int) -> dict[str, tuple[str, dict]]:
    """Name -> (base input, values to patch) of each scene; the scenes' own &solver
    max_step goes (the settings decide it)."""
    cycle = {**ONE_CYCLE, "solver.max_step": None}
    knit = {**cycle, "fabric.cells": [cell, cell]}
    clamp = {**cycle, "fabric.cells": [clamped, clamped], "fabric.boundary": "clamped",
             "fabric.lateral_strain": None, "fabric.sides": "rollers"}
    return {f"knit cell {cell}x{cell}": ("inputs/knit.nml", knit),
            f"clamped knit {clamped}x{clamped}": ("inputs/knit.nml", clamp),
            "belt": ("inputs/belt.nml", cycle),
            "TexGen weave": ("inputs/texgen_weave.nml", cycle)}


def preset_values() -> dict[str, dict]:
    """Preset -> the &solver values it sets (src/yarnfort/input/variables.py)."""
    sys.path.insert(0, str(TOP / "src" / "yarnfort" / "input"))
    from variables import GROUPS  # noqa: E402
    solver = next(g for g in GROUPS if g.name == "solver")
    return {p: {v.name: v.presets[p] for v in solver.variables if v.presets}
            for p in PRESETS}


def settings() -> dict[str, dict]:
    """Setting name -> &solver values; a grid point that a preset sets is left out
    (the preset stands for it)."""
    found: dict[str, dict] = {"defaults": {}}
    presets = list(preset_values().values())
    for preset in PRESETS:
        found[preset] = {"preset": preset}
    for step in (1.0, 0.5, 0.25, 0.1, 0.05):
        # Above a step of 0.25 the tolerance changed nothing but the cost (measured);
        # 1e-2 only where the cheapest settings are.
        tolerances = (1e-4, 1e-6) if step > 0.25 else (1e-2, 1e-4, 1e-6, 1e-8, 1e-10)
        for tolerance in tolerances[1 if step < 0.1 else 0:]:
            values = {"initial_step": step, "max_step": step, "residual_tolerance": tolerance}
            if {**values, "scheme": "monolithic"} not in presets:
                found[f"step {step:g} tol {tolerance:.0e}"] = values
    found["step 0.25 tol 1e-06 staggered"] = {
        "initial_step": 0.25, "max_step": 0.25, "residual_tolerance": 1e-6,
        "scheme": "staggered"}
    found["defaults staggered"] = {"scheme": "staggered"}
    return found


def read_curve(folder: Path) -> list[tuple[float, float]]:
    """(time, force_per_width) of each row of curve.csv, by time."""
    return sorted((t, float(row["force_per_width"])) for t, row in read_rows(folder).items())


def run(base: str, values: dict, solver: dict, folder: Path,
        limit: float | None = None) -> tuple[list, float] | str:
    """(curve, user CPU seconds of the child), or the last line of stderr on failure;
    a run stopped at `limit` CPU seconds is a failure."""
    patch = {**values, "output.vtk_every": 0}
    patch.update({f"solver.{k}": v for k, v in solver.items()})
    text = patched_scene(base, patch, folder)

    def cap() -> None:
        if limit is not None:
            resource.setrlimit(resource.RLIMIT_CPU, (int(limit) + 1, int(limit) + 2))

    before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_utime
    done = subprocess.run([str(PROGRAM)], input=text, capture_output=True, text=True,
                          cwd=TOP, preexec_fn=cap)
    cpu = resource.getrusage(resource.RUSAGE_CHILDREN).ru_utime - before
    if limit is not None and done.returncode < 0:
        return f"stopped at {limit:.0f} s CPU"
    if done.returncode != 0:
        tail = done.stderr.strip().splitlines()
        return tail[-1] if tail else f"exit {done.returncode}"
    return read_curve(folder), cpu


def fixed_cost(base: str, values: dict, folder: Path) -> tuple[float, ...] | str:
    """From the defaults' step trace of a scene (benchmarks' steps_trace --per-step): CPU
    s of all steps, of step 0 with the first load step from rest, of the last load step,
    and the Newton iterations of the first and last load steps. Every setting of step
    and tolerance takes those two steps."""
    folder.mkdir(parents=True, exist_ok=True)
    scene = folder / "scene.nml"
    scene.write_text(patched_scene(base, {**values, "output.vtk_every": 0}, folder / "out"))
    done = subprocess.run([str(TRACE), str(scene), "--per-step"], capture_output=True,
                          text=True, cwd=TOP)
    steps = [line.split() for line in done.stdout.splitlines() if line.startswith("step ")]
    if done.returncode != 0 or len(steps) < 3:
        return f"steps_trace failed: {done.stderr.strip()[-200:]}"
    ms = [float(fields[-1]) / 1e3 for fields in steps]
    return sum(ms), ms[0] + ms[1], ms[-1], int(steps[1][6]), int(steps[-1][6])


def curve_error(curve: list, reference: list) -> tuple[float, int]:
    """Worst branch's largest difference over the branch's peak; times left out."""
    worst, missed = 0.0, 0
    for lo, hi in ((0.0, 1.0), (1.0, 2.0)):
        ref = [(t, f) for t, f in reference if lo - TIME_MATCH <= t <= hi + TIME_MATCH]
        peak = max(abs(f) for _, f in ref) or 1.0
        k = 0
        for t, f in curve:
            if not lo < t <= hi + TIME_MATCH:
                continue
            while k < len(ref) and ref[k][0] < t - TIME_MATCH:
                k += 1
            if k == len(ref) or abs(ref[k][0] - t) > TIME_MATCH:
                missed += 1
                continue
            worst = max(worst, abs(f - ref[k][1]) / peak)
    return worst, missed


def front(rows: dict[str, dict]) -> dict[str, str]:
    """For each setting: '' if on the front, else the fastest setting that is faster and
    at least as accurate on every scene (one worse on a scene is not: a user's scene may
    be like that one, and the worst scene alone cannot see the tolerance)."""
    found = {}
    for name, row in rows.items():
        if "failed" in row:
            found[name] = row["failed"]
            continue
        better = [other for other, o in rows.items() if other != name
                  and "failed" not in o and o["cpu"] < row["cpu"]
                  and all(o["scenes"][s] <= e for s, e in row["scenes"].items())]
        found[name] = min(better, key=lambda o: rows[o]["cpu"]) if better else ""
    return found


def draw(rows: dict[str, dict], dominated: dict[str, str], path: Path, title: str) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    inf = float("inf")

    figure, axes = plt.subplots(figsize=(7.5, 5.0))
    stopped = {name: row["failed"] + "".join(f" on the {scene}" for scene, error
                                             in row["scenes"].items() if error == inf)
               for name, row in rows.items() if "failed" in row}
    rows = {name: row for name, row in rows.items() if "failed" not in row}
    for name, row in rows.items():
        preset = name in PRESETS or name == "defaults"
        staggered = "staggered" in name
        axes.scatter(row["error"], row["cpu"], s=60 if preset else 22,
                     marker="s" if staggered else "o",
                     color=("C3" if preset else "C0") if not dominated[name] else
                     ("C1" if preset else "0.6"), zorder=3 if preset else 2)
        if preset:
            axes.annotate(f"'{name}'" if name != "defaults" else "defaults",
                          (row["error"], row["cpu"]), textcoords="offset points",
                          xytext=(6, 4), fontsize=9)
    axes.scatter([], [], s=0, label="front: no setting faster and at least as accurate "
                 "on every scene")
    kinds = {("o", "C3", "preset or defaults, on the front"): False,
             ("o", "C1", "preset or defaults, dominated"): False,
             ("o", "C0", "grid setting on the front"): False,
             ("o", "0.6", "grid setting, dominated"): False,
             ("s", "0.6", "staggered scheme"): False}
    for name, row in rows.items():
        preset = name in PRESETS or name == "defaults"
        color = ("C3" if preset else "C0") if not dominated[name] else ("C1" if preset
                                                                        else "0.6")
        for marker, colour, label in kinds:
            if (marker == "s") == ("staggered" in name) and (marker == "s" or colour == color):
                kinds[(marker, colour, label)] = True
    for (marker, color, label), drawn in kinds.items():
        if drawn:
            axes.scatter([], [], marker=marker, color=color, label=label)
    for name in stopped:
        axes.scatter([], [], s=0, label=f"{name}: {stopped[name]}")
    axes.set_xscale("log")
    axes.set_yscale("log")
    axes.set_xlabel("curve error (force per width, worst branch of the worst scene, "
                    "over its peak)")
    axes.set_ylabel("user CPU of the scenes (s)")
    axes.set_title(title, fontsize=10)
    axes.grid(True, which="both", alpha=0.3)
    axes.legend(fontsize=8, loc="upper right")
    figure.tight_layout()
    figure.savefig(path, dpi=110)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cell", type=int, default=16, help="periodic knit cell loops")
    parser.add_argument("--clamped", type=int, default=24, help="clamped knit loops")
    parser.add_argument("--png", type=Path,
                        default=TOP / "docs" / "images" / "presets_front.png")
    parser.add_argument("--limit", type=float, default=LIMIT,
                        help="stop a run at this fraction of the reference's CPU")
    parser.add_argument("--json", type=Path, help="also write the measurements here")
    parser.add_argument("--only", nargs="*", help="settings to run (default: all)")
    parser.add_argument("--reference-step", type=float, default=REFERENCE_STEP,
                        help="max_step of the reference run")
    parser.add_argument("--replot", type=Path,
                        help="print and draw the measurements of --json FILE, run nothing")
    args = parser.parse_args()
    if args.replot:
        saved = json.loads(args.replot.read_text())
        report(saved["rows"], saved["reference_errors"], saved["fixed"], args.png)
    else:
        rows, reference_errors, fixed = measure(args)
        if args.json:
            args.json.write_text(json.dumps({"rows": rows, "fixed": fixed,
                                             "reference_errors": reference_errors}))
        report(rows, reference_errors, fixed, args.png)


def measure(args: argparse.Namespace) -> tuple[dict, dict, dict]:
    """Rows per setting, the references' own errors and the steps every setting takes."""
    work = Path(tempfile.mkdtemp(prefix="presets_front_"))
    chosen = settings()
    if args.only:
        chosen = {k: v for k, v in chosen.items() if k in args.only}
    rows: dict[str, dict] = {name: {"cpu": 0.0, "error": 0.0, "scenes": {}, "missed": 0,
                                    "scene_cpu": {}}
                             for name in chosen}
    reference_errors = {}
    fixed: dict[str, tuple | str] = {}
    core = blas_env.apply()
    print(f"OpenBLAS core: {core}; load average before: {os.getloadavg()[0]:.2f}",
          file=sys.stderr)
    for k, (scene, (base, values)) in enumerate(scenes(args.cell, args.clamped).items()):
        print(f"presets_front: {scene}: reference", file=sys.stderr, flush=True)
        step = args.reference_step
        fine = {"initial_step": step, "max_step": step,
                "residual_tolerance": REFERENCE_TOLERANCE, "scheme": "monolithic"}
        coarse = {**fine, "initial_step": 2 * step, "max_step": 2 * step,
                  "residual_tolerance": 10 * REFERENCE_TOLERANCE}
        reference = run(base, values, fine, work / f"{k}_ref")
        check = run(base, values, coarse, work / f"{k}_check")
        if isinstance(reference, str) or isinstance(check, str):
            sys.exit(f"presets_front: {scene}: reference failed: {reference} {check}")
        reference_errors[scene] = curve_error(check[0], reference[0])[0]
        fixed[scene] = fixed_cost(base, values, work / f"{k}_fixed")
        for name, solver in chosen.items():
            if "failed" in rows[name]:
                continue                # failed or stopped on a scene before
            print(f"presets_front: {scene}: {name}", file=sys.stderr, flush=True)
            got = run(base, values, solver, work / f"{k}_{len(rows[name]['scenes'])}",
                      limit=args.limit * reference[1])
            row = rows[name]
            if isinstance(got, str):
                row["scenes"][scene] = float("inf")
                row["error"] = float("inf")
                row["failed"] = got
                continue
            error, missed = curve_error(got[0], reference[0])
            row["scenes"][scene] = error
            row["error"] = max(row["error"], error)
            row["cpu"] += got[1]
            row["scene_cpu"][scene] = got[1]
            row["missed"] += missed
    spent = resource.getrusage(resource.RUSAGE_CHILDREN)
    print(f"load average after: {os.getloadavg()[0]:.2f}; children's CPU "
          f"{spent.ru_utime + spent.ru_stime:.0f} s", file=sys.stderr)
    return rows, reference_errors, fixed


def report(rows: dict, reference_errors: dict, fixed: dict, png: Path) -> None:
    """Print the tables and draw the picture."""
    dominated = front(rows)
    names = list(reference_errors)
    print("Reference error (run at twice the step and 10x the tolerance against the "
          "reference): " + ", ".join(f"{s} {e:.1e}" for s, e in reference_errors.items()))
    print()
    print("| setting | CPU s | " + " | ".join(names) + " | worst | times off the grid "
          "| dominated by |")
    print("|---|---:|" + "---:|" * len(names) + "---:|---:|---|")
    for name, row in sorted(rows.items(), key=lambda item: item[1]["cpu"]):
        errors = " | ".join(f"{row['scenes'].get(s, float('nan')):.1e}" for s in names)
        note = row.get("failed", dominated[name] or "on the front")
        print(f"| {name} | {row['cpu']:.2f} | {errors} | {row['error']:.1e} | "
              f"{row['missed']} | {note} |")
    print()
    print("Steps every setting takes, from the defaults' step trace (CPU s, Newton "
          "iterations): | scene | all steps | step 0 and first load step | last load step "
          "| iterations, first / last load step |")
    print("|---|---:|---:|---:|---:|")
    for scene, got in fixed.items():
        print(f"| {scene} | " + (f"{got[0]:.2f} | {got[1]:.2f} | {got[2]:.2f} | {got[3]} / "
              f"{got[4]}" if not isinstance(got, str) else f"{got} | | | ") + " |")
    found = [got for got in fixed.values() if not isinstance(got, str)]
    if found:
        both, whole = sum(g[1] + g[2] for g in found), sum(g[0] for g in found)
        print(f"\nThose two steps: {both:.2f} s of the {whole:.2f} s of all steps of the "
              f"defaults; no setting of step and tolerance that leaves them as they are runs "
              f"the scenes more than {whole / both:.1f}x faster than the defaults.")
    print()
    print("CPU s per scene: | setting | " + " | ".join(names) + " |")
    print("|---|" + "---:|" * len(names))
    for name in ("defaults",) + PRESETS:
        if name in rows:
            print(f"| {name} | " + " | ".join(
                f"{rows[name]['scene_cpu'].get(s, float('nan')):.2f}" for s in names) + " |")
    draw(rows, dominated, png, "&solver settings, one stretch cycle of each of\n"
         + ", ".join(names))
    print(f"\npicture: {png}")


if __name__ == "__main__":
    main()
