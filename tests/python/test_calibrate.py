# SPDX-License-Identifier: MIT
"""Tests of yarnfort.calibrate: recover the capstan friction parameters from a SYNTHETIC
curve made by the solver with known values plus seeded noise."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from yarnfort.calibrate import (CONDITION_LIMIT, IdentifiabilityWarning,
                                _central_jacobian, _mismatch, _problems, _uncertainty,
                                calibrate, plot_fit, read_measured, simulated_force,
                                write_synthetic_curve)
from yarnfort.results import Curve
from yarnfort import LoadPath, Scene, program_path

TOP = Path(__file__).resolve().parents[2]
CAPSTAN = TOP / "inputs" / "capstan.nml"
BELT = TOP / "inputs" / "belt.nml"
MU = "contact[0].friction_coefficient"
BETA = "contact[0].adhesion"
TRUTH = {MU: 0.3, BETA: 0.05}
START = {MU: (0.2, 0.01, 1.0), BETA: (0.1, 0.0, 0.5)}
WD, SD = "contact[0].decay_start", "contact[0].decay_end"
TRUTH_DECAY = {WD: 0.1, SD: 0.4}
#: A knot of the belt's gap-factor table (0.8 in inputs/belt.nml).
GAP = "fabric.gap_factor[1]"
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


@pytest.mark.parametrize("row, cells", [
    ("0,5,12,3", 4),      # decimal commas: strain 0.5 and force 12.3 are four cells
    ("1,1,234.5", 3),     # a thousands separator: 1,234.5 cN
])
def test_rows_with_more_cells_than_the_header_are_refused(tmp_path, row, cells):
    """Read under the header, '0,5,12,3' was strain 0 and force 5 (the rest dropped)."""
    lab = tmp_path / "lab.csv"
    lab.write_text(f"strain (%),force (cN)\n0,0\n{row}\n")
    with pytest.raises(ValueError, match=f"lab.csv, line 3: {cells} cells .* but the header "
                       "names 2 columns"):
        read_measured(lab)
    # Empty trailing cells (a spreadsheet's export) are no values.
    lab.write_text("strain (%),force (cN),\n0,0,\n5,250,,\n")
    np.testing.assert_allclose(read_measured(lab).force, [0.0, 2.5], rtol=1e-15)


def test_units_only_in_a_comment_are_refused(tmp_path):
    """'# strain (%),force (cN)' above 'strain,force': read in 1 and N before."""
    lab = tmp_path / "lab.csv"
    lab.write_text("# strain (%),force (cN)\nstrain,force\n0,0\n5,250\n")
    with pytest.raises(ValueError, match="lab.csv, line 1: the comment names the strain "
                       "column with the unit '%', but the header \\(line 2\\) gives none"):
        read_measured(lab)
    with pytest.raises(ValueError, match="the comment names the force column with the "
                       "unit 'cN'"):
        read_measured(lab, strain_unit="%")
    data = read_measured(lab, strain_unit="%", force_unit="cN")
    np.testing.assert_allclose(data.force, [0.0, 2.5], rtol=1e-15)
    # Comments that agree with the units read, or are notes, change nothing.
    lab.write_text("# strain (-), force (N)\n# sample 3, 20 mm wide\nstrain,force\n0,0\n"
                   "0.05,2.5\n")
    np.testing.assert_allclose(read_measured(lab).force, [0.0, 2.5], rtol=1e-15)


def test_a_column_named_twice_is_refused(tmp_path):
    """'force (N)' and 'force (cN)': the last was read, the first dropped."""
    lab = tmp_path / "lab.csv"
    lab.write_text("strain (%),force (N),force (cN)\n0,0,0\n5,2.5,250\n")
    with pytest.raises(ValueError, match="names the column 'force' 2 times"):
        read_measured(lab)


def test_a_byte_order_mark_is_not_part_of_the_first_name(tmp_path):
    lab = tmp_path / "lab.csv"
    lab.write_bytes(b"\xef\xbb\xbfstrain (%),force (cN)\r\n0,0\r\n5,250\r\n")
    data = read_measured(lab)
    np.testing.assert_allclose(data.strain, [0.0, 0.05], rtol=1e-15)
    np.testing.assert_allclose(data.force, [0.0, 2.5], rtol=1e-15)


def test_data_beyond_the_path_are_refused(synthetic, tmp_path):
    """The synthetic curve's strains times 10 (a column in permille read as 1/100, say)
    lie beyond the capstan path's p_disp 0..1: refused before the fit, not compared with
    the end values of the branches."""
    lines = synthetic.read_text().splitlines()
    header = next(k for k, line in enumerate(lines) if not line.startswith("#"))
    scaled = lines[:header + 1] + [
        ",".join([repr(10 * float(line.split(",")[0]))] + line.split(",")[1:])
        for line in lines[header + 1:]]
    wide = tmp_path / "wide.csv"
    wide.write_text("\n".join(scaled) + "\n")
    with pytest.raises(ValueError, match="branch 1 of the data spans strain .* to 10 \\(1\\), "
                       "the scene's path 0 to 1: points beyond"):
        calibrate(CAPSTAN, wide, START, support="pull", component="y", force_scale=-1.0,
                  fixed=COARSE, max_nfev=1)


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


def test_problems_name_what_is_not_identifiable():
    names = ("contact[0].friction_coefficient", "contact[0].adhesion")
    correlation = np.array([[1.0, -0.999], [-0.999, 1.0]])
    found = _problems(names, np.array([0.4, 0.01]), np.array([0.01, 0.02]), correlation,
                      2 * CONDITION_LIMIT, CONDITION_LIMIT, np.array([0, 1]))
    assert any("contact[0].adhesion = 0.01 has an uncertainty 0.02 larger than its value"
               in text for text in found)
    assert any("contact[0].adhesion = 0.01 is at its upper bound" in text for text in found)
    assert any("near-singular" in text and "(-0.9990)" in text for text in found)
    assert not any(text.startswith("contact[0].friction_coefficient") for text in found)


def test_decaying_adhesion_fitted_over_two_cycles_in_lab_units(tmp_path):
    # A Scene (not a file), two load cycles, the data in % and cN: fit w_d and s_d.
    scene = Scene.read(CAPSTAN)
    contact = scene.contacts[0]
    contact.law, contact.adhesion = "decaying_adhesion", 0.2
    contact.decay_start, contact.decay_end = TRUTH_DECAY[WD], TRUTH_DECAY[SD]
    scene.path = LoadPath(time=[0, 1, 2, 3, 4], p_disp=[0, 1, 0, 1, 0])
    scene.solver.update({"max_step": 0.1, "initial_step": 0.1})
    # Strain = pull / yarn length: 0.3 m over about 5 m.
    options = dict(support="pull", force_scale=-1.0, x_scale=0.06)
    csv = write_synthetic_curve(scene, {}, tmp_path / "lab.csv", strain_unit="%",
                                force_unit="cN", noise=NOISE, seed=2, **options)
    header = [line for line in csv.read_text().splitlines() if not line.startswith("#")][0]
    assert header == "strain (%),force (cN),branch"
    fit = calibrate(scene, csv, {WD: (0.2, 0.0, 0.25), SD: (0.3, 0.26, 0.8)},
                    errors="relative", **options)
    truth = np.array([TRUTH_DECAY[name] for name in fit.names])
    error = fit.values - truth
    print(fit.summary())
    assert fit.measured.n_branches == 4 and fit.measured.signs == [1, -1, 1, -1]
    assert np.all(np.abs(error) <= COVERAGE * fit.uncertainty)
    assert np.all(np.abs(error) <= 0.1 * truth)
    assert not fit.problems
    # Forces in the data's unit: the fitted curve is within a few % of the cN values
    # (where the yarn has tension: it goes slack at the end of each release).
    assert fit.force_unit == "cN" and "cN" in fit.summary()
    loaded = fit.force != 0
    assert np.median(np.abs(fit.fitted_force[loaded] / fit.force[loaded] - 1)) < 2 * NOISE
    # sigma is the relative error of the points: about the noise.
    assert 0.5 * NOISE < fit.sigma < 2 * NOISE


def test_a_gap_factor_knot_is_fitted_on_the_belt(tmp_path, monkeypatch):
    monkeypatch.chdir(TOP)  # the belt's tables are relative to the repository root
    coarse = {"solver.max_step": 0.1}
    csv = write_synthetic_curve(BELT, {GAP: 0.8, **coarse}, tmp_path / "belt.csv",
                                strain_unit="%", force_unit="N/mm", noise=NOISE, seed=4)
    fit = calibrate(BELT, csv, {GAP: (0.95, 0.3, 1.0)}, errors="relative", fixed=coarse)
    print(fit.summary())
    assert fit.measured.per_width and fit.force_unit == "N/mm"
    assert abs(fit.values[0] - 0.8) <= COVERAGE * fit.uncertainty[0]
    assert abs(fit.values[0] - 0.8) <= 0.05 * 0.8


def test_a_parameter_without_effect_is_reported(synthetic):
    # The pegs' stiffness: both ends of every peg are held, so the curve ignores it.
    with pytest.warns(IdentifiabilityWarning, match="material\\[1\\].stiffness: the data "
                      "do not determine it"):
        fit = calibrate(CAPSTAN, synthetic, {MU: (0.25, 0.01, 1.0),
                                             "material[1].stiffness": (10.0, 5.0, 20.0)},
                        support="pull", force_scale=-1.0, fixed={**COARSE, BETA: 0.05},
                        max_nfev=3)  # the verdict needs a Jacobian, not a converged fit
    assert np.isinf(fit.uncertainty[1]) and np.isfinite(fit.uncertainty[0])
    assert "NOT IDENTIFIABLE" in fit.summary()


def test_force_per_sample_against_force_per_width_needs_the_width(tmp_path, monkeypatch):
    monkeypatch.chdir(TOP)
    csv = tmp_path / "sample.csv"
    csv.write_text("strain (%),force (N)\n1,2\n2,4\n3,6\n")
    with pytest.raises(ValueError, match="the model gives a force per width, the data a "
                       "force \\(N\\): give the sample's width"):
        calibrate(BELT, csv, {GAP: (0.9, 0.3, 1.0)})
    with pytest.raises(ValueError, match="errors 'poisson'"):
        calibrate(BELT, csv, {GAP: (0.9, 0.3, 1.0)}, width=0.01, errors="poisson")


def test_the_derivative_check_differences_and_compares_columns():
    # A quadratic residual: central differences are exact for it, one-sided ones at a
    # bound are off by the step (d/dz of z^2 at 1 from [1 - h, 1]: 2 - h).
    a = np.array([[1.0, 2.0], [3.0, -1.0], [0.5, 0.0]])

    def residual(z):
        return a @ z + np.array([0.0, 0.0, z[1] ** 2])

    step = 0.01
    inside = _central_jacobian(residual, np.array([0.3, 0.6]), step)
    np.testing.assert_allclose(inside, a + [[0, 0], [0, 0], [0, 1.2]], rtol=1e-12,
                               atol=1e-12)
    at_bound = _central_jacobian(residual, np.array([0.3, 1.0]), step)
    assert at_bound[2, 1] == pytest.approx(2.0 - step, rel=1e-9)
    # Equal columns agree; a column against its negative differs by 2 (relative).
    np.testing.assert_allclose(_mismatch(a, a), [0.0, 0.0])
    np.testing.assert_allclose(_mismatch(a, a * [1.0, -1.0]), [0.0, 2.0])
    assert _mismatch(np.zeros((2, 1)), np.zeros((2, 1)))[0] == 0.0


def test_a_sample_width_in_mm_given_as_metres_is_refused(tmp_path, monkeypatch):
    from yarnfort.calibrate import sample_width

    # By hand: 50 mm = 0.05 m, 5 cm = 0.05 m, 2 in = 2 x 0.0254 m.
    assert sample_width("50 mm") == pytest.approx(0.05, rel=1e-15)
    assert sample_width("5cm") == pytest.approx(0.05, rel=1e-15)
    assert sample_width("2 in") == pytest.approx(0.0508, rel=1e-15)
    assert sample_width(0.05) == 0.05 and sample_width(None) is None
    with pytest.raises(ValueError, match=r"width = 50: a sample 50 m wide\? .*50 mm is 0.05"):
        sample_width(50)
    for bad in (0.0, -0.05, float("nan"), True, "50"):
        with pytest.raises(ValueError, match="width"):
            sample_width(bad)
    # A strip of 50 mm given as width=50 would scale the model's force 1000 times.
    monkeypatch.chdir(TOP)
    csv = tmp_path / "sample.csv"
    csv.write_text("strain (%),force (N)\n1,2\n2,4\n3,6\n")
    with pytest.raises(ValueError, match="width = 50"):
        calibrate(BELT, csv, {GAP: (0.9, 0.3, 1.0)}, width=50)
