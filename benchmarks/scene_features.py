#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Model only what the scene requires: the cost of the friction machinery.

Times the example scenes inputs/knit.nml (periodic knit cell, two cycles to 2x) and
inputs/belt.nml (clamped woven strip, 15 % and back), as they are and with 4x the cells
(so that the solve, not the process start, dominates), with every &contact group set to

- bonded             no sliding passages: the elastic solver alone;
- coulomb, mu = 100  the friction machinery on, every passage sticking (the answer must
                     be the bonded one: the difference is printed);
- coulomb            mu of the scene, no adhesion;
- adhesion           as in the scene;
- decaying_adhesion  mu and beta of the scene, adhesion fading from 0.1 N to 1 N.

For each: median over the repeats of the process wall time and of the solve time (the
sum of curve.csv's per-step wall_time), the Newton iterations and steps, the ratio of
the median wall time to the bonded run's (all measured in this run) and the largest
force-per-width difference to the bonded run.

    .venv/bin/python benchmarks/scene_features.py [--repeats 3]      # about 1 minute

Runs go to out/bench_scene_features/ (git-ignored). Timings are on whatever else the
machine is doing: compare ratios within one run, not across runs.
"""
from __future__ import annotations

import argparse
import os
import sys
from pathlib import Path

import numpy as np

TOP = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(TOP / "python"))
sys.path.insert(0, str(TOP / "tests" / "verification"))
from fabric_scenes import BONDED, patched_scene, run_scene  # noqa: E402
from yarnfort import read_curve  # noqa: E402

EXE = Path(os.environ.get("YARNFORT_EXE", TOP / "build" / "yarnfort"))
OUT = TOP / "out" / "bench_scene_features"
#: name: (scene, &fabric cells or None for the scene's own, &contact groups, mu, beta)
SCENES = {"knit 2x2": ("inputs/knit.nml", None, 2, 0.3999, 0.015),
          "knit 8x8": ("inputs/knit.nml", [8, 8], 2, 0.3999, 0.015),
          "belt 12x6": ("inputs/belt.nml", None, 1, 0.3, 0.01),
          "belt 24x12": ("inputs/belt.nml", [24, 12], 1, 0.3, 0.01)}
HUGE_MU = 100.0
DECAY = (0.1, 1.0)  # N


def variants(mu: float, beta: float) -> dict[str, dict]:
    none = {"friction_coefficient": None, "adhesion": None, "decay_start": None,
            "decay_end": None}
    return {
        "bonded": dict(BONDED),
        f"coulomb mu={HUGE_MU:g}": {**none, "law": "coulomb",
                                    "friction_coefficient": HUGE_MU},
        "coulomb": {**none, "law": "coulomb", "friction_coefficient": mu},
        "adhesion": {**none, "law": "adhesion", "friction_coefficient": mu,
                     "adhesion": beta},
        "decaying_adhesion": {"law": "decaying_adhesion", "friction_coefficient": mu,
                              "adhesion": beta, "decay_start": DECAY[0],
                              "decay_end": DECAY[1]},
    }


def scene_text(base: str, cells, n_contacts: int, contact: dict, folder: Path) -> str:
    values = {f"contact[{c}].{k}": v for c in range(n_contacts) for k, v in contact.items()}
    values["output.vtk_every"] = 0
    if cells:
        values["fabric.cells"] = cells
    return patched_scene(base, values, folder)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    if not EXE.exists():
        sys.exit(f"{EXE} is missing: build first (./yarnfort --version)")
    print(f"# scene features: median of {args.repeats} runs each, the variants of a scene "
          "interleaved; ratio = wall / bonded wall")
    print(f"{'scene':10s} {'contact law':18s} {'wall (s)':>9s} {'solve (s)':>9s} "
          f"{'ratio':>6s} {'steps':>5s} {'newton':>6s} {'slip max':>8s} "
          f"{'max|F - F_bonded| / max F':>26s}")
    for scene, (base, cells, n_contacts, mu, beta) in SCENES.items():
        runs = {}
        for name, contact in variants(mu, beta).items():
            folder = OUT / f"{scene}_{name}".replace(" ", "_").replace("=", "")
            runs[name] = (scene_text(base, cells, n_contacts, contact, folder), folder)
        walls = {name: [] for name in runs}
        solves = {name: [] for name in runs}
        curves, errors = {}, {}
        # Round-robin over the variants, so that a change in the machine's load hits all.
        for _ in range(args.repeats):
            for name, (text, folder) in runs.items():
                if name in errors:
                    continue
                proc, wall = run_scene(text, EXE)
                if proc.returncode != 0:
                    errors[name] = proc.stderr.strip().splitlines()[-1]
                    continue
                curves[name] = read_curve(folder)
                walls[name].append(wall)
                solves[name].append(float(np.sum(curves[name]["wall_time"])))
        reference = None
        for name in runs:
            if name in errors:
                print(f"{scene:10s} {name:18s} FAILED: {errors[name]}")
                continue
            wall, solve, curve = np.median(walls[name]), np.median(solves[name]), curves[name]
            if reference is None:
                reference = (wall, curve)
            force, ref = curve["force_per_width"], reference[1]["force_per_width"]
            if len(force) == len(ref) and np.array_equal(curve["time"],
                                                         reference[1]["time"]):
                difference = f"{np.max(np.abs(force - ref)) / np.max(np.abs(ref)):.2e}"
            else:
                difference = "(other steps)"
            print(f"{scene:10s} {name:18s} {wall:9.3f} {solve:9.3f} "
                  f"{wall / reference[0]:6.2f} {len(force):5d} "
                  f"{int(curve['newton_iterations'].sum()):6d} "
                  f"{int(curve['slipping'].max()):8d} {difference:>26s}", flush=True)


if __name__ == "__main__":
    main()
