# SPDX-License-Identifier: MIT
"""Shared pytest fixtures: run the built yarnfort program on namelist text."""
from __future__ import annotations

import os
import subprocess
from dataclasses import dataclass
from pathlib import Path

import pytest

import yarnfort

TOP = Path(__file__).resolve().parents[1]
#: The program of the installed package (tools/bootstrap: the editable install, whose
#: build folder is build/), or $YARNFORT_EXE.
EXECUTABLE = Path(os.environ.get("YARNFORT_EXE") or yarnfort.program_path())


@dataclass
class Run:
    returncode: int
    stdout: str
    stderr: str
    folder: Path


@pytest.fixture
def run_yarnfort(tmp_path):
    """Run the yarnfort program with namelist text on stdin inside a fresh folder."""

    def run(text: str, *args: str, cwd: Path | None = None, timeout: float = 600) -> Run:
        where = cwd or tmp_path
        proc = subprocess.run([str(EXECUTABLE), *args], input=text, capture_output=True,
                              text=True, cwd=where, timeout=timeout)
        return Run(proc.returncode, proc.stdout, proc.stderr, where)

    if not EXECUTABLE.exists():
        pytest.fail(f"{EXECUTABLE} is missing: build first (tests/run does)")
    return run
