# SPDX-License-Identifier: MIT
"""Make TexGen models (.tg3) with pytexgen, for the TexGen import tests and the examples.

Run with the Python of ``.venv-texgen`` (tools/bootstrap installs pytexgen there, apart
from ``.venv``)::

    .venv-texgen/bin/python tests/verification/texgen_models.py plain out.tg3 2 2 1.0 0.4 0.8
    .venv-texgen/bin/python tests/verification/texgen_models.py twill out.tg3 4 4 1.0 0.4
    .venv-texgen/bin/python tests/verification/texgen_models.py satin out.tg3 5 5 1.0 0.4
    .venv-texgen/bin/python tests/verification/texgen_models.py layered out.tg3 2 2 1.0 0.4
    .venv-texgen/bin/python tests/verification/texgen_models.py knit out.tg3 1.0 1.0 1.2 0.2

Weaves (``plain``, ``twill``, ``satin``: nx ny spacing thickness [width]) are TexGen's
``CTextileWeave2D(nx, ny, spacing, thickness)`` (its defaults: refined, in-plane
tangents): yarns along x and y, ``spacing`` apart, fabric ``thickness`` (TexGen places
the yarn centres thickness / 2 apart at a crossing). ``SetYarnWidths(width)`` only when a
width is given; without it TexGen takes the width equal to the spacing. The crossings
where (i + j) mod 2 = 0 (plain), (i + j) mod 4 < 2 (2/2 twill) or j = 2 i mod nx (satin,
nx = ny >= 5, odd: the 5-harness satin for 5) are swapped with ``SwapPosition(i, j)``
from TexGen's default (every crossing alike), then ``AssignDefaultDomain()``.
``layered``: ``CTextileLayered()`` with two such plain weaves, ``AddLayer(weave,
XYZ(0, 0, 0))`` and ``AddLayer(weave, XYZ(0, 0, thickness))`` (stacked, touching).
The weft knit (``knit``: wale height, loop height, course width, yarn thickness) is
``CTextileWeftKnit(2, 2, wale_height, loop_height, course_width, thickness)`` (two loops
wide and high, as TexGen's knit wizard makes it), whose cell is one loop.
Each textile is then ``AddTextile(name, textile)`` and ``SaveToXML(path, name,
OUTPUT_STANDARD)``. Lengths in mm (TexGen's GeometryScale).
pytexgen's own messages go to stderr.
"""
from __future__ import annotations

import contextlib
import os
import sys

WEAVES = ("plain", "twill", "satin")


def swapped(kind: str, nx: int, i: int, j: int) -> bool:
    """Crossings swapped from TexGen's default to make the pattern."""
    if kind == "plain":
        return (i + j) % 2 == 0
    if kind == "twill":
        return (i + j) % 4 < 2
    return j == (2 * i) % nx


def weave(kind: str, values: list[float]):
    from pytexgen import Core as tg  # imported here: only this script needs pytexgen

    nx, ny, spacing, thickness, *width = values
    nx, ny = int(nx), int(ny)
    if kind == "satin" and (nx != ny or nx < 5 or nx % 2 == 0):
        raise SystemExit("satin: nx = ny, odd and >= 5")
    textile = tg.CTextileWeave2D(nx, ny, spacing, thickness)
    if width:
        textile.SetYarnWidths(width[0])
    for i in range(nx):
        for j in range(ny):
            if swapped(kind, nx, i, j):
                textile.SwapPosition(i, j)
    textile.AssignDefaultDomain()
    return textile


def make(kind: str, path: str, values: list[float]) -> None:
    from pytexgen import Core as tg

    if kind in WEAVES:
        textile = weave(kind, values)
    elif kind == "layered":
        layer = weave("plain", values)
        textile = tg.CTextileLayered()
        textile.AddLayer(layer, tg.XYZ(0.0, 0.0, 0.0))
        textile.AddLayer(layer, tg.XYZ(0.0, 0.0, values[3]))
    elif kind == "knit":
        wale_height, loop_height, course_width, thickness = values
        textile = tg.CTextileWeftKnit(2, 2, wale_height, loop_height, course_width,
                                      thickness)
    else:
        raise SystemExit(f"unknown kind {kind!r} (plain, twill, satin, layered or knit)")
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
