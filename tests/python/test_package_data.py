# SPDX-License-Identifier: MIT
"""The package stands alone (issue 38 item 4): it carries the input reference, the
example scenes with their tables and models, and the input description; `python -m
yarnfort examples DIR` writes runnable examples and `python -m yarnfort reference`
prints the reference. The opt-in wheel test checks the same on a built wheel."""
from __future__ import annotations

import importlib.util
import os
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

import yarnfort
from yarnfort import resources

TOP = Path(__file__).resolve().parents[2]
INPUTS = TOP / "inputs"


def repository_examples() -> dict[str, bytes]:
    """Every file of inputs/ but the reference, by its path relative to the top."""
    return {path.relative_to(TOP).as_posix(): path.read_bytes()
            for path in sorted(INPUTS.rglob("*"))
            if path.is_file() and path.name != "REFERENCE.md"}


def cli(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "yarnfort", *args], capture_output=True,
                          text=True, timeout=120, cwd=cwd)


def test_package_carries_every_example_file_and_the_reference():
    # The installed list is python/meson.build's: a file added to inputs/ must be added
    # there too.
    assert resources.example_files() == sorted(repository_examples())
    assert resources.reference_text() == (INPUTS / "REFERENCE.md").read_text()


def test_examples_command_writes_runnable_examples(tmp_path):
    run = cli("examples", str(tmp_path / "ex"))
    assert run.returncode == 0, run.stderr
    written = {path.relative_to(tmp_path / "ex").as_posix(): path.read_bytes()
               for path in (tmp_path / "ex").rglob("*") if path.is_file()}
    assert written == repository_examples()
    # A scene with tables runs where they were written, by their relative paths.
    program = str(yarnfort.program_path())
    for scene in ("vnet", "knit"):
        with open(tmp_path / "ex" / "inputs" / f"{scene}.nml") as text:
            done = subprocess.run([program], stdin=text, capture_output=True, text=True,
                                  cwd=tmp_path / "ex", timeout=300)
        assert done.returncode == 0, done.stderr
        assert (tmp_path / "ex" / "out" / scene / "curve.csv").is_file()


def test_examples_command_keeps_existing_files(tmp_path):
    assert cli("examples", str(tmp_path)).returncode == 0
    scene = tmp_path / "inputs" / "vnet.nml"
    scene.write_text("! mine\n")
    again = cli("examples", str(tmp_path))
    assert again.returncode == 2
    assert "exists" in again.stderr and "--force" in again.stderr
    assert scene.read_text() == "! mine\n"
    assert cli("examples", str(tmp_path), "--force").returncode == 0
    assert scene.read_bytes() == (INPUTS / "vnet.nml").read_bytes()


def test_reference_command_prints_the_reference():
    run = cli("reference")
    assert run.returncode == 0, run.stderr
    assert run.stdout == (INPUTS / "REFERENCE.md").read_text()


def _variables_module():
    """src/yarnfort/input/variables.py itself (it imports descriptors.py beside it)."""
    folder = TOP / "src" / "yarnfort" / "input"
    sys.path.insert(0, str(folder))
    try:
        spec = importlib.util.spec_from_file_location("yarnfort_variables_under_test",
                                                      folder / "variables.py")
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
    finally:
        sys.path.remove(str(folder))
    return module


def test_installed_description_is_variables_py():
    groups = _variables_module().GROUPS
    installed = resources.input_description()["groups"]
    assert [g["name"] for g in installed] == [g.name for g in groups]
    for group, entry in zip(groups, installed):
        assert entry["kind"] == group.kind
        for var, described in zip(group.variables, entry["variables"], strict=True):
            assert (described["name"], described["type"], described["shape"],
                    described["range"], described["choices"], described["laws"]) == \
                (var.name, var.type, var.shape, var.range, var.choices, var.laws)
            assert described["default"] == var.default


@pytest.mark.skipif(os.environ.get("YARNFORT_TEST_INSTALL") != "1",
                    reason="builds a wheel of the whole package (minutes);"
                    " set YARNFORT_TEST_INSTALL=1")
def test_wheel_carries_reference_examples_and_description(tmp_path):
    # Without build isolation: the build tools of this environment (meson on its PATH).
    path = os.pathsep.join([str(Path(sys.executable).parent), os.environ.get("PATH", "")])
    subprocess.run([sys.executable, "-m", "pip", "wheel", "-q", "--no-deps",
                    "--no-build-isolation", "-w", str(tmp_path), str(TOP)], check=True,
                   timeout=3600, env=dict(os.environ, PATH=path))
    wheel = next(tmp_path.glob("yarnfort-*.whl"))
    names = set(zipfile.ZipFile(wheel).namelist())
    wanted = {f"yarnfort/data/{name}" for name in repository_examples()}
    wanted |= {"yarnfort/data/inputs/REFERENCE.md", "yarnfort/data/input_description.json",
               "yarnfort/bin/yarnfort"}
    assert wanted <= names, sorted(wanted - names)
