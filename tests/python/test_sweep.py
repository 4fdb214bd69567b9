# SPDX-License-Identifier: MIT
"""Tests of yarnfort.sweep: parameter grids over the capstan scene, on local worker
processes, serially, and on a real local Dask cluster."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import yarnfort
from yarnfort import program_path, read_curve
from yarnfort.results import read_contacts
from yarnfort.sweep import parameter_grid, run_patched, run_sweep

TOP = Path(__file__).resolve().parents[2]
CAPSTAN = TOP / "inputs" / "capstan.nml"
MU = "contact[0].friction_coefficient"
BETA = "contact[0].adhesion"
#: A 2x2 grid; coarse steps keep every run to a few milliseconds.
GRID = {MU: [0.1, 0.5], BETA: [0.02, 0.08], "solver.max_step": [0.1]}
#: Columns that must agree between two executions of one sweep (wall time does not).
SAME = ("status", "error", "n_steps", "final_reaction", "max_reaction")
#: The same program on the same input is deterministic: only I/O rounding may differ.
IDENTITY = 100 * np.finfo(float).eps


@pytest.fixture(scope="module", autouse=True)
def program() -> Path:
    try:
        return program_path()
    except FileNotFoundError as error:
        pytest.fail(str(error))


@pytest.fixture(scope="module")
def local_table() -> dict[str, np.ndarray]:
    return run_sweep(CAPSTAN, GRID, workers=2, progress=False, support="pull",
                     component="y")


def assert_same_table(actual: dict, expected: dict) -> None:
    assert list(actual) == list(expected)
    for key in [*parameter_grid(GRID)[0], *SAME]:
        if actual[key].dtype.kind == "f":
            np.testing.assert_allclose(actual[key], expected[key], rtol=IDENTITY)
        else:
            np.testing.assert_array_equal(actual[key], expected[key])


def test_grid_gives_one_ok_row_per_combination(local_table):
    assert len(local_table["status"]) == 4
    assert list(local_table["status"]) == ["ok"] * 4
    np.testing.assert_array_equal(local_table[MU], [0.1, 0.1, 0.5, 0.5])
    np.testing.assert_array_equal(local_table[BETA], [0.02, 0.08, 0.02, 0.08])
    assert np.all(local_table["n_steps"] > 10)
    assert np.all(local_table["wall_time"] > 0)


def test_larger_friction_needs_a_larger_pull_force(local_table):
    # The pull acts downwards (-y): compare magnitudes at each adhesion.
    peak = np.abs(local_table["max_reaction"])
    for beta in GRID[BETA]:
        rows = local_table[BETA] == beta
        order = np.argsort(local_table[MU][rows])
        assert np.all(np.diff(peak[rows][order]) > 0)


def test_parallel_sweep_equals_serial_sweep(local_table):
    serial = run_sweep(CAPSTAN, GRID, workers=1, progress=False, support="pull",
                       component="y")
    assert_same_table(local_table, serial)


def test_bad_value_gives_an_error_row_and_the_other_runs_still_finish():
    runs = [{MU: 0.3}, {MU: -1.0}, {MU: 0.3, "solver.max_step": "fast"}, {MU: 0.6}]
    table = run_sweep(CAPSTAN, runs, workers=2, progress=False, support="pull")
    assert list(table["status"]) == ["ok", "bad_input", "bad_input", "ok"]
    assert "friction_coefficient" in table["error"][1]
    assert "max_step" in table["error"][2]
    assert table["error"][0] == "" and np.isnan(table["max_reaction"][1])
    assert table["solver.max_step"][0] is None  # not set in that run


def test_malformed_address_is_rejected_before_any_run():
    with pytest.raises(ValueError, match="contact"):
        run_sweep(CAPSTAN, {"contact[3].adhesion": [0.1]}, progress=False)
    with pytest.raises(ValueError, match="appears 3 times"):
        run_sweep(CAPSTAN, {"support.nodes": [1]}, progress=False)


def test_kept_run_folders_hold_the_patched_input(tmp_path):
    run_sweep(CAPSTAN, {MU: [0.25]}, workers=1, progress=False, work_dir=tmp_path)
    text = (tmp_path / "run_00000" / "input.nml").read_text()
    assert "friction_coefficient = 0.25" in text
    assert (tmp_path / "run_00000" / "out" / "curve.csv").is_file()


def test_dask_cluster_gives_the_same_table(local_table):
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, processes=True, threads_per_worker=1,
                                  dashboard_address=None) as cluster:
        table = run_sweep(CAPSTAN, GRID, scheduler=cluster.scheduler_address,
                          progress=False, support="pull", component="y")
    assert_same_table(table, local_table)


def test_default_summary_is_the_pulled_support(tmp_path):
    """Without support=..., the table summarises the capstan's pulled end ('pull', the
    first &support that moves), not its first &support (the fixed end), and names it.
    At the peak all three pegs slip, so the pull is the capstan law with adhesion,
    dT/dalpha = max(mu T, beta), integrated from the fixed end's tension over the summed
    wrap angle (contacts.csv)."""
    mu, beta = 0.3, 0.05  # inputs/capstan.nml
    table = run_sweep(CAPSTAN, {MU: [mu]}, workers=1, progress=False, work_dir=tmp_path)
    assert list(table["status"]) == ["ok"] and list(table["support"]) == ["pull"]
    out = tmp_path / "run_00000" / "out"
    curve = read_curve(out)
    peak = int(np.argmax(curve["p_disp"]))
    contacts = read_contacts(out)
    at_peak = np.asarray(contacts["step"]) == curve["step"][peak]
    assert set(np.asarray(contacts["mode"])[at_peak]) == {"forward"}  # gross slip
    angle = float(np.sum(np.asarray(contacts["wrap_angle"])[at_peak]))
    low = float(np.linalg.norm(curve.reaction("fixed")[peak]))
    knee = beta / mu  # the tension where the exponential law takes over
    used = min(angle, max(knee - low, 0.0) / beta)
    high = (low + beta * used) * np.exp(mu * (angle - used))
    assert table["max_reaction"][0] == pytest.approx(high, rel=1e-8)
    assert table["max_reaction"][0] > 2.0 * low  # not the fixed end's reaction


def test_a_misspelled_group_or_variable_is_rejected_before_any_run(tmp_path):
    # Each run would otherwise fail alone, as a bad_input row.
    with pytest.raises(ValueError, match="no variable 'friction_coeficient'; did you mean"
                       " 'friction_coefficient'"):
        run_sweep(CAPSTAN, {"contact[0].friction_coeficient": [0.2]}, progress=False,
                  work_dir=tmp_path)
    with pytest.raises(ValueError, match="no group 'solvr'; did you mean 'solver'"):
        run_sweep(CAPSTAN, {"solvr.max_step": [0.2]}, progress=False, work_dir=tmp_path)
    assert not list(tmp_path.iterdir())  # nothing ran


def test_a_failed_run_in_a_kept_folder_does_not_report_an_earlier_curve(tmp_path):
    run_sweep(CAPSTAN, {MU: [0.25]}, workers=1, progress=False, work_dir=tmp_path)
    earlier = tmp_path / "run_00000" / "out" / "curve.csv"
    rows = len(read_curve(earlier))
    assert rows > 1
    text = earlier.read_bytes()
    table = run_sweep(CAPSTAN, {MU: [-0.25]}, workers=1, progress=False,
                      work_dir=tmp_path)
    # Bad input writes nothing: the row has no step, the earlier curve stays as it was.
    assert list(table["status"]) == ["bad_input"] and list(table["n_steps"]) == [0]
    assert earlier.read_bytes() == text


def test_a_string_is_not_a_list_of_values():
    # list('table') would be five runs of laws 't', 'a', 'b', 'l', 'e'.
    with pytest.raises(TypeError, match=r"'material\[0\].law': expected a list of values"):
        parameter_grid({"material[0].law": "table"})
    assert parameter_grid({"material[0].law": ["table"], MU: [0.1, 0.2]}) == [
        {"material[0].law": "table", MU: 0.1}, {"material[0].law": "table", MU: 0.2}]


def test_a_run_stopped_by_max_steps_is_not_ok(tmp_path):
    # capstan's path ends at time 2; 3 steps of at most 0.1 end well before it.
    runs = [{MU: 0.3, "control.max_steps": 3}, {MU: 0.3}]
    table = run_sweep(CAPSTAN, runs, workers=1, progress=False, support="pull")
    assert list(table["status"]) == ["max_steps", "ok"]
    assert list(table["n_steps"])[0] == 4 and "incomplete run" in table["error"][0]
    with pytest.raises(yarnfort.YarnfortError, match="incomplete run.*max_steps"):
        run_patched(CAPSTAN, {"control.max_steps": 3}, tmp_path)


def test_an_output_setting_the_sweep_makes_itself_is_refused():
    for address, value in (("output.folder", "out/mine"), ("output.progress", True),
                           ("output.vtk_every", 5)):
        with pytest.raises(ValueError, match=f"'{address}': the sweep sets &output"):
            run_sweep(CAPSTAN, {address: [value]}, progress=False)
