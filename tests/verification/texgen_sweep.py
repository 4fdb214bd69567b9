# SPDX-License-Identifier: MIT
"""A sweep of TexGen models as TexGen users make them: pytexgen's constructors with their
defaults (tests/verification/texgen_models.py), across widths, spacings and thicknesses
that TexGen accepts; each imported (a ``check_only`` run) and run (a short stretch).

    .venv/bin/python tests/verification/texgen_sweep.py [folder]    # prints the table

Models are made with pytexgen in .venv-texgen where it is installed; otherwise the cases
shipped as tests/data/texgen/<name>.tg3.gz (the same pytexgen files, gzipped) are used. Used by
tests/verification/test_texgen_sweep.py. Times are wall times: figures, not assertions.
"""
from __future__ import annotations

import gzip
import re
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

from fabric_scenes import TOP, patched_scene

TEXGEN_PYTHON = TOP / ".venv-texgen" / "bin" / "python"
MODELS = Path(__file__).with_name("texgen_models.py")
SHIPPED = TOP / "tests" / "data" / "texgen"
KNIT = "inputs/texgen_knit.nml"

#: name: (kind, parameters in mm as texgen_models.py takes them). Weaves: nx ny spacing
#: thickness [width]; no width: TexGen's default (the spacing). Knit: wale height, loop
#: height, course width, yarn thickness.
CASES: dict[str, tuple[str, tuple[float, ...]]] = {
    "plain_2x2_s1_t0.4": ("plain", (2, 2, 1.0, 0.4)),
    "plain_2x2_s1_t0.4_w0.8": ("plain", (2, 2, 1.0, 0.4, 0.8)),
    "plain_2x2_s1_t0.2_w0.5": ("plain", (2, 2, 1.0, 0.2, 0.5)),
    "plain_2x2_s1_t0.2": ("plain", (2, 2, 1.0, 0.2)),
    "plain_4x2_s2_t0.6": ("plain", (4, 2, 2.0, 0.6)),
    "plain_2x2_s0.5_t0.1_w0.4": ("plain", (2, 2, 0.5, 0.1, 0.4)),
    "twill_4x4_s1_t0.2": ("twill", (4, 4, 1.0, 0.2)),
    "twill_4x4_s1_t0.2_w0.8": ("twill", (4, 4, 1.0, 0.2, 0.8)),
    "twill_4x4_s1_t0.3_w0.8": ("twill", (4, 4, 1.0, 0.3, 0.8)),
    "twill_4x4_s1_t0.5": ("twill", (4, 4, 1.0, 0.5)),
    "satin_5x5_s1_t0.4": ("satin", (5, 5, 1.0, 0.4)),
    "satin_5x5_s1_t0.2_w0.8": ("satin", (5, 5, 1.0, 0.2, 0.8)),
    "layered_2x2_s1_t0.4": ("layered", (2, 2, 1.0, 0.4)),
    "layered_2x2_s1_t0.4_w0.8": ("layered", (2, 2, 1.0, 0.4, 0.8)),
    "knit_1_1_1.2_0.2": ("knit", (1.0, 1.0, 1.2, 0.2)),
    "knit_1.2_1_1.5_0.25": ("knit", (1.2, 1.0, 1.5, 0.25)),
    "knit_1_1_1.2_0.4": ("knit", (1.0, 1.0, 1.2, 0.4)),
    "plain_2x2_s1_t1": ("plain", (2, 2, 1.0, 1.0)),
    "plain_2x2_s1_t0.4_w1.2": ("plain", (2, 2, 1.0, 0.4, 1.2)),
    "twill_4x4_s1_t0.1": ("twill", (4, 4, 1.0, 0.1)),
    "layered_2x2_s1_t0.2": ("layered", (2, 2, 1.0, 0.2)),
    "knit_1_1_2_0.2": ("knit", (1.0, 1.0, 2.0, 0.2)),
    "knit_1_1.5_1.2_0.2": ("knit", (1.0, 1.5, 1.2, 0.2)),
    "knit_1_1_1.2_0.5": ("knit", (1.0, 1.0, 1.2, 0.5)),
    "knit_1_1_1.2_0.6": ("knit", (1.0, 1.0, 1.2, 0.6)),
}
#: Cases TexGen builds that the import refuses, and words the refusal must hold: a weft
#: knit whose YarnThickness reaches CourseWidth / 2 (the head of a loop meets its
#: neighbour's: TexGen puts its sides CourseWidth / 4 - YarnThickness / 2 from the
#: loop's middle), or whose loop legs are too close to be told apart.
REFUSED: dict[str, str] = {
    "knit_1_1_1.2_0.5": "give a smaller YarnThickness",
    "knit_1_1_1.2_0.6": "give a YarnThickness (here 0.6) below CourseWidth / 2 (here 0.6)",
}
#: What a refusal must name to be in TexGen's terms: TexGen's yarn index, and what to change.
TEXGEN_TERMS = re.compile(r"TexGen yarn \d+")


@dataclass
class Outcome:
    name: str
    ok: bool
    detail: str  # counts, or the refusal's message
    import_time: float
    run_time: float


def have_pytexgen() -> bool:
    if not TEXGEN_PYTHON.exists():
        return False
    probe = subprocess.run([str(TEXGEN_PYTHON), "-c", "import pytexgen.Core"],
                           capture_output=True, text=True)
    return probe.returncode == 0


def model(name: str, folder: Path, make: bool) -> Path | None:
    """The model file of case ``name``: made with pytexgen (``make``), else shipped."""
    path = folder / f"{name}.tg3"
    if not make:
        shipped = SHIPPED / f"{name}.tg3.gz"
        if not shipped.exists():
            return None
        path.write_bytes(gzip.decompress(shipped.read_bytes()))
        return path
    kind, values = CASES[name]
    if not path.exists():
        proc = subprocess.run([str(TEXGEN_PYTHON), str(MODELS), kind, str(path),
                               *map(str, values)], capture_output=True, text=True,
                              timeout=600)
        if proc.returncode != 0 or not path.exists():
            raise RuntimeError(f"pytexgen failed on {name}: {proc.stderr[-2000:]}")
    return path


def scene(name: str, path: Path, folder: Path, check_only: bool) -> str:
    """One material for every yarn; a short stretch (5 % for weaves, 50 % for knits)."""
    kind, _ = CASES[name]
    return patched_scene(KNIT, {"fabric.texgen_file": str(path),
                                "fabric.strain": 0.5 if kind == "knit" else 0.05,
                                "path.time": [0.0, 1.0], "path.p_disp": [0.0, 1.0],
                                "solver.max_step": 0.25, "output.vtk_every": 0,
                                "control.check_only": check_only}, folder)


def run_case(executable: Path, name: str, path: Path, folder: Path) -> Outcome:
    times = []
    for check_only in (True, False):
        start = time.perf_counter()
        proc = subprocess.run([str(executable)], input=scene(name, path, folder, check_only),
                              capture_output=True, text=True, cwd=TOP, timeout=600)
        times.append(time.perf_counter() - start)
        if proc.returncode != 0:
            message = proc.stderr.strip().splitlines()
            return Outcome(name, False, f"exit {proc.returncode}: "
                           + (message[-1] if message else ""), times[0], float("nan"))
    found = re.search(r"TexGen model: (\d+) yarns, (\d+) contacts", proc.stderr)
    detail = f"{found[1]} yarns, {found[2]} contacts" if found else "?"
    return Outcome(name, True, detail, times[0], times[1])


def table(outcomes: list[Outcome]) -> str:
    rows = ["| model | TexGen parameters (mm) | outcome | import (s) | run (s) |",
            "|---|---|---|---|---|"]
    for o in outcomes:
        kind, values = CASES[o.name]
        # A refusal: its message without the program's prefix and the file's path.
        detail = o.detail if o.ok else re.sub(r"^.*?texgen_file '[^']*': ", "", o.detail)
        run = f"{o.run_time:.2f}" if o.ok else "-"
        rows.append(f"| {o.name} | {kind} {' '.join(f'{v:g}' for v in values)} | "
                    f"{'runs: ' if o.ok else 'refused: '}{detail} | {o.import_time:.2f} | "
                    f"{run} |")
    return "\n".join(rows)


def main() -> None:
    import yarnfort
    folder = Path(sys.argv[1] if len(sys.argv) > 1 else TOP / "out" / "texgen_sweep")
    folder.mkdir(parents=True, exist_ok=True)
    make = have_pytexgen()
    outcomes = []
    for name in CASES:
        path = model(name, folder, make)
        if path is None:
            continue
        outcomes.append(run_case(Path(yarnfort.program_path()), name, path, folder / name))
        print(table(outcomes[-1:]).splitlines()[-1], file=sys.stderr, flush=True)
    print(table(outcomes))


if __name__ == "__main__":
    main()
