# SPDX-License-Identifier: MIT
"""Export example (issue 40): the knit of inputs/knit.nml, stretched along the courses to
1.5x and to 2x with a release after each (knit_cycles.nml), exported with
``python -m yarnfort export-fabric`` as an Abaqus *FABRIC block, LS-DYNA curves and a
CSV, in N and mm, for an ILLUSTRATIVE thickness of 0.6 mm. Run from the top folder:

    .venv/bin/python verification/export_fabric/run_study.py

Writes knit_fabric.inp, knit_fabric.k, knit_fabric.csv and results.txt next to this
script (the run itself goes to out/export_fabric/).
"""
from __future__ import annotations

import subprocess
import sys
import time
from pathlib import Path

import yarnfort

HERE = Path(__file__).resolve().parent
TOP = HERE.parents[1]
RUN = TOP / "out" / "export_fabric"
#: The command line of the example (the README shows it).
COMMAND = ["-m", "yarnfort", "export-fabric", "out/export_fabric", "--component", "1",
           "--thickness", "0.6mm", "--units", "N,mm", "--force"]


def main() -> None:
    start = time.perf_counter()
    with open(HERE / "knit_cycles.nml") as scene:
        done = subprocess.run([str(yarnfort.program_path())], stdin=scene, cwd=TOP,
                              capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"the run of knit_cycles.nml failed:\n{done.stderr}")
    run_time = time.perf_counter() - start
    lines = [f"run of knit_cycles.nml: {run_time:.1f} s"]
    for suffix, fmt in ((".inp", "abaqus"), (".k", "lsdyna"), (".csv", "csv")):
        out = HERE / f"knit_fabric{suffix}"
        subprocess.run([sys.executable, *COMMAND, "--format", fmt, "-o", str(out)],
                       cwd=TOP, check=True)
        lines.append(f"{out.name}: {len(out.read_text().splitlines())} lines")
    curves = yarnfort.fabric_curves(RUN, "1")
    lines.append(f"loading: {len(curves.loading.strain)} points to strain"
                 f" {curves.loading.peak_strain:.3g}; unloading curves from strains "
                 + ", ".join(f"{b.peak_strain:.3g}" for b in curves.unloading))
    (HERE / "results.txt").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
