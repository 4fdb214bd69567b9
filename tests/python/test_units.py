# SPDX-License-Identifier: MIT
"""Tests of yarnfort.units: lab units of measured curves to SI, checked against the
definitions of the units (not against the module's own tables)."""
from __future__ import annotations

import pytest

from yarnfort.units import force_factor, split_header, strain_factor

#: Round-off allowed in a product of two exact decimal factors.
RTOL = 4 * 2.0**-52
#: Standard gravity (m/s^2) and the avoirdupois pound (kg), both exact by definition.
G0 = 9.80665
POUND = 0.45359237


def test_headers_split_into_name_and_unit():
    assert split_header("strain (%)") == ("strain", "%")
    assert split_header(" Force [cN] ") == ("force", "cN")
    assert split_header("force (N/m)") == ("force", "N/m")
    assert split_header("branch") == ("branch", None)
    with pytest.raises(ValueError, match="expected 'name' or 'name \\(unit\\)'"):
        split_header("force (N))")


def test_strain_units():
    assert strain_factor("%") * 50 == pytest.approx(0.5, rel=RTOL)
    assert strain_factor("permille") * 500 == pytest.approx(0.5, rel=RTOL)
    assert strain_factor(None) == strain_factor("1") == 1.0
    with pytest.raises(ValueError, match="strain unit 'mm': known units are '1'"):
        strain_factor("mm")


def test_force_units_by_their_definitions():
    assert force_factor("N") == (1.0, False)
    assert force_factor(None) == (1.0, False)
    assert force_factor("cN")[0] * 250 == pytest.approx(2.5, rel=RTOL)
    assert force_factor("mN")[0] * 250 == pytest.approx(0.25, rel=RTOL)
    assert force_factor("gf")[0] == pytest.approx(G0 / 1000, rel=RTOL)
    assert force_factor("kgf")[0] == pytest.approx(G0, rel=RTOL)
    assert force_factor("lbf")[0] == pytest.approx(POUND * G0, rel=RTOL)


def test_force_per_width_units():
    factor, per_width = force_factor("N/m")
    assert per_width and factor == 1.0
    # 1 N/mm = 1000 N/m; 1 cN/cm = 0.01 N / 0.01 m = 1 N/m; 1 lbf/in = 175.1268... N/m.
    assert force_factor("N/mm")[0] == pytest.approx(1000.0, rel=RTOL)
    assert force_factor("cN/cm")[0] == pytest.approx(1.0, rel=RTOL)
    assert force_factor("lbf/in")[0] == pytest.approx(POUND * G0 / 0.0254, rel=RTOL)
    with pytest.raises(ValueError, match="force unit 'N/ft'"):
        force_factor("N/ft")
    with pytest.raises(ValueError, match="force unit 'MN'"):
        force_factor("MN")
