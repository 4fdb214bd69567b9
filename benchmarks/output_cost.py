#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The cost of the VTK state files: a straight chain of N nodes (one linear yarn, pulled
at one end: the solve is cheap, so the files dominate) run for 3 load steps (4 states)
with vtk_every = 0, then with binary (appended base64) and ASCII states. Prints the
median wall time over the repeats, the extra time per state over the run without
states, and the size of one state file.

    .venv/bin/python benchmarks/output_cost.py [--nodes 200000] [--repeats 3]

Runs go to out/bench_output_cost/ (git-ignored). Timings are on whatever else the
machine is doing: compare within one run.
"""
from __future__ import annotations

import argparse
import os
import shutil
import statistics
import subprocess
import time
from pathlib import Path

TOP = Path(__file__).resolve().parents[1]
EXECUTABLE = Path(os.environ.get("YARNFORT_EXE", TOP / "build" / "yarnfort"))
STEPS = 3


def scene(nodes: int, folder: str, every: int, fmt: str) -> str:
    return f"""&control max_steps = {STEPS} /
&material name = 'yarn', law = 'linear', stiffness = 10.0 /
&geometry file = 'chain.geo' /
&support name = 'a', nodes = 1, fix = 'xyz' /
&support name = 'b', nodes = {nodes}, fix = 'xyz', displacement = 1.0 0 0 /
&path time = 0 1, p_disp = 0 1 /
&solver max_step = 0.25, initial_step = 0.25 /
&output folder = '{folder}', vtk_every = {every}, vtk_format = '{fmt}', progress = .false. /
"""


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--nodes", type=int, default=200_000)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    work = TOP / "out" / "bench_output_cost"
    shutil.rmtree(work, ignore_errors=True)
    work.mkdir(parents=True)
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
        times = []
        for _ in range(args.repeats):
            start = time.perf_counter()
            proc = subprocess.run([str(EXECUTABLE)], input=scene(args.nodes, folder, every, fmt),
                                  capture_output=True, text=True, cwd=work, timeout=3600)
            times.append(time.perf_counter() - start)
            if proc.returncode != 0:
                raise SystemExit(proc.stderr)
        medians[name] = statistics.median(times)
        if every:
            per_state = (medians[name] - medians["no states"]) / (STEPS + 1)
            size = (work / folder / "state_00001.vtu").stat().st_size / 1e6
            print(f"{name:<10} {medians[name]:8.2f} {per_state:8.3f} {size:9.1f}")
        else:
            print(f"{name:<10} {medians[name]:8.2f} {'':>8} {'':>9}")


if __name__ == "__main__":
    main()
