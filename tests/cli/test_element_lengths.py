# SPDX-License-Identifier: MIT
"""Per-element reference lengths (`&yarn length0`, `stretch`, and the `length0` and
`stretch` lines of a geometry file): the L0 that `prestress` makes, given per element,
reproduces the prestress run bit for bit; a stretch per element gives L0 = l / stretch;
wrong counts, both given, or given with a prestress are named errors (exit 2, nothing
written)."""
from __future__ import annotations

import subprocess
from pathlib import Path

import numpy as np
import pytest

from yarnfort import read_curve, read_state

TOP = Path(__file__).resolve().parents[2]
PROGRAM = TOP / "build" / "yarnfort"
TIMEOUT = 300

#: A pretensioned 3 x 3 cable net (two crossing yarns of each direction, shared nodes),
#: a neo-Hookean law (so that the prestress stretch is found by the law's inverse, not a
#: closed form) and a transverse pull at the middle crossings.
NODES = [
    0, 1, 0,  3, 1, 0,  0, 2, 0,  3, 2, 0,  1, 0, 0,  1, 3, 0,  2, 0, 0,  2, 3, 0,
    1, 1, 0,  2, 1, 0,  1, 2, 0,  2, 2, 0,
]
YARNS = [[1, 9, 10, 2], [3, 11, 12, 4], [5, 9, 11, 6], [7, 10, 12, 8]]
ELEMENTS_PER_SEGMENT = 2


def net(folder: Path, yarn_extra=None, prestress: float = 0.05,
        geometry: str | None = None) -> str:
    """The net's namelist; yarn_extra[y] is extra text of &yarn y (0-based)."""
    text = ("&material name = 'cord', law = 'neo_hookean', modulus = 2.0e6, area = 1.0e-6,"
            f" prestress = {prestress!r} /\n")
    if geometry is None:
        text += "&nodes xyz = " + ", ".join(str(v) for v in NODES) + " /\n"
        for y, nodes in enumerate(YARNS):
            extra = (yarn_extra or {}).get(y, "")
            text += (f"&yarn material = 'cord', nodes = {', '.join(map(str, nodes))}, "
                     f"elements_per_segment = {ELEMENTS_PER_SEGMENT} {extra} /\n")
    else:
        text += f"&geometry file = '{geometry}' /\n"
    text += ("&support name = 'rim', nodes = 1, 2, 3, 4, 5, 6, 7, 8 /\n"
             "&load nodes = 9, 10, 11, 12, force = 0, 0, -0.02 /\n"
             "&path time = 0, 1, p_force = 0, 1 /\n"
             f"&output folder = '{folder}', vtk_format = 'ascii', progress = .false. /\n")
    return text


def run(text: str, cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run([str(PROGRAM)], input=text, capture_output=True, text=True,
                          cwd=cwd, timeout=TIMEOUT)


def l0_per_yarn(state_file: Path) -> list[np.ndarray]:
    """The L0 of each yarn's elements, in order along it, from a state file."""
    state = read_state(state_file)
    per_yarn = len(state.length0) // len(YARNS)
    return [np.asarray(state.length0[y * per_yarn:(y + 1) * per_yarn]) for y in range(len(YARNS))]


def values_text(values) -> str:
    """Values with 17 significant digits: they read back to the same doubles."""
    return ", ".join(f"{v:.17g}" for v in values)


def same_outputs(a: Path, b: Path) -> None:
    """curve.csv equal but for the wall time, and every state file equal byte for byte."""
    curve_a, curve_b = read_curve(a), read_curve(b)
    assert curve_a.names == curve_b.names
    for column in curve_a.names:
        if column != "wall_time":
            assert np.array_equal(curve_a[column], curve_b[column]), column
    states = sorted(p.name for p in a.glob("state_*.vtu"))
    assert states and states == sorted(p.name for p in b.glob("state_*.vtu"))
    for name in states:
        assert (a / name).read_bytes() == (b / name).read_bytes(), name


def test_length0_per_element_reproduces_prestress_bit_for_bit(tmp_path):
    first = run(net(tmp_path / "prestress"), tmp_path)
    assert first.returncode == 0, first.stderr
    # Without sliding the reference lengths never change: those of any state are the
    # ones the prestress made (ASCII states carry 17 significant digits: exact).
    lengths = l0_per_yarn(tmp_path / "prestress" / "state_00000.vtu")
    assert all(np.all(l0 < 0.5) for l0 in lengths)      # pretensioned: shorter than l
    extra = {y: f"length0 = {values_text(l0)}" for y, l0 in enumerate(lengths)}
    second = run(net(tmp_path / "given", extra, prestress=0.0), tmp_path)
    assert second.returncode == 0, second.stderr
    same_outputs(tmp_path / "prestress", tmp_path / "given")


def test_geometry_file_length0_lines_reproduce_prestress(tmp_path):
    first = run(net(tmp_path / "prestress"), tmp_path)
    assert first.returncode == 0, first.stderr
    lengths = l0_per_yarn(tmp_path / "prestress" / "state_00000.vtu")
    geo = tmp_path / "net.geo"
    lines = [f"node {i + 1} {NODES[3 * i]} {NODES[3 * i + 1]} {NODES[3 * i + 2]}"
             for i in range(len(NODES) // 3)]
    for nodes, l0 in zip(YARNS, lengths):
        lines.append(f"yarn cord {ELEMENTS_PER_SEGMENT} " + " ".join(map(str, nodes)))
        # Split over two lines with '&', as a long list would be.
        half = len(l0) // 2
        lines.append("length0 " + " ".join(f"{v:.17g}" for v in l0[:half]) + " &")
        lines.append("    " + " ".join(f"{v:.17g}" for v in l0[half:]))
    geo.write_text("\n".join(lines) + "\n")
    second = run(net(tmp_path / "given", prestress=0.0, geometry=str(geo)), tmp_path)
    assert second.returncode == 0, second.stderr
    same_outputs(tmp_path / "prestress", tmp_path / "given")


def test_stretch_per_element_divides_the_initial_length(tmp_path):
    # Element lengths of the net are 0.5 m (segments of 1 m split in two).
    stretches = {y: np.linspace(1.01, 1.06, 6) + 0.01 * y for y in range(len(YARNS))}
    extra = {y: f"stretch = {values_text(s)}" for y, s in stretches.items()}
    done = run(net(tmp_path / "out", extra, prestress=0.0), tmp_path)
    assert done.returncode == 0, done.stderr
    lengths = l0_per_yarn(tmp_path / "out" / "state_00000.vtu")
    for y, l0 in enumerate(lengths):
        # L0 = 0.5 / stretch, one division: to the rounding of the result.
        assert np.allclose(l0, 0.5 / stretches[y], rtol=4 * np.finfo(float).eps, atol=0)


@pytest.mark.parametrize("extra, prestress, message", [
    ("length0 = 0.5, 0.5", 0.0,
     "&yarn #1: length0 has 2 values but the yarn has 6 elements (3 segments of 2)"),
    ("stretch = 7*1.0", 0.0, "&yarn #1: stretch has 7 values but the yarn has 6 elements"),
    ("length0 = 6*0.5, stretch = 6*1.0", 0.0,
     "&yarn #1: length0 and stretch are both given"),
    ("length0 = 6*0.5", 0.05, "&yarn #1: length0 is given, but its material 'cord' has "
                              "prestress = 0.05"),
    ("length0 = 0.5, 0.5, 0.0, 0.5, 0.5, 0.5", 0.0, "length0(3)"),
    ("stretch = 0.5, 0.5, -1.0, 0.5, 0.5, 0.5", 0.0, "stretch(3)"),
])
def test_bad_element_lengths_are_named_errors(tmp_path, extra, prestress, message):
    done = run(net(tmp_path / "out", {0: extra}, prestress=prestress), tmp_path)
    assert done.returncode == 2, done.stderr
    assert message in done.stderr
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize("lines, message", [
    (["length0 0.5 0.5"], "line 1: a 'length0' line belongs to the yarn line before it"),
    (["yarn cord 1 1 2", "length0 0.5", "stretch 1.0"],
     "line 3: the yarn of line 1 already has a 'length0' or 'stretch' line"),
    (["yarn cord 1 1 2", "stretch"], "line 2: a 'stretch' line lists one value per element"),
    (["yarn cord 1 1 2", "length0 abc"], "line 2: length0 value 'abc' is not a number"),
    (["yarn cord 1 1 2", "length0 0.5 0.5"],
     "yarn #1 of &geometry file"),
])
def test_bad_geometry_length_lines(tmp_path, lines, message):
    geo = tmp_path / "bad.geo"
    geo.write_text("\n".join(lines + ["node 1 0 0 0", "node 2 1 0 0"]) + "\n")
    text = ("&material name = 'cord', law = 'linear', stiffness = 10.0 /\n"
            f"&geometry file = '{geo}' /\n&support name = 'a', nodes = 1 /\n"
            "&path time = 0, 1 /\n"
            f"&output folder = '{tmp_path / 'out'}' /\n")
    done = run(text, tmp_path)
    assert done.returncode == 2, done.stderr
    assert message in done.stderr
    assert not (tmp_path / "out").exists()
