# SPDX-License-Identifier: MIT
"""The Python API refuses what it should (issue 38 item 6): every group and variable is
known to Python from the one input description, a typo is an error at construction that
suggests the name meant, shapes, types and ranges are checked there, no 'not set' marker
collides with a user value; read_run and run_scene return one type; a missing extra names
the pip command; integer columns are integers."""
from __future__ import annotations

import shutil
import sys
from pathlib import Path

import numpy as np
import pytest

import yarnfort
from yarnfort import Fabric, LoadPath, Scene, SceneError, UnknownVariableError

TOP = Path(__file__).resolve().parents[2]


def scene() -> Scene:
    built = Scene("checks")
    built.add_material("yarn", "linear", stiffness=10.0)
    built.nodes = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]])
    return built


def test_a_typo_is_found_at_construction_with_the_name_meant():
    with pytest.raises(UnknownVariableError,
                       match=r"&material 'yarn'.*no variable 'stifness'; did you mean"
                       r" 'stiffness'\?") as info:
        Scene().add_material("yarn", "linear", stifness=10.0)
    # Both a SceneError and a TypeError (an unexpected keyword).
    assert isinstance(info.value, SceneError) and isinstance(info.value, TypeError)
    with pytest.raises(UnknownVariableError, match="did you mean 'elements_per_segment'"):
        scene().add_yarn("yarn", [1, 2, 3], element_per_segment=2)
    with pytest.raises(UnknownVariableError, match=r"&solver.*did you mean 'max_step'"):
        Scene(solver={"max_stepp": 0.1})
    with pytest.raises(UnknownVariableError, match="did you mean 'cells'"):
        Fabric("knit", cels=[2, 2])
    with pytest.raises(UnknownVariableError, match="did you mean 'p_disp'"):
        LoadPath(time=[0, 1], extra={"p_dsp": [0, 1]})


def test_a_setting_changed_later_is_checked_before_writing(tmp_path):
    built = scene()
    built.add_yarn("yarn", [1, 2, 3])
    built.path = LoadPath(time=[0, 1], p_force=[0, 1])
    built.output["vtk_evry"] = 2
    with pytest.raises(UnknownVariableError, match="did you mean 'vtk_every'"):
        built.write(tmp_path / "x.nml")


def test_shapes_types_ranges_and_choices():
    built = scene()
    with pytest.raises(SceneError, match=r"expected shape \(n, 3\).*\(3, 2\)"):
        built.nodes = np.zeros((3, 2))
    # -1 is no 'not set' marker in Python: it is out of range.
    with pytest.raises(SceneError, match=r"&material 'a' stiffness = -1.0 N: must be > 0"):
        built.add_material("a", "linear", stiffness=-1.0)
    with pytest.raises(SceneError, match="'linaer' is not one of 'linear', 'neo_hookean',"
                       " 'table'"):
        built.add_material("b", "linaer", stiffness=1.0)
    with pytest.raises(SceneError, match="elements_per_segment: expected an integer"):
        built.add_yarn("yarn", [1, 2, 3], elements_per_segment=1.5)
    with pytest.raises(SceneError, match="progress: expected True or False"):
        Scene(output={"progress": "yes"})
    with pytest.raises(SceneError, match=r"friction_coefficient = -0.1: must be >= 0"):
        built.add_contact(("yarn", "yarn"), "coulomb", friction_coefficient=-0.1)
    with pytest.raises(SceneError, match="residual_tolerance = 0.0: must be > 0"):
        Scene(solver={"residual_tolerance": 0.0})
    with pytest.raises(SceneError, match="not a yarnfort group; did you mean &solver"):
        Scene.from_namelist(yarnfort.make_namelist({"solvr": {"max_step": 0.1}}))


def test_a_retired_choice_is_refused_with_the_programs_advice():
    """preset = 'fast' was dropped: Python refuses it as the program does, with what to
    use instead, not as an unknown value (the text is the bad-input catalogue's)."""
    expected = (TOP / "tests/data/input/bad_preset_fast.nml").read_text().splitlines()[0]
    expected = expected.removeprefix("! expect: &solver: ")
    with pytest.raises(SceneError) as info:
        Scene(solver={"preset": "FAST"})
    assert str(info.value).endswith(expected.replace("'fast'", "'FAST'"))
    assert "not one of" not in str(info.value)


def test_echoed_inputs_read_back_without_markers(tmp_path, monkeypatch):
    """An echoed input leaves unset law parameters out (no value means 'not set', issue
    38); reading it gives None, and the scene writes and checks as before."""
    shutil.copytree(TOP / "inputs", tmp_path / "inputs")
    text = (TOP / "inputs" / "knit.nml").read_text().replace("out/knit", str(tmp_path / "o"))
    (tmp_path / "knit.nml").write_text(text)
    monkeypatch.chdir(tmp_path)
    first = yarnfort.run_scene(tmp_path / "knit.nml")
    echoed = (first.folder / "input.nml").read_text()
    assert "\n    stiffness =" not in echoed and "= -1.0" not in echoed
    assert "modulus" not in echoed and "friction_coefficient = 0.3999" in echoed
    read = Scene.read(first.folder / "input.nml")
    assert [m.stiffness for m in read.materials] == [None, None]
    read.check()


def test_read_run_and_run_scene_return_one_type(tmp_path, monkeypatch):
    shutil.copytree(TOP / "inputs", tmp_path / "inputs")
    monkeypatch.chdir(tmp_path)
    ran = yarnfort.run_scene("inputs/vnet.nml")
    read = yarnfort.read_run("out/vnet")
    assert type(read) is type(ran) is yarnfort.RunResult
    assert read.outcome == "read" and read.folder == ran.folder
    assert read.n_steps == len(ran.curve)
    np.testing.assert_array_equal(read.curve["p_force"], ran.curve["p_force"])
    assert len(read.states) == len(ran.states)
    with pytest.raises(yarnfort.ResultError, match="no output folder"):
        yarnfort.read_run("out/missing")


def test_integer_columns_are_integers(tmp_path):
    path = tmp_path / "curve.csv"
    path.write_text("step,time,p_force,direction,newton_iterations\n"
                    "0,0.0000000000000000E+000,0.0E+000,0,0\n"
                    "1,1.0000000000000001E-001,1.0E-001,1,7\n"
                    "2,2.0E-001,-5.0E-001,-1,12\n")
    curve = yarnfort.read_curve(path)
    for name in ("step", "direction", "newton_iterations"):
        assert curve[name].dtype.kind == "i", name
    np.testing.assert_array_equal(curve["direction"], [0, 1, -1])
    assert curve["time"].dtype.kind == "f" and curve["p_force"][2] == -0.5


def test_a_missing_extra_names_the_pip_command(tmp_path, monkeypatch):
    path = tmp_path / "curve.csv"
    path.write_text("step,time\n0,0.0E+000\n")
    monkeypatch.setitem(sys.modules, "pandas", None)  # import pandas now fails
    with pytest.raises(ImportError, match=r"pip install 'yarnfort\[pandas\]'"):
        yarnfort.read_curve(path).to_dataframe()
    monkeypatch.setitem(sys.modules, "distributed", None)
    with pytest.raises(ImportError, match=r"pip install 'yarnfort\[dask\]'"):
        yarnfort.run_sweep(TOP / "inputs" / "vnet.nml",
                           {"material[0].stiffness": [10.0]}, support="ends",
                           scheduler="tcp://127.0.0.1:1", progress=False)


def test_minus_one_read_from_a_namelist_is_a_value(tmp_path):
    """No value means 'not set' (issue 38): stiffness = -1.0 read from a file is refused as
    out of range, in Python as by the program (tests/data/input/bad_stiffness_minus_one.nml)."""
    text = (TOP / "inputs" / "vnet.nml").read_text()
    assert "stiffness = 10.0" in text
    path = tmp_path / "minus_one.nml"
    path.write_text(text.replace("stiffness = 10.0", "stiffness = -1.0"))
    with pytest.raises(SceneError, match=r"stiffness = -1.0 N: must be > 0"):
        Scene.read(path)


def test_a_bool_or_a_string_is_no_number():
    # float(True) is 1.0 and float('10') 10.0: they used to pass as a stiffness.
    with pytest.raises(SceneError, match="'a' stiffness: expected a number, got True"):
        scene().add_material("a", "linear", stiffness=True)
    with pytest.raises(SceneError, match="prestress: expected a number, got '10'"):
        scene().add_material("a", "linear", stiffness=1.0, prestress="10")


def test_a_string_is_measured_in_bytes_and_holds_no_line_break(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)

    def vnet(title: str) -> Scene:
        built = Scene(title, output={"folder": "out"})
        built.add_material("yarn", "linear", stiffness=10.0)
        built.nodes = [[-1.0, 0, 0], [0, -0.2, 0], [1, 0, 0]]
        built.add_yarn("yarn", [1, 2, 3])
        built.add_support("ends", [1, 3])
        built.add_support("plane", [2], fix="z")
        built.add_load([2], force=[0, -0.5, 0])
        built.path = LoadPath(time=[0, 1], p_force=[0, 1])
        return built

    # 'ü' is 2 bytes in UTF-8 and &control title holds 256: 128 fit, 129 do not.
    vnet("\u00fc" * 128).check()  # the library agrees
    with pytest.raises(SceneError, match="longer than 256 characters"):
        vnet("\u00fc" * 129)
    # f90nml would write the break as the two characters '\n'.
    with pytest.raises(SceneError, match="title: 'two\\\\nlines' holds a line break"):
        vnet("two\nlines")


def test_a_path_of_another_shape_is_named_by_its_shape():
    # A (2, 1) column of two values used to be '2 values for 2 knots'.
    with pytest.raises(SceneError, match=r"p_force: shape \(2, 1\) for 2 knots"):
        LoadPath(time=[0, 1], p_force=[[0], [1]])
    with pytest.raises(SceneError, match=r"time: expected a list of at least two knots, got"
                       r" shape \(1, 2\)"):
        LoadPath(time=[[0, 1]])


def test_an_output_folder_may_be_a_path(tmp_path):
    built = Scene("path", output={"folder": tmp_path / "out"})
    assert built.output["folder"] == str(tmp_path / "out")
    built.control["title"] = Path("later")  # set after construction: written as text
    built.add_material("yarn", "linear", stiffness=1.0)
    built.path = LoadPath(time=[0, 1])
    assert built.to_namelist()["control"]["title"] == "later"
