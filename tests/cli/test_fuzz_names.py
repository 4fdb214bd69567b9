# SPDX-License-Identifier: MIT
"""Mutation fuzzing, family 'names that collide' (issue 39): every name that makes a
column of curve.csv (load channels, supports, obstacles, the numbered loads, the fixed
columns) or that other groups refer to (materials, obstacles, rings) is renamed, at
random with a fixed seed, to one that another producer already makes, or to a near
miss that must stay legal (another case, a load number that does not exist, a suffix
that is no column's).

The seeds are the example scenes of tests/cli/test_fuzz.py plus ``inputs/capstan_pins.nml``
(an obstacle); those without ``&path channels`` get them (``p_force``, ``p_disp``, with
every load and support naming its channel), so that a channel can be added. Each case
applies one to three renames and knows what each one must do:

- a collision: exit code 2, nothing written, and, when it is the only rename, the
  message names the column (``two columns 'pins_rx'``) or the name given twice;
- only near misses: the input is accepted (exit code 0);
- always: the rules of test_fuzz.run_case (no crash, one error line iff the exit code is
  not 0, nothing written on bad input, no NaN in outputs); in full runs that exit 0, the
  header of curve.csv has no name twice and has the column of every channel and set.

Most cases only check the input (``check_only``); a few run in full, bounded by
``max_steps``. All cases share a wall-clock budget (cases after it are skipped and
counted, not failed). ``python tests/cli/test_fuzz_names.py KIND INDEX`` prints a case.
"""
from __future__ import annotations

import random
import re
import shutil
import sys
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

import pytest

from test_fuzz import (FUZZ_WORKERS, SEED, SEEDS, TOP, Case, executable, run_case,  # noqa: F401
                       with_control)

#: Cases checked only, and cases run in full (max_steps = RUN_MAX_STEPS).
CHECK_CASES, RUN_CASES = 240, 30
RUN_MAX_STEPS = 3
#: Wall-clock seconds for all cases of this file together.
NAMES_BUDGET = 60.0

#: Suffixes of the per-set columns and of the load columns (curve.csv, inputs/REFERENCE.md).
SET_SUFFIXES = ("_rx", "_ry", "_rz", "_ux", "_uy", "_uz")
LOAD_SUFFIXES = ("_ux", "_uy", "_uz")
#: Columns of every curve.csv that no channel, set or load names.
FIXED_COLUMNS = ("step", "time", "direction", "slipping", "held", "jumped", "passages",
                 "newton_iterations", "residual", "step_cuts", "wall_time")

GROUP = re.compile(r"^[ \t]*[&$](?P<group>\w+)(?P<body>.*?)^[ \t]*/[ \t]*$",
                   re.MULTILINE | re.DOTALL)
NAME = re.compile(r"\bname\s*=\s*'(?P<name>[^']*)'")


# ---------------------------------------------------------------- the scenes' names

def groups(text: str) -> list[re.Match]:
    return list(GROUP.finditer(text))


def names_of(text: str, group: str) -> list[str]:
    return [m["name"] for g in groups(text) if g["group"].lower() == group
            for m in NAME.finditer(g["body"])]


def channels_of(text: str) -> list[str]:
    match = re.search(r"channels\s*=\s*((?:'[^']*'\s*,?\s*)+)", text)
    return re.findall(r"'([^']*)'", match.group(1)) if match else []


def count_group(text: str, group: str) -> int:
    return sum(g["group"].lower() == group for g in groups(text))


def numbers(text: str) -> list[str]:
    return re.findall(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eEdD][-+]?\d+)?", re.sub(r"!.*", "", text))


def with_channels(text: str) -> str:
    """The scene with `&path channels = 'p_force', 'p_disp'` and `factors` instead of
    p_force and p_disp, every &load naming 'p_force' and every &support 'p_disp'."""
    if channels_of(text):
        return text
    path = next(g for g in groups(text) if g["group"].lower() == "path")
    body = re.sub(r"!.*", "", path["body"])
    lists = {}
    for key in ("time", "p_force", "p_disp"):
        match = re.search(rf"\b{key}\s*=\s*(.*?)(?=\b[a-z_]+\s*=|\Z)", body, re.DOTALL)
        lists[key] = numbers(match.group(1)) if match else []
    n = len(lists["time"])
    force = lists["p_force"] or ["0"] * n
    disp = lists["p_disp"] or ["0"] * n
    factors = ", ".join(f"{f} {d}" for f, d in zip(force, disp))
    new_path = (f"&path\n    time = {', '.join(lists['time'])}\n"
                f"    channels = 'p_force', 'p_disp'\n    factors = {factors}\n/")
    text = text[:path.start()] + new_path + text[path.end():]
    for group, channel in (("load", "p_force"), ("support", "p_disp")):
        text = re.sub(rf"^([ \t]*[&$]{group}\b)", rf"\1\n    channel = '{channel}'", text,
                      flags=re.IGNORECASE | re.MULTILINE)
    return text


def add_channel(text: str, name: str) -> str:
    """One more channel, last, all of whose factors are 0."""
    text = with_channels(text)
    old = channels_of(text)
    listed = re.search(r"channels\s*=\s*((?:'[^']*'\s*,?\s*)+)", text)
    text = (text[:listed.start(1)] + ", ".join(f"'{c}'" for c in old + [name]) + "\n"
            + text[listed.end(1):])
    n_knots = len(numbers(re.search(r"\btime\s*=\s*([^\n]*)", text).group(1)))
    factors = re.search(r"\bfactors\s*=\s*(.*?)(?=\n\s*/|\n\s*[a-z_]+\s*=)", text, re.DOTALL)
    values = numbers(factors.group(1))
    rows = [values[k * len(old):(k + 1) * len(old)] + ["0"] for k in range(n_knots)]
    return (text[:factors.start(1)] + ", ".join(" ".join(r) for r in rows)
            + text[factors.end(1):])


def unused_channel(text: str, name: str) -> str:
    """`name`, or it with '_' appended until it is no channel of the scene yet."""
    while name in channels_of(with_channels(text)):
        name += "_"
    return name


def rename(text: str, old: str, new: str) -> str:
    """Every quoted `'old'` (its definition and every reference) becomes `'new'`."""
    return text.replace(f"'{old}'", f"'{new}'")


def set_names(text: str) -> list[str]:
    """The support sets: &support groups, then &obstacle groups (all hold a coordinate
    in the seeds)."""
    return names_of(text, "support") + names_of(text, "obstacle")


# ---------------------------------------------------------------- the renames

@dataclass
class Rename:
    """What one rename did, and what it must cause: the colliding column or name
    (`collides`), or None for a near miss that must stay legal."""
    what: str
    collides: str | None
    words: str = ""


def channel_like_set(rng, text):
    sets = set_names(text)
    column = rng.choice(sets) + rng.choice(SET_SUFFIXES)
    return add_channel(text, column), Rename(f"channel {column}", column,
                                             f"two columns '{column}'")


def channel_like_load(rng, text):
    n = count_group(text, "load")
    if n == 0:
        return channel_like_fixed(rng, text)
    column = f"load_{rng.randint(1, n)}{rng.choice(LOAD_SUFFIXES)}"
    return add_channel(text, column), Rename(f"channel {column}", column,
                                             f"two columns '{column}'")


def channel_like_fixed(rng, text):
    column = rng.choice(FIXED_COLUMNS)
    return add_channel(text, column), Rename(f"channel {column}", column,
                                             f"= '{column}' is the name of another column")


def set_like_load(rng, text):
    n = count_group(text, "load")
    if n == 0:
        return set_like_set(rng, text)
    old = rng.choice(set_names(text))
    new = f"load_{rng.randint(1, n)}"
    return rename(text, old, new), Rename(f"set {old} -> {new}", f"{new}_ux",
                                          f"two columns '{new}_u")


def set_like_set(rng, text):
    """A support takes the name of another support or of an obstacle."""
    old = rng.choice(names_of(text, "support"))
    others = sorted(set(set_names(text)) - {old})
    if not others:
        return channel_like_set(rng, text)
    new = rng.choice(others)
    # Only the definition: references to the old name (an obstacle's &contact at) stay.
    text = re.sub(rf"(\bname\s*=\s*)'{re.escape(old)}'", rf"\1'{new}'", text, count=1)
    return text, Rename(f"set {old} named {new}", new, f"'{new}'")


def channel_like_channel(rng, text):
    text = with_channels(text)
    name = rng.choice(channels_of(text))
    return add_channel(text, name), Rename(f"channel {name} twice", name,
                                           f"channel '{name}' is named twice")


def material_like_material(rng, text):
    """The first &material group again."""
    first = next(g for g in groups(text) if g["group"].lower() == "material")
    name = names_of(first.group(0), "material")[0]
    text = text[:first.end()] + "\n" + first.group(0) + text[first.end():]
    return text, Rename(f"material {name} twice", name, f"name = '{name}' is defined twice")


def near_miss(rng, text):
    """A name that looks like a colliding one but makes no column twice."""
    kind = rng.randrange(4)
    if kind == 0:          # another case: names are case-sensitive
        column = unused_channel(text, rng.choice(set_names(text))
                                + rng.choice(SET_SUFFIXES).upper())
        return add_channel(text, column), Rename(f"channel {column}", None)
    if kind == 1:          # a load that does not exist, or a number that is no column's
        n = count_group(text, "load")
        new = rng.choice([f"load_{n + 1}", "load_0", "load_01", "load_", "load_1x"])
        old = rng.choice(set_names(text))
        while new in set_names(text):
            new += "_"
        return rename(text, old, new), Rename(f"set {old} -> {new}", None)
    if kind == 2:          # a suffix that is no column's
        column = unused_channel(text, rng.choice(set_names(text))
                                + rng.choice(("_rw", "_u", "_rxx", "rx", "_fx")))
        return add_channel(text, column), Rename(f"channel {column}", None)
    column = unused_channel(text, rng.choice(set_names(text)))   # named like a set itself
    return add_channel(text, column), Rename(f"channel {column}", None)


COLLIDING = (channel_like_set, channel_like_set, channel_like_load, channel_like_fixed,
             set_like_load, set_like_load, set_like_set, channel_like_channel,
             material_like_material)


# ---------------------------------------------------------------- cases

CAPSTAN_PINS = (TOP / "inputs" / "capstan_pins.nml").read_text()
#: capstan_pins has an obstacle; with a load (of no force, on a fixed node) its columns
#: meet the load's.
NAME_SEEDS = {**SEEDS, "capstan_pins": CAPSTAN_PINS,
              "capstan_pins_load": CAPSTAN_PINS.replace(
                  "\n&contact\n", "\n&load\n    nodes = 1\n    force = 0.0, 0.0, 0.0\n/\n"
                  "\n&contact\n")}
#: Share of renames that are near misses, in check-only cases and in full runs (where an
#: accepted case checks the header of curve.csv).
NEAR_MISS_SHARE = {"check": 0.3, "run": 0.6}


@dataclass
class NameCase:
    case: Case
    renames: list[Rename] = field(default_factory=list)

    @property
    def collides(self) -> bool:
        return any(r.collides for r in self.renames)


def make_name_cases(kind: str, count: int) -> list[NameCase]:
    rng = random.Random(f"{SEED}-names-{kind}")
    cases = []
    for index in range(count):
        seed_name = rng.choice(sorted(n for n in NAME_SEEDS if n != "knit"))
        text = NAME_SEEDS[seed_name]
        renames = []
        mutations = [near_miss if rng.random() < NEAR_MISS_SHARE[kind] else rng.choice(COLLIDING)
                     for _ in range(rng.choice((1, 1, 1, 2, 3)))]
        # Near misses first: a later rename of a set could undo a collision, but the
        # last collision made always stands.
        for mutation in sorted(mutations, key=lambda m: m is not near_miss):
            text, done = mutation(rng, text)
            renames.append(done)
        text = with_control(text, "check_only = .true." if kind == "check"
                            else f"max_steps = {RUN_MAX_STEPS}")
        case = Case(f"names_{kind}", 0, index, seed_name, [r.what for r in renames], text)
        cases.append(NameCase(case, renames))
    return cases


def header_problems(folder: Path, text: str) -> list[str]:
    """A run that exits 0: curve.csv's header has each name once, and the columns of
    every channel and set."""
    curves = list(folder.rglob("curve.csv"))
    if len(curves) != 1:
        return [f"{len(curves)} curve.csv files"]
    header = curves[0].read_text().splitlines()[0].split(",")
    problems = [f"column '{c}' twice" for c in sorted(set(header)) if header.count(c) > 1]
    wanted = channels_of(text) or ["p_force", "p_disp"]
    wanted += [s + x for s in set_names(text) for x in SET_SUFFIXES]
    problems += [f"no column '{c}'" for c in wanted if c not in header]
    return problems


def check_outcome(name_case: NameCase, outcome, folder: Path) -> list[str]:
    problems = list(outcome.problems)
    code = outcome.returncode
    if code is None:
        return problems
    if name_case.collides:
        if code != 2:
            problems.append(f"a name collides ({name_case.case.mutations}), yet exit {code}")
        elif len(name_case.renames) == 1 and name_case.renames[0].words not in outcome.stderr:
            problems.append(f"the message does not name it ('{name_case.renames[0].words}')")
    elif code != 0:
        problems.append(f"near misses only, yet exit {code}")
    if code == 0 and name_case.case.kind == "names_run":
        problems += header_problems(folder, name_case.case.text)
    return problems


def run_names(executable: Path, kind: str, count: int, tmp_path: Path) -> None:
    cases = make_name_cases(kind, count)
    deadline = time.monotonic() + NAMES_BUDGET * count / (CHECK_CASES + RUN_CASES)

    def work(name_case: NameCase):
        if time.monotonic() > deadline:
            return None
        folder = tmp_path / name_case.case.name
        outcome = run_case(executable, name_case.case, folder)
        problems = check_outcome(name_case, outcome, folder)
        if not problems:
            shutil.rmtree(folder, ignore_errors=True)
        return name_case, outcome, problems

    with ThreadPoolExecutor(max_workers=FUZZ_WORKERS) as pool:
        results = [r for r in pool.map(work, cases) if r is not None]
    failed = [r for r in results if r[2]]
    for name_case, _, _ in failed:
        (tmp_path / f"{name_case.case.name}.nml").write_text(name_case.case.text)
    refused = sum(o.returncode == 2 for _, o, _ in results)
    print(f"fuzz names {kind}: {len(results)} of {count} cases run (budget), {refused} "
          f"refused, {len(results) - refused} accepted, {len(failed)} failed")
    if not results:
        pytest.skip("wall-clock budget used up before any case")
    assert not failed, "\n\n".join(
        f"{c.case.name} ({c.case.seed_name}: {', '.join(c.case.mutations)}) -> exit "
        f"{o.returncode}: {'; '.join(p)}\n  stderr: {o.stderr.strip()[-400:]}\n"
        f"  input: {tmp_path / (c.case.name + '.nml')}" for c, o, p in failed[:8])
    # The family reaches both outcomes.
    assert 0 < refused < len(results), "the renames no longer make both kinds of case"


def test_fuzz_names_check_only(executable, tmp_path):
    """Colliding names are refused with a message naming them; near misses pass."""
    run_names(executable, "check", CHECK_CASES, tmp_path)


def test_fuzz_names_full_run(executable, tmp_path):
    """The same in full runs; those that pass write a curve.csv with unique columns."""
    run_names(executable, "run", RUN_CASES, tmp_path)


def test_fuzz_names_cases_are_reproducible():
    """The same seed gives the same cases, and every seed scene takes every rename."""
    first = [c.case.text for c in make_name_cases("check", 30)]
    assert first == [c.case.text for c in make_name_cases("check", 30)]
    assert len(set(first)) > 25


if __name__ == "__main__":
    # python tests/cli/test_fuzz_names.py KIND INDEX: print one case's input.
    kind, index = sys.argv[1], int(sys.argv[2])
    sys.stdout.write(make_name_cases(kind, index + 1)[index].case.text)
