# SPDX-License-Identifier: MIT
"""&solver preset: the documented values, explicit values override, the echo round-trips.

Each case runs one load step of a V-net (``&control max_steps = 1``) and reads the
effective input ``input.nml`` that the run writes (``check_only`` writes nothing).
"""
from __future__ import annotations

import re
from pathlib import Path

import f90nml
import pytest

TOP = Path(__file__).resolve().parents[2]
REFERENCE = TOP / "inputs" / "REFERENCE.md"

#: The presets as documented in inputs/REFERENCE.md (section Presets).
PRESETS = {
    "balanced": dict(initial_step=0.05, max_step=0.05, residual_tolerance=1e-9,
                     scheme="monolithic"),
    "accurate": dict(initial_step=0.01, max_step=0.01, residual_tolerance=1e-11,
                     scheme="monolithic"),
}
#: The individual defaults (preset 'custom', or none given).
DEFAULTS = dict(initial_step=0.1, max_step=0.25, residual_tolerance=1e-10,
                scheme="monolithic")
#: Variables no preset touches, with their defaults.
UNTOUCHED = dict(friction_tolerance=1e-9, min_step=1e-6, step_growth=1.5,
                 linear_solver="auto", max_iterations=50)

VNET = """\
&control
    title = 'V-net, one step'
    max_steps = 1
/
&material name = 'yarn', law = 'linear', stiffness = 10.0 /
&nodes xyz = -1.0, 0.0, 0.0,  0.0, -0.2, 0.0,  1.0, 0.0, 0.0 /
&yarn material = 'yarn', nodes = 1, 2, 3 /
&support name = 'ends', nodes = 1, 3 /
&support name = 'mid_plane', nodes = 2, fix = 'z' /
&load nodes = 2, force = 0.0, -0.5, 0.0 /
&path time = 0.0, 1.0, p_force = 0.0, 1.0 /
&output folder = 'out', vtk_every = 0, progress = .false. /
"""


def effective_solver(run_yarnfort, solver: str, cwd: Path | None = None) -> f90nml.Namelist:
    """Run one step with this &solver body; the &solver group of the echoed input."""
    run = run_yarnfort(VNET + f"&solver\n{solver}\n/\n", cwd=cwd)
    assert run.returncode == 0, run.stderr
    return f90nml.read(run.folder / "out" / "input.nml")["solver"]


def assert_values(solver: f90nml.Namelist, expected: dict[str, object]) -> None:
    for name, value in expected.items():
        if isinstance(value, float):
            assert solver[name] == pytest.approx(value, rel=1e-15), name
        else:
            assert solver[name] == value, name


@pytest.mark.parametrize("name", list(PRESETS))
def test_preset_sets_its_values(run_yarnfort, name):
    solver = effective_solver(run_yarnfort, f"preset = '{name.upper()}'")  # any case
    assert solver["preset"] == name
    assert_values(solver, PRESETS[name])
    assert_values(solver, UNTOUCHED)


@pytest.mark.parametrize("body", ["", "preset = 'custom'"])
def test_custom_or_no_preset_keeps_the_defaults(run_yarnfort, body):
    solver = effective_solver(run_yarnfort, body)
    assert solver["preset"] == "custom"
    assert_values(solver, DEFAULTS | UNTOUCHED)


def test_explicit_values_override_the_preset(run_yarnfort):
    solver = effective_solver(run_yarnfort, "max_step = 0.1, preset = 'accurate',"
                              " scheme = 'staggered', friction_tolerance = 1e-6")
    assert solver["preset"] == "accurate"
    assert_values(solver, dict(max_step=0.1, scheme="staggered", friction_tolerance=1e-6,
                               initial_step=0.01, residual_tolerance=1e-11))


def test_explicit_value_equal_to_the_default_still_overrides(run_yarnfort):
    """Set is set: a value equal to the plain default is not mistaken for 'unset'."""
    solver = effective_solver(run_yarnfort, "preset = 'balanced', residual_tolerance = 1e-10,"
                              " max_step = 0.25, initial_step = 0.1")
    assert_values(solver, dict(residual_tolerance=1e-10, max_step=0.25, initial_step=0.1))


def test_echo_reads_back_the_same(run_yarnfort, tmp_path):
    """The echo gives the preset and every effective value; read again, it is the same."""
    first = effective_solver(run_yarnfort, "preset = 'balanced', max_step = 0.02")
    echoed = (tmp_path / "out" / "input.nml").read_text()
    again = tmp_path / "again"
    again.mkdir()
    run = run_yarnfort(echoed, cwd=again)
    assert run.returncode == 0, run.stderr
    second = f90nml.read(again / "out" / "input.nml")["solver"]
    assert dict(second) == dict(first)


def test_unknown_preset_is_rejected(run_yarnfort):
    run = run_yarnfort(VNET.replace("max_steps = 1", "check_only = .true.")
                       + "&solver preset = 'acurate' /\n")
    assert run.returncode == 2
    assert ("&solver: preset = 'acurate' is unknown (use custom, balanced, accurate);"
            " did you mean 'accurate'?") in run.stderr


def test_reference_documents_the_same_presets():
    """The table of REFERENCE.md's Presets section lists exactly these values (and the
    plain defaults as 'custom')."""
    text = REFERENCE.read_text()
    section = text[text.index("### Presets"):]
    rows = re.findall(r"^\| `'(\w+)'` \| ([^|]+) \| ([^|]+) \| ([^|]+) \| `'(\w+)'` \|",
                      section, flags=re.M)
    documented = {name: dict(initial_step=float(step), max_step=float(step2),
                             residual_tolerance=float(tol), scheme=scheme)
                  for name, step, step2, tol, scheme in rows}
    assert documented == PRESETS | {"custom": DEFAULTS}
