# SPDX-License-Identifier: MIT
"""Units of table files and geometry files: a table in lab units (%, cN, mm of a gauge
length) runs as the same table converted to SI by hand, a geometry file in mm as the
same file in m; tables read in the wrong unit are refused (the bad-input catalogue,
tests/cli/test_cli.py, holds the other refusals)."""
from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np
import pytest

from yarnfort import read_curve

TOP = Path(__file__).resolve().parents[2]
DATA = TOP / "tests" / "data" / "input"
VNET = (TOP / "inputs" / "vnet.nml").read_text()
#: Relative agreement of two runs whose inputs differ by one rounding per value.
ROUND_OFF = 1e-12

#: A yarn's table in SI (strain, N), the knots by hand from the lab table below.
SI_TABLE = "strain,force\n0,0\n0.01,0.08\n0.02,0.2\n0.05,0.6\n0.1,1.5\n0.2,4.0\n"
#: The same table as a tensile tester writes it: elongation in %, force in cN.
LAB_TABLE = ("# tensile test, 500 mm gauge length\nElongation (%),Force (cN)\n"
             "0,0\n1,8\n2,20\n5,60\n10,150\n20,400\n")
#: The same again as an elongation in mm of a 500 mm specimen, force in gf, by hand:
#: e = strain * 500 mm, F / 9.80665e-3 N.
GAUGE_LENGTH = 0.5


def elongation_table() -> str:
    rows = [(0.0, 0.0), (0.01, 0.08), (0.02, 0.2), (0.05, 0.6), (0.1, 1.5), (0.2, 4.0)]
    return "Extension [mm],Load [gf]\n" + "".join(
        f"{strain * 500.0!r},{force / 9.80665e-3!r}\n" for strain, force in rows)


def table_scene(folder: str, extra: str = "") -> str:
    """inputs/vnet.nml with its yarn made of the table 'yarn.csv'."""
    text = VNET.replace("law = 'linear'", "law = 'table'").replace(
        "stiffness = 10.0        ! EA in N", f"table_file = 'yarn.csv' {extra}")
    return text.replace("folder = 'out/vnet'", f"folder = '{folder}'")


def run_table(run_yarnfort, tmp_path: Path, name: str, table: str, extra: str = ""):
    (tmp_path / "yarn.csv").write_text(table)
    run = run_yarnfort(table_scene(name, extra), cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    return read_curve(tmp_path / name)


def same_curve(a, b) -> None:
    """The same columns and rows, every value to round-off relative to its column (not
    the final residual, at the noise level, nor the wall time)."""
    assert a.names == b.names
    for column in a.names:
        if column in ("residual", "wall_time"):
            continue
        x, y = np.asarray(a[column]), np.asarray(b[column])
        assert x.shape == y.shape, column
        scale = max(np.max(np.abs(x)), np.finfo(float).tiny)
        assert np.all(np.abs(x - y) <= ROUND_OFF * scale), column


def test_table_in_percent_and_cn_runs_as_the_si_table(run_yarnfort, tmp_path):
    si = run_table(run_yarnfort, tmp_path, "si", SI_TABLE)
    lab = run_table(run_yarnfort, tmp_path, "lab", LAB_TABLE)
    same_curve(lab, si)
    # The load is carried: the curve is not trivially equal.
    assert np.max(np.abs(si["ends_ry"])) > 0.1


def test_units_stated_in_material_run_as_the_si_table(run_yarnfort, tmp_path):
    si = run_table(run_yarnfort, tmp_path, "si", SI_TABLE)
    bare = "\n".join(line for line in LAB_TABLE.splitlines() if not line[0].isalpha())
    lab = run_table(run_yarnfort, tmp_path, "lab", bare + "\n",
                    "strain_unit = '%', force_unit = 'cN'")
    same_curve(lab, si)


def test_elongation_over_gauge_length_runs_as_the_si_table(run_yarnfort, tmp_path):
    si = run_table(run_yarnfort, tmp_path, "si", SI_TABLE)
    lab = run_table(run_yarnfort, tmp_path, "lab", elongation_table(),
                    f"gauge_length = {GAUGE_LENGTH}")
    same_curve(lab, si)
    echo = (tmp_path / "lab" / "input.nml").read_text()
    assert "gauge_length = 0.5" in echo


@pytest.mark.parametrize("table, words", [
    ("Elongation,Force\n0,0\n5,12.3\n10,31\n25,80\n",
     ["yarn.csv', line 5, column 1", "strain 25.0", "exceeds 10.0"]),
    ("Elongation (%),Force (N/tex)\n0,0\n5,12.3\n",
     ["yarn.csv', line 1, column 2", "'N/tex' is not a known force unit"]),
])
def test_misread_table_refused_nothing_written(run_yarnfort, tmp_path, table, words):
    (tmp_path / "yarn.csv").write_text(table)
    run = run_yarnfort(table_scene("out"), cwd=tmp_path)
    assert run.returncode == 2, run.stderr
    for word in words:
        assert word in run.stderr, run.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["yarn.csv"]


@pytest.mark.parametrize("notes", [
    # Notes of settings (values with units), not column names.
    "# tested 2026-03-02, gauge 500 mm, pretension 0.5 cN\n",
    # Column names with the units the columns are read in (strain 1, N).
    "# strain (-), force (N)\n",
    "Strain (1),Force [N]\nspecimen 1\n",
])
def test_notes_that_agree_with_the_units_read_run_as_the_si_table(run_yarnfort, tmp_path,
                                                                  notes):
    si = run_table(run_yarnfort, tmp_path, "si", SI_TABLE)
    noted = run_table(run_yarnfort, tmp_path, "noted", notes + SI_TABLE)
    same_curve(noted, si)


@pytest.mark.parametrize("table, extra", [
    # The units in a comment, also stated in &material (then the comment is a note).
    ("# Elongation (%),Force (cN)\n" + LAB_TABLE.split("Force (cN)\n")[1],
     "strain_unit = '%', force_unit = 'cN'"),
    # A units line below the names: the last header line states them.
    ("Elongation,Force\n%,cN\n" + LAB_TABLE.split("Force (cN)\n")[1], ""),
])
def test_units_stated_with_a_note_run_as_the_si_table(run_yarnfort, tmp_path, table,
                                                       extra):
    si = run_table(run_yarnfort, tmp_path, "si", SI_TABLE)
    lab = run_table(run_yarnfort, tmp_path, "lab", table, extra)
    same_curve(lab, si)


@pytest.mark.parametrize("table, extra, words", [
    # numpy.savetxt(header=...) writes the header as a comment: 8 % would be a strain of 8.
    ("# Elongation (%),Force (cN)\n0,0\n1,8\n2,20\n5,60\n8,110\n", "",
     ["yarn.csv', line 1, column 1 ('Elongation (%)'): states the unit '%'",
      "it would be read in '1'", "strain_unit = '%'"]),
    # The strain's unit given in &material, the force's only in the comment.
    ("# Elongation (%),Force (cN)\n0,0\n1,8\n2,20\n5,60\n8,110\n", "strain_unit = '%'",
     ["yarn.csv', line 1, column 2 ('Force (cN)'): states the unit 'cN'",
      "it would be read in 'N'", "force_unit = 'cN'"]),
    # A note line between the header with units and the rows.
    ("Elongation (%),Force (cN)\nspecimen 1\n0,0\n1,8\n2,20\n", "",
     ["yarn.csv', line 1, column 1 ('Elongation (%)'): states the unit '%'"]),
    ("Load,Elongation\n0,0\n0.08,0.01\n0.2,0.02\n", "",
     ["yarn.csv', line 1, column 1 ('Load'): names a force", "swap the columns"]),
    ("Strain,Extension\n0,0\n0.01,0.08\n", "",
     ["yarn.csv', line 1, column 2 ('Extension'): names a strain", "swap the columns"]),
    ("Strain,Force\n0,0\n0.01,0.08\n", "", None),
    ("Elongation (%),Tenacity\n0,0\n1,8\n", "",
     ["yarn.csv', line 1, column 2 ('Tenacity'): names a quantity that is not a force"]),
    # A header with units but not two comma-separated fields: its units were not read.
    ("Elongation (%),Force (cN),\n0,0\n1,8\n2,20\n", "",
     ["yarn.csv', line 1: the header states the unit '%' but is not two comma-separated"]),
    ("Elongation (%);Force (cN)\n0,0\n1,8\n2,20\n", "",
     ["yarn.csv', line 1: the header states the unit '%' but is not two comma-separated"]),
    ("Elongation (%)\tForce (cN)\n0,0\n1,8\n2,20\n", "",
     ["yarn.csv', line 1: the header states the unit '%' but is not two comma-separated"]),
    (elongation_table(), "gauge_length = 500",
     ["gauge_length = 500.0 m is longer than any tensile specimen", "(500 mm is 0.5)"]),
])
def test_table_read_otherwise_than_meant_refused(run_yarnfort, tmp_path, table, extra,
                                                 words):
    (tmp_path / "yarn.csv").write_text(table)
    run = run_yarnfort(table_scene("out", extra), cwd=tmp_path)
    if words is None:  # the control: the same scene with plain names runs
        assert run.returncode == 0, run.stderr
        return
    assert run.returncode == 2, run.stderr
    for word in words:
        assert word in run.stderr, run.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["yarn.csv"]


def test_largest_gauge_length_runs(run_yarnfort, tmp_path):
    """5 m, the limit, is read: the table's strains are the elongations over it."""
    table = "Extension (m),Load (N)\n0,0\n0.05,0.08\n0.1,0.2\n0.25,0.6\n0.5,1.5\n1,4\n"
    si = run_table(run_yarnfort, tmp_path, "si", SI_TABLE)
    long = run_table(run_yarnfort, tmp_path, "long", table, "gauge_length = 5.0")
    same_curve(long, si)


def test_geometry_in_mm_runs_as_the_geometry_in_m(run_yarnfort, tmp_path):
    for name in ("grid.geo", "grid_mm.geo", "valid_geometry.nml"):
        shutil.copy(DATA / name, tmp_path)
    scene = (tmp_path / "valid_geometry.nml").read_text()
    metres = run_yarnfort(scene.replace("out/two_yarns", "m"), cwd=tmp_path)
    assert metres.returncode == 0, metres.stderr
    millimetres = run_yarnfort(scene.replace("out/two_yarns", "mm").replace(
        "'grid.geo'", "'grid_mm.geo'"), cwd=tmp_path)
    assert millimetres.returncode == 0, millimetres.stderr
    same_curve(read_curve(tmp_path / "mm"), read_curve(tmp_path / "m"))
    # The unit given in &geometry instead of the file.
    (tmp_path / "plain_mm.geo").write_text(
        "\n".join(line for line in (DATA / "grid_mm.geo").read_text().splitlines()
                  if not line.startswith("unit")) + "\n")
    stated = run_yarnfort(scene.replace("out/two_yarns", "stated").replace(
        "'grid.geo'", "'plain_mm.geo', unit = 'mm'"), cwd=tmp_path)
    assert stated.returncode == 0, stated.stderr
    same_curve(read_curve(tmp_path / "stated"), read_curve(tmp_path / "m"))
