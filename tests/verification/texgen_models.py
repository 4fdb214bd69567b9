# SPDX-License-Identifier: MIT
"""Make TexGen models (.tg3) with pytexgen, for the TexGen import tests and the examples.

Run with the Python of ``.venv-texgen`` (tools/bootstrap installs pytexgen there, apart
from ``.venv``)::

    .venv-texgen/bin/python tests/verification/texgen_models.py plain out.tg3 2 2 1.0 0.4 0.8
    .venv-texgen/bin/python tests/verification/texgen_models.py twill out.tg3 4 4 1.0 0.4 0.8
    .venv-texgen/bin/python tests/verification/texgen_models.py knit out.tg3 1.0 1.0 1.2 0.2

Weaves: yarns along x and y, ``spacing`` apart, fabric ``thickness`` (TexGen places the
yarn centres thickness / 2 apart at a crossing), yarn ``width``; the crossings where
(i + j) mod 2 = 0 (plain) or (i + j) mod 4 < 2 (2/2 twill) are swapped from TexGen's default.
The weft knit: TexGen's CTextileWeftKnit (wale height, loop height, course width, yarn
thickness), whose cell is one loop. Lengths in mm (TexGen's GeometryScale).
pytexgen's own messages go to stderr; the file is written with OUTPUT_STANDARD.
"""
from __future__ import annotations

import contextlib
import os
import sys


def make(kind: str, path: str, values: list[float]) -> None:
    from pytexgen import Core as tg  # imported here: only this script needs pytexgen

    if kind in ("plain", "twill"):
        nx, ny, spacing, thickness, width = values
        textile = tg.CTextileWeave2D(int(nx), int(ny), spacing, thickness, True)
        textile.SetYarnWidths(width)
        repeat = 2 if kind == "plain" else 4
        for i in range(int(nx)):
            for j in range(int(ny)):
                if (i + j) % repeat < repeat // 2:
                    textile.SwapPosition(i, j)
        textile.AssignDefaultDomain()
    elif kind == "knit":
        wale_height, loop_height, course_width, thickness = values
        textile = tg.CTextileWeftKnit(2, 2, wale_height, loop_height, course_width,
                                      thickness)
    else:
        raise SystemExit(f"unknown kind {kind!r} (plain, twill or knit)")
    tg.AddTextile(kind, textile)
    tg.SaveToXML(path, kind, tg.OUTPUT_STANDARD)


def main() -> None:
    kind, path, *values = sys.argv[1:]
    # pytexgen prints its progress on stdout (the C++ side too): send it to stderr.
    sys.stdout.flush()
    saved = os.dup(1)
    os.dup2(2, 1)
    try:
        with contextlib.redirect_stdout(sys.stderr):
            make(kind, path, [float(v) for v in values])
    finally:
        sys.stdout.flush()
        os.dup2(saved, 1)
    if not os.path.exists(path):
        raise SystemExit(f"pytexgen wrote no file {path}")


if __name__ == "__main__":
    main()
