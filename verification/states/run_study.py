# SPDX-License-Identifier: MIT
"""Deformed states of every fabric route at 0, 50 and 100 % strain, coloured by tension,
with the figures behind their reading, and the build and run times of the shipped
fabric examples.

    nice .venv/bin/python verification/states/run_study.py           # all (about 1 min)
    nice .venv/bin/python verification/states/run_study.py timings   # the timing table only

Runs build/yarnfort from the repository top (one run at a time) into out/states_study/,
writes one PNG per route next to this script (yarnfort.plots.plot_states) and
results.txt, and prints the tables of README.md. The yarn laws are the illustrative
tables of inputs/data/: no figure here is a measurement. Times are wall times on a
machine shared with other work (the median of TIMING_RUNS runs): figures, not assertions.
"""
from __future__ import annotations

import re
import statistics
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import f90nml
import numpy as np

HERE = Path(__file__).resolve().parent
TOP = HERE.parents[1]
sys.path.insert(0, str(TOP / "tests" / "verification"))
from fabric_scenes import patched_scene  # noqa: E402
from yarnfort import read_curve  # noqa: E402
from yarnfort.plots import nearest_states, plot_states, save_figure  # noqa: E402
from yarnfort.results import GAP_HOLDER, PERIODIC_LINK, read_contacts, read_states  # noqa: E402

OUT = TOP / "out" / "states_study"
EXE = TOP / "build" / "yarnfort"
#: Runs per shipped example for the timing table (the median is reported).
TIMING_RUNS = 3
#: Strains of the panels: values for the knits (shipped to strain 1), fractions of the
#: shipped stretch (15 %) for the weaves.
STRAINS = (0.0, 0.5, 1.0)
#: texgen_weave.nml's cell from the built-in generator (tests/verification/test_texgen.py
#: shows the two give the same curve).
PLAIN_CELL = {"fabric.kind": "plain", "fabric.cells": [2, 2],
              "fabric.spacing": [1.0e-3, 1.0e-3], "fabric.gap": 0.2e-3,
              "fabric.warp_material": "warp", "fabric.weft_material": "weft",
              "fabric.texgen_file": None, "fabric.texgen_materials": None}
lines: list[str] = []


def say(text: str = "") -> None:
    print(text)
    lines.append(text)


@dataclass
class Route:
    """One way to a fabric: a scene (an example, maybe changed) and how to draw it."""

    key: str
    label: str
    base: str
    values: dict = field(default_factory=dict)
    of_peak: bool = False
    images: tuple[int, int] = (1, 1)
    projections: tuple[str, ...] = ("xy", "xz")
    depth_scale: float = 1.0


ROUTES = [
    Route("knit", "built-in knit with inlay (inputs/knit.nml, 2 x 2 cell)",
          "inputs/knit.nml", images=(2, 2), depth_scale=4.0),
    Route("knit3d", "built-in 3D knit (inputs/knit3d.nml, one loop)", "inputs/knit3d.nml",
          images=(3, 3), projections=("xy", "3d"), depth_scale=6.0),
    Route("texgen_knit", "TexGen weft knit (inputs/texgen_knit.nml, one loop)",
          "inputs/texgen_knit.nml", images=(3, 3), projections=("xy", "3d"),
          depth_scale=6.0),
    Route("plain_cell", "built-in plain weave, periodic 2 x 2 cell (texgen_weave's"
          " parameters)", "inputs/texgen_weave.nml", PLAIN_CELL, of_peak=True,
          images=(2, 2), depth_scale=5.0),
    Route("texgen_weave", "TexGen plain weave (inputs/texgen_weave.nml, 2 x 2 cell)",
          "inputs/texgen_weave.nml", of_peak=True, images=(2, 2), depth_scale=5.0),
    Route("plain_belt", "built-in plain weave, clamped 12 x 8 strip (inputs/belt.nml,"
          " kind = 'plain')", "inputs/belt.nml", {"fabric.kind": "plain"}, of_peak=True,
          depth_scale=8.0),
    Route("twill_belt", "built-in 2/2 twill, clamped 12 x 8 strip (inputs/belt.nml)",
          "inputs/belt.nml", of_peak=True, depth_scale=8.0),
]


@dataclass
class Run:
    folder: Path
    stderr: str
    wall: float


def run(base: str, values: dict, name: str) -> Run:
    """The program on ``base`` with ``values``, output to out/states_study/<name>."""
    folder = OUT / name
    text = patched_scene(base, values, folder)
    start = time.perf_counter()
    proc = subprocess.run([str(EXE)], input=text, capture_output=True, text=True, cwd=TOP)
    wall = time.perf_counter() - start
    if proc.returncode != 0:
        raise SystemExit(f"{name}: {proc.stderr}")
    return Run(folder, proc.stderr, wall)


def counts(stderr: str) -> dict:
    """What the program reports on stderr: nodes, elements, unknowns, passages, the
    TexGen import's yarns and contacts, and the scene build time."""
    found: dict = {}
    net = re.search(r"(\d+) nodes, (\d+) elements, (\d+) unknowns", stderr)
    found.update(nodes=int(net[1]), elements=int(net[2]), unknowns=int(net[3]))
    passages = re.search(r"(\d+) sliding passages", stderr)
    found["passages"] = int(passages[1]) if passages else 0
    texgen = re.search(r"TexGen model: (\d+) yarns, (\d+) contacts", stderr)
    if texgen:
        found.update(texgen_yarns=int(texgen[1]), texgen_contacts=int(texgen[2]))
    built = re.search(r"scene built in ([0-9.]+) s", stderr)
    if built is None:
        raise SystemExit("the program does not report 'scene built in ... s': rebuild it")
    found["built"] = float(built[1])
    return found


def fabric_examples() -> list[Path]:
    """The shipped examples of a fabric kind: inputs/*.nml with a &fabric group."""
    return [path for path in sorted((TOP / "inputs").glob("*.nml"))
            if "fabric" in f90nml.read(str(path))]


def timings() -> None:
    say("## Shipped fabric examples: scene build (read, generate or import, check) and run")
    say(f"wall times, median of {TIMING_RUNS} runs each, as shipped (output folder"
        " changed, progress lines off)")
    say("")
    say("| example | kind | yarns | contacts (gap-holders) | periodic links | passages |"
        " elements | unknowns | steps | scene built (s) | run (s) |")
    say("|---|---|---|---|---|---|---|---|---|---|---|")
    for path in fabric_examples():
        runs = [run(str(path), {"output.progress": False}, f"timing_{path.stem}")
                for _ in range(TIMING_RUNS)]
        found = [counts(r.stderr) for r in runs]
        # The first state written: the counts are the same in every state, and a
        # force-controlled example does not start at strain 0.
        state = read_states(runs[0].folder)[0]
        yarns = len(np.unique(state.cell_data["yarn"]))
        holders = int(np.sum(state.link_kind == GAP_HOLDER))
        periodic = int(np.sum(state.link_kind == PERIODIC_LINK))
        kind = f90nml.read(str(path))["fabric"]["kind"]
        if "texgen_yarns" in found[0]:
            assert found[0]["texgen_yarns"] == yarns and found[0]["texgen_contacts"] == holders
        built = statistics.median(f["built"] for f in found)
        wall = statistics.median(r.wall for r in runs)
        c = found[0]
        say(f"| `inputs/{path.name}` | {kind} | {yarns} | {holders} | {periodic} |"
            f" {c['passages']} | {c['elements']} | {c['unknowns']} |"
            f" {len(read_curve(runs[0].folder))} | {built:.4f} | {wall:.2f} |")
    say("")


def material_names(folder: Path) -> list[str]:
    groups = f90nml.read(str(folder / "input.nml"))["material"]
    groups = groups if isinstance(groups, list) else [groups]
    return [group["name"] for group in groups]


def describe(route: Route, folder: Path) -> None:
    """The figures behind the reading of one route, at each state drawn."""
    chosen = nearest_states(folder, STRAINS, of_peak=route.of_peak)
    names = material_names(folder)
    contacts = read_contacts(folder) if (folder / "contacts.csv").exists() else None
    say(f"### {route.label}")
    for state, strain in chosen:
        start = chosen[0][0]
        material = state.cell_data["material"].astype(int)
        yarn_of_passage = {}
        # Dominant direction of each element in the initial state: x, y or z.
        d0 = start.position[start.elements[:, 1]] - start.position[start.elements[:, 0]]
        axis = np.argmax(np.abs(d0), axis=1)
        parts = []
        for m in np.unique(material):
            mine = material == m
            nodes = np.unique(state.elements[mine])
            depth = np.ptp(state.position[nodes, 2]) * 1e3
            along = ", ".join(
                f"along {'xyz'[a]} {state.tension[mine & (axis == a)].min():.3f}-"
                f"{state.tension[mine & (axis == a)].max():.3f} N"
                for a in range(3) if np.any(mine & (axis == a)))
            parts.append(f"{names[m - 1]}: {along}; z extent {depth:.3f} mm")
        say(f"- strain {strain:.4g} (step {state.step}): " + " | ".join(parts))
        if contacts is None:
            continue
        rows = contacts["step"] == state.step
        yarn = contacts["yarn"][rows].astype(int)
        element_yarn = state.cell_data["yarn"].astype(int)
        for y in np.unique(element_yarn):
            yarn_of_passage[y] = names[int(material[element_yarn == y][0]) - 1]
        modes = contacts["mode"][rows]
        flow = np.abs(contacts["flow"][rows])
        wrap = contacts["wrap_angle"][rows]
        ratio = contacts["tension_max"][rows] / contacts["tension_min"][rows]
        by_material = []
        for name in sorted(set(yarn_of_passage.values())):
            mine = np.array([yarn_of_passage[y] == name for y in yarn])
            if not np.any(mine):
                continue
            slipping = np.isin(modes[mine], ("forward", "backward"))
            by_material.append(
                f"{name} passages: {int(slipping.sum())}/{int(mine.sum())} slip, flow up to"
                f" {flow[mine].max() * 1e3:.4f} mm, wrap {wrap[mine].min():.3f}-"
                f"{wrap[mine].max():.3f} rad, T_max/T_min up to {ratio[mine].max():.4f}")
        say("  " + "; ".join(by_material))
    say("")


def states() -> None:
    say("## Deformed states (0, 50, 100 % strain; weaves: of their 15 % stretch)")
    for route in ROUTES:
        folder = run(route.base, {**route.values, "output.progress": False,
                                  "output.vtk_every": 1}, route.key).folder
        describe(route, folder)
        figure = plot_states(folder, STRAINS, of_peak=route.of_peak, images=route.images,
                             projections=route.projections, depth_scale=route.depth_scale,
                             title=f"{route.label}: computed, illustrative yarn tables")
        save_figure(figure, HERE / f"{route.key}.png", dpi=100)


def main() -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    say("# Deformed states and timings (verification/states/run_study.py)")
    if sys.argv[1:] != ["timings"]:
        states()
    timings()
    if sys.argv[1:] != ["timings"]:
        (HERE / "results.txt").write_text("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
