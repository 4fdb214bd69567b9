# SPDX-License-Identifier: MIT
"""The one description of the input (src/yarnfort/input/variables.py) against what is
made from it or written by hand about it: the variable tables of inputs/REFERENCE.md,
the --help summary and the effective input the program writes back."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import f90nml

TOP = Path(__file__).resolve().parents[2]
INPUT = TOP / "src" / "yarnfort" / "input"
GENERATE = INPUT / "generate.py"
REFERENCE = TOP / "inputs" / "REFERENCE.md"
sys.path.insert(0, str(INPUT))
from variables import GROUPS  # noqa: E402


def check_reference(path: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, str(GENERATE), "check", str(path)],
                          capture_output=True, text=True, timeout=60)


def test_reference_tables_match_the_description():
    run = check_reference(REFERENCE)
    assert run.returncode == 0, ("inputs/REFERENCE.md and variables.py disagree; run "
                                 "python src/yarnfort/input/generate.py update inputs/REFERENCE.md"
                                 "\n" + run.stdout + run.stderr)


def test_a_changed_default_in_the_reference_is_found(tmp_path):
    text = REFERENCE.read_text()
    row = "| `max_iterations` | integer >= 1 | `50` |"
    assert row in text
    changed = tmp_path / "REFERENCE.md"
    changed.write_text(text.replace(row, row.replace("`50`", "`60`")))
    run = check_reference(changed)
    assert run.returncode == 1 and "`60`" in run.stdout


def test_help_names_every_group_and_variable(run_yarnfort):
    run = run_yarnfort("", "--help")
    assert run.returncode == 0
    words = run.stdout.split()
    for group in GROUPS:
        assert f"&{group.name}" in words
        for var in group.variables:
            assert var.name in words, (group.name, var.name)


def test_echo_has_every_variable_with_its_default(run_yarnfort):
    """A minimal scene: input.nml holds every variable of its groups, at the defaults of
    the description where the scene does not set them; a variable without a default (a
    law parameter) that the scene does not set is left out: no value stands for 'not
    set'."""
    scene = """&material name = 'a', law = 'linear', stiffness = 2.0 /
&nodes xyz = 0 0 0  1 0 0 /
&yarn material = 'a', nodes = 1 2 /
&support name = 'left', nodes = 1 /
&support name = 'right', nodes = 2, fix = 'x', displacement = 0.1 0 0 /
&path time = 0 1, p_disp = 0 1 /
&output vtk_every = 0 /
"""
    run = run_yarnfort(scene)
    assert run.returncode == 0, run.stderr
    echo = f90nml.read(run.folder / "out" / "input.nml")
    set_here = {("material", "name"), ("material", "law"), ("material", "stiffness"),
                ("output", "vtk_every"), ("yarn", "material"), ("support", "name"), ("support", "nodes"),
                ("support", "fix"), ("support", "displacement")}
    for group in GROUPS:
        if group.name not in echo or group.name == "path":
            continue
        values = echo[group.name]
        values = values[0] if isinstance(values, list) else values
        for var in group.variables:
            if var.is_list or (group.name, var.name) in set_here:
                continue
            if var.optional:
                assert var.name not in values, (group.name, var.name)
                continue
            assert var.name in values, (group.name, var.name)
            value = values[var.name]
            default = var.default
            if var.type == "character" and isinstance(default, str):
                assert (value or "") == default, (group.name, var.name)
            elif isinstance(default, list):
                assert list(value) == default, (group.name, var.name)
            else:
                assert value == default, (group.name, var.name)


def test_presets_table_matches_the_description():
    """The preset columns of the *Presets* table of REFERENCE.md are the values that
    variables.py gives each preset (its other columns are measurements)."""
    solver = next(g for g in GROUPS if g.name == "solver")
    described = [v for v in solver.variables if v.presets]
    lines = REFERENCE.read_text().split("### Presets", 1)[1].splitlines()
    header = next(line for line in lines if line.startswith("| preset |"))
    columns = [c.strip().strip("`") for c in header.strip("|").split("|")]
    rows = {}
    for line in lines[lines.index(header) + 2:]:
        if not line.startswith("|"):
            break
        cells = [c.strip().strip("`").strip("'") for c in line.strip("|").split("|")]
        rows[cells[0]] = dict(zip(columns, cells))
    assert {v.name for v in described} <= set(columns)
    for var in described:
        # 'custom' is the table's defaults.
        for preset, value in {**var.presets, "custom": var.default}.items():
            text = rows[preset][var.name]
            assert (float(text) if var.type == "real" else text) == value, \
                (preset, var.name, text, value)
