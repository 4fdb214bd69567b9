# SPDX-License-Identifier: MIT
"""Restart: a run stopped after some step (by &control max_steps, or killed) and then
continued with &control restart = .true. must give the curve of an uninterrupted run,
keep curve.csv and the VTK states up to the restart step, and refuse a restart file
that does not belong to the scene."""
from __future__ import annotations

import csv
import os
import signal
import struct
import subprocess
import time
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from yarnfort import read_state

TOP = Path(__file__).resolve().parents[2]
EXECUTABLE = Path(os.environ.get("YARNFORT_EXE", TOP / "build" / "yarnfort"))
CAPSTAN = (TOP / "inputs" / "capstan.nml").read_text()
VNET = (TOP / "inputs" / "vnet.nml").read_text()

#: Curve columns that are not part of the path: timing, and the final scaled Newton
#: residual (below the tolerance, its digits are round-off).
NOT_COMPARED = {"wall_time", "residual"}
#: Counts that must agree exactly.
INTEGER_COLUMNS = {"step", "direction", "slipping", "held", "jumped", "passages",
                   "newton_iterations", "step_cuts"}
#: Largest difference allowed between the restarted and the uninterrupted curve,
#: relative to the largest magnitude in the column. The restarted run repeats every
#: operation of the uninterrupted one from the same bits, except that the linear
#: solvers fix their pivot order at their first factorisation (KLU refactorisation),
#: which is a different matrix after a restart: differences are round-off, far below
#: Newton's tolerance (measured: bitwise equal on the example scenes; on the
#: elastic-peg scene stopped after step 50, 9e-14 of the column scale, 2e-15 N).
RELATIVE_TOLERANCE = 1e-10


def elastic_pegs() -> str:
    """The capstan scene with the pegs free to move (each held by its elastic 'peg'
    yarn to a fixed anchor) and three elements per yarn segment: positions and sliding
    are solved together, the secant predictor and step cuts are used. The anchors sit
    outside the cylinder (radius 1.2), so the yarn pulling the pegs inwards stretches
    the peg yarns (anchors inside would leave them slack and the pegs undetermined)."""
    text = CAPSTAN
    for inside, outside in (("-0.6928203,  0.4", "-1.0392305,  0.6"),
                            ("0.0,        0.8", "0.0,        1.2"),
                            ("0.6928203,  0.4", "1.0392305,  0.6")):
        assert inside in text
        text = text.replace(inside, outside)
    text = text.replace("    name = 'pegs'\n    nodes = 2, 3, 4, 6, 7, 8\n/",
                           "    name = 'anchors'\n    nodes = 6, 7, 8\n/\n"
                           "&support\n    name = 'plane'\n    nodes = 2, 3, 4\n    fix = 'z'\n/")
    text = text.replace("nodes = 1, 2, 3, 4, 5\n",
                        "nodes = 1, 2, 3, 4, 5\n    elements_per_segment = 3\n")
    assert "'anchors'" in text and "elements_per_segment" in text
    return text


SCENES = {
    "capstan": CAPSTAN,
    "capstan_staggered": CAPSTAN.replace("scheme = 'monolithic'", "scheme = 'staggered'"),
    "capstan_growing_steps": CAPSTAN.replace("max_step = 0.05",
                                             "max_step = 0.4\n    initial_step = 0.01"),
    "vnet": VNET,
    "elastic_pegs": elastic_pegs(),
}


def with_output(text: str, folder: str, *, control: str = "", output: str = "") -> str:
    """The scene writing to `folder`, with extra &control and &output settings."""
    lines = []
    for line in text.splitlines():
        if line.strip().startswith("folder ="):
            line = f"    folder = '{folder}'" + (f"\n    {output}" if output else "")
        lines.append(line)
    text = "\n".join(lines) + "\n"
    assert f"folder = '{folder}'" in text
    if control:
        if "&control" in text:
            text = text.replace("&control", "&control\n    " + control, 1)
        else:
            text = f"&control {control} /\n" + text
    return text


def read_rows(folder: Path) -> list[dict[str, str]]:
    with open(folder / "curve.csv", newline="") as stream:
        return list(csv.DictReader(stream))


def compare_curves(full: list[dict[str, str]], restarted: list[dict[str, str]]) -> float:
    """Assert the curves agree; return the largest difference relative to the column
    scale."""
    assert len(restarted) == len(full)
    assert list(restarted[0]) == list(full[0])
    worst = 0.0
    for name in full[0]:
        if name in NOT_COMPARED:
            continue
        if name in INTEGER_COLUMNS:
            assert [r[name] for r in restarted] == [r[name] for r in full], name
            continue
        a = [float(r[name]) for r in full]
        b = [float(r[name]) for r in restarted]
        scale = max(max(abs(v) for v in a), 1e-300)
        difference = max(abs(x - y) for x, y in zip(a, b)) / scale
        assert difference <= RELATIVE_TOLERANCE, (name, difference)
        worst = max(worst, difference)
    return worst


def folder_content(folder: Path) -> dict[str, bytes]:
    """Every file of an output folder and its bytes, but the lock file (whose line
    names the run that holds or last held the lock)."""
    return {p.name: p.read_bytes() for p in folder.iterdir() if p.name != ".yarnfort-lock"}


def state_list(folder: Path) -> list[tuple[str, str]]:
    root = ET.parse(folder / "states.pvd").getroot()
    return [(d.get("file"), d.get("timestep")) for d in root.iter("DataSet")]


def positions(path: Path) -> list[float]:
    return [float(v) for v in read_state(path).position.ravel()]


@pytest.mark.parametrize("name, stop", [("capstan", 15), ("capstan", 1),
                                        ("capstan_staggered", 9),
                                        ("capstan_growing_steps", 4), ("vnet", 7),
                                        ("elastic_pegs", 19), ("elastic_pegs", 33)])
def test_restart_gives_the_uninterrupted_curve(run_yarnfort, tmp_path, name, stop):
    text = SCENES[name]
    full = run_yarnfort(with_output(text, "full"))
    assert full.returncode == 0, full.stderr
    first = run_yarnfort(with_output(text, "parts", control=f"max_steps = {stop}"))
    assert first.returncode == 0, first.stderr
    assert "stopped after max_steps" in first.stderr
    parts = tmp_path / "parts"
    assert [r["step"] for r in read_rows(parts)] == [str(k) for k in range(stop + 1)]
    # Only &control and &output may change: here the title and the progress lines.
    second = run_yarnfort(with_output(text.replace("title = '", "title = 'second part: "),
                                      "parts", control="restart = .true.",
                                      output="progress = .false."))
    assert second.returncode == 0, second.stderr
    assert f"restarting after step {stop}" in second.stderr
    worst = compare_curves(read_rows(tmp_path / "full"), read_rows(parts))
    print(f"{name}, stopped after step {stop}: restarted curve differs by {worst:.1e} "
          f"of the column scale")
    # The VTK states continue: the same list, the same files.
    assert state_list(parts) == state_list(tmp_path / "full")
    last = [name for name, _ in state_list(parts) if name.startswith("state_")][-1]
    a, b = positions(tmp_path / "full" / last), positions(parts / last)
    assert max(abs(x - y) for x, y in zip(a, b)) <= RELATIVE_TOLERANCE * max(map(abs, a))
    assert not (parts / "restart.dat.tmp").exists()


def test_restart_after_a_kill(run_yarnfort, tmp_path):
    """Kill the run (SIGKILL) part way, then restart: the kill may come at any moment,
    also while the restart file or a curve row is being written."""
    text = CAPSTAN.replace("max_step = 0.05", "max_step = 0.002\n    initial_step = 0.002")
    full = run_yarnfort(with_output(text, "full", output="vtk_every = 0"))
    assert full.returncode == 0, full.stderr
    n_steps = len(read_rows(tmp_path / "full")) - 1
    kill_at = n_steps // 3
    process = subprocess.Popen([str(EXECUTABLE)], cwd=tmp_path, text=True,
                               stdin=subprocess.PIPE, stdout=subprocess.DEVNULL,
                               stderr=subprocess.PIPE)
    process.stdin.write(with_output(text, "parts", output="vtk_every = 0"))
    process.stdin.close()
    for line in process.stderr:
        if line.startswith("step") and int(line.split()[1]) >= kill_at:
            os.kill(process.pid, signal.SIGKILL)
            break
    process.stderr.close()
    assert process.wait() == -signal.SIGKILL, "the run ended before it was killed"
    kept = read_rows(tmp_path / "parts")
    assert kill_at <= int(kept[-1]["step"]) < n_steps
    again = run_yarnfort(with_output(text, "parts", control="restart = .true.",
                                     output="vtk_every = 0"))
    assert again.returncode == 0, again.stderr
    compare_curves(read_rows(tmp_path / "full"), read_rows(tmp_path / "parts"))


def test_rows_after_the_restart_step_are_dropped(run_yarnfort, tmp_path):
    """Rows written after the last restart file (a kill between the curve row and the
    restart file), and a row cut short, are replaced by the restarted run's."""
    full = run_yarnfort(with_output(CAPSTAN, "full"))
    assert full.returncode == 0, full.stderr
    assert run_yarnfort(with_output(CAPSTAN, "parts", control="max_steps = 10")).returncode == 0
    curve = tmp_path / "parts" / "curve.csv"
    rows = curve.read_text().splitlines()
    extra = "11" + rows[-1][len("10"):]
    curve.write_text("\n".join(rows + [extra, extra[:40]]))
    again = run_yarnfort(with_output(CAPSTAN, "parts", control="restart = .true."))
    assert again.returncode == 0, again.stderr
    compare_curves(read_rows(tmp_path / "full"), read_rows(tmp_path / "parts"))


def test_restart_of_a_finished_run_does_nothing(run_yarnfort, tmp_path):
    assert run_yarnfort(with_output(VNET, "out")).returncode == 0
    before = read_rows(tmp_path / "out")
    again = run_yarnfort(with_output(VNET, "out", control="restart = .true."))
    assert again.returncode == 0, again.stderr
    assert read_rows(tmp_path / "out") == before


def test_restart_without_a_restart_file(run_yarnfort, tmp_path):
    run = run_yarnfort(with_output(VNET, "out", control="restart = .true."))
    assert run.returncode == 2
    assert "error (restart): &control restart: no restart file 'out/restart.dat'" in run.stderr


def test_restart_of_another_input_is_refused(run_yarnfort, tmp_path):
    """Same sizes, another friction coefficient: refused, and nothing is changed."""
    assert run_yarnfort(with_output(CAPSTAN, "out", control="max_steps = 5")).returncode == 0
    before = folder_content(tmp_path / "out")
    other = CAPSTAN.replace("friction_coefficient = 0.3", "friction_coefficient = 0.31")
    run = run_yarnfort(with_output(other, "out", control="restart = .true."))
    assert run.returncode == 2
    assert "was written for another input" in run.stderr
    assert "only &control and &output may change" in run.stderr
    assert folder_content(tmp_path / "out") == before


def test_restart_of_another_scene_is_refused(run_yarnfort, tmp_path):
    assert run_yarnfort(with_output(VNET, "out", control="max_steps = 3")).returncode == 0
    run = run_yarnfort(with_output(CAPSTAN, "out", control="restart = .true."))
    assert run.returncode == 2
    assert ("'out/restart.dat' does not match the scene: it has 3 nodes, 2 elements, "
            "2 unknowns, 0 passages, the scene has 8 nodes, 7 elements") in run.stderr


def test_cut_short_restart_file_is_refused(run_yarnfort, tmp_path):
    assert run_yarnfort(with_output(VNET, "out", control="max_steps = 3")).returncode == 0
    restart = tmp_path / "out" / "restart.dat"
    restart.write_bytes(restart.read_bytes()[:-20])
    run = run_yarnfort(with_output(VNET, "out", control="restart = .true."))
    assert run.returncode == 2
    assert "'out/restart.dat' is cut short or unreadable" in run.stderr


#: Restart file format 5 ends with the two force-control slopes (float64), the end
#: marker (16 bytes) and the checksum (16); format 4 had no slopes. The version (int32)
#: follows the 16-byte magic.
SLOPES, VERSION = slice(-48, -32), slice(16, 20)


def test_restart_file_of_format_4_is_read(run_yarnfort, tmp_path):
    """A file written before the slopes were added (format 4, made here from a format-5
    file: the slopes, zero without force control, cut out) still restarts the run, to
    the curve of the run that never stopped."""
    from test_faults import checksum

    assert run_yarnfort(with_output(CAPSTAN, "full")).returncode == 0
    assert run_yarnfort(with_output(CAPSTAN, "parts", control="max_steps = 5")).returncode == 0
    restart = tmp_path / "parts" / "restart.dat"
    data = bytearray(restart.read_bytes())
    assert struct.unpack("<i", data[VERSION]) == (5,)
    assert struct.unpack("<2d", data[SLOPES]) == (0.0, 0.0)
    del data[SLOPES]
    data[VERSION] = struct.pack("<i", 4)
    data[-16:] = checksum(bytes(data[:-16]))
    restart.write_bytes(bytes(data))
    run = run_yarnfort(with_output(CAPSTAN, "parts", control="restart = .true."))
    assert run.returncode == 0, run.stderr
    assert "restarting after step 5" in run.stderr
    compare_curves(read_rows(tmp_path / "full"), read_rows(tmp_path / "parts"))


@pytest.mark.parametrize("version", [3, 6])
def test_restart_file_of_another_format_is_refused(run_yarnfort, tmp_path, version):
    assert run_yarnfort(with_output(VNET, "out", control="max_steps = 3")).returncode == 0
    restart = tmp_path / "out" / "restart.dat"
    data = bytearray(restart.read_bytes())
    data[VERSION] = struct.pack("<i", version)
    restart.write_bytes(bytes(data))
    run = run_yarnfort(with_output(VNET, "out", control="restart = .true."))
    assert run.returncode == 2
    assert (f"'out/restart.dat' has format version {version}, this yarnfort reads versions "
            "4 to 5") in run.stderr


def test_new_run_removes_an_old_restart_file(run_yarnfort, tmp_path):
    """A run from the beginning replaces the folder's restart file; a failed step 0
    leaves none (so no stale file can be continued)."""
    assert run_yarnfort(with_output(VNET, "out", control="max_steps = 3")).returncode == 0
    assert (tmp_path / "out" / "restart.dat").exists()
    broken = VNET.replace("0.0, -0.2, 0.0,  ! node 2", "0.0, 0.0, 0.0,  ! node 2").replace(
        "max_step = 0.1", "max_step = 0.1\n    slack_stiffness = 0.0\n    min_step = 1e-3")
    broken = broken.replace("p_force = 0.0, 1.0, 0.0", "p_force = 0.1, 1.0, 0.0")
    run = run_yarnfort(with_output(broken, "out"))
    assert run.returncode == 1
    assert not (tmp_path / "out" / "restart.dat").exists()
    assert not (tmp_path / "out" / "restart.sync").exists()


def test_restart_after_a_power_cut(run_yarnfort, tmp_path):
    """After a power cut restart.dat may be damaged, or on disk further than curve.csv
    (it is replaced every step, flushed to disk only every 10 s).
    restart.sync, the restart file of the last flush, is one the tables hold: the
    refusal names it, and renamed to restart.dat it goes on to the uninterrupted curve.
    The cut is made by hand: the files flushed at the end of a first piece of 10 steps,
    then curve.csv rows up to step 15 and the restart.dat of step 20 of a second."""
    full = run_yarnfort(with_output(CAPSTAN, "full"))
    assert full.returncode == 0, full.stderr
    parts = tmp_path / "parts"
    first = run_yarnfort(with_output(CAPSTAN, "parts", control="max_steps = 10"))
    assert first.returncode == 0, first.stderr
    # The end of a run flushes: restart.sync is restart.dat (one file, two names).
    assert (parts / "restart.sync").samefile(parts / "restart.dat")
    synced = (parts / "restart.sync").read_bytes()
    second = run_yarnfort(with_output(CAPSTAN, "parts",
                                      control="max_steps = 10, restart = .true."))
    assert second.returncode == 0, second.stderr
    (parts / "restart.sync").unlink()
    (parts / "restart.sync").write_bytes(synced)
    curve = parts / "curve.csv"
    curve.write_text("".join(curve.read_text().splitlines(keepends=True)[:1 + 16]))
    hint = ("(after a power cut: 'parts/restart.sync' is the restart file last flushed to "
            "disk, of step 10; rename it to restart.dat to go on from there)")
    ahead = run_yarnfort(with_output(CAPSTAN, "parts", control="restart = .true."))
    assert ahead.returncode == 2
    assert "has no row for step 20" in ahead.stderr and hint in ahead.stderr
    restart = parts / "restart.dat"
    restart.write_bytes(restart.read_bytes()[:-20])
    damaged = run_yarnfort(with_output(CAPSTAN, "parts", control="restart = .true."))
    assert damaged.returncode == 2
    assert "is cut short or unreadable" in damaged.stderr and hint in damaged.stderr
    os.replace(parts / "restart.sync", restart)
    again = run_yarnfort(with_output(CAPSTAN, "parts", control="restart = .true."))
    assert again.returncode == 0, again.stderr
    assert "restarting after step 10" in again.stderr
    compare_curves(read_rows(tmp_path / "full"), read_rows(parts))
    assert state_list(parts) == state_list(tmp_path / "full")


def test_max_steps_must_not_be_negative(run_yarnfort, tmp_path):
    run = run_yarnfort(with_output(VNET, "out", control="max_steps = -1"))
    assert run.returncode == 2
    assert "&control: max_steps = -1 must be >= 0" in run.stderr


def test_restart_from_the_initial_state(run_yarnfort, tmp_path):
    """A run killed during its first load step leaves the restart file of step 0 (the
    initial state). The restarted run must take the first load step as the
    uninterrupted one does (all-stick from the initial state, not from its slip set):
    the same Newton iterations and curve. The scene is inputs/knit_clamped.nml as a
    24 x 12 strip, whose initial state has 72 slipping passages (measured: from that
    slip set the first step took 60 Newton iterations instead of 17)."""
    text = (TOP / "inputs" / "knit_clamped.nml").read_text()
    assert "cells = 8, 4 " in text
    text = text.replace("cells = 8, 4 ", "cells = 24, 12 ")
    full_folder, parts_folder = tmp_path / "full", tmp_path / "parts"
    full = run_yarnfort(with_output(text, str(full_folder), control="max_steps = 2"), cwd=TOP)
    assert full.returncode == 0, full.stderr
    assert int(read_rows(full_folder)[0]["slipping"]) > 0, "the initial state must slip"
    restart_file = parts_folder / "restart.dat"
    for _ in range(5):
        # Kill as soon as the restart file of step 0 is there (the first load step takes
        # about 0.2 s); try again should the kill come after step 1.
        process = subprocess.Popen([str(EXECUTABLE)], cwd=TOP, text=True,
                                   stdin=subprocess.PIPE, stdout=subprocess.DEVNULL,
                                   stderr=subprocess.DEVNULL)
        process.stdin.write(with_output(text, str(parts_folder), control="max_steps = 2"))
        process.stdin.close()
        while not restart_file.exists() and process.poll() is None:
            time.sleep(0.002)
        process.kill()
        process.wait()
        if [r["step"] for r in read_rows(parts_folder)] == ["0"]:
            break
    else:
        pytest.fail("the run could not be stopped during its first load step")
    again = run_yarnfort(with_output(text, str(parts_folder),
                                     control="max_steps = 2, restart = .true."), cwd=TOP)
    assert again.returncode == 0, again.stderr
    assert "restarting after step 0" in again.stderr
    compare_curves(read_rows(full_folder), read_rows(parts_folder))
