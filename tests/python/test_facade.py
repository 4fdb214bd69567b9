# SPDX-License-Identifier: MIT
"""Tests of the f2py extension through yarnfort's Python wrappers (force laws, friction
laws, whole scenes), against formulas written independently here."""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

import yarnfort
from yarnfort import YarnfortError
from yarnfort._native import extension as load_extension

TOP = Path(__file__).resolve().parents[2]
#: Relative tolerance of identities between closed forms (a few roundings apart).
IDENTITY = 100 * np.finfo(float).eps
#: Default magnitude of the compared values, which scales the absolute tolerance.
SCALE = 1.0


@pytest.fixture(scope="module", autouse=True)
def extension():
    """The installed extension; fail with the reason when it is missing."""
    try:
        return load_extension()
    except ImportError as error:
        pytest.fail(f"yarnfort is not installed with its extension: {error}")


def close(actual, expected, scale: float = SCALE) -> bool:
    return np.allclose(actual, expected, rtol=IDENTITY, atol=IDENTITY * scale)


def test_linear_force_is_ea_times_strain_when_taut_and_zero_when_slack():
    stiffness = 12.5
    stretch = np.linspace(0.5, 2.0, 31)
    force, dforce, energy = yarnfort.force_law("linear", stretch, stiffness=stiffness)
    taut = stretch > 1.0
    assert close(force, np.where(taut, stiffness * (stretch - 1.0), 0.0), stiffness)
    assert close(dforce, np.where(taut, stiffness, 0.0), stiffness)
    assert close(energy, np.where(taut, 0.5 * stiffness * (stretch - 1.0) ** 2, 0.0),
                 stiffness)
    assert np.all(force[~taut] == 0.0)


def test_neo_hookean_force_and_energy():
    modulus, area = 2.0e9, 3.0e-8
    stretch = np.linspace(0.8, 3.0, 23)
    force, dforce, energy = yarnfort.force_law("neo_hookean", stretch, modulus=modulus,
                                               area=area)
    taut = stretch > 1.0
    scale = area * modulus
    expected = np.where(taut, scale * (stretch - stretch ** -2.0), 0.0)
    assert close(force, expected, scale)
    assert close(dforce, np.where(taut, scale * (1.0 + 2.0 * stretch ** -3.0), 0.0), scale)
    # Integral of the force from 1 to lambda.
    integral = scale * ((stretch ** 2 - 1.0) / 2.0 + 1.0 / stretch - 1.0)
    assert close(energy, np.where(taut, integral, 0.0), scale)


def test_table_law_passes_through_its_rows(tmp_path):
    table = tmp_path / "a_rather_long_folder_name_for_the_measured_table" / "yarn.csv"
    table.parent.mkdir()
    table.write_text("strain,force\n0.0,0.0\n0.1,1.0\n0.2,3.0\n0.3,4.0\n")
    force, dforce, _ = yarnfort.force_law("table", [1.0, 1.1, 1.2, 1.3, 0.9],
                                          table_file=table)
    assert close(force, [0.0, 1.0, 3.0, 4.0, 0.0], 4.0)
    assert np.all(dforce[1:4] > 0.0)


def test_scalar_stretch_gives_scalars_and_shape_is_kept():
    force, _, _ = yarnfort.force_law("linear", 1.5, stiffness=2.0)
    assert np.ndim(force) == 0 and close(force, 1.0)
    force, _, _ = yarnfort.force_law("linear", np.full((2, 3), 1.25), stiffness=4.0)
    assert force.shape == (2, 3) and close(force, 1.0)


def test_empty_input_still_checks_the_law():
    force, _, _ = yarnfort.force_law("linear", [], stiffness=1.0)
    assert force.shape == (0,)
    critical, _, _ = yarnfort.critical_tension("adhesion", [], 1.0, friction_coefficient=0.2,
                                               adhesion=0.1)
    assert critical.shape == (0,)
    with pytest.raises(YarnfortError, match="stiffness"):
        yarnfort.force_law("linear", np.empty((0, 2)), stiffness=0.0)

def test_negative_stiffness_raises_naming_the_value():
    with pytest.raises(YarnfortError, match=r"stiffness -2\b") as info:
        yarnfort.force_law("linear", [1.0, 1.1], stiffness=-2.0)
    assert (info.value.status, info.value.category) == (2, "bad_input")


def test_bad_neo_hookean_area_and_unknown_law_raise():
    with pytest.raises(YarnfortError, match="area 0"):
        yarnfort.force_law("neo_hookean", 1.1, modulus=1.0, area=0.0)
    with pytest.raises(YarnfortError, match="'hookean' is unknown"):
        yarnfort.force_law("hookean", 1.1)
    with pytest.raises(YarnfortError, match="missing.csv"):
        yarnfort.force_law("table", 1.1, table_file="missing.csv")


def test_wrong_keywords_are_a_type_error():
    with pytest.raises(TypeError, match="missing stiffness"):
        yarnfort.force_law("linear", 1.1)
    with pytest.raises(TypeError, match="unexpected modulus"):
        yarnfort.force_law("linear", 1.1, stiffness=1.0, modulus=2.0)


def test_coulomb_critical_tension_is_capstan_exponential():
    mu = 0.3
    tension_min, angle = np.meshgrid([0.0, 0.02, 1.0, 7.5], [0.0, 0.4, np.pi, 12.0])
    critical, d_dtension, d_dangle = yarnfort.critical_tension(
        "coulomb", tension_min, angle, friction_coefficient=mu)
    expected = tension_min * np.exp(mu * angle)
    assert critical.shape == tension_min.shape
    assert close(critical, expected, expected.max())
    assert close(d_dtension, np.exp(mu * angle), np.exp(mu * angle).max())
    assert close(d_dangle, mu * expected, expected.max())


def test_decaying_adhesion_equals_adhesion_when_mu_w_d_reaches_beta():
    mu, beta, w_d, s_d = 0.4, 0.3, 1.0, 2.5
    assert mu * w_d >= beta
    tension_min, angle = np.meshgrid([0.0, 0.1, 0.9, 3.0], [0.0, 0.5, 2.0, 6.0])
    decaying = yarnfort.critical_tension("decaying_adhesion", tension_min, angle,
                                         friction_coefficient=mu, adhesion=beta,
                                         decay_start=w_d, decay_end=s_d)
    adhesion = yarnfort.critical_tension("adhesion", tension_min, angle,
                                         friction_coefficient=mu, adhesion=beta)
    for got, expected in zip(decaying, adhesion):
        assert close(got, expected, np.abs(expected).max())


def test_decaying_adhesion_follows_its_rate_when_adhesion_decays():
    mu, beta, w_d, s_d = 0.1, 0.5, 0.2, 1.0
    assert mu * w_d < beta
    tension_min = np.array([0.0, 0.1, 0.5, 2.0])
    angle = np.linspace(0.0, 4.0, 9)[:, None]
    critical, _, d_dangle = yarnfort.critical_tension(
        "decaying_adhesion", tension_min, angle, friction_coefficient=mu, adhesion=beta,
        decay_start=w_d, decay_end=s_d)
    assert np.all(np.isfinite(critical))
    assert close(critical[0], tension_min)
    assert np.all(np.diff(critical, axis=0) > 0.0)
    # dT_crit/dalpha is the ODE's rate g(T) at T_crit (paper eq. 41).
    rate = np.maximum(beta * np.minimum(1.0, (s_d - critical) / (s_d - w_d)), mu * critical)
    assert close(d_dangle, rate, beta)


def test_negative_friction_coefficient_raises():
    with pytest.raises(YarnfortError, match=r"friction_coefficient \(mu\)") as info:
        yarnfort.critical_tension("coulomb", 1.0, 1.0, friction_coefficient=-0.5)
    value = re.search(r"got (\S+)$", str(info.value))
    assert value is not None and float(value.group(1)) == -0.5


def scene_in(tmp_path: Path, folder: Path, solver: str = "") -> Path:
    """inputs/vnet.nml with its &output folder moved to `folder` and `solver` lines added
    to its &solver group."""
    text = (TOP / "inputs" / "vnet.nml").read_text()
    text, count = re.subn(r"(?m)^(\s*folder\s*=\s*)'[^']*'", rf"\1'{folder}'", text)
    assert count == 1
    text, count = re.subn(r"(?m)^&solver\s*$", "&solver\n" + solver, text)
    assert count == 1
    path = tmp_path / "vnet.nml"
    path.write_text(text)
    return path


def test_run_scene_writes_curve(tmp_path):
    folder = tmp_path / "out"
    run = yarnfort.run_scene(scene_in(tmp_path, folder))
    assert run.folder == folder
    assert (folder / "curve.csv").is_file()
    assert (folder / "input.nml").is_file()
    curve = yarnfort.read_curve(folder)
    assert run.n_steps > 1
    assert len(next(iter(curve.columns.values()))) == run.n_steps


def test_run_scene_bad_input_raises(tmp_path):
    with pytest.raises(YarnfortError, match="cannot open input file") as info:
        yarnfort.run_scene(tmp_path / "missing.nml")
    assert info.value.status == 2
    bad = tmp_path / "bad.nml"
    bad.write_text("&material\n    name = 'yarn'\n    law = 'linear'\n    stiffness = -1.0\n/\n")
    with pytest.raises(YarnfortError, match="^input: ") as info:
        yarnfort.run_scene(bad)
    assert info.value.status == 2


def test_failed_solve_raises_and_keeps_the_converged_steps(tmp_path):
    folder = tmp_path / "out"
    # One Newton iteration cannot reach the default tolerance on a loaded step. The
    # exact tension-only law (slack_stiffness = 0) keeps the unloaded state 0 exactly in
    # equilibrium, so the first step converges and the second fails.
    path = scene_in(tmp_path, folder,
                    "    max_iterations = 1\n    max_step_cuts = 0\n    slack_stiffness = 0.0\n")
    with pytest.raises(YarnfortError, match="^solve: ") as info:
        yarnfort.run_scene(path)
    assert info.value.status == 1
    assert info.value.category == "solve_failed"
    assert info.value.result is not None and info.value.result.folder == folder
    assert info.value.result.outcome == "failed"
    curve = yarnfort.read_curve(folder)
    assert len(curve) == info.value.result.n_steps
