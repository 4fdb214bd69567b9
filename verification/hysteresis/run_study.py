# SPDX-License-Identifier: MIT
"""Hysteresis of one yarn over one frictional pin: yarnfort against the closed form.

Runs the scene of ``tests/verification/test_hysteresis.py`` (fixed end A, fixed pin C,
end B pulled along C->B and released twice, constant wrap angle) for several friction
coefficients and both the Coulomb and the adhesion law, with both friction schemes,
and compares every converged step with the piecewise closed form derived there.
Writes ``hysteresis.png`` and ``results.txt`` (the error table) next to this script and
prints the table.

    .venv/bin/python verification/hysteresis/run_study.py   (after ./yarnfort has built once;
    YARNFORT_EXE picks another binary)
"""
from __future__ import annotations

import os
import subprocess
import sys
import tempfile
from dataclasses import replace
from pathlib import Path

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

HERE = Path(__file__).resolve().parent
TOP = HERE.parents[1]
sys.path[:0] = [str(TOP / "tests" / "verification"), str(TOP / "python")]
from test_hysteresis import Case, ClosedForm, compare, hysteresis_scene  # noqa: E402

EXECUTABLE = Path(os.environ.get("YARNFORT_EXE", TOP / "build" / "yarnfort"))
MUS = (0.1, 0.3, 0.6)
BETA = 0.1                       #: adhesion (N) of the 'adhesion' runs
MAX_STEP = 0.05                  #: 20 steps per half cycle
SCHEMES = ("monolithic", "staggered")


def run(case: Case):
    """Run one case in a fresh folder (old state files would mix in) and compare."""
    with tempfile.TemporaryDirectory() as tmp:
        proc = subprocess.run([str(EXECUTABLE)], input=hysteresis_scene(case), text=True,
                              capture_output=True, cwd=tmp)
        if proc.returncode != 0:
            raise RuntimeError(f"yarnfort failed for {case}:\n{proc.stderr}")
        return compare(case, Path(tmp) / "out")


def exact_loop(case: Case, per_half_cycle: int = 4000):
    """Closed form on a fine path (for the curves and the exact loop areas)."""
    knots = case.knots
    d = np.concatenate([np.linspace(knots[i], knots[i + 1], per_half_cycle + 1)[i > 0:]
                        for i in range(len(knots) - 1)])
    _, force, _ = ClosedForm(case).follow(d)
    return d, force


def main() -> None:
    rows = []
    fig, axes = plt.subplots(2, len(MUS), figsize=(4.2 * len(MUS), 7.6), sharex=True)
    for row, law in enumerate(("coulomb", "adhesion")):
        for col, mu in enumerate(MUS):
            ax = axes[row, col]
            case = Case(law=law, mu=mu, beta=BETA if law == "adhesion" else 0.0,
                        max_step=MAX_STEP)
            d_fine, f_fine = exact_loop(case)
            half = len(d_fine) // 2          # the first release ends at the middle
            ax.plot(d_fine[:half + 1] * 1e3, f_fine[:half + 1], "-", color="0.55", lw=1.4,
                    label="closed form, cycle 1")
            ax.plot(d_fine[half:] * 1e3, f_fine[half:], "-", color="tab:blue", lw=1.4,
                    label="closed form, cycle 2")
            for scheme in SCHEMES:
                cmp = run(replace(case, scheme=scheme))
                area, area_exact = cmp.areas()
                area_fine = [np.trapezoid(f_fine[:half + 1], d_fine[:half + 1]),
                             np.trapezoid(f_fine[half:], d_fine[half:])]
                s_err = max(abs(cmp.s[i] - cmp.s_exact[i]) / cmp.s_exact[i]
                            for i in cmp.unload_steps)
                rows.append(dict(
                    law=law, mu=mu, scheme=scheme, steps=len(cmp.d) - 1,
                    force=cmp.force_error(),
                    area=float(np.max(np.abs(area - area_exact) / area_exact)),
                    s=s_err, areas=area, areas_fine=area_fine,
                    s_left=[cmp.s[i] for i in cmp.unload_steps],
                    alpha=float(np.max(np.abs(cmp.alpha - case.alpha))),
                    branches="".join(sorted(cmp.branches))))
                if scheme == "monolithic":
                    c1, c2 = cmp.cycles()
                    ax.plot(cmp.d[c1] * 1e3, cmp.force[c1], "o", color="0.3", ms=3.5,
                            mfc="none", label="yarnfort, cycle 1")
                    ax.plot(cmp.d[c2] * 1e3, cmp.force[c2], "x", color="tab:red", ms=4,
                            label="yarnfort, cycle 2")
            kind = "Coulomb" if law == "coulomb" else f"adhesion beta = {BETA} N"
            ax.set_title(f"{kind}, mu = {mu}", fontsize=10)
            ax.grid(alpha=0.3)
            if row == 1:
                ax.set_xlabel("pull d of end B along C->B (mm)")
            if col == 0:
                ax.set_ylabel("reaction at B along C->B (N)")
    axes[0, 0].legend(fontsize=7, loc="upper left")
    fig.suptitle(f"One yarn (EA = {case.stiffness} N) over one pin, wrap angle "
                 f"{case.alpha} rad, pulled and released twice "
                 "(d: 0 -> 200 -> 50 -> 200 -> 50 mm); markers: every converged step",
                 fontsize=10)
    fig.tight_layout()
    fig.savefig(HERE / "hysteresis.png", dpi=120)

    lines = [f"{'law':9} {'mu':>4} {'scheme':10} {'steps':>5} {'max rel err F':>14} "
             f"{'rel err area':>13} {'rel err s':>10} {'|d alpha|':>9} branches  "
             f"area per cycle (steps | fine) mJ   s after release mm"]
    for r in rows:
        lines.append(f"{r['law']:9} {r['mu']:4.1f} {r['scheme']:10} {r['steps']:5d} "
                     f"{r['force']:14.2e} {r['area']:13.2e} {r['s']:10.2e} "
                     f"{r['alpha']:9.1e} {r['branches']:9} "
                     + " ".join(f"{a * 1e3:.3f}" for a in r["areas"]) + " | "
                     + " ".join(f"{a * 1e3:.3f}" for a in r["areas_fine"]) + "   "
                     + " ".join(f"{s * 1e3:.4f}" for s in r["s_left"]))
    worst = max(r["force"] for r in rows)
    lines.append(f"worst force error {worst:.2e}")

    # The default slack regularisation (a spring in the Newton tangent of slack strings
    # only) must leave the exact law's answer: its effect, for the record.
    for law in ("coulomb", "adhesion"):
        case = Case(law=law, mu=0.3, beta=BETA if law == "adhesion" else 0.0,
                    max_step=MAX_STEP, slack_stiffness=1e-6)
        cmp = run(case)
        lines.append(f"default slack_stiffness = 1e-6, {law}, mu = 0.3: max rel err F "
                     f"{cmp.force_error():.2e}, max abs err F "
                     f"{np.max(np.abs(cmp.force - cmp.force_exact)):.2e} N")
    (HERE / "results.txt").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))
    if worst > 1e-6:
        sys.exit(1)


if __name__ == "__main__":
    main()
