# SPDX-License-Identifier: MIT
"""Namelist syntax that the input reader (our own, not gfortran's namelist READ) must read
as the namelist rules say: repeat counts, null values, sections, quotes and '&' or '!'
inside character values. Each case is checked on the echoed input (out/input.nml), whose
values the reader must reproduce, or on the message of a case that must fail."""
from __future__ import annotations

import re

import pytest

SCENE = """&control title = {title} /
&material name = 'a', law = 'linear', stiffness = 1.0 /
&nodes xyz = {xyz} /
&yarn material = 'a', nodes = 1 2 3 /
&support name = 'left', nodes = 1 /
&support name = 'right', nodes = 3, fix = 'x', displacement = {displacement} /
&path {path} /
&output folder = 'out', vtk_every = 0, progress = .false. /
"""
PLAIN = dict(title="'t'", xyz="0 0 0  1 0 0  2 0 0", displacement="0.1 0 0",
             path="time = 0 1, p_disp = 0 1")


def echoed(run_yarnfort, **changes: str) -> str:
    run = run_yarnfort(SCENE.format(**{**PLAIN, **changes}))
    assert run.returncode == 0, run.stderr
    return (run.folder / "out" / "input.nml").read_text()


def values(echo: str, group: str, name: str) -> list[str]:
    """The value words of `name` in the last echoed `group` (over continuation lines)."""
    body = re.findall(rf"&{group}\n(.*?)\n/", echo, re.S)[-1]
    text = re.search(rf"^\s+{name} = (.*?)(?=^\s+\w+ = |\Z)", body, re.S | re.M)[1]
    return text.replace(",", " ").split()


def test_repeat_counts_and_null_values(run_yarnfort):
    echo = echoed(run_yarnfort, xyz="3*0.0, 1 2*0, 2.0, 2*0, 2*", displacement="0.1, , 0.0",
                  path="time = 0 1, p_disp = 1*0, 1")
    assert [float(v) for v in values(echo, "nodes", "xyz")] == [0, 0, 0, 1, 0, 0, 2, 0, 0]
    assert [float(v) for v in values(echo, "support", "displacement")] == [0.1, 0, 0]
    assert [float(v) for v in values(echo, "path", "p_disp")] == [0.0, 1.0]


def test_sections(run_yarnfort):
    echo = echoed(run_yarnfort, path="time(1:2) = 0 1, p_disp(2:) = 1, p_disp(:1) = 0")
    assert [float(v) for v in values(echo, "path", "p_disp")] == [0.0, 1.0]


def test_quotes_ampersand_and_bang_in_text(run_yarnfort):
    echo = echoed(run_yarnfort, title="'it''s &yarn! \"q\"'")
    assert values(echo, "control", "title") == ["'it''s", "&yarn!", "\"q\"'"]


@pytest.mark.parametrize("changes, words", [
    (dict(path="time(1:2) = 0 1 2, p_disp = 0 1"), "&path: time has more than 2 values"),
    (dict(path="time = 0, , 1, p_disp = 0 1 1"), "&path: time(2) has no value"),
    (dict(path="time = 0 1, p_disp = 0 1, time(2) = 3"),
     "&path: time(2) (line 7) sets again an entry that time (line 7) sets"),
    (dict(title="t"), "&control: t is not a valid value of title (line 1: a character"),
    (dict(xyz="0 0 0  1 0 0  2 0 0, 0*1"), "&nodes: 0*1 (line 3) in xyz: a repeat count"),
    (dict(displacement="0.1 0 0 0"), "&support #2: displacement has more than 3 values"),
])
def test_bad_syntax_is_named(run_yarnfort, changes, words):
    run = run_yarnfort(SCENE.format(**{**PLAIN, **changes}))
    assert run.returncode == 2, run.stderr
    assert words in run.stderr, run.stderr
