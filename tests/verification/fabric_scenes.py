# SPDX-License-Identifier: MIT
"""Fabric scenes for the verification tests, the fabric study and the scene benchmark:
the example inputs (``inputs/knit.nml``, ``inputs/belt.nml``) with some variables
changed, and measurements on the VTK states of a woven fabric.

Scenes are patched as text (f90nml), never edited in place. Their table files are
relative to the repository top, so the program runs with the top as working directory
and writes to an absolute output folder.
"""
from __future__ import annotations

import subprocess
import time
from pathlib import Path
from typing import Any, Mapping

import f90nml
import numpy as np

TOP = Path(__file__).resolve().parents[2]

#: One loading-unloading cycle (p_disp 0 -> 1 -> 0) and monotone loading (0 -> 1).
ONE_CYCLE = {"path.time": [0.0, 1.0, 2.0], "path.p_disp": [0.0, 1.0, 0.0]}
LOADING = {"path.time": [0.0, 1.0], "path.p_disp": [0.0, 1.0]}
#: Where between two wefts interior_measures cuts the warps (no element node there for
#: 1 to 10 elements per segment).
CUT_FRACTION = 0.437
#: Contact values that turn a &contact group into 'bonded' (no sliding).
BONDED = {"law": "bonded", "friction_coefficient": None, "adhesion": None,
          "decay_start": None, "decay_end": None}


def _instances(nml: f90nml.Namelist, group: str) -> list:
    found = nml[group]
    return list(found) if isinstance(found, list) else [found]


def patched_scene(base: str | Path, values: Mapping[str, Any], folder: str | Path) -> str:
    """Namelist text of scene ``base`` with ``values`` set and output sent to ``folder``.

    ``values`` maps ``'group.variable'`` or ``'group[i].variable'`` (i from 0, file
    order) to a value; ``None`` removes the variable (back to its default).
    ``'contact[*].law'`` style keys (``*``) set the variable in every such group.
    """
    nml = f90nml.read(str(Path(base) if Path(base).is_absolute() else TOP / base))
    settings = dict(values)
    settings["output.folder"] = str(folder)
    settings.setdefault("output.progress", False)
    for address, value in settings.items():
        head, variable = address.rsplit(".", 1)
        group, _, index = head.partition("[")
        if group not in nml:
            nml[group] = f90nml.Namelist()
        instances = _instances(nml, group)
        index = index.rstrip("]")
        chosen = instances if index == "*" else [instances[int(index or 0)]]
        for instance in chosen:
            if value is None:
                instance.pop(variable, None)
            else:
                instance[variable] = value.item() if isinstance(value, np.generic) else value
    return str(nml) + "\n"


def bonded(n_contacts: int = 2) -> dict[str, Any]:
    """Values that make every one of ``n_contacts`` &contact groups bonded."""
    return {f"contact[{c}].{k}": v for c in range(n_contacts) for k, v in BONDED.items()}


def run_scene(text: str, executable: str | Path, cwd: Path = TOP,
              timeout: float = 600) -> tuple[subprocess.CompletedProcess, float]:
    """Run the program on namelist ``text``; the process and its wall time (s)."""
    start = time.perf_counter()
    proc = subprocess.run([str(executable)], input=text, capture_output=True, text=True,
                          cwd=cwd, timeout=timeout)
    return proc, time.perf_counter() - start


def crossing_nodes(position0: np.ndarray, spacing: tuple[float, float], i: int,
                   warps) -> np.ndarray:
    """Nodes at crossing (i, j) of a woven fabric for the warps j in ``warps``: those
    within a quarter of the smaller spacing (in x, y) of ((i + 1/2) sx, (j + 1/2) sy) in
    the initial state ``position0`` (the warp node and the weft node of each crossing;
    they move together, joined by the gap-holder)."""
    sx, sy = spacing
    found = []
    for j in warps:
        centre = np.array([(i + 0.5) * sx, (j + 0.5) * sy])
        distance = np.hypot(*(position0[:, :2] - centre).T)
        found.extend(np.flatnonzero(distance < 0.25 * min(sx, sy)))
    return np.array(found, dtype=int)


def middle_warps(n_warps: int) -> range:
    """The warps away from the side edges: the middle half (all of them below 8)."""
    return range(n_warps) if n_warps < 8 else range(n_warps // 4, n_warps - n_warps // 4)


def interior_measures(states, cells: tuple[int, int], spacing: tuple[float, float]
                      ) -> tuple[np.ndarray, np.ndarray]:
    """Strain and force per width of a clamped woven sample away from its edges.

    Strain: the mean x distance between the crossings of weft nx/4 and weft 3nx/4 of
    the middle warps, over its initial value (nx/2 sx), minus 1. Force per width: the x
    forces of the middle warps' elements cut by a plane between wefts
    nx/2 - 1 and nx/2 (at CUT_FRACTION of the way), over the width of those warps (the
    wefts run along y and do not cross that plane).
    """
    nx, ny = cells
    sx, sy = spacing
    warps = middle_warps(ny)
    position0 = states[0].position
    first = crossing_nodes(position0, spacing, nx // 4, warps)
    last = crossing_nodes(position0, spacing, 3 * nx // 4, warps)
    left = crossing_nodes(position0, spacing, nx // 2 - 1, warps)
    right = crossing_nodes(position0, spacing, nx // 2, warps)
    ends = states[0].elements
    # Warp index of each element from its initial mid-point (weft elements excluded by
    # the cut itself).
    y0 = 0.5 * (position0[ends[:, 0], 1] + position0[ends[:, 1], 1])
    in_middle = (y0 > (warps[0]) * sy) & (y0 < (warps[-1] + 1) * sy)
    strain, force = [], []
    for state in states:
        x = state.position
        strain.append((x[last, 0].mean() - x[first, 0].mean()) / ((nx // 2) * sx) - 1)
        # Not half way: with 2 elements per segment a node sits there.
        cut = x[left, 0].mean() + CUT_FRACTION * (x[right, 0].mean() - x[left, 0].mean())
        d = x[ends[:, 1]] - x[ends[:, 0]]
        crossed = ((x[ends[:, 0], 0] - cut) * (x[ends[:, 1], 0] - cut) < 0) & in_middle
        fx = np.abs(state.tension * d[:, 0] / np.linalg.norm(d, axis=1))
        force.append(fx[crossed].sum() / (len(warps) * sy))
    return np.array(strain), np.array(force)


def yarn_chains(elements: np.ndarray) -> list[np.ndarray]:
    """Split the element list into yarns: elements come yarn by yarn, each yarn a chain
    (an element starts where the previous one ended); a new yarn starts elsewhere."""
    breaks = np.flatnonzero(elements[1:, 0] != elements[:-1, 1]) + 1
    return np.split(np.arange(len(elements)), breaks)
