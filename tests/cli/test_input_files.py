# SPDX-License-Identifier: MIT
"""Input that is not a plain, well-formed text: very long lines, devices, folders, closed
standard input, byte order marks and old Mac line ends. Each must either be read as
meant or fail as an input error (exit 2) with a message that points at the real cause."""
from __future__ import annotations

import subprocess
from pathlib import Path

import pytest

from conftest import EXECUTABLE

#: Generous bound on runs that must end on their own (a hang guard, not a speed test).
HANG_GUARD = 120

SCENE = """&control check_only = .true. /
&material name = 'a', law = {law} /
{network}
&support name = 'left', nodes = 1 /
&support name = 'right', nodes = {last}, fix = 'x', displacement = 0.1 0 0 /
&path time = 0 1, p_disp = 0 1 /
"""
LINEAR = "'linear', stiffness = 1.0"


def network(n: int) -> str:
    """&nodes and one &yarn through n nodes along x, each list on one line."""
    xyz = " ".join(f"{0.0123456789012345 * i:.16f} 1.0e-3 2.0e-3" for i in range(n))
    nodes = " ".join(str(i + 1) for i in range(n))
    return f"&nodes xyz = {xyz} /\n&yarn material = 'a', nodes = {nodes} /"


def run_stdin(stdin, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([str(EXECUTABLE)], stdin=stdin, capture_output=True, text=True,
                          cwd=cwd, timeout=HANG_GUARD)


def input_error(proc: subprocess.CompletedProcess) -> str:
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.count("yarnfort: error (input): ") == 1, proc.stderr
    return proc.stderr


def test_documented_longest_lines_are_read(run_yarnfort):
    """100 000 nodes with their coordinates on one line (about 6 MB) and an 8 MB
    comment line: read and checked like any other input."""
    n = 100_000
    text = "! " + "x" * 8_000_000 + "\n" + SCENE.format(law=LINEAR, network=network(n),
                                                         last=n)
    run = run_yarnfort(text, timeout=HANG_GUARD)
    assert run.returncode == 0, run.stderr
    assert f"{n} nodes, {n - 1} elements" in run.stderr


def test_stdin_without_line_ends_is_bounded(tmp_path):
    """/dev/zero never ends a line: the reader stops at its line limit with a message."""
    with open("/dev/zero", "rb") as zero:
        stderr = input_error(run_stdin(zero, tmp_path))
    assert "standard input, line 1: a line is longer than" in stderr


def test_stdin_folder(tmp_path):
    proc = subprocess.run(f"'{EXECUTABLE}' < .", shell=True, capture_output=True,
                          text=True, cwd=tmp_path, timeout=HANG_GUARD)
    stderr = input_error(proc)
    assert "standard input is empty" in stderr and "folder" in stderr


def test_stdin_closed(tmp_path):
    proc = subprocess.run(f"'{EXECUTABLE}' <&-", shell=True, capture_output=True,
                          text=True, cwd=tmp_path, timeout=HANG_GUARD)
    assert "standard input is empty" in input_error(proc)


def table_scene(table: str) -> str:
    return SCENE.format(law=f"'table', table_file = '{table}'",
                        network="&nodes xyz = 0 0 0 1 0 0 /\n&yarn material = 'a', "
                                "nodes = 1 2 /", last=2)


def test_table_with_byte_order_mark(run_yarnfort, tmp_path):
    (tmp_path / "law.csv").write_bytes(b"\xef\xbb\xbf0,0\n0.1,1.0\n0.2,2.5\n")
    run = run_yarnfort(table_scene("law.csv"))
    assert run.returncode == 0, run.stderr


def test_table_that_is_a_folder(run_yarnfort, tmp_path):
    (tmp_path / "law.csv").mkdir()
    run = run_yarnfort(table_scene("law.csv"))
    assert run.returncode == 2, run.stderr
    assert "table 'law.csv': is a folder, not a file" in run.stderr


@pytest.mark.parametrize("end", ["\r", "\r\n", "\n"], ids=["cr", "crlf", "lf"])
def test_geometry_line_ends(run_yarnfort, tmp_path, end):
    lines = ["# three nodes", "node 1 0 0 0", "node 2 1 0 0", "node 3 2 0 0",
             "yarn a 1 1 2 &", "  3"]
    (tmp_path / "net.geo").write_bytes(end.join(lines).encode() + end.encode())
    text = SCENE.format(law=LINEAR, network="&geometry file = 'net.geo' /", last=3)
    run = run_yarnfort(text)
    assert run.returncode == 0, run.stderr
    assert "3 nodes, 2 elements" in run.stderr


def test_geometry_with_byte_order_mark(run_yarnfort, tmp_path):
    (tmp_path / "net.geo").write_bytes(b"\xef\xbb\xbfnode 1 0 0 0\nnode 2 1 0 0\nyarn a 1 1 2\n")
    text = SCENE.format(law=LINEAR, network="&geometry file = 'net.geo' /", last=2)
    run = run_yarnfort(text)
    assert run.returncode == 0, run.stderr
    assert "2 nodes, 1 elements" in run.stderr


def test_geometry_file_that_is_a_folder(run_yarnfort, tmp_path):
    (tmp_path / "net.geo").mkdir()
    text = SCENE.format(law=LINEAR, network="&geometry file = 'net.geo' /", last=3)
    run = run_yarnfort(text)
    assert run.returncode == 2, run.stderr
    assert "&geometry: file 'net.geo' is a folder, not a file" in run.stderr


def test_table_without_line_ends_is_bounded(run_yarnfort):
    run = run_yarnfort(table_scene("/dev/zero"), timeout=HANG_GUARD)
    assert run.returncode == 2, run.stderr
    assert "table '/dev/zero', line 1: cannot read the line (a line is longer than" \
        in run.stderr


def test_subscript_after_a_shorter_list_is_accepted(run_yarnfort):
    """'nodes = 1 2, nodes(3) = 3' sets each entry once (issue 14 item 9 must not turn
    this into an error); the yarn then has 3 nodes, 2 elements."""
    network = ("&nodes xyz = 0 0 0  1 0 0  2 0 0 /\n"
               "&yarn material = 'a', nodes = 1 2, nodes(3) = 3 /")
    run = run_yarnfort(SCENE.format(law=LINEAR, network=network, last=3))
    assert run.returncode == 0, run.stderr
    assert "3 nodes, 2 elements" in run.stderr
