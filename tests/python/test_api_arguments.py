# SPDX-License-Identifier: MIT
"""Python API arguments and missing files (issue 39 items 9 and 11): a missing state is a
FileNotFoundError with either VTK reader, and a progress argument that is neither a bool
nor a callable is a TypeError before anything runs."""
from __future__ import annotations

import re
import sys
from pathlib import Path

import pytest

import yarnfort
from yarnfort import Scene

TOP = Path(__file__).resolve().parents[2]
COLLECTION = """<?xml version="1.0"?>
<VTKFile type="Collection" version="1.0">
  <Collection>
    <DataSet timestep="0.0" file="state_00000.vtu"/>
  </Collection>
</VTKFile>
"""


@pytest.fixture(params=["meshio", "ascii reader"])
def reader(request, monkeypatch) -> str:
    """Both state readers: meshio (where installed) and the built-in ASCII one."""
    if request.param == "meshio":
        pytest.importorskip("meshio")
    else:
        monkeypatch.setitem(sys.modules, "meshio", None)   # import meshio fails
    return request.param


def test_read_state_of_a_missing_file_is_file_not_found(tmp_path, reader):
    missing = tmp_path / "state_00000.vtu"
    with pytest.raises(FileNotFoundError) as info:
        yarnfort.read_state(missing)
    assert info.value.filename == str(missing)
    (tmp_path / "states.pvd").write_text(COLLECTION)
    # Caught as the OSError it is, by code that reads whatever a folder holds.
    with pytest.raises(OSError, match=re.escape(str(missing))):
        yarnfort.read_states(tmp_path)


@pytest.mark.parametrize("progress", ["yes", 42, None, 1.0, [True]])
def test_run_scene_progress_must_be_a_bool_or_a_callable(tmp_path, monkeypatch, progress):
    monkeypatch.chdir(tmp_path)
    text = (TOP / "inputs" / "vnet.nml").read_text()
    text, count = re.subn(r"(?m)^(\s*folder\s*=\s*)'[^']*'", r"\1'out'", text)
    assert count == 1
    (tmp_path / "vnet.nml").write_text(text)
    with pytest.raises(TypeError, match=r"progress must be a bool or a callable") as info:
        yarnfort.run_scene(tmp_path / "vnet.nml", progress=progress)
    assert repr(progress) in str(info.value)
    with pytest.raises(TypeError, match=r"progress must be a bool or a callable"):
        Scene("never run", output={"folder": "out"}).run(progress=progress)
    assert not (tmp_path / "out").exists()
