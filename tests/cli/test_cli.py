# SPDX-License-Identifier: MIT
"""The command line: --help, --version, exit codes, bad input, no partial outputs."""
from __future__ import annotations

import re
import shutil
from pathlib import Path

import pytest

TOP = Path(__file__).resolve().parents[2]
DATA = TOP / "tests" / "data" / "input"
BAD_INPUTS = sorted(DATA.glob("bad_*.nml"))
#: Files a catalogued input may name (geometry files, tables, TexGen models), copied
#: next to it.
COMPANIONS = sorted([*DATA.glob("*.geo"), *DATA.glob("*.csv"), *DATA.glob("*.tg3")])
VNET = (TOP / "inputs" / "vnet.nml").read_text()
#: First line of every catalogued bad input: the words its error message must contain.
EXPECT = re.compile(r"! expect: (?P<words>.*\S)")


def test_help(run_yarnfort):
    run = run_yarnfort("", "--help")
    assert run.returncode == 0
    assert "usage: yarnfort" in run.stdout and "REFERENCE.md" in run.stdout
    # Every table and file a run writes is named (README.md, *Outputs*).
    for name in ("curve.csv", "contacts.csv", "reactions.csv", "input.nml", "restart.dat",
                 "states.pvd", "state_NNNNN.vtu"):
        assert name in run.stdout, name


def test_version_matches_meson_project(run_yarnfort):
    run = run_yarnfort("", "--version")
    assert run.returncode == 0
    version = re.search(r"version: '([^']+)'", (TOP / "meson.build").read_text()).group(1)
    assert run.stdout.strip() == f"yarnfort {version}"


def test_unknown_argument(run_yarnfort):
    run = run_yarnfort("", "--frobnicate")
    assert run.returncode == 2
    assert "unknown argument '--frobnicate'" in run.stderr


def test_empty_input(run_yarnfort):
    run = run_yarnfort("")
    assert run.returncode == 2
    assert "error (input)" in run.stderr


@pytest.mark.parametrize("path", BAD_INPUTS, ids=lambda p: p.stem)
def test_bad_input_fails_cleanly(run_yarnfort, tmp_path, path):
    """Every catalogued bad input: exit code 2, one message with the words of its
    ``! expect:`` first line, nothing written. Relative file names in the input are
    resolved against the working directory (input from stdin), so the geometry files and
    tables of tests/data/input are copied into it first."""
    text = path.read_text()
    expect = EXPECT.fullmatch(text.splitlines()[0]) if text else None
    assert expect, f"{path.name}: the first line must be '! expect: <words of the message>'"
    for companion in COMPANIONS:
        shutil.copy(companion, tmp_path)
    run = run_yarnfort(text, cwd=tmp_path)
    assert run.returncode == 2, run.stderr
    assert run.stderr.count("yarnfort: error (input): ") == 1, run.stderr
    assert expect["words"] in run.stderr, run.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == [p.name for p in COMPANIONS]


def test_unwritable_output_folder(run_yarnfort, tmp_path):
    (tmp_path / "blocker").write_text("a file where the folder should be")
    text = VNET.replace("folder = 'out/vnet'", "folder = 'blocker/vnet'")
    run = run_yarnfort(text, cwd=tmp_path)
    assert run.returncode == 2
    assert "folder 'blocker/vnet' cannot be created or written" in run.stderr


def test_table_file_relative_to_working_directory_when_reading_stdin(run_yarnfort, tmp_path):
    text = VNET.replace("law = 'linear'", "law = 'table'").replace(
        "stiffness = 10.0        ! EA in N", "table_file = 'missing.csv'")
    run = run_yarnfort(text, cwd=tmp_path)
    assert run.returncode == 2
    assert "missing.csv" in run.stderr
    assert list(tmp_path.iterdir()) == []


def test_failed_solve_keeps_converged_steps(run_yarnfort, tmp_path):
    """A straight string at zero tension with the exact tension-only law has no
    stiffness at all: every step fails. The run must stop with exit code 1 and a
    message, after cutting steps down to min_step, keeping step 0 in the curve."""
    text = VNET.replace("0.0, -0.2, 0.0,  ! node 2", "0.0, 0.0, 0.0,  ! node 2").replace(
        "max_step = 0.1", "max_step = 0.1\n    slack_stiffness = 0.0\n    min_step = 1e-3")
    run = run_yarnfort(text, cwd=tmp_path)
    assert run.returncode == 1, run.stderr
    assert "error (solve): step from time 0" in run.stderr
    assert "singular" in run.stderr
    curve = (tmp_path / "out" / "vnet" / "curve.csv").read_text().splitlines()
    assert len(curve) == 2 and curve[1].startswith("0,")


def test_example_run_writes_curve_vtk_and_echo(run_yarnfort, tmp_path):
    run = run_yarnfort(VNET, cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    out = tmp_path / "out" / "vnet"
    names = {p.name for p in out.iterdir()}
    assert {"curve.csv", "input.nml", "states.pvd", "state_00000.vtu"} <= names
    # The echoed input is itself a valid input giving the same run.
    echo = (out / "input.nml").read_text().replace("'out/vnet'", "'again'")
    again = run_yarnfort(echo, cwd=tmp_path)
    assert again.returncode == 0, again.stderr
    assert (tmp_path / "again" / "curve.csv").read_text().count("\n") == \
        (out / "curve.csv").read_text().count("\n")
    assert "step    20" in run.stderr
    # The build time is reported once, before any step, as a number of seconds.
    built = re.findall(r"^yarnfort: scene built in (\S+) s \(", run.stderr, re.MULTILINE)
    assert len(built) == 1 and float(built[0]) >= 0.0
    assert run.stderr.index("scene built in") < run.stderr.index("step     0")


def test_rerun_into_same_folder_leaves_no_stale_states(run_yarnfort, tmp_path):
    """A second, shorter run into the same folder removes the first run's states."""
    assert run_yarnfort(VNET, cwd=tmp_path).returncode == 0
    short = VNET.replace("initial_step = 0.1", "initial_step = 1.0").replace(
        "max_step = 0.1", "max_step = 1.0")
    assert run_yarnfort(short, cwd=tmp_path).returncode == 0
    out = tmp_path / "out" / "vnet"
    states = sorted(p.name for p in out.glob("state_*.vtu"))
    assert states == ["state_00000.vtu", "state_00001.vtu", "state_00002.vtu"]
