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

#: A Python process that runs the scene file argv[1] through run_scene, printing
#: "STEP n" per converged step; on Ctrl-C it prints "INTERRUPTED <steps> <outcome>" and
#: the exception's text, and exits 130 (tests/cli/test_interrupt.py,
#: tests/python/test_package.py).
INTERRUPTED_RUN = r"""
import sys, yarnfort
def report(step):
    print("STEP", step.step, flush=True)
try:
    yarnfort.run_scene(sys.argv[1], progress=report)
except yarnfort.RunInterrupted as stop:
    print("INTERRUPTED", stop.result.n_steps, stop.result.outcome, flush=True)
    print(stop, flush=True)
    sys.exit(130)
print("FINISHED", flush=True)
"""


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
