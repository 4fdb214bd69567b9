# SPDX-License-Identifier: MIT
"""Shared pytest fixtures: run the built yarnfort program on namelist text."""
from __future__ import annotations

import subprocess
from dataclasses import dataclass
from pathlib import Path

import pytest

TOP = Path(__file__).resolve().parents[1]
import os
EXECUTABLE = Path(os.environ.get("YARNFORT_EXE", TOP / "build" / "yarnfort"))


@dataclass
class Run:
    returncode: int
    stdout: str
    stderr: str
    folder: Path


@pytest.fixture
def run_yarnfort(tmp_path):
    """Run ``build/yarnfort`` with namelist text on stdin inside a fresh folder."""

    def run(text: str, *args: str, cwd: Path | None = None, timeout: float = 600) -> Run:
        where = cwd or tmp_path
        proc = subprocess.run([str(EXECUTABLE), *args], input=text, capture_output=True,
                              text=True, cwd=where, timeout=timeout)
        return Run(proc.returncode, proc.stdout, proc.stderr, where)

    if not EXECUTABLE.exists():
        pytest.fail(f"{EXECUTABLE} is missing: build first (tests/run does)")
    return run
