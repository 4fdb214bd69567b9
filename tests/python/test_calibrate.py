# SPDX-License-Identifier: MIT
"""Tests of yarnfort.calibrate: recover the capstan friction parameters from a SYNTHETIC
curve made by the solver with known values plus seeded noise."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from yarnfort.calibrate import (calibrate, plot_fit, read_measured, simulated_force,
                                write_synthetic_curve)
from yarnfort.results import Curve
from yarnfort import program_path

TOP = Path(__file__).resolve().parents[2]
CAPSTAN = TOP / "inputs" / "capstan.nml"
MU = "contact[0].friction_coefficient"
BETA = "contact[0].adhesion"
TRUTH = {MU: 0.3, BETA: 0.05}
START = {MU: (0.2, 0.01, 1.0), BETA: (0.1, 0.0, 0.5)}
#: Uniform continuation steps: 20 loading and 20 unloading points.
COARSE = {"solver.max_step": 0.05, "solver.initial_step": 0.05}
#: Relative noise on the synthetic force, and the accepted relative error of a fit.
NOISE = 0.01
RELATIVE_ERROR = 0.03
#: Accepted error in standard uncertainties.
COVERAGE = 3.0


@pytest.fixture(scope="module")
def synthetic(tmp_path_factory) -> Path:
    try:
        program_path()
    except FileNotFoundError as error:
        pytest.fail(str(error))
    path = tmp_path_factory.mktemp("calibrate") / "synthetic.csv"
    return write_synthetic_curve(CAPSTAN, {**TRUTH, **COARSE}, path, support="pull",
                                 force_scale=-1.0, noise=NOISE, seed=1)


@pytest.fixture(scope="module")
def result(synthetic):
    return calibrate(CAPSTAN, synthetic, START, support="pull", component="y",
                     force_scale=-1.0, fixed=COARSE)


def test_synthetic_file_is_labelled_and_has_both_branches(synthetic):
    assert synthetic.read_text().startswith("# SYNTHETIC")
    strain, force, branch = read_measured(synthetic)
    assert strain.size == 40 and set(branch) == {1, -1}
    assert np.all(force[branch == 1] >= -NOISE)


def test_fit_recovers_the_true_parameters(result):
    truth = np.array([TRUTH[name] for name in result.names])
    error = result.values - truth
    print("relative errors:", dict(zip(result.names, error / truth)),
          "in uncertainties:", dict(zip(result.names, error / result.uncertainty)))
    assert result.success
    assert np.all(result.uncertainty > 0)
    assert np.all(np.abs(error) <= COVERAGE * result.uncertainty)
    assert np.all(np.abs(error) <= RELATIVE_ERROR * truth)
    # The residual is the noise: sigma about 1 % of the typical force.
    assert result.sigma < 2 * NOISE * np.max(np.abs(result.force))


def test_branches_are_matched_separately():
    # A loop: loading 0 -> 2 (force = x), unloading 2 -> 0 (force = x / 2).
    x = np.array([0.0, 1.0, 2.0, 1.0, 0.0])
    force = np.array([0.0, 1.0, 2.0, 0.5, 0.0])
    curve = Curve({"p_disp": x, "direction": np.array([0, 1, 1, -1, -1]),
                   "s_rx": force, "s_ry": 0 * x, "s_rz": 0 * x})
    at = simulated_force(curve, np.array([1.5, 1.5, 0.5]), np.array([1, -1, -1]),
                         support="s", component=0)
    np.testing.assert_allclose(at, [1.5, 1.25, 0.25])


def test_branch_column_may_be_a_sign_or_missing(tmp_path):
    signed = tmp_path / "signed.csv"
    signed.write_text("strain,force,sign\n0,0,1\n1,1,1\n0.5,0.2,-1\n")
    assert list(read_measured(signed)[2]) == [1, 1, -1]
    bare = tmp_path / "bare.csv"
    bare.write_text("strain,force\n0,0\n1,1\n2,2\n1,0.5\n")
    assert list(read_measured(bare)[2]) == [1, 1, 1, -1]


def test_plot_fit_writes_an_image(result, tmp_path):
    path = plot_fit(result, tmp_path / "fit.png")
    assert path.stat().st_size > 1000
