# SPDX-License-Identifier: MIT
"""Mutation fuzzing of TexGen models, family 'huge attributes' (issue 39 item 6).

The example models ``inputs/texgen_knit.tg3`` and ``inputs/texgen_weave.tg3`` (their
scenes' table laws made linear) get, at random with a fixed seed, on a random tag: an
attribute whose value is long (up to a few MB of text, entities, lone '&' or '<'), an
attribute with a long name, many attributes (up to 100 000), a used value (Position,
Repeat value, Width) padded with blanks or digits, a value whose closing quote is
missing, or many empty elements. Each case is read with ``check_only = .true.`` and must
satisfy the rules of tests/cli/test_fuzz.py (exit code 0 or 2, one error line iff it
fails, no crash, nothing written, within its timeout), plus:

- an unused attribute within the reader's limits changes nothing: the run passes;
- a tag with more attributes, or a value longer, than the limits fails with a message
  naming the TexGen file, the line and the limit.

The reader is linear in the file's size (a few MB take well under a second); the
per-case timeout only guards against a hang, and the cases share a wall-clock budget
(cases after it are skipped and counted, not failed).
``python tests/cli/test_fuzz_xml.py BATCH INDEX`` prints a case's mutations.
"""
from __future__ import annotations

import os
import random
import re
import shutil
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import pytest

from test_fuzz import CASE_TIMEOUT, Case, _without_tables, run_case, with_control

TOP = Path(__file__).resolve().parents[2]
SEEDS = {name: ((TOP / "inputs" / f"texgen_{name}.tg3").read_text(),
                _without_tables((TOP / "inputs" / f"texgen_{name}.nml").read_text()))
         for name in ("knit", "weave")}
#: Fixed seed: the cases are the same on every run.
SEED = 20261207
#: Batches and cases per batch.
BATCHES, CASES_PER_BATCH = 2, 30
#: Wall-clock seconds for all batches of this family together.
TOTAL_BUDGET = 90.0
#: The reader's limits (src/yarnfort/generate/xml_subset.f90).
MAX_ATTRIBUTES = 1000
MAX_ATTRIBUTE_LENGTH = 2**20
#: Lengths of long values and names: below, at and above the limit, and far above.
LENGTHS = (1000, 100_000, MAX_ATTRIBUTE_LENGTH, MAX_ATTRIBUTE_LENGTH + 1, 3_000_000)
#: Numbers of attributes added to one tag (the tags hold up to 45 already).
COUNTS = (100, 900, MAX_ATTRIBUTES + 1, 50_000, 100_000)
#: What the text of a long value is made of.
PIECES = ("x", " ", "&amp;", "&", "&#65;", "&#x41;", "&lt;", "<", ">", "'", "&#", ";")
OPENING_TAG = re.compile(r"<([A-Za-z][\w]*)")
#: Values the reader uses: padded, they must still read (blanks) or fail (digits).
USED_VALUE = re.compile(r'\b(Position|value|Width|Height)="([^"]*)"')


@dataclass
class Expect:
    """What a mutation must give: 'pass', 'limit' (exit 2 naming a limit) or 'any'."""
    outcome: str = "any"


def _tag(rng: random.Random, model: str) -> int:
    """Where a random opening tag's name ends."""
    tags = list(OPENING_TAG.finditer(model))
    return rng.choice(tags).end()


def _long_text(rng: random.Random, length: int) -> str:
    pieces = rng.sample(PIECES, rng.choice((1, 2, 3)))
    text = "".join(rng.choice(pieces) for _ in range(64))
    text = (text * (length // len(text) + 1))[:length]
    return text.replace('"', "")


def long_value(rng: random.Random, model: str, expect: Expect) -> str:
    length = rng.choice(LENGTHS)
    text = _long_text(rng, length)
    expect.outcome = "limit" if len(text) > MAX_ATTRIBUTE_LENGTH else "pass"
    at = _tag(rng, model)
    return f'{model[:at]} Padding="{text}"{model[at:]}'


def long_name(rng: random.Random, model: str, expect: Expect) -> str:
    length = rng.choice(LENGTHS)
    expect.outcome = "limit" if length > MAX_ATTRIBUTE_LENGTH else "pass"
    at = _tag(rng, model)
    return f'{model[:at]} {"n" * length}="1"{model[at:]}'


def many_attributes(rng: random.Random, model: str, expect: Expect) -> str:
    count = rng.choice(COUNTS)
    at = _tag(rng, model)
    # Up to 900 added to the at most 45 a tag holds: within the limit.
    expect.outcome = "limit" if count > MAX_ATTRIBUTES else "pass" if count <= 900 else "any"
    added = "".join(f' pad{k}="{k}"' for k in range(count))
    return model[:at] + added + model[at:]


def padded_used_value(rng: random.Random, model: str, expect: Expect) -> str:
    matches = list(USED_VALUE.finditer(model))
    match = rng.choice(matches)
    pad, length = rng.choice((" ", " ", "0", "1")), rng.choice(LENGTHS)
    # Blanks after the last number leave the numbers as they were (digits may not:
    # 'e-01' + '00' is 'e-0100').
    value = match.group(2) + pad * (length - len(match.group(2)))
    expect.outcome = ("limit" if len(value) > MAX_ATTRIBUTE_LENGTH
                      else "pass" if pad == " " else "any")
    return f'{model[:match.start(2)]}{value}{model[match.end(2):]}'


def unclosed_value(rng: random.Random, model: str, expect: Expect) -> str:
    matches = list(USED_VALUE.finditer(model))
    match = rng.choice(matches)
    padding = "x" * rng.choice(LENGTHS)
    expect.outcome = "any"      # an error; which one depends on what follows
    return model[:match.end(2)] + padding + model[match.end(2) + 1:]


def many_elements(rng: random.Random, model: str, expect: Expect) -> str:
    """Many empty elements inside a random element that is not empty."""
    ends = [m.end() for m in re.finditer(r"<[A-Za-z][^>]*[^/]>", model)]
    at = rng.choice(ends)
    expect.outcome = "pass"     # elements of another name are not read
    return model[:at] + '<Pad a="1"/>' * rng.choice(COUNTS) + model[at:]


MUTATIONS: tuple[Callable[[random.Random, str, Expect], str], ...] = (
    long_value, long_name, many_attributes, padded_used_value, unclosed_value,
    many_elements)


@dataclass
class XmlCase:
    case: Case
    model: str
    expect: str


def make_cases(batch: int, count: int) -> list[XmlCase]:
    rng = random.Random(f"{SEED}-xml-{batch}")
    cases = []
    for index in range(count):
        seed_name = rng.choice(sorted(SEEDS))
        model, scene = SEEDS[seed_name]
        expect = Expect()
        applied = []
        for _ in range(rng.choice((1, 1, 2))):
            mutation = rng.choice(MUTATIONS)
            model = mutation(rng, model, expect)
            applied.append(mutation.__name__)
        # Judged only for one mutation: another one may fail first, or on the same tag.
        if len(applied) > 1:
            expect.outcome = "any"
        text = with_control(scene, "check_only = .true.")
        case = Case("xml", batch, index, seed_name, applied, text)
        cases.append(XmlCase(case, model, expect.outcome))
    return cases


@pytest.fixture
def executable(run_yarnfort) -> Path:
    """The program under test (the run_yarnfort fixture has checked that it exists)."""
    return Path(os.environ.get("YARNFORT_EXE", TOP / "build" / "yarnfort"))


class Budget:
    """The wall-clock budget shared by the batches of this family."""
    deadline: float | None = None

    @classmethod
    def remaining(cls) -> float:
        if cls.deadline is None:
            cls.deadline = time.monotonic() + TOTAL_BUDGET
        return cls.deadline - time.monotonic()


@pytest.mark.parametrize("batch", range(BATCHES))
def test_fuzz_huge_attributes(executable, tmp_path, batch):
    """TexGen models with huge attributes: read in bounded time, refused with a message
    naming file, line and limit, or read as if the padding were not there."""
    Budget.remaining()
    problems, skipped, codes, slowest = [], 0, {0: 0, 2: 0}, 0.0
    models = tmp_path / "models"
    models.mkdir()
    for xml_case in make_cases(batch, CASES_PER_BATCH):
        case = xml_case.case
        if Budget.remaining() <= 0:
            skipped += 1
            continue
        model = models / f"{case.name}.tg3"
        model.write_text(xml_case.model)
        case.text = re.sub(r"texgen_file = '[^']*'", f"texgen_file = '{model}'", case.text)
        folder = tmp_path / case.name
        outcome = run_case(executable, case, folder)
        slowest = max(slowest, outcome.seconds)
        codes[outcome.returncode] = codes.get(outcome.returncode, 0) + 1
        if outcome.returncode not in (0, 2, None):
            outcome.problems.append("not exit code 0 or 2 for a check-only run")
        if xml_case.expect == "pass" and outcome.returncode != 0:
            outcome.problems.append("unused padding within the limits was refused")
        if xml_case.expect == "limit":
            limit = re.search(rf"texgen_file '{re.escape(str(model))}': line \d+: .*"
                              r"\(the limit of this reader\)", outcome.stderr)
            if outcome.returncode != 2 or limit is None:
                outcome.problems.append("beyond a limit, yet no message naming file, "
                                        "line and limit")
        if outcome.problems:
            problems.append(f"{case.name} ({case.seed_name}: {', '.join(case.mutations)}, "
                            f"expect {xml_case.expect}) -> exit {outcome.returncode}: "
                            f"{'; '.join(outcome.problems)}\n  stderr: "
                            f"{outcome.stderr.strip()[-300:]}")
        else:
            shutil.rmtree(folder, ignore_errors=True)
            model.unlink()
    run = sum(codes.values())
    print(f"fuzz xml batch {batch}: {run} cases run, {skipped} skipped (budget), "
          f"exit codes {codes}, slowest {slowest:.2f} s, {len(problems)} failed")
    if run == 0:
        pytest.skip("all cases skipped: wall-clock budget used up")
    assert not problems, "\n\n".join(problems[:8])


def test_fuzz_huge_attributes_reach_both_outcomes():
    """The family makes cases that must pass and cases beyond a limit (guard against
    mutations that no longer reach the reader's limits), the same on every call."""
    cases = [c for b in range(BATCHES) for c in make_cases(b, CASES_PER_BATCH)]
    assert {c.expect for c in cases} >= {"pass", "limit"}
    again = make_cases(0, CASES_PER_BATCH)
    assert [c.model for c in again] == [c.model for c in cases[:CASES_PER_BATCH]]


if __name__ == "__main__":
    # python tests/cli/test_fuzz_xml.py BATCH INDEX: the case's mutations and scene.
    batch, index = int(sys.argv[1]), int(sys.argv[2])
    chosen = make_cases(batch, index + 1)[index]
    print(chosen.case.seed_name, chosen.case.mutations, chosen.expect, len(chosen.model))
