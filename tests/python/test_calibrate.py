# SPDX-License-Identifier: MIT
"""Tests of yarnfort.calibrate: recover the capstan friction parameters from a SYNTHETIC
curve made by the solver with known values plus seeded noise."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from yarnfort.calibrate import (CONDITION_LIMIT, IdentifiabilityWarning, _uncertainty,
                                calibrate, plot_fit, read_measured, simulated_force,
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
    data = read_measured(synthetic)
    strain, force, branch = data.strain, data.force, data.branch
    assert strain.size == 40 and set(branch) == {1, -1}
    assert np.all(force[branch == 1] >= -NOISE)
    assert data.n_branches == 2 and data.signs == [1, -1]


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
    assert list(read_measured(signed).branch) == [1, 1, -1]
    bare = tmp_path / "bare.csv"
    bare.write_text("strain,force\n0,0\n1,1\n2,2\n1,0.5\n")
    assert list(read_measured(bare).branch) == [1, 1, 1, -1]


def test_plot_fit_writes_an_image(result, tmp_path):
    path = plot_fit(result, tmp_path / "fit.png")
    assert path.stat().st_size > 1000


def test_units_in_headers_give_si_values(tmp_path):
    lab = tmp_path / "lab.csv"
    lab.write_text("strain (%),force (cN)\n0,0\n5,250\n10,400\n")
    data = read_measured(lab)
    np.testing.assert_allclose(data.strain, [0.0, 0.05, 0.10], rtol=1e-15)
    np.testing.assert_allclose(data.force, [0.0, 2.5, 4.0], rtol=1e-15)
    assert (data.strain_unit, data.force_unit, data.per_width) == ("%", "cN", False)
    per_width = tmp_path / "per_width.csv"
    per_width.write_text("strain,force\n0.1,2\n")
    data = read_measured(per_width, strain_unit="permille", force_unit="N/mm")
    assert data.per_width and data.strain[0] == pytest.approx(1e-4, rel=1e-15)
    assert data.force[0] == pytest.approx(2000.0, rel=1e-15)
    with pytest.raises(ValueError, match="the force column says 'cN', the argument 'N'"):
        read_measured(lab, force_unit="N")
    with pytest.raises(ValueError, match="force unit 'kp'"):
        read_measured(per_width, force_unit="kp")


def test_cycles_are_split_into_monotone_branches(tmp_path):
    # Two cycles 0 -> 2 -> 0 without a branch column, then with a cycle column.
    bare = tmp_path / "bare.csv"
    bare.write_text("strain,force\n1,1\n2,2\n1,0.5\n0,0\n1,1.2\n2,2.1\n1,0.6\n0,0.1\n")
    data = read_measured(bare)
    assert list(data.segment) == [0, 0, 1, 1, 2, 2, 3, 3]
    assert data.signs == [1, -1, 1, -1]
    cycles = tmp_path / "cycles.csv"
    cycles.write_text("strain,force,branch,cycle\n1,1,loading,1\n2,2,loading,1\n"
                      "1,1.2,loading,2\n2,2.1,loading,2\n")
    assert list(read_measured(cycles).segment) == [0, 0, 1, 1]


def _two_cycle_curve() -> Curve:
    """Two cycles 0 -> 2 -> 0 with a hold at the top of the first: force = x on the
    first loading, from the turning point (2, 2) to x / 2 on its unloading, x + 1 on
    the second loading, from (2, 3) to x - 1 after."""
    x = np.array([0.0, 1.0, 2.0, 2.0, 1.0, 0.0, 1.0, 2.0, 1.0, 0.0])
    force = np.array([0.0, 1.0, 2.0, 2.0, 0.5, 0.0, 2.0, 3.0, 0.0, -1.0])
    direction = np.array([0, 1, 1, 0, -1, -1, 1, 1, -1, -1])
    return Curve({"p_disp": x, "direction": direction, "s_rx": force, "s_ry": 0 * x,
                  "s_rz": 0 * x})


def test_several_cycles_are_matched_cycle_by_cycle():
    curve = _two_cycle_curve()
    strain = np.array([1.5, 1.5, 1.5, 1.5, 0.5])
    branch = np.array([1, -1, 1, -1, -1])
    segment = np.array([0, 1, 2, 3, 3])
    at = simulated_force(curve, strain, branch, support="s", component=0, segment=segment)
    # On each branch's polyline (the docstring): 1.5; halfway from (1, 0.5) to the
    # turning point (2, 2) after the hold, 1.25; 2.5; halfway from (1, 0) to (2, 3), 1.5,
    # and halfway from (0, -1) to (1, 0), -0.5.
    np.testing.assert_allclose(at, [1.5, 1.25, 2.5, 1.5, -0.5])
    with pytest.raises(ValueError, match="the data have 5 loading/unloading branches, the"
                       " scene's path gives 4: give the &path as many load cycles"):
        simulated_force(curve, np.ones(5), np.array([1, -1, 1, -1, 1]), support="s",
                        component=0, segment=np.arange(5))
    with pytest.raises(ValueError, match="branch 1 of the data is unloading"):
        simulated_force(curve, np.ones(1), np.array([-1]), support="s", component=0)


def test_uncertainty_of_a_known_jacobian():
    # J = diag(2, 4) on the first two rows: (J^T J)^-1 = diag(1/4, 1/16), no correlation.
    jac = np.array([[2.0, 0.0], [0.0, 4.0], [0.0, 0.0]])
    covariance, uncertainty, condition = _uncertainty(jac, 0.5, CONDITION_LIMIT)
    np.testing.assert_allclose(covariance, np.diag([0.5 / 4, 0.5 / 16]), atol=1e-17)
    np.testing.assert_allclose(uncertainty, np.sqrt([0.5 / 4, 0.5 / 16]), rtol=1e-15)
    assert condition == pytest.approx(1.0, rel=1e-15)  # unit columns are orthonormal
    # Two columns along one direction (the second scaled): no parameter is determined.
    collinear = np.array([[1.0, 3.0], [2.0, 6.0], [1.0, 3.0]])
    _, uncertainty, condition = _uncertainty(collinear, 0.5, CONDITION_LIMIT)
    assert condition > CONDITION_LIMIT and np.all(np.isinf(uncertainty))
    # A parameter without effect: a zero column.
    _, uncertainty, _ = _uncertainty(np.array([[1.0, 0.0], [1.0, 0.0]]), 0.5,
                                     CONDITION_LIMIT)
    assert np.isfinite(uncertainty[0]) and np.isinf(uncertainty[1])
