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
