# SPDX-License-Identifier: MIT
"""Bounds that every route to the same quantity shares (issue 39): the stretch l / L0 of
an element, whether a prestress, ``length0`` or ``stretch`` gives it, stays within
[2**-60, 2**60]; the bound on a gap factor; and scenes whose every coordinate is
prescribed are input errors however the coordinates are held, while one in which a yarn
still slides at a contact is solved. The bad inputs of the catalogue
(tests/data/input/bad_*.nml) check the messages; these tests check where the bounds lie.
"""
from __future__ import annotations

import math
from pathlib import Path

import pytest

TOP = Path(__file__).resolve().parents[2]
VNET = (TOP / "inputs" / "vnet.nml").read_text()
CAPSTAN = (TOP / "inputs" / "capstan.nml").read_text()
#: The documented bound on the stretch of an element (inputs/REFERENCE.md).
MAX_STRETCH = 2.0 ** 60
#: Just inside and just outside it (relative 1e-9: far above round-off, far below the bound).
INSIDE, OUTSIDE = MAX_STRETCH * (1 - 1e-9), MAX_STRETCH * (1 + 1e-9)
#: vnet's elements: from (+-1, 0, 0) to (0, -0.2, 0), by hand.
VNET_LENGTH = math.sqrt(1.0 + 0.2 ** 2)
#: vnet's linear law: f(lambda) = EA (lambda - 1) with EA = 10 N.
VNET_EA = 10.0


def check_only(text: str) -> str:
    return text.replace("&control", "&control\n    check_only = .true.", 1)


def vnet_with(yarn_line: str = "", material_line: str = "") -> str:
    text = VNET.replace("    nodes = 1, 2, 3\n", f"    nodes = 1, 2, 3\n    {yarn_line}\n")
    text = text.replace("    stiffness = 10.0        ! EA in N",
                        f"    stiffness = 10.0\n    {material_line}")
    return check_only(text)


def accepted(run) -> bool:
    assert run.returncode in (0, 2), run.stderr
    if run.returncode == 2:
        assert "error (input)" in run.stderr and not any(run.folder.iterdir()), run.stderr
    return run.returncode == 0


@pytest.mark.parametrize("stretch, ok", [(INSIDE, True), (OUTSIDE, False)])
def test_prestress_reaches_up_to_the_bound(run_yarnfort, stretch, ok):
    """A prestress is refused exactly when its law needs a stretch above 2**60."""
    prestress = VNET_EA * (stretch - 1.0)
    run = run_yarnfort(vnet_with(material_line=f"prestress = {prestress!r}"))
    assert accepted(run) == ok, run.stderr
    if not ok:
        assert "prestress" in run.stderr and "more than the force law reaches" in run.stderr


@pytest.mark.parametrize("stretch, ok", [(INSIDE, True), (OUTSIDE, False),
                                         (1 / INSIDE, True), (1 / OUTSIDE, False)])
def test_stretch_list_has_the_prestress_bound(run_yarnfort, stretch, ok):
    run = run_yarnfort(vnet_with(yarn_line=f"stretch = {stretch!r}, 1.0"))
    assert accepted(run) == ok, run.stderr
    if not ok:
        assert "&yarn #1: stretch(1) = " in run.stderr and "outside [" in run.stderr


@pytest.mark.parametrize("stretch, ok", [(INSIDE, True), (OUTSIDE, False),
                                         (1 / INSIDE, True), (1 / OUTSIDE, False)])
def test_length0_has_the_prestress_bound(run_yarnfort, stretch, ok):
    """length0 = l / lambda for the same lambda as above, l computed by hand."""
    run = run_yarnfort(vnet_with(yarn_line=f"length0 = 1.0, {VNET_LENGTH / stretch!r}"))
    assert accepted(run) == ok, run.stderr
    if not ok:
        assert "&yarn #1: length0(2) = " in run.stderr and "stretches element 2" in run.stderr


def test_over_stretch_of_the_issue_is_refused_before_any_output(run_yarnfort, tmp_path):
    """The issue's case, run in full (not check-only): exit 2, nothing written."""
    text = VNET.replace("    nodes = 1, 2, 3\n", "    nodes = 1, 2, 3\n    length0 = 1e-300, 1.0\n")
    run = run_yarnfort(text)
    assert run.returncode == 2, run.stderr
    assert "length0(1) = 1.0e-300" in run.stderr
    assert list(tmp_path.iterdir()) == []


BELT = """&material name = 'warp', law = 'linear', stiffness = 5.0, prestress = 0.02 /
&material name = 'weft', law = 'linear', stiffness = 5.0, prestress = 0.02 /
&contact materials = 'warp' 'weft', law = 'adhesion', friction_coefficient = 0.3,
    adhesion = 0.01 /
&fabric kind = 'twill', cells = 4 4, spacing = 1.0e-3 0.5e-3, boundary = 'clamped',
    sides = 'rollers', strain = 0.15, warp_material = 'warp', weft_material = 'weft',
    gap = 0.2e-3, gap_factor_p_disp = 0.0 1.0, gap_factor = 1.0 {factor!r} /
&path time = 0 1, p_disp = 0 1 /
&control check_only = .true. /
"""
#: The smallest gap factor (documented): 100 * epsilon.
MIN_GAP_FACTOR = 100 * 2.0 ** -52


@pytest.mark.parametrize("factor, ok", [
    (MIN_GAP_FACTOR * 1.01, True), (MIN_GAP_FACTOR * 0.99, False), (5e-324, False),
    (2.2250738585072014e-308, False), (0.5, True)])
def test_gap_factor_bound(run_yarnfort, factor, ok):
    run = run_yarnfort(BELT.format(factor=factor))
    assert accepted(run) == ok, run.stderr
    if not ok:
        assert "&fabric: gap_factor(2) = " in run.stderr and "100 * epsilon" in run.stderr


def capstan_all_supported(law: str) -> str:
    """The capstan (every node is supported: the ends and the pegs) with the pegs' law."""
    return CAPSTAN.replace("""    law = 'adhesion'            ! dT/dalpha = max(mu T, beta)
    friction_coefficient = 0.3  ! mu
    adhesion = 0.05             ! beta (N)""", f"    law = '{law}'" + (
        "\n    friction_coefficient = 0.3" if law == "coulomb" else ""))


def test_no_unknowns_with_bonded_pegs_is_an_input_error(run_yarnfort, tmp_path):
    """Every peg bonded: nothing moves and nothing slides: exit 2, nothing written."""
    run = run_yarnfort(capstan_all_supported("bonded"))
    assert run.returncode == 2, run.stderr
    assert "the scene has no unknowns" in run.stderr
    assert list(tmp_path.iterdir()) == []


def test_all_nodes_prescribed_but_sliding_is_solved(run_yarnfort, tmp_path):
    """The same scene with sliding pegs has unknowns (the sliding) and runs."""
    text = capstan_all_supported("coulomb").replace("max_step = 0.05", "max_step = 0.5")
    run = run_yarnfort(text)
    assert run.returncode == 0, run.stderr
    assert (tmp_path / "out" / "capstan" / "curve.csv").exists()
