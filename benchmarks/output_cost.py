#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The cost of a run's output files, two ways.

``steps`` (the default): long paths of a tiny scene, where the solve is cheap and the
writing shows. A two-element yarn pulled in 1,000 / 2,000 / 4,000 / 8,000 steps, with a
VTK state after every step (vtk_every = 1) and without (vtk_every = 0), and a one-pin
hysteresis path of 160 knots with preset = 'accurate' (about 16,000 steps, a state
every step). Prints the user CPU time and the wall time of each run (the child's
rusage, and a clock around it), and the number of steps.

``size``: the cost of the VTK state files themselves: a straight chain of N nodes (one
linear yarn, pulled at one end) run for 3 load steps (4 states) with vtk_every = 0, then
with binary (appended base64) and ASCII states. Prints the median wall time over the
repeats, the extra time per state over the run without states, and the size of one
state file.

    .venv/bin/python benchmarks/output_cost.py [steps] [--repeats 1]
    .venv/bin/python benchmarks/output_cost.py size [--nodes 200000] [--repeats 3]

YARNFORT_EXE names the program to time (default build/yarnfort), e.g. the build of
another commit. Runs go to out/bench_output_cost/ (git-ignored) unless --work says
otherwise: the folder's file system decides what an fsync costs. Timings are on
whatever else the machine is doing: compare within one run.
"""
from __future__ import annotations

import argparse
import os
import resource
import shutil
import statistics
import subprocess
import time
from pathlib import Path

TOP = Path(__file__).resolve().parents[1]
EXECUTABLE = Path(os.environ.get("YARNFORT_EXE", TOP / "build" / "yarnfort"))
STEPS = 3
PULL_STEPS = (1000, 2000, 4000, 8000)
PIN_KNOTS = 160


def chain_scene(nodes: int, folder: str, every: int, fmt: str) -> str:
    return f"""&control max_steps = {STEPS} /
&material name = 'yarn', law = 'linear', stiffness = 10.0 /
&geometry file = 'chain.geo' /
&support name = 'a', nodes = 1, fix = 'xyz' /
&support name = 'b', nodes = {nodes}, fix = 'xyz', displacement = 1.0 0 0 /
&path time = 0 1, p_disp = 0 1 /
&solver max_step = 0.25, initial_step = 0.25 /
&output folder = '{folder}', vtk_every = {every}, vtk_format = '{fmt}', progress = .false. /
"""


def output_group(folder: str, every: int) -> str:
    return f"&output folder = '{folder}', vtk_every = {every}, progress = .false. /\n"


def pull_scene(steps: int, folder: str, every: int) -> str:
    """Two elements, pulled to 10 % strain in `steps` equal steps."""
    return f"""&material name = 'yarn', law = 'linear', stiffness = 10.0 /
&nodes xyz = 0 0 0, 0.5 0 0, 1 0 0 /
&yarn material = 'yarn', nodes = 1, 2, 3 /
&support name = 'a', nodes = 1, fix = 'xyz' /
&support name = 'b', nodes = 3, fix = 'xyz', displacement = 0.1 0 0 /
&support name = 'm', nodes = 2, fix = 'yz' /
&path time = 0 1, p_disp = 0 1 /
&solver max_step = {1.0 / steps!r}, initial_step = {1.0 / steps!r} /
""" + output_group(folder, every)


def pin_scene(folder: str, every: int) -> str:
    """A yarn over one pin (a quarter turn), pulled and released with a growing amplitude
    over PIN_KNOTS knots."""
    times = ", ".join(str(k) for k in range(PIN_KNOTS))
    factors = ", ".join(f"{(k % 2) * (0.5 + 0.5 * k / (PIN_KNOTS - 1)):.6f}"
                        for k in range(PIN_KNOTS))
    return f"""&material name = 'yarn', law = 'linear', stiffness = 10.0 /
&nodes xyz = -1 -1 0, 0 0 0, 1 -1 0 /
&yarn material = 'yarn', nodes = 1, 2, 3 /
&obstacle name = 'pin', nodes = 2 /
&support name = 'fixed', nodes = 1 /
&support name = 'pull', nodes = 3, displacement = 0.0, -0.3, 0.0 /
&contact at = 'pin', law = 'adhesion', friction_coefficient = 0.3, adhesion = 0.05 /
&path time = {times}, p_disp = {factors} /
&solver preset = 'accurate' /
""" + output_group(folder, every)


def timed_run(text: str, work: Path) -> tuple[float, float]:
    """Run the program on `text` in `work`: (user CPU s, wall s)."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN).ru_utime
    start = time.perf_counter()
    proc = subprocess.run([str(EXECUTABLE)], input=text, capture_output=True, text=True,
                          cwd=work, timeout=3600)
    wall = time.perf_counter() - start
    user = resource.getrusage(resource.RUSAGE_CHILDREN).ru_utime - before
    if proc.returncode != 0:
        raise SystemExit(proc.stderr)
    return user, wall


def count_steps(folder: Path) -> int:
    with open(folder / "curve.csv") as stream:
        return sum(1 for _ in stream) - 1


def best_run(text: str, work: Path, repeats: int) -> tuple[float, float]:
    """The median user CPU and wall time over `repeats` runs."""
    runs = [timed_run(text, work) for _ in range(repeats)]
    return (statistics.median(r[0] for r in runs), statistics.median(r[1] for r in runs))


def run_steps(args: argparse.Namespace, work: Path) -> None:
    print(f"# {EXECUTABLE}, median of {args.repeats}")
    print(f"{'case':<30} {'steps':>6} {'user s':>8} {'wall s':>8} {'user s':>8} {'wall s':>8}")
    print(f"{'':<30} {'':>6} {'VTK every step':>17} {'no VTK':>17}")
    for steps in PULL_STEPS:
        row = []
        for every in (1, 0):
            folder = f"pull_{steps}_{every}"
            row += best_run(pull_scene(steps, folder, every), work, args.repeats)
        name = f"two elements, {steps} steps"
        print(f"{name:<30} {count_steps(work / folder):6d} "
              + " ".join(f"{value:8.2f}" for value in row))
    row = []
    for every in (1, 0):
        folder = f"pin_{every}"
        row += best_run(pin_scene(folder, every), work, args.repeats)
    name = f"one pin, {PIN_KNOTS} knots, accurate"
    print(f"{name:<30} {count_steps(work / folder):6d} "
          + " ".join(f"{value:8.2f}" for value in row))


def run_size(args: argparse.Namespace, work: Path) -> None:
    with open(work / "chain.geo", "w") as stream:
        for i in range(1, args.nodes + 1):
            stream.write(f"node {i} {i * 0.01} 0 0\n")
        stream.write("yarn yarn 1 " + " ".join(map(str, range(1, args.nodes + 1))) + "\n")
    cases = [("no states", 0, "binary"), ("binary", 1, "binary"), ("ascii", 1, "ascii")]
    medians = {}
    print(f"# chain of {args.nodes} nodes, {STEPS} load steps ({STEPS + 1} states when "
          f"written), median of {args.repeats}")
    print(f"{'case':<10} {'wall s':>8} {'s/state':>8} {'MB/state':>9}")
    for name, every, fmt in cases:
        folder = f"run_{every}_{fmt}"
        medians[name] = best_run(chain_scene(args.nodes, folder, every, fmt), work,
                                 args.repeats)[1]
        if every:
            per_state = (medians[name] - medians["no states"]) / (STEPS + 1)
            size = (work / folder / "state_00001.vtu").stat().st_size / 1e6
            print(f"{name:<10} {medians[name]:8.2f} {per_state:8.3f} {size:9.1f}")
        else:
            print(f"{name:<10} {medians[name]:8.2f} {'':>8} {'':>9}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("case", nargs="?", choices=["steps", "size"], default="steps")
    parser.add_argument("--nodes", type=int, default=200_000, help="size: chain length")
    parser.add_argument("--repeats", type=int, default=None,
                        help="runs per case (median); default 1 for steps, 3 for size")
    parser.add_argument("--work", type=Path, default=TOP / "out" / "bench_output_cost",
                        help="folder of the runs (emptied first)")
    args = parser.parse_args()
    if args.repeats is None:
        args.repeats = 1 if args.case == "steps" else 3
    work = args.work.resolve()
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
    if args.case == "steps":
        run_steps(args, work)
    else:
        run_size(args, work)


if __name__ == "__main__":
    main()
