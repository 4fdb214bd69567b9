# SPDX-License-Identifier: MIT
"""The installed package: version, program, console command, in-process runs (progress,
stop at a step boundary, restart and max_steps as the CLI, errors), relative paths on
every route, scene building and the namelist round trip, and the quickstart example."""
from __future__ import annotations

import os
import re
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import f90nml
import numpy as np
import pytest

import yarnfort
from yarnfort import Scene, YarnfortError
from conftest import INTERRUPTED_RUN

TOP = Path(__file__).resolve().parents[2]
EXAMPLES = sorted((TOP / "inputs").glob("*.nml"))
#: Columns that differ between identical runs (timing).
TIMING = ("wall_time",)


@pytest.fixture
def workdir(tmp_path, monkeypatch) -> Path:
    """A working directory holding a copy of inputs/ (the examples' tables included)."""
    shutil.copytree(TOP / "inputs", tmp_path / "inputs")
    monkeypatch.chdir(tmp_path)
    return tmp_path


def same_curve(a: yarnfort.Curve, b: yarnfort.Curve) -> None:
    assert a.names == b.names
    for name in a.names:
        if name not in TIMING:
            np.testing.assert_array_equal(a[name], b[name], err_msg=name)


def patched(source: Path, target: Path, **values) -> Path:
    nml = f90nml.read(source)
    for address, value in values.items():
        yarnfort.set_parameter(nml, address.replace("__", "."), value)
    nml.write(str(target), force=True)
    return target


def test_version_comes_from_meson_build():
    project = re.search(r"version: '([^']+)'", (TOP / "meson.build").read_text()).group(1)
    assert yarnfort.__version__ == project
    out = subprocess.run([str(yarnfort.program_path()), "--version"], capture_output=True,
                         text=True, check=True).stdout
    assert out.strip() == f"yarnfort {project}"


def test_citation_names_this_version_and_the_paper():
    yaml = pytest.importorskip("yaml")
    citation = yaml.safe_load((TOP / "CITATION.cff").read_text())
    assert citation["version"] == yarnfort.__version__
    assert citation["license"] == "MIT"
    dois = [reference.get("doi") for reference in citation["references"]]
    assert "10.3390/lubricants6020033" in dois
    assert "The yarnfort developers" in (TOP / "LICENSE").read_text()


def test_console_command_is_the_program(workdir):
    command = Path(sys.executable).parent / "yarnfort"
    assert command.is_file(), "the yarnfort console command is not installed"
    text = (workdir / "inputs" / "vnet.nml").read_text()
    run = subprocess.run([str(command)], input=text, capture_output=True, text=True,
                         timeout=120)
    assert run.returncode == 0, run.stderr
    assert "done; results in out/vnet" in run.stderr
    bad = subprocess.run([str(command)], input="&nope /\n", capture_output=True, text=True)
    assert bad.returncode == 2 and "error (input)" in bad.stderr


def test_no_code_searches_build_folders():
    sources = (TOP / "python" / "yarnfort").glob("*.py")
    for path in sources:
        text = path.read_text()
        assert "build*" not in text and '"build"' not in text, path


@pytest.mark.parametrize("example", EXAMPLES, ids=lambda p: p.stem)
def test_examples_run_alike_from_every_route(workdir, run_yarnfort, example):
    """CLI from stdin, run_scene on the file, a Scene read and written again, and a
    sweep: all from the same working directory, with the same relative paths."""
    relative = Path("inputs") / example.name
    cli = run_yarnfort(relative.read_text(), cwd=workdir)
    assert cli.returncode == 0, cli.stderr
    folder = workdir / f90nml.read(relative)["output"]["folder"]
    echoed, curve = (folder / "input.nml").read_text(), yarnfort.read_curve(folder)

    run = yarnfort.run_scene(relative)
    assert run.outcome == "done" and run.folder == folder
    assert (folder / "input.nml").read_text() == echoed
    same_curve(run.curve, curve)

    again = Scene.read(relative).write(workdir / "again.nml")
    run = yarnfort.run_scene(again)
    assert (folder / "input.nml").read_text() == echoed, "round trip changed the input"
    same_curve(run.curve, curve)

    table = yarnfort.run_sweep(relative, [{"output.vtk_every": 0}], workers=1,
                               progress=False, support=_support(relative, curve))
    assert list(table["status"]) == ["ok"], table["error"]
    assert table["n_steps"][0] == len(curve)


def _support(path: Path, curve: yarnfort.Curve) -> str:
    names = [name[:-3] for name in curve.names if name.endswith("_rx")]
    return names[-1]


def test_run_scene_progress_and_stop_from_the_callback(workdir):
    seen: list[yarnfort.Step] = []

    def report(step: yarnfort.Step) -> bool:
        seen.append(step)
        return step.step == 3

    run = yarnfort.run_scene("inputs/vnet.nml", progress=report)
    assert run.outcome == "stopped" and run.n_steps == 4
    assert [s.step for s in seen] == [0, 1, 2, 3]
    assert all(0.0 <= s.fraction <= 1.0 for s in seen)
    assert len(run.curve) == 4 and (run.folder / "restart.dat").is_file()


def test_ctrl_c_stops_at_a_step_boundary_and_restart_completes(workdir):
    full = yarnfort.run_scene(patched(Path("inputs/knit.nml"), workdir / "full.nml",
                                      output__folder="out/full"))
    scene = patched(Path("inputs/knit.nml"), workdir / "cut.nml", output__folder="out/cut")

    def interrupt(step: yarnfort.Step) -> None:
        if step.step == 5:
            os.kill(os.getpid(), signal.SIGINT)  # as Ctrl-C

    with pytest.raises(yarnfort.RunInterrupted) as info:
        yarnfort.run_scene(scene, progress=interrupt)
    kept = info.value.result
    assert kept.outcome == "interrupted" and kept.n_steps == 6
    assert len(kept.curve) == 6
    assert signal.getsignal(signal.SIGINT) is not None  # the handler was restored
    restart = patched(scene, workdir / "restart.nml", control__restart=True)
    rest = yarnfort.run_scene(restart)
    assert rest.outcome == "done" and rest.n_steps == len(full.curve) - 6
    a, b = full.curve, rest.curve
    assert a.names == b.names
    for name in a.names:
        if name not in TIMING:
            # An uninterrupted run and a restarted one agree to round-off.
            scale = max(np.abs(a[name]).max(), 1.0)
            np.testing.assert_allclose(b[name], a[name], rtol=0,
                                       atol=1e3 * np.finfo(float).eps * scale, err_msg=name)


def test_max_steps_and_restart_as_the_cli(workdir, run_yarnfort):
    scene = patched(Path("inputs/vnet.nml"), workdir / "piece.nml", control__max_steps=3,
                    output__folder="out/py")
    first = yarnfort.run_scene(scene)
    assert first.outcome == "max_steps" and first.n_steps == 4
    second = yarnfort.run_scene(patched(scene, workdir / "more.nml", control__restart=True))
    assert second.outcome == "max_steps" and second.n_steps == 3
    assert len(second.curve) == 7  # the kept rows are not deleted
    cli_text = patched(scene, workdir / "cli.nml", output__folder="out/cli").read_text()
    assert run_yarnfort(cli_text, cwd=workdir).returncode == 0
    cli_again = re.sub(r"(?i)&control", "&control\n    restart = .true.", cli_text, count=1)
    assert run_yarnfort(cli_again, cwd=workdir).returncode == 0
    same_curve(second.curve, yarnfort.read_curve(workdir / "out" / "cli"))
    # A run stopped by the program goes on in Python: the same restart file and input.
    mixed = patched(scene, workdir / "mixed.nml", output__folder="out/mixed")
    assert run_yarnfort(mixed.read_text(), cwd=workdir).returncode == 0
    going_on = yarnfort.run_scene(patched(mixed, workdir / "mixed2.nml",
                                          control__restart=True))
    assert going_on.outcome == "max_steps" and len(going_on.curve) == 7
    same_curve(going_on.curve, second.curve)


def test_errors_raise_with_message_and_category(workdir):
    with pytest.raises(YarnfortError, match="cannot open input file") as info:
        yarnfort.run_scene("missing.nml")
    assert (info.value.status, info.value.category) == (2, "bad_input")
    scene = patched(Path("inputs/vnet.nml"), workdir / "r.nml", control__restart=True,
                    output__folder="out/none")
    with pytest.raises(YarnfortError, match="^restart: ") as info:
        yarnfort.run_scene(scene)
    assert info.value.category == "bad_input"
    assert not (workdir / "out" / "none" / "curve.csv").exists()


def test_curve_as_arrays_and_dataframe(workdir):
    run = yarnfort.run_scene("inputs/vnet.nml")
    table = run.curve.to_array()
    assert table.dtype.names == tuple(run.curve.names) and len(table) == run.n_steps
    np.testing.assert_array_equal(table["p_force"], run.curve["p_force"])
    state = run.states[-1]
    assert state.position.shape == (3, 3) and state.elements.shape == (2, 2)
    assert state.tension.shape == (2,) and state.length0.shape == (2,)
    pandas = pytest.importorskip("pandas")
    frame = run.to_dataframe()
    assert isinstance(frame, pandas.DataFrame) and list(frame.columns) == run.curve.names


def vnet_scene(folder: str = "out/built") -> Scene:
    scene = Scene("V-net built in Python", output={"folder": folder})
    scene.add_material("yarn", "linear", stiffness=100.0)
    scene.nodes = np.array([[-1.0, 0.0, 0.0], [0.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    scene.add_yarn("yarn", np.array([1, 2, 3]))
    scene.add_support("ends", [1, 3])
    scene.add_load([2], force=[0.0, -1.0, 0.0])
    scene.path = yarnfort.LoadPath(time=[0.0, 1.0], p_force=[0.0, 1.0])
    return scene


def test_built_scene_runs_and_matches_the_closed_form(workdir):
    run = vnet_scene().run()
    # A V of two strings with EA = 100 under P at the middle: P = 2 f w / l.
    state = run.states[-1]
    mid = state.position[1]
    length = np.linalg.norm(state.position[0] - mid)
    force = 2 * state.tension[0] * abs(mid[1]) / length
    assert force == pytest.approx(1.0, rel=1e-6)
    assert np.allclose(run.curve.reaction("ends")[-1], [0.0, 1.0, 0.0], rtol=1e-6,
                       atol=1e-6)


def test_scene_validation_names_the_problem(workdir):
    scene = Scene()
    with pytest.raises(yarnfort.SceneError, match="no &material named 'wool'"):
        scene.add_yarn("wool", [1, 2])
    scene.add_material("yarn", "linear", stiffness=1.0)
    with pytest.raises(yarnfort.SceneError, match="given twice"):
        scene.add_material("yarn", "linear", stiffness=2.0)
    with pytest.raises(yarnfort.SceneError, match="not .x, y, z. triplets"):
        scene.nodes = [0.0, 1.0]
    scene.nodes = np.zeros((2, 3))
    with pytest.raises(yarnfort.SceneError, match="node id 3 is not in 1..2"):
        scene.add_support("a", [3])
    with pytest.raises(yarnfort.SceneError, match="shape"):
        scene.add_load([1], force=[1.0, 2.0])
    with pytest.raises(yarnfort.SceneError, match="no &path"):
        scene.write(workdir / "x.nml")
    bad = vnet_scene()
    bad.materials[0].stiffness = -1.0
    # A value out of range is found in Python, also after construction (and -1 is no
    # 'not set' marker there).
    with pytest.raises(yarnfort.SceneError, match=r"stiffness = -1.0 N: must be > 0"):
        bad.check()
    # A rule across variables is the library's: a parameter of another law.
    bad.materials[0].stiffness = 100.0
    bad.materials[0].modulus = 5.0
    with pytest.raises(YarnfortError, match="modulus") as info:
        bad.check()
    assert info.value.category == "bad_input"
    vnet_scene().check()


def test_fabric_and_geometry_scenes(workdir):
    knit = Scene.read("inputs/knit.nml")
    assert knit.fabric is not None and knit.fabric.kind == "knit"
    knit.fabric.extra["cells"] = [1, 2]
    knit.output["folder"] = "out/small"
    assert len(knit.run().curve) > 1
    geo = workdir / "net.geo"
    shutil.copy(TOP / "tests" / "data" / "input" / "grid.geo", geo)
    scene = Scene.read(TOP / "tests" / "data" / "input" / "valid_geometry.nml")
    assert scene.geometry is not None
    scene.geometry.file = "net.geo"  # relative to the working directory
    scene.check()


def test_round_trip_of_partly_set_arrays(workdir, run_yarnfort):
    """A namelist may set single entries (``displacement(2) = ...``) or fewer values; the
    others keep their default 0, and so they do after the round trip."""
    text = Path("inputs/capstan.nml").read_text()
    text, count = re.subn(r"displacement = 0.0, -0.3, 0.0", "displacement(2) = -0.3", text)
    assert count == 1
    text = text.replace("out/capstan", "out/partial")
    (workdir / "partial.nml").write_text(text)
    cli = run_yarnfort(text, cwd=workdir)
    assert cli.returncode == 0, cli.stderr
    echoed = (workdir / "out" / "partial" / "input.nml").read_text()
    scene = Scene.read(workdir / "partial.nml")
    assert list(scene.supports[1].displacement) == [0.0, -0.3, 0.0]
    yarnfort.run_scene(scene.write(workdir / "again.nml"))
    assert (workdir / "out" / "partial" / "input.nml").read_text() == echoed
    # A variable Scene keeps as it is (&fabric cells): the first entry stays default.
    text = Path("inputs/knit.nml").read_text().replace("out/knit", "out/cells")
    text, count = re.subn(r"cells = 2, 2", "cells(2) = 1", text)
    assert count == 1
    (workdir / "cells.nml").write_text(text)
    run = yarnfort.run_scene(workdir / "cells.nml")
    echoed = (run.folder / "input.nml").read_text()
    assert re.search(r"cells\s*=\s*4,\s*1", echoed), echoed
    yarnfort.run_scene(Scene.read(workdir / "cells.nml").write(workdir / "cells2.nml"))
    assert (run.folder / "input.nml").read_text() == echoed


def test_make_namelist_writes_repeated_groups(tmp_path):
    nml = yarnfort.make_namelist({"material": [{"name": "a", "law": "linear"},
                                               {"name": "b", "law": "linear"}],
                                  "path": {"time": [0.0, 1.0]}})
    path = yarnfort.write_scene(nml, tmp_path / "s.nml")
    again = f90nml.read(path)
    assert [group["name"] for group in again["material"]] == ["a", "b"]
    assert again["path"]["time"] == [0.0, 1.0]


def test_quickstart_example(tmp_path):
    script = TOP / "python" / "examples" / "quickstart.py"
    run = subprocess.run([sys.executable, str(script)], cwd=tmp_path, capture_output=True,
                         text=True, timeout=300, env=dict(os.environ, MPLBACKEND="Agg"))
    assert run.returncode == 0, run.stderr
    assert "100%" in run.stderr  # the progress bars
    for name in ("rig.png", "jersey.png"):
        assert (tmp_path / "out" / name).stat().st_size > 1000
    states = yarnfort.read_states(tmp_path / "out" / "rig")
    curve = yarnfort.read_curve(tmp_path / "out" / "rig")
    assert len(states) == len(curve) > 2
    # The rig is inputs/capstan.nml built in Python (its pegs of the yarn's material and
    # one support for the fixed end and the pegs: the same mechanics), run with the
    # default step sizes: the same pulled-end force to the Newton tolerance
    # (residual_tolerance 1e-10 relative), here allowed 1e3 times that.
    capstan = f90nml.read(TOP / "inputs" / "capstan.nml")
    del capstan["solver"]["max_step"]
    capstan["output"]["folder"] = str(tmp_path / "out" / "capstan")
    capstan.write(str(tmp_path / "capstan.nml"))
    reference = yarnfort.run_scene(tmp_path / "capstan.nml").curve
    np.testing.assert_array_equal(reference["p_disp"], curve["p_disp"])
    pull, expected = curve.reaction("pull"), reference.reaction("pull")
    np.testing.assert_allclose(pull, expected, rtol=0, atol=1e-7 * np.abs(expected).max())
    # Friction: on release the pulled end holds less than when loading at the same p_disp.
    loading, unloading = curve["direction"] > 0, curve["direction"] < 0
    half = [np.interp(0.5, curve["p_disp"][branch][::order], pull[branch, 1][::order])
            for branch, order in ((loading, 1), (unloading, -1))]
    assert abs(half[1]) < abs(half[0])


@pytest.mark.skipif(os.environ.get("YARNFORT_TEST_INSTALL") != "1",
                    reason="builds the whole package in a fresh venv (about a minute);"
                    " set YARNFORT_TEST_INSTALL=1")
def test_pip_install_in_a_fresh_venv(tmp_path):
    venv = tmp_path / "venv"
    subprocess.run([sys.executable, "-m", "venv", str(venv)], check=True)
    python = venv / "bin" / "python"
    subprocess.run([str(python), "-m", "pip", "install", "-q", str(TOP)], check=True,
                   timeout=1800)
    code = ("import yarnfort; r = yarnfort.run_scene(%r); print(r.outcome)"
            % str(TOP / "inputs" / "vnet.nml"))
    out = subprocess.run([str(python), "-c", code], cwd=tmp_path, capture_output=True,
                         text=True, check=True).stdout
    assert out.strip() == "done"
    version = subprocess.run([str(venv / "bin" / "yarnfort"), "--version"],
                             capture_output=True, text=True, check=True).stdout
    assert version.startswith("yarnfort ")
    # It stands alone: the reference and the runnable examples come with it.
    reference = subprocess.run([str(python), "-m", "yarnfort", "reference"], cwd=tmp_path,
                               capture_output=True, text=True, check=True).stdout
    assert reference == (TOP / "inputs" / "REFERENCE.md").read_text()
    subprocess.run([str(python), "-m", "yarnfort", "examples", "ex"], cwd=tmp_path,
                   check=True)
    with open(tmp_path / "ex" / "inputs" / "knit.nml") as scene:
        subprocess.run([str(venv / "bin" / "yarnfort")], stdin=scene, cwd=tmp_path / "ex",
                       capture_output=True, check=True, timeout=600)
    # Only the runtime dependencies are installed: an extra's function names the extra.
    code = ("import yarnfort\ntry:\n    yarnfort.read_run('ex/out/knit').to_dataframe()\n"
            "except ImportError as error:\n    print(error)")
    out = subprocess.run([str(python), "-c", code], cwd=tmp_path, capture_output=True,
                         text=True, check=True).stdout
    assert "pip install 'yarnfort[pandas]'" in out


def test_ctrl_c_from_outside_keeps_the_converged_steps(workdir):
    """SIGINT sent by another process while the library solves: the run stops at the
    next step boundary, and the kept rows match the steps reported."""
    scene = patched(Path("inputs/knit.nml"), workdir / "slow.nml",
                    solver__max_step=0.002, solver__initial_step=0.002,
                    output__folder="out/slow")
    proc = subprocess.Popen([sys.executable, "-c", INTERRUPTED_RUN, str(scene)],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        for line in proc.stdout:
            if line.startswith("STEP 3"):
                proc.send_signal(signal.SIGINT)
                break
        out, err = proc.communicate(timeout=120)
    finally:
        proc.kill()
    assert proc.returncode == 130, err
    last = [line for line in out.splitlines() if line.startswith("INTERRUPTED")]
    assert last, out + err
    _, n_steps, outcome = last[0].split()
    assert outcome == "interrupted" and int(n_steps) >= 4
    curve = yarnfort.read_curve(workdir / "out" / "slow")
    assert len(curve) == int(n_steps)
    assert curve["time"][-1] < 4.0  # stopped before the end of the path
    assert (workdir / "out" / "slow" / "restart.dat").is_file()


def test_states_read_alike_with_and_without_meshio(workdir):
    pytest.importorskip("meshio")
    from yarnfort import results

    # The fallback reads the ASCII encoding only: write the states so.
    text = Path("inputs/capstan.nml").read_text()
    assert "folder = 'out/capstan'" in text
    scene_file = Path("capstan_ascii.nml")
    scene_file.write_text(text.replace("folder = 'out/capstan'",
                                       "folder = 'out/capstan'\n    vtk_format = 'ascii'"))
    run = yarnfort.run_scene(scene_file)
    for path in sorted(run.folder.glob("state_*.vtu"))[-2:]:
        state = results.read_state(path)
        points, elements, _, cells, fields = results._read_ascii(path)
        np.testing.assert_array_equal(state.position, points)
        np.testing.assert_array_equal(state.elements, elements)
        np.testing.assert_array_equal(state.tension, cells["tension"])
        assert set(state.field_data) == set(fields)
        for name, values in fields.items():
            np.testing.assert_array_equal(np.ravel(state.field_data[name]), values)


def test_built_scene_with_an_obstacle_and_a_ring(workdir):
    """Obstacles, rings and their laws (Contact at) built in Python, written and read
    back unchanged, and checked by the library; the pin scene runs to the capstan law."""
    scene = Scene("pin and ring", output={"folder": "out/pin"})
    scene.add_material("yarn", "linear", stiffness=10.0)
    scene.nodes = np.array([[-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]])
    scene.add_yarn("yarn", [1, 2, 3])
    scene.add_support("ends", [1])
    scene.add_support("pull", [3], displacement=[0.0, -0.2, 0.0])
    scene.add_obstacle("pin", [2])
    scene.add_contact((), "coulomb", at="pin", friction_coefficient=0.3)
    scene.path = yarnfort.LoadPath(time=[0.0, 1.0], p_disp=[0.0, 1.0])
    with pytest.raises(yarnfort.SceneError, match="given twice"):
        scene.add_ring("pin", [2])
    with pytest.raises(yarnfort.SceneError, match="one name or none"):
        yarnfort.Contact(("yarn", "yarn"), "coulomb", at="pin")
    again = Scene.read(scene.write(workdir / "pin.nml"))
    assert [(o.name, list(o.nodes)) for o in again.obstacles] == [("pin", [2])]
    assert again.contacts[0].at == "pin" and again.contacts[0].materials == ()
    run = again.run()
    state = run.states[-1]
    t = state.tension
    a, b = state.position[0] - state.position[1], state.position[2] - state.position[1]
    alpha = np.pi - np.arctan2(np.linalg.norm(np.cross(a, b)), a @ b)
    assert t[1] == pytest.approx(t[0] * np.exp(0.3 * alpha), rel=1e-8)
    ring = Scene.read(TOP / "inputs" / "clothesline.nml")
    assert [r.name for r in ring.rings] == ["ring"] and ring.contacts[0].at == "ring"
    ring.check()
