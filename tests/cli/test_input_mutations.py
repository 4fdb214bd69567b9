# SPDX-License-Identifier: MIT
"""Mutations of the example inputs in the families of issue 14 that the input reader
must survive: encodings (byte order marks, CR and CR LF line ends), very long lines,
subscripts that set an entry again, values equal to the reader's old "not set"
markers, and numbers at the edges of the floating-point range.

Every case runs with ``check_only = .true.`` and a fixed seed. It must end with exit
code 0 or 2, one ``yarnfort: error (input)`` line exactly when the code is 2, no Fortran
runtime error, and nothing written. A few mutations have a known outcome, asserted
exactly (``KNOWN``)."""
from __future__ import annotations

import random
import re
import subprocess
from pathlib import Path

import pytest

from conftest import EXECUTABLE

TOP = Path(__file__).resolve().parents[2]
SCENES = {name: (TOP / "inputs" / f"{name}.nml").read_text() for name in ("vnet", "capstan")}
SEED = 20141
CASES_PER_FAMILY = 12
#: A hang guard per case (not a speed test).
TIMEOUT = 60
CRASH_MARKERS = ("Fortran runtime", "Program received signal", "Backtrace", "ERROR STOP")
MARKER_REAL = "-1.7976931348623157e308"
MARKER_INTEGER = "-2147483647"
EXTREMES = (MARKER_REAL, "1.7976931348623157e308", MARKER_INTEGER, "2147483647",
            "4.9e-324", "2.2250738585072014e-308", "-0.0", "1e300", "-1e300")


def check_only(text: str) -> str:
    """The scene with check_only = .true. as the first variable of &control."""
    if re.search(r"&control\b", text, re.IGNORECASE):
        return re.sub(r"&control\b", "&control check_only = .true.,", text, count=1,
                      flags=re.IGNORECASE)
    return "&control check_only = .true. /\n" + text


def encodings(text: str, rng: random.Random) -> bytes:
    data = text.encode()
    choice = rng.randrange(4)
    if choice == 0:
        return b"\xef\xbb\xbf" + data
    if choice == 1:
        return data.replace(b"\n", b"\r\n")
    if choice == 2:
        return data.replace(b"\n", b"\r")
    lines = data.split(b"\n")
    k = rng.randrange(len(lines))
    lines[k] = lines[k] + b"\r"
    return b"\n".join(lines)


def long_lines(text: str, rng: random.Random) -> bytes:
    lines = text.split("\n")
    k = rng.randrange(len(lines))
    pad = "x" * rng.choice((10_000, 300_000, 2_000_000))
    if rng.random() < 0.5:
        lines.insert(k, "! " + pad)
    else:
        lines[k] = lines[k] + " ! " + pad
    return "\n".join(lines).encode()


def subscripts(text: str, rng: random.Random) -> bytes:
    """Set an entry of a list again (or one beyond it) with a subscript."""
    lists = [m for m in re.finditer(r"\b(nodes|time|p_disp|p_force|xyz)\s*=", text)]
    m = rng.choice(lists)
    index = rng.choice((1, 2, 3, 50))
    value = "1" if m[1] == "nodes" else "0.5"
    end = text.index("/", m.end())
    return (text[:end] + f" {m[1]}({index}) = {value} " + text[end:]).encode()


def markers(text: str, rng: random.Random) -> bytes:
    """Replace a number by a marker or an extreme value."""
    numbers = [m for m in re.finditer(r"(?<![\w.])-?\d+(\.\d*)?([eEdD][-+]?\d+)?(?![\w.])",
                                      text)
               if not text[:m.start()].rstrip().endswith("(")]
    m = rng.choice(numbers)
    return (text[:m.start()] + rng.choice(EXTREMES) + text[m.end():]).encode()


FAMILIES = {"encodings": encodings, "long_lines": long_lines, "subscripts": subscripts,
            "markers": markers}


def run(data: bytes, folder: Path) -> subprocess.CompletedProcess:
    return subprocess.run([str(EXECUTABLE)], input=data, capture_output=True,
                          cwd=folder, timeout=TIMEOUT)


@pytest.mark.parametrize("family", sorted(FAMILIES))
def test_mutations_end_cleanly(tmp_path, family):
    rng = random.Random(f"{SEED}-{family}")
    for index in range(CASES_PER_FAMILY):
        scene = rng.choice(sorted(SCENES))
        data = FAMILIES[family](check_only(SCENES[scene]), rng)
        folder = tmp_path / f"case_{index}"
        folder.mkdir()
        proc = run(data, folder)
        stderr = proc.stderr.decode(errors="replace")
        where = f"{family} case {index} ({scene}): {stderr[-400:]}"
        assert proc.returncode in (0, 2), where
        assert not any(marker in stderr for marker in CRASH_MARKERS), where
        assert stderr.count("yarnfort: error (input): ") == (proc.returncode == 2), where
        assert not any(folder.iterdir()), where


#: Mutations with a known outcome: (scene, old text, new text, words of the result).
KNOWN = [
    ("vnet", "\n", "\r", "input checked"),
    ("vnet", "! A V-shaped", "\ufeff! A V-shaped", "input checked"),
    ("vnet", "&control", "\ufeff&control", "line 7: text outside a group"),
    ("vnet", "nodes = 1, 2, 3", "nodes = 1, 2, 3, nodes(2) = 2",
     "&yarn #1: nodes(2) (line"),
    ("vnet", "nodes = 1, 2, 3", f"nodes = 1, 2, 3, {MARKER_INTEGER}",
     f"&yarn #1: nodes(4) = {MARKER_INTEGER} is not a node"),
]


@pytest.mark.parametrize("scene, old, new, words", KNOWN)
def test_known_mutations(tmp_path, scene, old, new, words):
    text = check_only(SCENES[scene])
    assert old in text
    proc = run(text.replace(old, new, 1).encode(), tmp_path)
    assert words in proc.stderr.decode(), proc.stderr.decode()


#: Named errors of the contact-node kinds (&obstacle, &ring, &contact at), made from the
#: examples by replacing texts: (scene, [(old, new), ...], words of the one error line).
#: Each must exit with code 2 before anything is written (the scenes run for real).
NODE_SCENES = {name: (TOP / "inputs" / f"{name}.nml").read_text()
               for name in ("capstan_pins", "clothesline", "knit")}
EXTRA_NODE = "1.0,       -1.0, 0.0 ! 5: B, pulled end\n          0.0, 0.0, 0.0"
CONTACT_NODE_ERRORS = [
    ("capstan_pins", [("nodes = 2, 3, 4", "nodes = 1, 2, 3, 4")],
     "&yarn #1 ends at node 1, a node of &obstacle 'pins': a yarn passes through"),
    ("clothesline", [("nodes = 2\n/\n\n&support", "nodes = 3\n/\n\n&support"),
                     ("nodes = 1, 3", "nodes = 1")],
     "&yarn #1 ends at node 3, a node of &ring 'ring'"),
    ("capstan_pins", [("1.0,       -1.0, 0.0 ! 5: B, pulled end", EXTRA_NODE),
                      ("&support\n    name = 'fixed'", "&ring name = 'loose', nodes = 6 /\n"
                       "&support\n    name = 'fixed'")],
     "&ring 'loose': no yarn passes through node 6 (nodes(1); a ring needs at least one "
     "yarn through it)"),
    ("capstan_pins", [("1.0,       -1.0, 0.0 ! 5: B, pulled end", EXTRA_NODE),
                      ("nodes = 2, 3, 4", "nodes = 2, 3, 4, 6")],
     "&obstacle 'pins': no yarn passes through node 6 (nodes(4); an obstacle"),
    ("capstan_pins", [("\n    at = 'pins'", "\n    at = 'pin'")],
     "&contact #1: at = 'pin' is not the name of an &obstacle or &ring (defined: 'pins'); "
     "did you mean 'pins'?"),
    ("clothesline", [("\n    at = 'ring'", "\n    at = 'rings'")],
     "&contact #1: at = 'rings' is not the name of an &obstacle or &ring"),
    ("capstan_pins", [("\n    at = 'pins'", "\n    materials = 'yarn', 'yarn'")],
     "no &contact for yarn type 'yarn' at &obstacle 'pins' (&yarn #1 passes through its "
     "node 2)"),
    ("capstan_pins", [("\n    at = 'pins'", "\n    at = 'pins', materials = 'yarn', 'yarn'")],
     "&contact #1: at = 'pins' with materials(2) = 'yarn': a law at an obstacle or ring "
     "takes one yarn type"),
    ("capstan_pins", [("\n    at = 'pins'", "\n    at = 'pins', materials = 'wool'")],
     "&contact #1: materials(1) = 'wool' is not defined by any &material"),
    ("clothesline", [("&path", "&contact at = 'ring', law = 'bonded' /\n&path")],
     "&contact #2: at = 'ring' for every yarn type is also &contact #1"),
    ("capstan_pins", [("&path", "&contact at = 'pins', materials = 'yarn', law = 'bonded' /\n"
                       "&contact at = 'pins', materials = 'yarn', law = 'bonded' /\n&path")],
     "&contact #3: at = 'pins', materials = 'yarn' is also &contact #2"),
    ("capstan_pins", [("name = 'pins'", "name = 'pull'"),
                      ("\n    at = 'pins'", "\n    at = 'pull'")],
     "&obstacle: name = 'pull' is also the name of &support #2"),
    ("capstan_pins", [("&path", "&ring name = 'pins', nodes = 1 /\n&path")],
     "&ring: name = 'pins' is used twice (&obstacle #1 and &ring #1"),
    ("capstan_pins", [("&path", "&ring name = 'r', nodes = 3 /\n&path")],
     "&ring 'r': node 3 is already a node of &obstacle 'pins'"),
    ("capstan_pins", [("nodes = 2, 3, 4", "nodes = 2, 3, 9")],
     "&obstacle 'pins': nodes(3) = 9"),
    ("capstan_pins", [("name = 'pins'", "name = ''")], "&obstacle #1: name is empty"),
    ("capstan_pins", [("&path", "&load nodes = 3, force = 0, 1, 0 /\n&path")],
     "&load #1: node 3 has force(2) = 1.0 but it is a node of &obstacle 'pins', held in place"),
    ("knit", [("&path", "&ring name = 'r', nodes = 1 /\n&path")],
     "&ring: not allowed together with &fabric"),
]


@pytest.mark.parametrize("scene, replacements, words", CONTACT_NODE_ERRORS)
def test_contact_node_errors(tmp_path, scene, replacements, words):
    text = NODE_SCENES[scene]
    for old, new in replacements:
        assert old in text, old
        text = text.replace(old, new, 1)
    proc = run(text.encode(), tmp_path)
    stderr = proc.stderr.decode()
    assert proc.returncode == 2, stderr
    errors = [line for line in stderr.splitlines() if line.startswith("yarnfort: error")]
    assert len(errors) == 1 and errors[0].startswith("yarnfort: error (input): "), stderr
    assert words in errors[0], stderr
    assert not any(tmp_path.iterdir()), stderr
