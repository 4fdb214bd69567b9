# SPDX-License-Identifier: MIT
"""TexGen import: import and run times of the examples, contact counts of pytexgen
models, and TexGen's weft knit against the built-in planar knit of the same spacing.

    .venv/bin/python verification/texgen/run_study.py          # all (pytexgen: minutes)
    .venv/bin/python verification/texgen/run_study.py plots    # knit_states.png only

Runs build/yarnfort (from the repository top, one run at a time) into out/texgen_study/,
prints the tables of README.md, writes results.txt and knit_curves.png. The models are
made with pytexgen in .venv-texgen where it is installed (else only the shipped examples
are measured). Times are wall times of this machine, shared with other work: figures,
not assertions.
"""
from __future__ import annotations

import re
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

TOP = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(TOP / "tests" / "verification"))
from fabric_scenes import patched_scene  # noqa: E402
from yarnfort import read_curve  # noqa: E402

OUT = TOP / "out" / "texgen_study"
EXE = TOP / "build" / "yarnfort"
TEXGEN_PYTHON = TOP / ".venv-texgen" / "bin" / "python"
MODELS = TOP / "tests" / "verification" / "texgen_models.py"
lines: list[str] = []


def say(text: str = "") -> None:
    print(text)
    lines.append(text)


def run(base: str, values: dict, name: str):
    """(curve, stderr, wall time of the run, wall time of check_only: the import)."""
    folder = OUT / name
    timings = []
    for check in (True, False):
        text = patched_scene(base, {**values, "control.check_only": check,
                                    "output.vtk_every": 0}, folder)
        start = time.perf_counter()
        proc = subprocess.run([str(EXE)], input=text, capture_output=True, text=True, cwd=TOP)
        timings.append(time.perf_counter() - start)
        if proc.returncode != 0:
            raise SystemExit(f"{name}: {proc.stderr}")
    return read_curve(folder), proc.stderr, timings[1], timings[0]


def counts(stderr: str) -> str:
    found = re.search(r"TexGen model: (\d+) yarns, (\d+) contacts", stderr)
    nodes = re.search(r"(\d+) nodes, (\d+) elements", stderr)
    return (f"{found[1]} yarns, {found[2]} contacts, {nodes[2]} elements"
            if found else f"(built-in) {nodes[2]} elements")


def main() -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    say("# TexGen import study (verification/texgen/run_study.py)")
    say("## examples: import (check_only run) and full run, wall time (s)")
    for base in ("inputs/texgen_weave.nml", "inputs/texgen_knit.nml"):
        curve, stderr, wall, check = run(base, {}, Path(base).stem)
        say(f"{base:28s} | {counts(stderr)} | check_only {check:.3f} s | run {wall:.3f} s "
            f"| {len(curve['step'])} steps | peak F {curve['force_per_width'].max():.1f} N/m")
    if not TEXGEN_PYTHON.exists():
        say("pytexgen is not installed (.venv-texgen): model-making part skipped")
        return (OUT / "results.txt").write_text("\n".join(lines) + "\n")
    say("## pytexgen models: contacts against the pattern")
    for kind, cells in (("plain", (8, 8)), ("twill", (8, 8)), ("twill", (16, 16))):
        model = OUT / f"{kind}{cells[0]}x{cells[1]}.tg3"
        start = time.perf_counter()
        subprocess.run([str(TEXGEN_PYTHON), str(MODELS), kind, str(model), *map(str, cells),
                        "1.0", "0.4", "0.8"], capture_output=True, check=True)
        made = time.perf_counter() - start
        materials = ["warp"] * cells[1] + ["weft"] * cells[0]
        curve, stderr, wall, check = run("inputs/texgen_weave.nml", {
            "fabric.texgen_file": str(model), "fabric.texgen_materials": materials},
            model.stem)
        say(f"{kind} {cells[0]}x{cells[1]} | expected {cells[0] * cells[1]} contacts | "
            f"{counts(stderr)} | pytexgen {made:.2f} s | check_only {check:.3f} s | "
            f"run {wall:.3f} s")
    say("## TexGen weft knit (one loop: course width 1.2 mm, wale height 1.0 mm, yarn 0.2 mm)"
        " against the built-in planar knit (spacing 1.2 mm x 1.0 mm, no inlay), knit.nml's"
        " yarn and knit-knit law, one cycle to strain 1")
    cycle = {"path.time": [0.0, 1.0, 2.0], "path.p_disp": [0.0, 1.0, 0.0],
             "solver.max_step": 0.05}
    texgen, stderr_t, *_ = run("inputs/texgen_knit.nml", cycle, "knit_texgen")
    planar, stderr_p, *_ = run("inputs/knit.nml", {
        **cycle, "fabric.cells": [1, 1], "fabric.spacing": [1.2e-3, 1.0e-3],
        "fabric.inlay_material": None, "fabric.gap": None, "fabric.inlay_offset": None,
        "fabric.inlay_every": None}, "knit_planar")
    for name, curve, stderr in (("TexGen", texgen, stderr_t), ("planar", planar, stderr_p)):
        strain, force = curve["strain"], curve["force_per_width"]
        peak = int(np.argmax(strain))
        area = np.trapezoid(force[:peak + 1], strain[:peak + 1]) \
            - np.trapezoid(force[peak:][::-1], strain[peak:][::-1])
        at = {s: np.interp(s, strain[:peak + 1], force[:peak + 1]) for s in (0.25, 0.5, 1.0)}
        say(f"{name:7s} | {counts(stderr)} | F at 0.25, 0.5, 1: {at[0.25]:.1f}, {at[0.5]:.1f}, "
            f"{at[1.0]:.1f} N/m | loop area {area:.2f} J/m^2")
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(6, 4))
        for name, curve in (("TexGen weft knit (3D loop)", texgen),
                            ("built-in planar knit", planar)):
            ax.plot(curve["strain"], curve["force_per_width"], label=name)
        ax.set_xlabel("strain")
        ax.set_ylabel("force per width (N/m)")
        ax.set_title("computed, illustrative yarn table (no measured data)")
        ax.legend()
        fig.tight_layout()
        fig.savefig(Path(__file__).with_name("knit_curves.png"), dpi=120)
    except ImportError:
        say("matplotlib missing: no plot")
    (Path(__file__).with_name("results.txt")).write_text("\n".join(lines) + "\n")


def plot_states() -> None:
    """knit_states.png: the TexGen knit at strain 0, 0.5 and 1 (loading), 3 x 3 cells,
    seen from the front (x-y), elements coloured by tension (yarnfort.plots.plot_states)."""
    import matplotlib
    matplotlib.use("Agg")
    from yarnfort.plots import plot_states as draw_states, save_figure

    folder = OUT / "knit_states"
    text = patched_scene("inputs/texgen_knit.nml", {
        "path.time": [0.0, 1.0], "path.p_disp": [0.0, 1.0], "solver.max_step": 0.05,
        "solver.initial_step": 0.05, "output.vtk_every": 1}, folder)
    proc = subprocess.run([str(EXE)], input=text, capture_output=True, text=True, cwd=TOP)
    if proc.returncode != 0:
        raise SystemExit(proc.stderr)
    figure = draw_states(folder, (0.0, 0.5, 1.0), images=(3, 3), title="TexGen weft knit,"
                         " 3 x 3 periodic cells (computed; illustrative yarn table)")
    save_figure(figure, Path(__file__).with_name("knit_states.png"), dpi=110)


if __name__ == "__main__":
    if sys.argv[1:] == ["plots"]:
        OUT.mkdir(parents=True, exist_ok=True)
        plot_states()
    else:
        main()
        plot_states()
