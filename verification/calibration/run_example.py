#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Calibration example on the capstan scene, with SYNTHETIC data, and a sweep speed-up.

1. Make a SYNTHETIC force-strain curve: the solver itself on inputs/capstan.nml with
   mu = 0.3, beta = 0.05 N, plus 1 % Gaussian noise (seeded). It is not a measurement;
   the file says so in its first lines.
2. Fit mu and beta to it from another start (0.2, 0.1) with yarnfort.calibrate; print
   fitted values +- standard uncertainty and the errors against the known truth; write
   fit.png.
3. Time the same 8-run sweep (a finer scene, so each run is ~0.5 s) with 1 and with 2
   local worker processes and print the wall-time ratio.

Run:  .venv/bin/python verification/calibration/run_example.py   (after ./yarnfort once)
Writes synthetic_curve.csv, fit.png and results.txt next to this script.
"""
from __future__ import annotations

import os
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
TOP = HERE.parents[1]
sys.path.insert(0, str(TOP / "python"))

from yarnfort.calibrate import calibrate, plot_fit, write_synthetic_curve  # noqa: E402
from yarnfort.sweep import run_sweep  # noqa: E402

SCENE = TOP / "inputs" / "capstan.nml"
MU = "contact[0].friction_coefficient"
BETA = "contact[0].adhesion"
TRUTH = {MU: 0.3, BETA: 0.05}
START = {MU: (0.2, 0.01, 1.0), BETA: (0.1, 0.0, 0.5)}
STEPS = {"solver.max_step": 0.05, "solver.initial_step": 0.05}
#: Length of the yarn from the fixed end over the three pegs to the pulled end (m), and
#: the pull at p_disp = 1 (m): strain = PULL / LENGTH * p_disp.
LENGTH = 2 * np.hypot(1 - 0.8660254, 1.5) + 2 * 1.0
PULL = 0.3
NOISE = 0.01
#: The timed sweep: 8 runs of ~4000 steps each.
SWEEP = {MU: list(np.linspace(0.1, 0.8, 8)), "solver.max_step": [0.0005]}


def fit_example(lines: list[str]) -> None:
    csv = write_synthetic_curve(SCENE, {**TRUTH, **STEPS}, HERE / "synthetic_curve.csv",
                                support="pull", x_scale=PULL / LENGTH, force_scale=-1.0,
                                noise=NOISE, seed=1)
    start = time.perf_counter()
    result = calibrate(SCENE, csv, START, support="pull", component="y",
                       x_scale=PULL / LENGTH, force_scale=-1.0, fixed=STEPS)
    elapsed = time.perf_counter() - start
    plot_fit(result, HERE / "fit.png", title="capstan: SYNTHETIC data (solver + 1 % noise)"
             " vs fitted model")
    lines.append(f"Fit to SYNTHETIC data ({csv.name}; truth mu = {TRUTH[MU]}, "
                 f"beta = {TRUTH[BETA]} N, noise {NOISE:.0%}), start "
                 f"({START[MU][0]}, {START[BETA][0]}), {elapsed:.1f} s:")
    lines.append(result.summary())
    for name, value, sigma in zip(result.names, result.values, result.uncertainty):
        error = value - TRUTH[name]
        lines.append(f"  {name}: error {error:+.3g} = {error / TRUTH[name]:+.2%} "
                     f"= {error / sigma:+.2f} standard uncertainties")


def speedup(lines: list[str]) -> None:
    load = os.getloadavg()[0]
    times = {}
    for workers in (1, 2):
        start = time.perf_counter()
        table = run_sweep(SCENE, SWEEP, workers=workers, progress=True, support="pull",
                          component="y")
        times[workers] = time.perf_counter() - start
        assert all(table["status"] == "ok"), table["error"]
    lines.append(f"Sweep of 8 runs ({table['n_steps'][0]} steps each, mean "
                 f"{np.mean(table['wall_time']):.2f} s per run): 1 worker "
                 f"{times[1]:.2f} s, 2 workers {times[2]:.2f} s, speed-up "
                 f"{times[1] / times[2]:.2f} ({os.cpu_count()} CPUs, load average "
                 f"{load:.2f} before the sweeps: other processes share the cores)")


def main() -> None:
    lines: list[str] = []
    fit_example(lines)
    speedup(lines)
    text = "\n".join(lines)
    print(text)
    (HERE / "results.txt").write_text(text + "\n")


if __name__ == "__main__":
    main()
