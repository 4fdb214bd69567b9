# SPDX-License-Identifier: MIT
"""yarnfort._blas: the OpenBLAS kernel set chosen from the processor's instruction sets
(Debian's OpenBLAS falls back to its oldest kernels on Intel models it does not know),
and that the program and the extension run with it."""
from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from yarnfort._blas import apply_openblas_core, choose_openblas_core

TOP = Path(__file__).resolve().parents[2]
AVX512 = "avx512f avx512dq avx512cd avx512bw avx512vl"


def cpuinfo(vendor: str, flags: str) -> str:
    """Two processors of /proc/cpuinfo's form (only the first one counts)."""
    first = f"processor\t: 0\nvendor_id\t: {vendor}\ncpu family\t: 6\nflags\t\t: {flags}\n"
    return first + "\nprocessor\t: 1\nvendor_id\t: Other\nflags\t\t: fpu\n"


@pytest.mark.parametrize("vendor, flags, core", [
    ("GenuineIntel", f"fpu sse3 avx fma avx2 {AVX512} avx512_bf16", "SkylakeX"),
    ("GenuineIntel", "fpu sse3 avx fma avx2", "Haswell"),
    # One AVX-512 subset missing: the AVX2 kernels.
    ("GenuineIntel", "fpu avx fma avx2 avx512f avx512dq avx512cd avx512vl", "Haswell"),
    ("GenuineIntel", "fpu sse3 avx avx2", None),      # no FMA
    ("GenuineIntel", "fpu sse3 sse4_2", None),
    ("AuthenticAMD", f"fpu avx fma avx2 {AVX512}", None),   # OpenBLAS knows its own
])
def test_core_from_the_instruction_sets(vendor, flags, core):
    assert choose_openblas_core(cpuinfo(vendor, flags)) == core


def test_no_flags_no_choice():
    assert choose_openblas_core("") is None
    assert choose_openblas_core("vendor_id\t: GenuineIntel\n") is None


def test_the_users_setting_is_kept_and_a_missing_cpuinfo_changes_nothing(tmp_path):
    info = tmp_path / "cpuinfo"
    info.write_text(cpuinfo("GenuineIntel", "fma avx2"))
    environ = {"OPENBLAS_CORETYPE": "Sandybridge"}
    assert apply_openblas_core(environ, str(info)) == "Sandybridge"
    assert environ == {"OPENBLAS_CORETYPE": "Sandybridge"}
    environ = {}
    assert apply_openblas_core(environ, str(info)) == "Haswell"
    assert environ == {"OPENBLAS_CORETYPE": "Haswell"}
    environ = {}
    assert apply_openblas_core(environ, str(tmp_path / "missing")) is None
    assert environ == {}


def openblas_core(command: list[str]) -> str:
    """The kernel set OpenBLAS reports when `command` loads it (OPENBLAS_VERBOSE=2)."""
    environ = {k: v for k, v in os.environ.items() if k != "OPENBLAS_CORETYPE"}
    environ["OPENBLAS_VERBOSE"] = "2"
    done = subprocess.run(command, capture_output=True, text=True, env=environ, timeout=120,
                          cwd=TOP)
    assert done.returncode == 0, done.stderr
    found = re.search(r"^Core: (\w+)", done.stdout + done.stderr, re.MULTILINE)
    if found is None:
        pytest.skip("the BLAS in use is not OpenBLAS (no 'Core:' line)")
    return found.group(1)


@pytest.mark.parametrize("route", ["program", "extension"])
def test_program_and_extension_run_with_the_chosen_kernels(route):
    # The choice for this processor, made as `import yarnfort` makes it (into an empty
    # environment, so that a user's setting does not hide it).
    expected = apply_openblas_core({})
    if expected is None:
        pytest.skip("no choice for this processor: OpenBLAS's own detection runs")
    if route == "program":
        command = [str(Path(sys.executable).parent / "yarnfort"), "--version"]
    else:
        command = [sys.executable, "-c", "from yarnfort._native import extension; extension()"]
    assert openblas_core(command) == expected
