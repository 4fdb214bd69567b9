# SPDX-License-Identifier: MIT
"""yarnfort.units: the factors by hand, the same conversions as the program's table
reader (through yarnfort.force_law), and measured curves in lab units."""
from __future__ import annotations

import numpy as np
import pytest

import yarnfort
from yarnfort.calibrate import read_measured
from yarnfort.units import UNITS, force_factor, split_header, strain_factor, to_scene_unit

#: Identities up to rounding (relative).
IDENTITY = 100 * np.finfo(float).eps

#: One value in each unit and the same by hand in the scene's unit (1, N, m).
BY_HAND = [
    ("%", "strain", 5.0, 0.05), ("permille", "strain", 7.0, 0.007),
    ("\u2030", "strain", 7.0, 0.007), ("-", "strain", 0.3, 0.3), ("1", "strain", 0.3, 0.3),
    ("N", "force", 1.25, 1.25), ("cN", "force", 12.3, 0.123), ("mN", "force", 250.0, 0.25),
    ("kN", "force", 2.5, 2500.0), ("gf", "force", 2.0, 0.0196133),
    ("kgf", "force", 2.0, 19.6133), ("lbf", "force", 2.0, 8.896443230521),
    ("mm", "length", 3.0, 0.003), ("cm", "length", 2.0, 0.02), ("um", "length", 250.0, 2.5e-4),
]


@pytest.mark.parametrize("unit, kind, value, expected", BY_HAND)
def test_each_unit_converts_as_by_hand(unit, kind, value, expected):
    np.testing.assert_allclose(to_scene_unit(value, unit, kind), expected, rtol=IDENTITY)


def test_every_unit_is_covered_by_hand():
    assert {unit for unit, *_ in BY_HAND} | {"m", "\u00b5m"} == set(UNITS)


@pytest.mark.parametrize("unit, kind", [("MN", "force"), ("CN", "force"), ("pct", "strain"),
                                        ("mm", "force"), ("N", "strain")])
def test_unknown_or_wrong_kind_refused(unit, kind):
    with pytest.raises(ValueError, match=f"'{unit}' is not a known {kind} unit"):
        to_scene_unit(1.0, unit, kind)


@pytest.mark.parametrize("field, name, unit", [
    ("Force (cN)", "Force", "cN"), ("strain [%]", "strain", "%"), ("Force in cN", "Force", "cN"),
    ("Force/GF", "Force", "GF"), ("Force (cN) mean", "Force", "cN"), ("strain", "strain", None),
    ("Maximum force", "Maximum force", None), ("Stress (N/tex)", "Stress", "N/tex"),
])
def test_header_fields(field, name, unit):
    assert split_header(field) == (name, unit)


@pytest.mark.parametrize("strain_unit", ["1", "%", "permille", "\u2030"])
@pytest.mark.parametrize("force_unit", ["N", "cN", "mN", "kN", "gf", "KGF", "lbf"])
def test_program_reads_tables_as_python_converts(tmp_path, strain_unit, force_unit):
    """The program's table law at its knots is the Python conversion of the rows: both
    sides use the same factors."""
    strain = np.array([0.0, 2.0, 5.0, 9.0])
    force = np.array([0.0, 1.5, 4.0, 11.0])
    table = tmp_path / "lab.csv"
    table.write_text(f"strain ({strain_unit}),force ({force_unit})\n"
                     + "".join(f"{float(e)!r},{float(f)!r}\n" for e, f in zip(strain, force)))
    knots = to_scene_unit(strain, strain_unit, "strain")
    expected = to_scene_unit(force, force_unit.lower() if force_unit == "KGF" else force_unit,
                             "force")
    tension, _, _ = yarnfort.force_law("table", 1.0 + knots, table_file=table)
    np.testing.assert_allclose(tension, expected, rtol=1e-12)


def test_measured_curve_in_lab_units(tmp_path):
    lab = tmp_path / "lab.csv"
    lab.write_text("# tensile test\nStrain (%),Force [cN],branch\n0,0,loading\n5,12.3,loading\n"
                   "10,31,loading\n5,8,unloading\n")
    measured = read_measured(lab)
    np.testing.assert_allclose(measured.strain, [0.0, 0.05, 0.1, 0.05], rtol=IDENTITY)
    np.testing.assert_allclose(measured.force, [0.0, 0.123, 0.31, 0.08], rtol=IDENTITY)
    assert list(measured.branch) == [1, 1, 1, -1]
    bad = tmp_path / "bad.csv"
    bad.write_text("strain,force (N/tex)\n0,0\n1,2\n")
    with pytest.raises(ValueError, match="bad.csv: force unit 'N/tex'"):
        read_measured(bad)


#: Round-off allowed in a product of two exact decimal factors.
RTOL = 4 * 2.0**-52
#: Standard gravity (m/s^2) and the avoirdupois pound (kg), both exact by definition.
G0 = 9.80665
POUND = 0.45359237


def test_strain_units():
    assert strain_factor("%") * 50 == pytest.approx(0.5, rel=RTOL)
    assert strain_factor("permille") * 500 == pytest.approx(0.5, rel=RTOL)
    assert strain_factor(None) == strain_factor("1") == 1.0
    with pytest.raises(ValueError, match="'mm' is not a known strain unit \\('1'"):
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
