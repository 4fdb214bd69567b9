# SPDX-License-Identifier: MIT
"""The three-dimensional built-in knit (&fabric knit_depth) against the planar knit and
TexGen's weft knit of the same spacing: one load cycle to strain 1.

    .venv/bin/python verification/knit3d/run_study.py          # tables, curves, states
    .venv/bin/python verification/knit3d/run_study.py plots    # knit3d_states.png only

Runs build/yarnfort (from the repository top, one run at a time, a few seconds in all)
into out/knit3d_study/, prints the tables of README.md, writes results.txt,
knit3d_curves.png and knit3d_states.png. The yarn law is the illustrative table of
inputs/data/knit_yarn.csv: no curve here is a measurement.
"""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np

TOP = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(TOP / "tests" / "verification"))
from fabric_scenes import patched_scene  # noqa: E402
from yarnfort import read_curve, read_states  # noqa: E402
from yarnfort.results import read_contacts  # noqa: E402

OUT = TOP / "out" / "knit3d_study"
EXE = TOP / "build" / "yarnfort"
HERE = Path(__file__).parent
SPACING = (1.2e-3, 1.0e-3)  # inputs/knit3d.nml, inputs/texgen_knit.tg3's repeats (m)
CYCLE = {"path.time": [0.0, 1.0, 2.0], "path.p_disp": [0.0, 1.0, 0.0],
         "solver.max_step": 0.05}
lines: list[str] = []


def say(text: str = "") -> None:
    print(text)
    lines.append(text)


def run(base: str, values: dict, name: str, vtk_every: int = 0) -> Path:
    folder = OUT / name
    text = patched_scene(base, {**CYCLE, **values, "output.vtk_every": vtk_every}, folder)
    proc = subprocess.run([str(EXE)], input=text, capture_output=True, text=True, cwd=TOP)
    if proc.returncode != 0:
        raise SystemExit(f"{name}: {proc.stderr}")
    return folder


def summary(name: str, folder: Path) -> dict:
    curve, contacts = read_curve(folder), read_contacts(folder)
    strain, force = curve["strain"], curve["force_per_width"]
    peak = int(np.argmax(strain))
    area = np.trapezoid(force[:peak + 1], strain[:peak + 1]) \
        - np.trapezoid(force[peak:][::-1], strain[peak:][::-1])
    at = [np.interp(s, strain[:peak + 1], force[:peak + 1]) for s in (0.1, 0.25, 0.5, 1.0)]
    alpha = contacts["wrap_angle"]
    state = read_states(folder)[peak] if (folder / "states.pvd").exists() else None
    length = None
    if state is not None:
        start = read_states(folder)[0]
        length = np.sum(np.linalg.norm(start.position[start.elements[:, 1]]
                                       - start.position[start.elements[:, 0]], axis=1))
    say(f"{name:22s} | F at 0.1, 0.25, 0.5, 1: {at[0]:.1f}, {at[1]:.1f}, {at[2]:.1f}, "
        f"{at[3]:.1f} N/m | loop area {area:.2f} J/m^2 | wrap {alpha.min():.4f}-"
        f"{alpha.max():.4f} rad" + (f" | yarn per cell {length * 1e3:.4f} mm"
                                    if length is not None else ""))
    return {"curve": curve, "at": at, "area": area}


def main() -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    say("# Three-dimensional knit study (verification/knit3d/run_study.py)")
    say("one cycle to strain 1; knit.nml's yarn and knit-knit law; one loop, spacing "
        "1.2 mm x 1.0 mm, head width 0.5, no inlay")
    results = {}
    results["3D knit, d = 0.2 mm"] = summary(
        "3D knit, d = 0.2 mm", run("inputs/knit3d.nml", {}, "knit3d", vtk_every=1))
    results["planar knit"] = summary("planar knit", run(
        "inputs/knit3d.nml", {"fabric.knit_depth": 0.0}, "planar", vtk_every=1))
    results["TexGen weft knit"] = summary("TexGen weft knit", run(
        "inputs/texgen_knit.nml", {}, "texgen", vtk_every=1))
    base = results["planar knit"]
    for name in ("3D knit, d = 0.2 mm", "TexGen weft knit"):
        r = results[name]
        diff = [100 * (a / b - 1) for a, b in zip(r["at"], base["at"])]
        say(f"{name} against planar: F {diff[0]:+.2f} %, {diff[1]:+.2f} %, {diff[2]:+.2f} %, "
            f"{diff[3]:+.2f} % at 0.1, 0.25, 0.5, 1; loop area "
            f"{100 * (r['area'] / base['area'] - 1):+.2f} %")
    # TexGen's loop at step 0: its legs (the two elements each side of the cell's ends
    # make one leg) and its heads and sinkers, which rise 0.056 mm in depth
    start = read_states(OUT / "texgen")[0]
    length = np.linalg.norm(start.position[start.elements[:, 1]]
                            - start.position[start.elements[:, 0]], axis=1)
    along_y = np.abs(start.position[start.elements[:, 1], 1]
                     - start.position[start.elements[:, 0], 1]) > 0.25 * SPACING[1]
    texgen_leg = 0.5 * np.sum(length[along_y])
    say(f"TexGen loop: legs {texgen_leg * 1e3:.4f} mm each, heads and sinkers "
        f"{np.sum(length[~along_y]) * 1e3:.4f} mm in all")
    say("## depth sweep (one loop, the same cycle); the last: the depth that gives "
        "TexGen's leg length")
    for depth in (0.05e-3, 0.1e-3, 0.2e-3, 0.3e-3, 0.5e-3,
                  np.sqrt(texgen_leg ** 2 - SPACING[1] ** 2)):
        folder = run("inputs/knit3d.nml", {"fabric.knit_depth": depth}, f"depth{depth:.2e}")
        curve = read_curve(folder)
        peak = int(np.argmax(curve["strain"]))
        leg = np.hypot(SPACING[1], depth)
        say(f"d = {depth * 1e3:.3f} mm | leg {leg * 1e3:.4f} mm | F at 1 "
            f"{curve['force_per_width'][peak]:.1f} N/m "
            f"({100 * (curve['force_per_width'][peak] / base['at'][3] - 1):+.2f} % of planar)")
    say("## periodic 4 x 2 cells of inputs/knit.nml's spacing (1.0 mm x 0.8 mm), no inlay: "
        "peak force per width")
    for depth in (0.0, 0.2e-3):
        folder = run("inputs/knit3d.nml", {"fabric.spacing": [1.0e-3, 0.8e-3],
                                           "fabric.cells": [4, 2], "fabric.knit_depth": depth},
                     "cell4x2")
        say(f"d = {depth * 1e3:.1f} mm | {read_curve(folder)['force_per_width'].max():.1f} N/m")
    say("## clamped 4 x 2 samples (inputs/knit.nml's spacing 1.0 mm x 0.8 mm), one cycle "
        "to strain 1: peak force per width")
    for sides in ("rollers", "free"):
        for inlay in (False, True):
            row = []
            for depth in (0.0, 0.2e-3):
                values = {"fabric.cells": [4, 2], "fabric.boundary": "clamped",
                          "fabric.sides": sides, "fabric.knit_depth": depth,
                          "output.vtk_every": 0}
                if not inlay:
                    values.update({"fabric.inlay_material": None, "fabric.gap": None})
                folder = OUT / "clamped"
                text = patched_scene("inputs/knit.nml", {**CYCLE, **values}, folder)
                proc = subprocess.run([str(EXE)], input=text, capture_output=True,
                                      text=True, cwd=TOP)
                if proc.returncode == 0:
                    row.append(f"{read_curve(folder)['force_per_width'].max():.1f} N/m")
                else:
                    row.append("fails: " + proc.stderr.strip().splitlines()[-1][:160])
            say(f"sides {sides:7s} {'with' if inlay else 'no':4s} inlay | planar {row[0]} | "
                f"3D d = 0.2 mm {row[1]}")
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(6, 4))
        for name, r in results.items():
            ax.plot(r["curve"]["strain"], r["curve"]["force_per_width"], label=name)
        ax.set_xlabel("strain")
        ax.set_ylabel("force per width (N/m)")
        ax.set_title("computed, illustrative yarn table (no measured data)")
        ax.legend()
        fig.tight_layout()
        fig.savefig(HERE / "knit3d_curves.png", dpi=120)
    except ImportError:
        say("matplotlib missing: no plot")
    (HERE / "results.txt").write_text("\n".join(lines) + "\n")


def plot_states() -> None:
    """knit3d_states.png: the 3D knit at strain 0, 0.5 and 1 (loading), 3 x 3 periodic
    cells, seen from the front (x-y, top row) and in perspective with depth drawn 6 times
    (bottom row), elements coloured by tension, gap-holders grey
    (yarnfort.plots.plot_states)."""
    import matplotlib
    matplotlib.use("Agg")
    from yarnfort.plots import plot_states as draw_states, save_figure

    folder = run("inputs/knit3d.nml", {"path.time": [0.0, 1.0], "path.p_disp": [0.0, 1.0],
                                       "solver.initial_step": 0.05}, "knit3d_states",
                 vtk_every=1)
    figure = draw_states(folder, (0.0, 0.5, 1.0), images=(3, 3), projections=("xy", "3d"),
                         depth_scale=6.0, title="3D knit (knit_depth 0.2 mm), 3 x 3 periodic"
                         " cells: front (x-y) and perspective (depth x 6); computed,"
                         " illustrative yarn table")
    save_figure(figure, HERE / "knit3d_states.png", dpi=110)


if __name__ == "__main__":
    if sys.argv[1:] != ["plots"]:
        main()
    OUT.mkdir(parents=True, exist_ok=True)
    plot_states()
