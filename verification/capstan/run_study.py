#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Capstan study: a yarn pulled over a half cylinder discretised by K contact nodes.

For K = 2 ... 64 pegs on the upper half of the unit circle (total wrap angle exactly pi
for every K: the yarn arrives vertically at (-1, 0) and leaves vertically at (1, 0)),
pull the right end down and measure the pull force against the displacement. Checks:

1. at gross slip the pull force equals T_crit(T_fixed, pi) for each friction law (the
   node laws compose exactly, so every K gives the same ratio);
2. the whole force-displacement curve (stick, moving slip front, gross slip) converges
   as K grows: the error against K = 64 and the observed order.

Run:  .venv/bin/python verification/capstan/run_study.py   (after ./yarnfort once)
Writes capstan.png and results.txt next to this script.
"""
from __future__ import annotations

import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
TOP = HERE.parents[1]
sys.path.insert(0, str(TOP / "python"))
sys.path.insert(0, str(TOP / "tests" / "verification"))
from scenes import group, scene  # noqa: E402
from yarnfort import read_curve, read_states  # noqa: E402

EXE = Path(os.environ.get("YARNFORT_EXE", TOP / "build" / "yarnfort"))
MU, BETA, EA, PULL = 0.3, 0.2, 10.0, 0.4
LAWS = {"coulomb": dict(law="coulomb", friction_coefficient=MU),
        "adhesion": dict(law="adhesion", friction_coefficient=MU, adhesion=BETA)}


def capstan_text(k: int, contact: dict, steps: int = 40) -> str:
    theta = np.pi * (1 - np.arange(k) / (k - 1))
    pegs = [[np.cos(t), np.sin(t), 0.0] for t in theta]
    anchors = [[0.8 * np.cos(t), 0.8 * np.sin(t), 0.0] for t in theta]
    nodes = [[-1.0, -2.0, 0.0]] + pegs + [[1.0, -2.0, 0.0]] + anchors
    yarns = [dict(material="yarn", nodes=list(range(1, k + 3)))]
    yarns += [dict(material="peg", nodes=[2 + i, k + 3 + i]) for i in range(k)]
    text = scene(
        nodes=nodes, yarns=yarns,
        materials=[dict(name="yarn", law="linear", stiffness=EA),
                   dict(name="peg", law="linear", stiffness=EA)],
        supports=[dict(name="fixed", nodes=[1]),
                  dict(name="pull", nodes=[k + 2], displacement=[0.0, -PULL, 0.0]),
                  dict(name="pegs", nodes=list(range(2, k + 2)) + list(range(k + 3, 2 * k + 3)))],
        path=dict(time=[0.0, 1.0], p_force=[0.0, 0.0], p_disp=[0.0, 1.0]),
        solver=dict(initial_step=1.0 / steps, max_step=1.0 / steps, slack_stiffness=1e-12,
                    residual_tolerance=1e-12),
        output=dict(folder="out", vtk_every=steps))
    return text.replace("&path", group("contact", materials=["yarn", "peg"], **contact) + "&path")


def critical(law: str, t0: float, angle: float) -> float:
    """Closed forms (paper eqs. 20, 35; alpha* = 1/mu - t0/beta, where T' = beta brings
    t0 to beta/mu)."""
    if law == "coulomb" or t0 >= BETA / MU:
        return t0 * np.exp(MU * angle)
    star = 1 / MU - t0 / BETA
    return t0 + BETA * angle if angle <= star else BETA / MU * np.exp(MU * (angle - star))


def run(k: int, law: str):
    with tempfile.TemporaryDirectory() as folder:
        proc = subprocess.run([str(EXE)], input=capstan_text(k, LAWS[law]), text=True,
                              capture_output=True, cwd=folder)
        if proc.returncode != 0:
            raise RuntimeError(proc.stderr)
        curve = read_curve(Path(folder) / "out")
        state = read_states(Path(folder) / "out")[-1]
    return curve["p_disp"] * PULL, -curve.reaction("pull")[:, 1], curve, state


def main() -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ks = [2, 4, 8, 16, 32, 64]
    lines = ["# capstan study: yarn over a half cylinder (wrap pi), K contact nodes",
             f"# EA = {EA} N, mu = {MU}, beta = {BETA} N, pull {PULL} m in 40 steps"]
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    for law, marker in (("coulomb", "o"), ("adhesion", "s")):
        results = {k: run(k, law) for k in ks}
        d_ref, f_ref, _, _ = results[ks[-1]]
        errors = []
        for k in ks:
            d, f, curve, state = results[k]
            t_first, t_last = state.tension[0], state.tension[k]
            gross = curve["slipping"][-1] == curve["passages"][-1]
            ratio_error = abs(t_last / critical(law, t_first, np.pi) - 1)
            errors.append(np.max(np.abs(f - f_ref)) / np.max(np.abs(f_ref)))
            lines.append(f"{law:9s} K={k:3d}  gross slip at end: {gross}  "
                         f"|T_last/T_crit(T_first, pi) - 1| = {ratio_error:.2e}  "
                         f"max curve error vs K={ks[-1]}: {errors[-1]:.3e}")
            if k in (2, 8, 64):
                axes[0].plot(d, f, marker=marker, markevery=5, ms=4, label=f"{law}, K={k}")
        orders = [np.log(errors[i] / errors[i + 1]) / np.log(2) for i in range(len(ks) - 2)]
        lines.append(f"{law:9s} observed orders (K -> 2K): "
                     + ", ".join(f"{o:.2f}" for o in orders))
        axes[1].loglog(ks[:-1], errors[:-1], marker=marker, label=law)
    axes[0].set_xlabel("pull displacement (m)")
    axes[0].set_ylabel("pull force (N)")
    axes[0].legend(fontsize=8)
    axes[0].set_title("force-displacement over a half cylinder")
    axes[1].set_xlabel("contact nodes K")
    axes[1].set_ylabel("max |F_K - F_64| / max F_64")
    axes[1].set_title("convergence in K")
    axes[1].legend()
    fig.tight_layout()
    fig.savefig(HERE / "capstan.png", dpi=120)
    (HERE / "results.txt").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
