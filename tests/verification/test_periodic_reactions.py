# SPDX-License-Identifier: MIT
"""Reactions of periodic fabric cells balance (issue: the anchor reaction was incomplete).

In a periodic cell an image node follows its leader, x = u(root) + offset + p_disp *
macro. When the root coordinate is prescribed (the cell's `anchor`), so is every
coordinate that follows it, and its force belongs to the root's reaction: the reaction
of a prescribed coordinate is the force on it and on all its followers (the force its
prescribed value holds). The set `stretch` is not a constraint: it lists the x
coordinates of the right-edge images, of free roots as well, and its x reaction is the
force carried across the cell (`force_per_width`). So, with no applied load:

(a) the constraint sets (every set but `stretch`) add up to zero in every state, i.e.
    the anchor holds the cell against a rigid translation that no force drives;
(b) the per-node rows of reactions.csv add up to the curve.csv columns of their set;
(c) force_per_width is the stretch set's x reaction over the cell's width, and stays
    what the closed forms of test_fabrics.py / test_knit3d.py check (those tests run
    unchanged).

Before the fix the anchor's images were in no set: knit3d reported an anchor x reaction
equal to the stretch force (1.22 N at step 16) instead of zero.
"""
from __future__ import annotations

import numpy as np
import pytest

from fabric_scenes import TOP, patched_scene
from yarnfort import read_curve
from yarnfort.results import read_reactions

#: Scenes: example inputs at their default settings (plain weave from belt.nml as the
#: periodic cell test_fabrics.py uses).
SCENES = {
    "knit": ("inputs/knit.nml", {}),
    "knit3d": ("inputs/knit3d.nml", {}),
    "plain_weave": ("inputs/belt.nml", {"fabric.kind": "plain", "fabric.boundary": "periodic",
                                        "fabric.cells": [2, 2], "fabric.sides": None}),
    "texgen_weave": ("inputs/texgen_weave.nml", {}),
    "texgen_knit": ("inputs/texgen_knit.nml", {}),
}
#: The constraint reactions add up to minus the residual of the free unknowns, which
#: Newton brings below residual_tolerance (1e-10) of the forces meeting at each node;
#: those rows partly cancel. 1e-9 of the largest reaction of the run (ten times the
#: Newton tolerance) leaves a margin of 20 over the worst measured (4.7e-11,
#: texgen_knit) and is far from what the missing images gave (0.03 weaves, 1 knits).
BALANCE = 1e-9
#: Per-node rows against the set columns: the same doubles added in another order.
SUM_RTOL = 1e-12


def set_names(curve) -> list[str]:
    return [name[:-3] for name in curve.columns if name.endswith("_rx")]


@pytest.mark.parametrize("shear", [None, 0.3])
@pytest.mark.parametrize("name", sorted(SCENES))
def test_periodic_cell_reactions_balance(run_yarnfort, tmp_path, name, shear):
    """With `shear` too: the images one y period up then move along x with p_disp, and
    the sets must balance as before."""
    base, values = SCENES[name]
    folder = tmp_path / name
    values = {**values, "output.node_reactions": True, "output.vtk_every": 0}
    if shear is not None:
        values["fabric.shear"] = shear
    result = run_yarnfort(patched_scene(base, values, folder), cwd=TOP)
    assert result.returncode == 0, result.stderr
    curve = read_curve(folder)
    sets = set_names(curve)
    assert "anchor" in sets and "stretch" in sets, sets
    assert not [c for c in curve.columns if c.startswith("load_")], "scene has a load"
    reaction = {s: np.column_stack([curve[f"{s}_r{k}"] for k in "xyz"]) for s in sets}
    largest = max(np.abs(r).max() for r in reaction.values())
    assert largest > 0
    # (a) every state: the constraint sets balance (no applied load).
    total = sum(r for s, r in reaction.items() if s != "stretch")
    assert np.abs(total).max() <= BALANCE * largest, (name, np.abs(total).max() / largest)
    # The stretch force is not balanced by a constraint: it is a cut force.
    assert np.abs(reaction["stretch"][:, 0]).max() > 1e-3 * largest
    # (b) the per-node rows add up to the set columns.
    rows = read_reactions(folder)
    for s in sets:
        for i, step in enumerate(curve["step"]):
            mine = (rows["support"] == s) & (rows["step"] == step)
            assert mine.any(), (s, step)
            node_sum = np.array([rows[f"r{k}"][mine].sum() for k in "xyz"])
            scale = max(np.abs(reaction[s][i]).max(), np.abs(
                np.column_stack([rows[f"r{k}"][mine] for k in "xyz"])).max(), 1e-300)
            assert np.abs(node_sum - reaction[s][i]).max() <= SUM_RTOL * scale, (s, step)
    # (c) force_per_width is the stretch x reaction over one width for the whole run.
    width = reaction["stretch"][:, 0] / np.where(curve["force_per_width"] == 0, 1,
                                                 curve["force_per_width"])
    loaded = curve["force_per_width"] != 0
    assert np.allclose(width[loaded], width[loaded][0], rtol=1e-15, atol=0)
