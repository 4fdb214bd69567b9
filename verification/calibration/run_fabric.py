#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Calibration of fabrics in lab units, on SYNTHETIC "measured" curves.

1. Knit (inputs/knit.nml, two stretch cycles to 100 %, read as a yarnfort.Scene): a
   SYNTHETIC curve in strain (%) and force (cN) per sample of 20 mm width, from the
   solver with kmu = 0.3999, kbeta = 0.015 N plus 2 % Gaussian noise (seeded). Fit
   kmu and kbeta from (0.3, 0.03), the residuals relative (errors='relative') and, for
   comparison, of equal weight. Then a fit of kmu with the knit-inlay ikmu, which this
   cell's curve does not depend on: the fit warns that it is not identifiable.
2. Belt (inputs/belt.nml, the paper's Fig. 13 workflow): a SYNTHETIC curve in strain (%)
   and force per width (N/mm) from the gap-factor table (1, 0.8, 0.7) at p_disp (0, 0.5,
   1) plus 2 % noise. Fit the knot values at p_disp 0.5 and 1 from (0.95, 0.95).

Run from anywhere:  .venv/bin/python verification/calibration/run_fabric.py [--seeds N]
Writes knit_measured.csv, knit_fit.png, belt_measured.csv, belt_fit.png,
belt_gap_factor.png and fabric_results.txt next to this script. ``--seeds N`` repeats
both fits for N further noise seeds and reports the errors in standard uncertainties
(a check of the stated uncertainties; about a minute per seed).
"""
from __future__ import annotations

import argparse
import os
import sys
import time
import warnings
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
TOP = HERE.parents[1]
sys.path.insert(0, str(TOP / "python"))

from yarnfort import Scene  # noqa: E402
from yarnfort.calibrate import (IdentifiabilityWarning, calibrate, plot_fit,  # noqa: E402
                                write_synthetic_curve)

KMU, KBETA = "contact[0].friction_coefficient", "contact[0].adhesion"
IKMU = "contact[1].friction_coefficient"
KNIT_TRUTH = {KMU: 0.3999, KBETA: 0.015}
KNIT_START = {KMU: (0.3, 0.1, 0.8), KBETA: (0.03, 0.0, 0.1)}
#: Width of the "measured" knit sample (m): its force is per sample, in cN.
WIDTH = 0.02
G1, G2 = "fabric.gap_factor[1]", "fabric.gap_factor[2]"
BELT_TRUTH = {G1: 0.8, G2: 0.7}
BELT_START = {G1: (0.95, 0.3, 1.0), G2: (0.95, 0.3, 1.0)}
NOISE = 0.02
SEEDS = {"knit": 3, "belt": 5}


def knit_data(scene: Scene, seed: int, path: Path) -> Path:
    return write_synthetic_curve(scene, KNIT_TRUTH, path, strain_unit="%", force_unit="cN",
                                 width=WIDTH, noise=NOISE, seed=seed)


def belt_data(seed: int, path: Path) -> Path:
    return write_synthetic_curve("inputs/belt.nml", BELT_TRUTH, path, strain_unit="%",
                                 force_unit="N/mm", noise=NOISE, seed=seed)


def errors_in_u(result, truth) -> str:
    return ", ".join(f"{name}: {(v - truth[name]) / u:+.2f} u "
                     f"({(v - truth[name]) / truth[name]:+.2%})"
                     for name, v, u in zip(result.names, result.values, result.uncertainty))


def knit(lines: list[str]) -> None:
    scene = Scene.read("inputs/knit.nml")
    csv = knit_data(scene, SEEDS["knit"], HERE / "knit_measured.csv")
    lines.append(f"KNIT: SYNTHETIC {csv.name} (% and cN per {WIDTH * 1e3:g} mm sample, "
                 f"two cycles), truth kmu = {KNIT_TRUTH[KMU]}, kbeta = {KNIT_TRUTH[KBETA]}"
                 f" N, noise {NOISE:.0%} (seed {SEEDS['knit']}), start (0.3, 0.03)")
    for errors in ("relative", "equal"):
        result = calibrate(scene, csv, KNIT_START, width=WIDTH, errors=errors)
        lines += [f"-- errors='{errors}':", result.summary(),
                  "   errors: " + errors_in_u(result, KNIT_TRUTH)]
        if errors == "relative":
            plot_fit(result, HERE / "knit_fit.png", title="knit cell, 2 cycles: SYNTHETIC "
                     f"data (solver + {NOISE:.0%} noise) vs fitted model")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", IdentifiabilityWarning)
        result = calibrate(scene, csv, {KMU: (0.3, 0.1, 0.8), IKMU: (0.3, 0.1, 0.8)},
                           width=WIDTH, errors="relative", fixed={KBETA: 0.015})
    lines += ["-- kmu with the knit-inlay ikmu (no effect on this cell's curve):",
              result.summary()]
    lines += [f"   warning: {w.category.__name__}: {w.message}" for w in caught]


def belt(lines: list[str]) -> None:
    csv = belt_data(SEEDS["belt"], HERE / "belt_measured.csv")
    lines.append(f"BELT: SYNTHETIC {csv.name} (% and N/mm), gap factor (1, 0.8, 0.7) at "
                 f"p_disp (0, 0.5, 1), noise {NOISE:.0%} (seed {SEEDS['belt']}), start "
                 "(0.95, 0.95)")
    result = calibrate("inputs/belt.nml", csv, BELT_START, errors="relative")
    lines += [result.summary(), "   errors: " + errors_in_u(result, BELT_TRUTH)]
    plot_fit(result, HERE / "belt_fit.png", title="twill belt: SYNTHETIC data (solver + "
             f"{NOISE:.0%} noise) vs fitted gap factor")
    plot_gap_factor(result, HERE / "belt_gap_factor.png")


def plot_gap_factor(result, path: Path) -> None:
    """The gap-factor curve over p_disp (paper Fig. 13b): truth, start, fit."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    knots = [0.0, 0.5, 1.0]
    fig, ax = plt.subplots(figsize=(4.8, 3.4))
    ax.plot(knots, [1.0, BELT_TRUTH[G1], BELT_TRUTH[G2]], "k-", label="truth")
    ax.plot(knots, [1.0, BELT_START[G1][0], BELT_START[G2][0]], ":", color="0.5",
            label="start")
    ax.errorbar(knots, [1.0, *result.values], yerr=[0.0, *result.uncertainty], fmt="o--",
                capsize=3, color="C3", label="fitted ± standard uncertainty")
    ax.set_xlabel("p_disp (strain / 15 %)")
    ax.set_ylabel("gap factor")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def coverage(lines: list[str], seeds: int) -> None:
    """Both fits for further seeds: errors in standard uncertainties."""
    scene = Scene.read("inputs/knit.nml")
    rows = {"knit": [], "belt": []}
    folder = HERE / "_seeds"
    folder.mkdir(exist_ok=True)
    for seed in range(100, 100 + seeds):
        knit_fit = calibrate(scene, knit_data(scene, seed, folder / "knit.csv"), KNIT_START,
                             width=WIDTH, errors="relative")
        belt_fit = calibrate("inputs/belt.nml", belt_data(seed, folder / "belt.csv"),
                             BELT_START, errors="relative")
        for key, fit, truth in (("knit", knit_fit, KNIT_TRUTH), ("belt", belt_fit,
                                                                  BELT_TRUTH)):
            rows[key].append((fit.values - [truth[n] for n in fit.names]) / fit.uncertainty)
    for path in folder.iterdir():
        path.unlink()
    folder.rmdir()
    for key, errors in rows.items():
        errors = np.array(errors)
        lines.append(f"{key}, seeds 100..{99 + seeds}: errors in u " + "; ".join(
            " ".join(f"{e:+.2f}" for e in row) for row in errors)
            + f"; RMS per parameter {np.sqrt(np.mean(errors**2, axis=0)).round(2).tolist()}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=0, help="coverage check over N seeds")
    args = parser.parse_args()
    os.chdir(TOP)  # the scenes' tables are relative to the repository root
    lines: list[str] = []
    start = time.perf_counter()
    knit(lines)
    belt(lines)
    if args.seeds:
        coverage(lines, args.seeds)
    lines.append(f"total {time.perf_counter() - start:.0f} s ({os.cpu_count()} CPUs, load "
                 f"average {os.getloadavg()[0]:.1f})")
    text = "\n".join(lines)
    print(text)
    (HERE / "fabric_results.txt").write_text(text + "\n")


if __name__ == "__main__":
    main()
