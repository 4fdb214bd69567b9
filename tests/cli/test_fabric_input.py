# SPDX-License-Identifier: MIT
"""Bad &fabric input: each mistake gets exit code 2, a message naming the variable and
value, and nothing written. The base input is a valid periodic plain-weave cell."""
from __future__ import annotations

from pathlib import Path

import pytest

BASE = """
&material name = 'warp', law = 'linear', stiffness = 20.0, prestress = 0.02 /
&material name = 'weft', law = 'linear', stiffness = 10.0 /
&contact materials = 'warp', 'weft', law = 'coulomb', friction_coefficient = 0.3 /
&fabric
    kind = 'plain'
    cells = 2, 2
    spacing = 1.0e-3, 1.0e-3
    warp_material = 'warp'
    weft_material = 'weft'
    gap = 0.2e-3
    strain = 0.1
/
&path time = 0, 1, p_disp = 0, 1 /
&output folder = 'out' /
"""

CASES = {
    "unknown_kind": ("kind = 'plain'", "kind = 'satin'",
                     "&fabric: kind = 'satin' is unknown (use knit, plain, twill or texgen)"),
    "odd_periodic_plain": ("cells = 2, 2", "cells = 3, 2",
                           "cells = 3, 2 must be multiples of 2 for a periodic plain cell"),
    "twill_repeat": ("kind = 'plain'", "kind = 'twill'",
                     "must be multiples of 4 for a periodic twill cell"),
    "no_spacing": ("spacing = 1.0e-3, 1.0e-3", "",
                   "&fabric: spacing = -1.0"),
    "negative_spacing": ("spacing = 1.0e-3, 1.0e-3", "spacing = 1.0e-3, -1.0e-3",
                         "must be two positive lengths"),
    "no_gap": ("gap = 0.2e-3", "", "&fabric: gap is required"),
    "gap_too_wide": ("gap = 0.2e-3", "gap = 2.0e-3",
                     "must be positive and smaller than the yarn spacing"),
    "gap_table_lengths": ("gap = 0.2e-3", "gap = 0.2e-3\n gap_factor_p_disp = 0, 1\n"
                          " gap_factor = 1.0", "gap_factor_p_disp has 2 values but gap_factor has 1"),
    "gap_table_order": ("gap = 0.2e-3", "gap = 0.2e-3\n gap_factor_p_disp = 0, 1, 0.5\n"
                        " gap_factor = 1.0, 0.9, 0.8", "gap_factor_p_disp must increase strictly"),
    "gap_factor_negative": ("gap = 0.2e-3", "gap = 0.2e-3\n gap_factor_p_disp = 0, 1\n"
                            " gap_factor = 1.0, -0.5", "gap_factor value 2"),
    "unknown_material": ("weft_material = 'weft'", "weft_material = 'wool'",
                         "&fabric: weft_material = 'wool' is not the name of any &material"),
    "missing_material": ("weft_material = 'weft'", "",
                         "&fabric: weft_material is required for kind = 'plain'"),
    "knit_variable_on_weave": ("gap = 0.2e-3", "gap = 0.2e-3\n knit_material = 'warp'",
                               "knit_material does not apply to kind = 'plain'"),
    "unknown_boundary": ("strain = 0.1", "strain = 0.1\n boundary = 'open'",
                         "boundary = 'open' is unknown"),
    "huge_strain": ("strain = 0.1", "strain = 1e300", "&fabric: strain = "),
    "zero_cells": ("cells = 2, 2", "cells = 0, 2", "must be at least 1"),
    "huge_network": ("strain = 0.1", "strain = 0.1\n elements_per_segment = 300000000",
                     "elements_per_segment = 300000000 makes too large a network"),
    "elements_per_segment": ("strain = 0.1", "strain = 0.1\n elements_per_segment = 0",
                             "elements_per_segment = 0 must be at least 1"),
    "fabric_with_nodes": ("&path", "&nodes xyz = 0, 0, 0 /\n&path",
                          "&nodes: not allowed together with &fabric"),
    "fabric_with_support": ("&path", "&support name = 'x', nodes = 1 /\n&path",
                            "&support: not allowed together with &fabric"),
    "negative_prestress": ("prestress = 0.02", "prestress = -0.02",
                           "&material 'warp': prestress = -0.02"),
    "nan_prestress": ("prestress = 0.02", "prestress = NaN", "prestress = NaN"),
    "fabric_twice": ("&path", "&fabric kind = 'plain' /\n&path",
                     "&fabric appears more than once"),
    "no_kind": ("kind = 'plain'", "", "kind is required"),
    "knit_needs_knit_material": ("kind = 'plain'", "kind = 'knit'",
                                 "&fabric: knit_material is required for kind = 'knit'"),
    "knit_depth_on_weave": ("strain = 0.1", "strain = 0.1\n knit_depth = 0.1e-3",
                            "&fabric: knit_depth does not apply to kind = 'plain'"),
    "edge_material_on_weave": ("strain = 0.1", "strain = 0.1\n edge_material = 'warp'",
                               "&fabric: edge_material does not apply to kind = 'plain'"),
}

#: A valid three-dimensional knit cell (knit_depth > 0), and its mistakes.
KNIT_3D = """
&material name = 'knit', law = 'linear', stiffness = 5.0, prestress = 0.02 /
&fabric
    kind = 'knit'
    cells = 2, 2
    spacing = 1.0e-3, 0.8e-3
    knit_material = 'knit'
    knit_depth = 0.2e-3
    strain = 0.1
/
&path time = 0, 1, p_disp = 0, 1 /
&output folder = 'out' /
"""

KNIT_3D_CASES = {
    "negative": ("knit_depth = 0.2e-3", "knit_depth = -0.2e-3",
                 "&fabric: knit_depth = -0.2000"),
    "as_deep_as_spacing": ("knit_depth = 0.2e-3", "knit_depth = 0.8e-3",
                           "must be 0 (a planar knit) or positive and smaller than the spacing"),
    "nan": ("knit_depth = 0.2e-3", "knit_depth = NaN", "knit_depth = NaN"),
    "gap_without_inlay": ("knit_depth = 0.2e-3", "knit_depth = 0.2e-3\n gap = 0.1e-3",
                          "gap applies to woven fabrics and to the inlay of a knit"),
    "gap_factor_too_large": ("knit_depth = 0.2e-3", "knit_depth = 0.2e-3\n"
                             " gap_factor_p_disp = 0, 1\n gap_factor = 1.0, 5.0",
                             "gap_factor must keep knit_depth * factor below the spacing"),
    "gap_factor_negative": ("knit_depth = 0.2e-3", "knit_depth = 0.2e-3\n"
                            " gap_factor_p_disp = 0, 1\n gap_factor = 1.0, -1.0",
                            "gap_factor values must be positive and finite"),
    # The cast-on and bind-off threads close a clamped knit's free sides only.
    "edge_material_on_cell": ("strain = 0.1", "strain = 0.1\n edge_material = 'knit'",
                              "&fabric: edge_material applies to a clamped knit with "
                              "sides = 'free'"),
    "edge_material_with_rollers": ("strain = 0.1", "strain = 0.1\n edge_material = 'knit'"
                                   "\n boundary = 'clamped'\n sides = 'rollers'",
                                   "edge_material applies to a clamped knit with sides = "
                                   "'free'"),
    "edge_material_unknown": ("strain = 0.1", "strain = 0.1\n edge_material = 'silk'"
                              "\n boundary = 'clamped'",
                              "&fabric: edge_material = 'silk' is not the name of any "
                              "&material"),
}


@pytest.mark.parametrize("name", sorted(CASES))
def test_bad_fabric_input(run_yarnfort, tmp_path, name):
    old, new, words = CASES[name]
    assert old in BASE
    run = run_yarnfort(BASE.replace(old, new, 1), cwd=tmp_path)
    assert run.returncode == 2, run.stderr
    assert words in run.stderr, run.stderr
    assert list(tmp_path.iterdir()) == []


def test_base_input_is_valid(run_yarnfort, tmp_path):
    run = run_yarnfort(BASE, cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    header = (tmp_path / "out" / "curve.csv").read_text().splitlines()[0].split(",")
    assert "force_per_width" in header and "strain" in header


def test_knit_inlay_needs_gap(run_yarnfort, tmp_path):
    text = """
&material name = 'knit', law = 'linear', stiffness = 5.0 /
&material name = 'inlay', law = 'linear', stiffness = 1.0 /
&fabric kind = 'knit', spacing = 1e-3, 1e-3, knit_material = 'knit',
        inlay_material = 'inlay' /
&path time = 0, 1, p_disp = 0, 1 /
"""
    run = run_yarnfort(text, cwd=tmp_path)
    assert run.returncode == 2
    assert "&fabric: gap is required" in run.stderr
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("name", sorted(KNIT_3D_CASES))
def test_bad_knit_depth(run_yarnfort, tmp_path, name):
    old, new, words = KNIT_3D_CASES[name]
    assert old in KNIT_3D
    run = run_yarnfort(KNIT_3D.replace(old, new, 1), cwd=tmp_path)
    assert run.returncode == 2, run.stderr
    assert words in run.stderr, run.stderr
    assert list(tmp_path.iterdir()) == []


def test_knit_3d_input_is_valid(run_yarnfort, tmp_path):
    run = run_yarnfort(KNIT_3D, cwd=tmp_path)
    assert run.returncode == 0, run.stderr


def test_clamped_knit_with_edge_material_is_valid(run_yarnfort, tmp_path):
    text = KNIT_3D.replace("strain = 0.1", "strain = 0.1\n boundary = 'clamped'\n"
                           " edge_material = 'thread'").replace(
        "&fabric", "&material name = 'thread', law = 'linear', stiffness = 5.0, "
        "prestress = 0.5 /\n&fabric", 1)
    run = run_yarnfort(text, cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    header = (tmp_path / "out" / "curve.csv").read_text().splitlines()[0].split(",")
    assert "edge_right_rx" in header and "edge_left_rx" in header


@pytest.mark.parametrize("materials, count", [("'warp', 'weft'", 2),
                                              ("'warp', 'warp', 'weft', 'weft', 'weft'", 5)])
def test_texgen_materials_one_or_one_per_yarn(run_yarnfort, tmp_path, materials, count):
    """inputs/texgen_weave.tg3 has 4 TexGen yarns (0, 1 along x, 2, 3 along y): two names
    gave yarn 1, along x, the weft's material; five name a yarn the file lacks."""
    top = Path(__file__).resolve().parents[2]
    scene = (top / "inputs" / "texgen_weave.nml").read_text()
    given = "texgen_materials = 'warp', 'warp', 'weft', 'weft'"
    assert given in scene
    run = run_yarnfort(scene.replace(given, f"texgen_materials = {materials}"), cwd=top)
    assert run.returncode == 2, run.stderr
    assert (f"texgen_file 'inputs/texgen_weave.tg3': texgen_materials names {count} "
            "materials for the 4 TexGen yarns of the file") in run.stderr
