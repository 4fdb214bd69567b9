# SPDX-License-Identifier: MIT
"""Fabric generators and the periodic cell: facts derived independently of the code.

(a) A plain weave is symmetric under the half turns about the yarn ends (half way
    between crossings) and the mirror planes of the warps; the ends of a clamped sample
    with rollers (weft ends held in y and z) sit on those symmetry elements, so the
    sample is a union of periodic cells: same force per width at the same strain as the
    periodic cell, at any length, to the Newton tolerance (1e-8 of the largest force),
    and the strain between interior crossings equals the clamp strain. A 2/2 twill lacks
    that symmetry: its clamps add an edge layer of fixed width, so its difference to the
    cell halves when the sample doubles.
(b) Prestress: each element's L0 is its generated length over the stretch at which the
    law carries the prestress (L0 (1 + P/EA) = l for a linear law, l from the generator's
    documented geometry); in a symmetric woven cell (equal spacings, yarns and
    prestress) the generated geometry is already in equilibrium, so every element
    carries exactly the prestress.
(c) Sliding moves reference length between the elements of a yarn: each yarn's total
    L0 is conserved in the knit cycle.
(d) Gap-holders: the two nodes of a crossing stay exactly (0, 0, +-gap g(p_disp)) apart.
(e) A periodic knit of 4 x 4 loops is 2 x 2 copies of the 2 x 2 cell: same force per
    width at every step.
(f) inputs/knit.nml runs through and unloads below its loading curve (hysteresis).
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from fabric_scenes import (LOADING, ONE_CYCLE, TOP, bonded, interior_measures,
                           patched_scene, yarn_chains)
from yarnfort import read_curve, read_states

KNIT, BELT = "inputs/knit.nml", "inputs/belt.nml"
SPACING = (1.0e-3, 0.5e-3)   # belt.nml's weft and warp spacing (m)
#: Periodic cell against a plain-weave sample: equal up to the Newton tolerance
#: (residual 1e-10 of the force scale); 1e-8 of the largest force per width leaves a
#: margin of 25 over the worst difference measured (3.8e-10, verification/fabrics).
PLAIN_TOLERANCE = 1e-8
#: Identities computed in floating point (lengths, sums of some 40 lengths).
ROUND_OFF = 1e-12


def run(run_yarnfort, base: str, values: dict, folder: Path, vtk: bool = True):
    """Run a patched example scene from the repository top (its table files are
    relative to it); the curve and the states."""
    values = {**values, "output.vtk_every": 1 if vtk else 0}
    result = run_yarnfort(patched_scene(base, values, folder), cwd=TOP)
    assert result.returncode == 0, result.stderr
    return read_curve(folder), (read_states(folder) if vtk else None)


UNIFORM = {"solver.max_step": 0.25, "solver.initial_step": 0.25}
#: belt.nml is a twill; the plain-weave checks say so.
PLAIN = {"fabric.kind": "plain"}


def test_plain_sample_equals_periodic_cell(run_yarnfort, tmp_path):
    cell, _ = run(run_yarnfort, BELT, {**PLAIN, **LOADING, **UNIFORM,
                                       "fabric.boundary": "periodic",
                                       "fabric.cells": [4, 4], "fabric.sides": None},
                  tmp_path / "cell", vtk=False)
    sample, states = run(run_yarnfort, BELT, {**PLAIN, **LOADING, **UNIFORM,
                                              "fabric.cells": [8, 4]}, tmp_path / "sample")
    strain, middle_force = interior_measures(states, (8, 4), SPACING)
    assert np.allclose(sample["strain"], cell["strain"], rtol=0, atol=ROUND_OFF)
    assert np.max(np.abs(strain - sample["strain"])) < ROUND_OFF
    scale = cell["force_per_width"].max()
    assert np.max(np.abs(sample["force_per_width"] - cell["force_per_width"])) \
        < PLAIN_TOLERANCE * scale
    assert np.max(np.abs(middle_force - cell["force_per_width"])) < PLAIN_TOLERANCE * scale


def test_twill_sample_edge_layer_halves_with_length(run_yarnfort, tmp_path):
    twill = {**LOADING, "fabric.kind": "twill", "solver.max_step": 0.1,
             "solver.initial_step": 0.1}
    cell, _ = run(run_yarnfort, BELT, {**twill, "fabric.boundary": "periodic",
                                       "fabric.cells": [4, 4], "fabric.sides": None},
                  tmp_path / "cell", vtk=False)
    differences = []
    for nx, ny in ((8, 4), (16, 8)):
        sample, _ = run(run_yarnfort, BELT, {**twill, "fabric.cells": [nx, ny]},
                        tmp_path / f"sample{nx}", vtk=False)
        assert int(sample["slipping"].max()) > 0  # friction is at work in the twill
        # Compare at the strains both runs reached (a run that had to cut a step has
        # extra ones in between; interpolating the convex curve would add its own error).
        common = np.isclose(cell["strain"][:, None], sample["strain"][None, :],
                            rtol=0.0, atol=1e-12)
        i, j = np.nonzero(common)
        assert len(i) >= 3
        differences.append(np.max(np.abs(sample["force_per_width"][j]
                                         - cell["force_per_width"][i]))
                           / cell["force_per_width"].max())
    assert differences[0] < 0.01
    assert 1.5 < differences[0] / differences[1] < 2.5, differences


LINEAR = {"material[*].law": "linear", "material[*].table_file": None,
          "material[*].stiffness": 20.0, "material[*].prestress": 0.02}


@pytest.mark.parametrize("law", ["linear", "table"])
def test_symmetric_woven_cell_carries_its_prestress(run_yarnfort, tmp_path, law):
    """Plain weave, equal spacings, warp and weft alike, no stretch: the generated
    geometry is in equilibrium, each element carries the prestress exactly."""
    sx, gap, prestress = 1.0e-3, 0.2e-3, 0.02
    values = {**bonded(1), **PLAIN, "fabric.boundary": "periodic", "fabric.cells": [2, 2],
              "fabric.sides": None, "fabric.spacing": [sx, sx], "fabric.gap": gap,
              "fabric.gap_factor": None, "fabric.gap_factor_p_disp": None,
              "fabric.elements_per_segment": 1, "solver.slack_stiffness": 0.0,
              "path.time": [0.0, 1.0], "path.p_disp": [0.0, 0.0],
              "material[*].prestress": prestress}
    if law == "linear":
        values.update(LINEAR)
    else:
        values["material[1].table_file"] = "inputs/data/warp_yarn.csv"
    curve, states = run(run_yarnfort, BELT, values, tmp_path / "cell")
    assert curve["newton_iterations"][0] <= 1
    state = states[0]
    assert np.max(np.abs(state.tension / prestress - 1)) < 1e-10
    if law == "linear":
        # Between crossings a yarn goes from +gap/2 to -gap/2 over one spacing; the ends
        # are half way between crossings (half that length).
        segment = np.hypot(sx, gap)
        generated = state.length0 * (1 + prestress / 20.0)
        nearest = np.where(generated > 0.75 * segment, segment, 0.5 * segment)
        assert np.max(np.abs(generated / nearest - 1)) < ROUND_OFF


def knit_lengths(cells, spacing, head_width, inlay_offset, gap) -> list[float]:
    """Element lengths of the generated knit (one element per segment), from the
    geometry documented in src/yarnfort/generate/knit.f90, yarn by yarn: course j,
    then its inlay."""
    nw, nc = cells
    w, c = spacing
    a = 0.5 * (1 - head_width) * w
    g = 0.5 * gap
    lengths = []
    for j in range(nc):
        y, y0, yi = (j + 1) * c, j * c, (j + inlay_offset) * c
        points = [(0.0, y0, 0.0)]
        for i in range(nw):
            left, right = i * w + a, (i + 1) * w - a
            points += [(left, y0, 0.0), (left, yi, -g), (left, y, 0.0), (right, y, 0.0),
                       (right, yi, g), (right, y0, 0.0)]
        points.append((nw * w, y0, 0.0))
        inlay = [(0.0, yi, 0.0)]
        for i in range(nw):
            inlay += [(i * w + a, yi, g), ((i + 1) * w - a, yi, -g)]
        inlay.append((nw * w, yi, 0.0))
        for chain in (points, inlay):
            p = np.array(chain)
            lengths += list(np.linalg.norm(np.diff(p, axis=0), axis=1))
    return lengths


def test_knit_reference_lengths_carry_the_prestress(run_yarnfort, tmp_path):
    """Before any equilibrium: L0 (1 + P/EA) equals the generated length of every
    element (bonded contacts, so the first solve cannot change L0)."""
    values = {**LINEAR, **bonded(2), "fabric.elements_per_segment": 1,
              "path.time": [0.0, 1.0], "path.p_disp": [0.0, 0.0]}
    _, states = run(run_yarnfort, KNIT, values, tmp_path / "knit")
    expected = knit_lengths((2, 2), (1.0e-3, 0.8e-3), 0.5, 0.5, 0.3e-3)
    generated = states[0].length0 * (1 + 0.02 / 20.0)
    assert len(generated) == len(expected)
    assert np.max(np.abs(generated / np.array(expected) - 1)) < ROUND_OFF


def test_knit_sliding_conserves_each_yarns_length(run_yarnfort, tmp_path):
    _, states = run(run_yarnfort, KNIT, ONE_CYCLE, tmp_path / "knit")
    yarns = yarn_chains(states[0].elements)
    assert len(yarns) == 4  # two courses, two inlays
    total0 = [states[0].length0[y].sum() for y in yarns]
    moved = 0.0
    for state in states:
        for y, total in zip(yarns, total0):
            assert abs(state.length0[y].sum() / total - 1) < ROUND_OFF
        moved = max(moved, np.max(np.abs(state.length0 / states[0].length0 - 1)))
    assert moved > 0.1  # the yarns do slide (not a vacuous check)


def holder_pairs(position0: np.ndarray, tolerance: float) -> list[tuple[int, int]]:
    """Pairs of nodes at the same (x, y): the two sides of a gap-holder."""
    pairs = []
    for a in range(len(position0)):
        same = np.flatnonzero(np.max(np.abs(position0[a + 1:, :2] - position0[a, :2]),
                                     axis=1) < tolerance) + a + 1
        pairs += [(a, b) for b in same]
    return pairs


@pytest.mark.parametrize("scene, gap, n_pairs", [(BELT, 0.2e-3, 8), (KNIT, 0.3e-3, 8)])
def test_gap_holders_keep_gap_times_factor(run_yarnfort, tmp_path, scene, gap, n_pairs):
    values = {"fabric.cells": [4, 2]} if scene == BELT else dict(ONE_CYCLE)
    curve, states = run(run_yarnfort, scene, values, tmp_path / "run")
    assert len(states) == len(curve["step"])
    pairs = holder_pairs(states[0].position, 1e-6 * gap)
    assert len(pairs) == n_pairs
    a, b = np.array(pairs).T
    for state, p_disp in zip(states, curve["p_disp"]):
        factor = np.interp(p_disp, [0.0, 0.5, 1.0], [1.0, 0.8, 0.7]) if scene == BELT \
            else 1.0
        d = state.position[b] - state.position[a]
        assert np.max(np.abs(d[:, :2])) < 1e-10 * gap
        assert np.max(np.abs(np.abs(d[:, 2]) / (gap * factor) - 1)) < 1e-10


def test_knit_cell_force_does_not_depend_on_cell_size(run_yarnfort, tmp_path):
    curves = [run(run_yarnfort, KNIT, {**ONE_CYCLE, "fabric.cells": cells},
                  tmp_path / f"cell{cells[0]}", vtk=False)[0] for cells in ([2, 2], [4, 4])]
    small, large = curves
    assert np.array_equal(small["time"], large["time"])
    assert np.max(np.abs(large["force_per_width"] - small["force_per_width"])) \
        < 1e-8 * small["force_per_width"].max()


def test_knit_example_runs_and_shows_hysteresis(run_yarnfort, tmp_path):
    curve, _ = run(run_yarnfort, KNIT, {}, tmp_path / "knit", vtk=False)
    assert curve["time"][-1] == 4.0
    direction, strain, force = curve["direction"], curve["strain"], curve["force_per_width"]
    peak = int(np.argmax(strain))  # end of the first loading
    end = peak + int(np.argmax(direction[peak + 1:] == 1))  # end of the first unloading
    grid = np.linspace(0.1, 0.9, 9)
    loading = np.interp(grid, strain[:peak + 1], force[:peak + 1])
    unloading = np.interp(grid, strain[peak:end + 1][::-1], force[peak:end + 1][::-1])
    assert np.all(unloading < loading - 0.01 * loading)
