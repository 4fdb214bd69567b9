# SPDX-License-Identifier: MIT
"""Addresses of one entry of a list variable: ``'fabric.gap_factor[1]'``."""
from __future__ import annotations

from pathlib import Path

import pytest

from yarnfort import AddressError, get_parameter, read_scene, set_parameter
from yarnfort.address import parse_address

BELT = Path(__file__).resolve().parents[2] / "inputs" / "belt.nml"


def test_entry_addresses_parse():
    where = parse_address("fabric.gap_factor[2]")
    assert (where.group, where.index, where.variable, where.element) == (
        "fabric", None, "gap_factor", 2)
    where = parse_address("support[pull].displacement[-1]")
    assert (where.index, where.element) == ("pull", -1)
    assert parse_address("contact[0].adhesion").element is None
    with pytest.raises(AddressError, match="bad parameter address"):
        parse_address("fabric.gap_factor[x]")


def test_an_entry_is_read_and_set_and_the_others_kept():
    scene = read_scene(BELT)  # gap_factor = 1.0, 0.8, 0.7
    assert get_parameter(scene, "fabric.gap_factor[1]") == 0.8
    assert get_parameter(scene, "fabric.gap_factor[-1]") == 0.7
    set_parameter(scene, "fabric.gap_factor[2]", 0.55)
    set_parameter(scene, "fabric.gap_factor[0]", 1)
    assert get_parameter(scene, "fabric.gap_factor") == [1.0, 0.8, 0.55]
    assert isinstance(get_parameter(scene, "fabric.gap_factor[0]"), float)


def test_an_entry_outside_the_list_or_of_an_unset_list_is_refused():
    scene = read_scene(BELT)
    with pytest.raises(AddressError, match="gap_factor has 3 value"):
        set_parameter(scene, "fabric.gap_factor[3]", 0.5)
    with pytest.raises(AddressError, match="no variable 'lateral_strain' set"):
        set_parameter(scene, "fabric.lateral_strain[0]", 0.1)
    assert get_parameter(scene, "fabric.gap_factor") == [1.0, 0.8, 0.7]


VNET = BELT.with_name("vnet.nml")


def _echoed_displacement(scene, tmp_path, name):
    """The displacement of support `name` as the program read it (its input.nml echo)."""
    import yarnfort

    set_parameter(scene, "output.folder", str(tmp_path / name))
    yarnfort.write_scene(scene, tmp_path / f"{name}.nml")
    result = yarnfort.run_scene(tmp_path / f"{name}.nml")
    echo = read_scene(result.folder / "input.nml")
    return next(g["displacement"] for g in echo["support"] if g["name"] == "ends")


def test_a_list_given_from_a_later_entry_is_addressed_from_its_first(tmp_path):
    # 'displacement(2) = -0.3' sets y; f90nml keeps it as [-0.3] with a start index, so
    # entry [0] used to be y and a whole list set was written shifted (2:4).
    text = VNET.read_text().replace("fix = 'xyz'", "fix = 'xyz'\n    displacement(2) = -0.3")
    (tmp_path / "given.nml").write_text(text)  # p_disp is 0: the solve does not change
    scene = read_scene(tmp_path / "given.nml")
    assert get_parameter(scene, "support[ends].displacement") == [None, -0.3]
    assert get_parameter(scene, "support[ends].displacement[1]") == -0.3
    assert get_parameter(scene, "support[ends].displacement[0]") is None
    set_parameter(scene, "support[ends].displacement[0]", 0.25)
    assert _echoed_displacement(scene, tmp_path, "entry") == [0.25, -0.3, 0.0]
    scene = read_scene(tmp_path / "given.nml")
    set_parameter(scene, "support[ends].displacement", [0.1, 0.2, 0.3])
    assert _echoed_displacement(scene, tmp_path, "whole") == [0.1, 0.2, 0.3]


def test_a_position_that_is_another_groups_name_is_refused():
    import f90nml

    scene = f90nml.reads("&support name = '1', nodes = 1 /\n&support name = 'b', nodes = 2 /")
    with pytest.raises(AddressError, match=r"ambiguous, a &support is named '1' \(position"
                       r" 0\); write support\['1'\].nodes for the name"):
        get_parameter(scene, "support[1].nodes")
    assert get_parameter(scene, "support['1'].nodes") == 1
    assert get_parameter(scene, "support[0].nodes") == 1  # position and name agree
    assert get_parameter(scene, "support[b].nodes") == 2
