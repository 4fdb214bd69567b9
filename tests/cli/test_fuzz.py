# SPDX-License-Identifier: MIT
"""Mutation fuzzing of the input: the example scenes with random damage must never crash.

The example inputs ``inputs/vnet.nml``, ``inputs/capstan.nml``, ``inputs/ring_sideways.nml``
(load channels) and ``inputs/knit.nml`` (its
table laws made linear) are mutated at random
with a fixed seed: characters and lines deleted, inserted, duplicated or swapped, the text
truncated, numbers replaced by extreme values (0, -1, 1e300, nan, huge integers, ...),
small integers or scaled ones, names replaced by garbage, group names changed, '=', '/'
and ',' swapped, quotes broken, subscripts and repeat counts added; and the families of
issue 14: other encodings (a UTF-8 byte order mark, CR-only or CRLF line ends, bytes that
are not ASCII, a NUL), long lines (a group or the whole input on one line, a comment line
of 200 kB), an entry set again by a later subscript, and the reader's own "not set"
markers as values (-huge, -2147483647). Most cases only read
and check the input (``check_only = .true.`` put first in &control: reading, checks and
scene set-up, no solve, no output); a few hundred run in full, bounded by
``max_steps = RUN_MAX_STEPS`` in &control and a per-case timeout. For every case:

- the exit code is 0, 1 or 2: no signal, no timeout;
- stderr has exactly one ``yarnfort: error (...)`` line when the exit code is not 0 and
  none when it is 0, and never a Fortran runtime error or a backtrace;
- a case that fails on its input writes nothing, nor does a check-only case;
- no output file (curve.csv, states.pvd, the VTK states) holds NaN or Infinity (the
  states are read with yarnfort.read_state, their other blocks with meshio, whatever
  their encoding).

A third family damages restart files: a run of each seed stops after a few steps
(``max_steps``), then bytes or whole fields of its ``restart.dat`` are overwritten at
random (sizes, step, time, knot, next step, load factors, flags, values) and the run is
continued with ``restart = .true.``. Beyond the rules above, a restart that is accepted
(exit code 0) must give the curve of the uninterrupted run (1e-6 relative): a damaged
file is refused or harmless, never silently used.

Cases run in batches (one pytest item per batch) on ``FUZZ_WORKERS`` processes (default
2), each case in a folder of its own under the test's tmp folder; file names in the
mutated inputs are kept relative and inside it (``sanitize``). Every batch must also
have some cases that pass (guard against mutations that no longer reach the solver).
Batches share a wall-clock budget: cases that would start after it are skipped and
counted (reported, not failed), so a slow machine makes the test shorter, not longer.
A failing case is written to the tmp folder as ``case_<kind>_<batch>_<index>.nml``;
``python tests/cli/test_fuzz.py KIND BATCH INDEX`` prints it again.
"""
from __future__ import annotations

import math
import os
import random
import re
import shutil
import struct
import subprocess
import sys
import threading
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

import meshio
import numpy as np
import pytest

from test_faults import CHECKSUM_LENGTH, checksum
from yarnfort.results import read_curve, read_state

TOP = Path(__file__).resolve().parents[2]
SEEDS = {name: (TOP / "inputs" / f"{name}.nml").read_text()
         for name in ("vnet", "capstan", "ring_sideways")}


def _without_tables(text: str) -> str:
    """The scene with its table laws made linear: its table files are relative to the
    repository top, and each case runs in a folder of its own."""
    text = re.sub(r"law = 'table'", "law = 'linear'", text)
    return re.sub(r"table_file = '[^']*'", "stiffness = 5.0", text)


#: The generated knitted fabric (&fabric) too: its reader, checks and generator.
SEEDS["knit"] = _without_tables((TOP / "inputs" / "knit.nml").read_text())

#: Fixed seed: the cases are the same on every run.
SEED = 20250611
#: Check-only cases (read + checks + scene set-up) and full runs, each in batches.
CHECK_BATCHES, CHECK_CASES_PER_BATCH = 12, 250
RUN_BATCHES, RUN_CASES_PER_BATCH = 12, 50
#: Seconds one case may take.
CASE_TIMEOUT = 20.0
#: Full runs stop after this many load steps (&control max_steps, exit code 0): a mutated
#: path or step size can make a valid scene of 1e4 and more steps (vnet: 20).
RUN_MAX_STEPS = 1000
#: Wall-clock seconds for all batches together (cases after it are skipped, not failed).
TOTAL_BUDGET = 150.0
#: Parallel yarnfort processes.
FUZZ_WORKERS = int(os.environ.get("FUZZ_WORKERS", "2"))
#: Least share of the cases of a batch that must exit 0 (measured: about 1/4 or more).
MIN_PASSING_SHARE = 0.05

GROUPS = ("control", "solver", "material", "contact", "fabric", "nodes", "geometry",
          "yarn", "support", "load", "path", "output")
#: Replacements for a number. Huge values are rejected as input or make the solve fail
#: fast; path times so large that a step could not advance the pseudo-time (above about
#: 5e7 with the default min_step) are rejected too. Steps in number are RUN_MAX_STEPS.
EXTREME_VALUES = ("0", "-1", "-0.0", "1", "1e300", "-1e300", "1e-300", "4.9e-324", "1e-320",
                  "nan", "NaN", "-nan", "inf", "-Infinity", "2147483647", "2147483648",
                  "-2147483648", "-2147483649", "99999999999999999999", "1d999",
                  "1.7976931348623157e308", "0.5", ".5", "1.", "+", "-", "e5", "5e", "1e", "T",
                  ".true.", "3*", "*", "'x'", "''")
SUBSCRIPTS = ("0", "-1", "1", "2", "3", "4", "7", "100000", "100001", "300001", "2147483647",
              "-2147483648", "1:2", "2:1", "", "*", "1,1", "x")
REPEATS = ("0", "1", "2", "3", "99999", "100000", "100001", "300001", "2147483647",
           "99999999999", "-1")
#: Every variable of every group (inserted into random groups, mostly the wrong one).
VARIABLES = ("title", "check_only", "restart", "max_steps", "linear_solver",
             "residual_tolerance", "step_tolerance", "max_iterations", "max_setup_calls",
             "line_search", "slack_stiffness", "initial_step", "min_step", "max_step",
             "step_growth", "step_cut", "easy_iterations", "max_step_cuts", "scheme",
             "max_friction_iterations", "min_length_ratio", "friction_tolerance", "name", "law",
             "stiffness", "modulus", "area", "table_file", "prestress", "materials",
             "friction_coefficient", "adhesion", "decay_start", "decay_end", "xyz", "file",
             "material", "nodes", "elements_per_segment", "fix", "displacement", "force", "time",
             "p_force", "p_disp", "folder", "vtk_every", "progress", "residual_history", "kind",
             "cells", "spacing")
GARBAGE_CHARACTERS = ("abcdefghijklmnopqrstuvwxyzABCXYZ0123456789_ &/=!'\",*()$;.:%\t-+")
#: Values equal to the reader's internal "not set" markers, and their neighbours.
MARKER_VALUES = ("-1.7976931348623157e308", "-1.7976931348623157d308", "-1.797e308",
                 "1.7976931348623157e308", "-2147483647", "-2147483648", "2147483647",
                 "-1", "-1.0")
#: Text that is not plain ASCII: accented letters, a byte order mark, a NUL, a tab.
FOREIGN_TEXT = ("\u00e9", "\u00b5m", "\ufeff", "\x00", "\t", "\u2013", "\x7f")

NUMBER = re.compile(r"(?<![\w.])[-+]?(?:\d+\.?\d*|\.\d+)(?:[eEdD][-+]?\d+)?(?![\w.])")
WORD = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
GROUP_NAME = re.compile(r"[&$]([A-Za-z_]\w*)")
ASSIGNMENT = re.compile(r"\b([A-Za-z_]\w{0,63})(\s*=)")
DELIMITER = re.compile(r"[=/,]")
QUOTE = re.compile(r"['\"]")

ERROR_LINE = re.compile(r"^yarnfort: error \([a-z]+\): \S", re.MULTILINE)
CRASH_MARKERS = ("Fortran runtime", "Program received signal", "Backtrace", "ERROR STOP",
                 "Error termination", "Segmentation fault", "malloc", "core dumped")
NON_FINITE = re.compile(r"(?<![A-Za-z_])[-+]?(?:nan|inf(?:inity)?)(?![A-Za-z_])", re.IGNORECASE)


# ---------------------------------------------------------------- mutations

def _pick(rng: random.Random, pattern: re.Pattern, text: str) -> re.Match | None:
    matches = list(pattern.finditer(text))
    return rng.choice(matches) if matches else None


def _replace(text: str, match: re.Match, new: str, group: int = 0) -> str:
    return text[:match.start(group)] + new + text[match.end(group):]


def _garbage(rng: random.Random) -> str:
    kind = rng.randrange(6)
    if kind == 0:
        return ""
    if kind == 1:
        return "x" * rng.choice((65, 300, 600, 3000))
    if kind == 2:
        return "".join(rng.choice("abcdefghijklmnopqrstuvwxyz_") for _ in range(rng.randint(1, 9)))
    return "".join(rng.choice(GARBAGE_CHARACTERS) for _ in range(rng.randint(1, 8)))


def delete_character(rng: random.Random, text: str) -> str:
    if not text:
        return text
    i = rng.randrange(len(text))
    return text[:i] + text[i + 1:]


def insert_character(rng: random.Random, text: str) -> str:
    i = rng.randint(0, len(text))
    return text[:i] + rng.choice(GARBAGE_CHARACTERS) + text[i:]


def delete_line(rng: random.Random, text: str) -> str:
    lines = text.splitlines(keepends=True)
    if lines:
        del lines[rng.randrange(len(lines))]
    return "".join(lines)


def duplicate_line(rng: random.Random, text: str) -> str:
    lines = text.splitlines(keepends=True)
    if lines:
        i = rng.randrange(len(lines))
        lines.insert(rng.randint(0, len(lines)), lines[i])
    return "".join(lines)


def swap_lines(rng: random.Random, text: str) -> str:
    lines = text.splitlines(keepends=True)
    if len(lines) > 1:
        i, j = rng.sample(range(len(lines)), 2)
        lines[i], lines[j] = lines[j], lines[i]
    return "".join(lines)


def extreme_number(rng: random.Random, text: str) -> str:
    match = _pick(rng, NUMBER, text)
    return _replace(text, match, rng.choice(EXTREME_VALUES)) if match else text


def small_integer(rng: random.Random, text: str) -> str:
    """A node id, count or factor changed to a small integer (dangling ids, repeated
    nodes, duplicate segments, supports that overlap)."""
    match = _pick(rng, NUMBER, text)
    return _replace(text, match, str(rng.randint(-1, 9))) if match else text


def scale_number(rng: random.Random, text: str) -> str:
    match = _pick(rng, NUMBER, text)
    if not match:
        return text
    try:
        value = float(match.group(0).replace("d", "e").replace("D", "e"))
    except ValueError:
        return text
    return _replace(text, match, repr(value * rng.choice((-1.0, 1e-8, 1e-3, 1e3, 1e8, 1e150))))


def swap_numbers(rng: random.Random, text: str) -> str:
    matches = list(NUMBER.finditer(text))
    if len(matches) < 2:
        return text
    first, second = sorted(rng.sample(matches, 2), key=lambda m: m.start())
    return (text[:first.start()] + second.group(0) + text[first.end():second.start()]
            + first.group(0) + text[second.end():])


def add_assignment(rng: random.Random, text: str) -> str:
    """A variable (of any group) with an extreme value, first in a random group."""
    match = _pick(rng, GROUP_NAME, text)
    if not match:
        return text
    value = rng.choice(EXTREME_VALUES + ("'dense'", "'staggered'", "'table'", "'x'", ".false."))
    return _replace(text, match, f"{match.group(0)} {rng.choice(VARIABLES)} = {value},")


def truncate(rng: random.Random, text: str) -> str:
    return text[:rng.randrange(len(text))] if text else text


def garbage_name(rng: random.Random, text: str) -> str:
    match = _pick(rng, WORD, text)
    return _replace(text, match, _garbage(rng)) if match else text


def rename_group(rng: random.Random, text: str) -> str:
    match = _pick(rng, GROUP_NAME, text)
    if not match:
        return text
    new = rng.choice(GROUPS + ("end", "END", "Solver", "solvr", "materials", "")) \
        if rng.random() < 0.8 else _garbage(rng)
    return _replace(text, match, new, 1)


def swap_delimiter(rng: random.Random, text: str) -> str:
    match = _pick(rng, DELIMITER, text)
    return _replace(text, match, rng.choice(("", "=", "/", ",", "&", "!", " ", "=="))) \
        if match else text


def add_subscript(rng: random.Random, text: str) -> str:
    match = _pick(rng, ASSIGNMENT, text)
    return _replace(text, match, f"{match.group(1)}({rng.choice(SUBSCRIPTS)})", 1) \
        if match else text


def add_repeat_count(rng: random.Random, text: str) -> str:
    match = _pick(rng, NUMBER, text)
    return _replace(text, match, f"{rng.choice(REPEATS)}*{match.group(0)}") if match else text


def break_quote(rng: random.Random, text: str) -> str:
    match = _pick(rng, QUOTE, text)
    if not match:
        return text
    return _replace(text, match, rng.choice(("", "''", "'", '"', "&yarn", "!")))


def long_value(rng: random.Random, text: str) -> str:
    match = _pick(rng, NUMBER, text)
    value = rng.choice(("1" * 400, "0." + "0" * 1000 + "1", "1" + "0" * 400, "9" * 30,
                        ", ".join(["1"] * 2000)))
    return _replace(text, match, value) if match else text


def byte_order_mark(rng: random.Random, text: str) -> str:
    return "\ufeff" + text


def line_ends(rng: random.Random, text: str) -> str:
    """CR-only (old Mac) or CRLF line ends, everywhere or from a random line on."""
    end = rng.choice(("\r", "\r\n"))
    lines = text.split("\n")
    start = rng.randrange(len(lines)) if rng.random() < 0.3 else 0
    return "\n".join(lines[:start]) + ("\n" if start else "") + end.join(lines[start:])


def foreign_text(rng: random.Random, text: str) -> str:
    i = rng.randint(0, len(text))
    return text[:i] + rng.choice(FOREIGN_TEXT) + text[i:]


def one_line(rng: random.Random, text: str) -> str:
    """A group, or the whole input, on one line (comments dropped: they would swallow
    the rest of the line)."""
    body = re.sub(r"!.*", "", text)
    if rng.random() < 0.5:
        return " ".join(body.splitlines())
    groups = list(re.finditer(r"[&$]\w+.*?^\s*/", body, flags=re.MULTILINE | re.DOTALL))
    if not groups:
        return body
    g = rng.choice(groups)
    return body[:g.start()] + " ".join(g.group(0).splitlines()) + body[g.end():]


def long_comment(rng: random.Random, text: str) -> str:
    lines = text.splitlines(keepends=True)
    lines.insert(rng.randint(0, len(lines)), "! " + "x" * 200_000 + "\n")
    return "".join(lines)


def subscript_again(rng: random.Random, text: str) -> str:
    """An entry of an assigned list set again by a later subscript in the same group
    (documented "set only once"; e.g. p_force = 0, 1, 0 then p_force(2) = 3)."""
    match = _pick(rng, ASSIGNMENT, text)
    if not match:
        return text
    end = text.find("/", match.end())
    if end < 0:
        return text
    value = rng.choice(("3", "0.5", "1", "'x'", ".true."))
    return text[:end] + f" {match.group(1)}({rng.randint(1, 3)}) = {value} " + text[end:]


def marker_value(rng: random.Random, text: str) -> str:
    match = _pick(rng, NUMBER, text)
    return _replace(text, match, rng.choice(MARKER_VALUES)) if match else text


MUTATIONS = (delete_character, insert_character, delete_line, duplicate_line, swap_lines,
             extreme_number, extreme_number, extreme_number, small_integer, small_integer,
             scale_number, swap_numbers, truncate, garbage_name, rename_group, swap_delimiter,
             add_subscript, add_repeat_count, break_quote, long_value, add_assignment,
             add_assignment, byte_order_mark, line_ends, foreign_text, one_line, long_comment,
             subscript_again, subscript_again, marker_value, marker_value)


def sanitize(text: str) -> str:
    """Keep every file name relative and inside the case's folder (tests may run as
    root): no '..' and no absolute path in a character value."""
    while ".." in text:
        text = text.replace("..", ".")
    return re.sub(r"(['\"])([ \t]*)[/~]+", r"\1\2", text)


@dataclass
class Case:
    kind: str
    batch: int
    index: int
    seed_name: str
    mutations: list[str]
    text: str

    @property
    def name(self) -> str:
        return f"case_{self.kind}_{self.batch}_{self.index}"


def with_control(text: str, setting: str) -> str:
    """``setting`` first in the (first) &control group, or in a new &control group."""
    match = re.search(r"[&$]control\b", text, flags=re.IGNORECASE)
    if match is None:
        return text + f"\n&control {setting} /\n"
    return text[:match.end()] + f" {setting}," + text[match.end():]


def make_cases(kind: str, batch: int, count: int) -> list[Case]:
    rng = random.Random(f"{SEED}-{kind}-{batch}")
    cases = []
    for index in range(count):
        seed_name = rng.choice(sorted(SEEDS))
        text = SEEDS[seed_name]
        applied = []
        for _ in range(rng.choice((1, 1, 1, 2, 2, 3))):
            mutation = rng.choice(MUTATIONS)
            text = mutation(rng, text)
            applied.append(mutation.__name__)
        text = with_control(text, "check_only = .true." if kind == "check"
                            else f"max_steps = {RUN_MAX_STEPS}")
        cases.append(Case(kind, batch, index, seed_name, applied, sanitize(text)))
    return cases


# ---------------------------------------------------------------- running and checking

@dataclass
class Outcome:
    case: Case
    problems: list[str] = field(default_factory=list)
    returncode: int | None = None
    stderr: str = ""
    seconds: float = 0.0


def non_finite_in_outputs(folder: Path) -> list[str]:
    """Output files that hold NaN or Infinity, with the first bad value."""
    bad = []
    for path in sorted(folder.rglob("*")):
        if not path.is_file():
            continue
        text = path.read_text(errors="replace")
        if path.name.endswith(".csv"):
            for line in text.splitlines()[1:]:
                for value in line.split(","):
                    try:
                        finite = math.isfinite(float(value))
                    except ValueError:
                        finite = NON_FINITE.search(value) is None
                    if not finite:
                        bad.append(f"{path.name}: {value}")
                        break
        elif path.name.startswith("state_") and path.suffix in (".vtu", ".vtm"):
            # A state (the yarns' file, or the multiblock file that lists its blocks).
            try:
                state = read_state(path)
            except Exception as error:          # noqa: BLE001 (any unreadable state)
                bad.append(f"{path.name}: unreadable ({error})")
                continue
            arrays = [state.position, state.tension, state.stretch, state.length0,
                      *state.point_data.values(), *state.cell_data.values()]
            if not all(np.all(np.isfinite(np.asarray(a, dtype=float))) for a in arrays):
                bad.append(f"{path.name}: a non-finite value")
        elif path.suffix == ".vtu":
            # A state's other block (gap-holders, periodic links, passages).
            try:
                block = meshio.read(path)
            except Exception as error:          # noqa: BLE001 (any unreadable block)
                bad.append(f"{path.name}: unreadable ({error})")
                continue
            arrays = [block.points, *block.point_data.values(), *block.field_data.values(),
                      *(a for per_type in block.cell_data.values() for a in per_type)]
            if not all(np.all(np.isfinite(np.asarray(a, dtype=float))) for a in arrays):
                bad.append(f"{path.name}: a non-finite value")
        elif path.suffix == ".pvd":
            match = NON_FINITE.search(" ".join(re.findall(r'timestep="([^"]*)"', text)))
            if match:
                bad.append(f"{path.name}: {match.group(0)}")
    return bad


def run_case(executable: Path, case: Case, folder: Path) -> Outcome:
    outcome = Outcome(case)
    folder.mkdir(parents=True)
    start = time.monotonic()
    try:
        proc = subprocess.run([str(executable)], input=case.text.encode(), capture_output=True,
                              cwd=folder, timeout=CASE_TIMEOUT)
    except subprocess.TimeoutExpired:
        outcome.seconds = time.monotonic() - start
        outcome.problems.append(f"timeout after {CASE_TIMEOUT} s")
        return outcome
    outcome.seconds = time.monotonic() - start
    outcome.returncode = proc.returncode
    outcome.stderr = proc.stderr.decode(errors="replace")
    errors = ERROR_LINE.findall(outcome.stderr)
    if proc.returncode not in (0, 1, 2):
        outcome.problems.append(f"exit code {proc.returncode}")
    for marker in CRASH_MARKERS:
        if marker in outcome.stderr:
            outcome.problems.append(f"'{marker}' on stderr")
    if proc.returncode == 0 and errors:
        outcome.problems.append("exit code 0 with an error line")
    if proc.returncode != 0 and len(errors) != 1:
        outcome.problems.append(f"exit code {proc.returncode} with {len(errors)} error lines")
    if "yarnfort: error (input)" in outcome.stderr and any(folder.iterdir()):
        outcome.problems.append("bad input, yet files were written: "
                                + ", ".join(p.name for p in folder.iterdir()))
    if "check_only = .true.), nothing solved" in outcome.stderr and any(folder.iterdir()):
        outcome.problems.append("check_only run wrote files")
    outcome.problems.extend(non_finite_in_outputs(folder))
    return outcome


class Budget:
    """The wall-clock budget shared by all batches of one pytest session."""
    deadline: float | None = None

    @classmethod
    def remaining(cls) -> float:
        if cls.deadline is None:
            cls.deadline = time.monotonic() + TOTAL_BUDGET
        return cls.deadline - time.monotonic()


def run_batch(executable: Path, kind: str, batch: int, count: int, tmp_path: Path) -> None:
    cases = make_cases(kind, batch, count)
    Budget.remaining()
    skipped = []
    lock = threading.Lock()

    def work(case: Case) -> Outcome | None:
        if Budget.remaining() <= 0:
            with lock:
                skipped.append(case.index)
            return None
        folder = tmp_path / case.name
        outcome = run_case(executable, case, folder)
        if not outcome.problems:
            shutil.rmtree(folder, ignore_errors=True)
        return outcome

    with ThreadPoolExecutor(max_workers=FUZZ_WORKERS) as pool:
        outcomes = [o for o in pool.map(work, cases) if o is not None]
    failed = [o for o in outcomes if o.problems]
    for outcome in failed:
        (tmp_path / f"{outcome.case.name}.nml").write_text(outcome.case.text)
    codes = {code: sum(o.returncode == code for o in outcomes) for code in (0, 1, 2)}
    slowest = max((o.seconds for o in outcomes), default=0.0)
    print(f"fuzz {kind} batch {batch}: {len(outcomes)} cases run, {len(skipped)} skipped "
          f"(budget), exit codes {codes}, slowest {slowest:.2f} s, {len(failed)} failed")
    if not outcomes:
        pytest.skip(f"all {count} cases skipped: wall-clock budget used up")
    assert not failed, "\n\n".join(
        f"{o.case.name} ({o.case.seed_name}: {', '.join(o.case.mutations)}) -> "
        f"exit {o.returncode}: {'; '.join(o.problems)}\n  stderr: {o.stderr.strip()[-400:]}\n"
        f"  input: {tmp_path / (o.case.name + '.nml')}"
        for o in failed[:8])
    assert codes[0] >= MIN_PASSING_SHARE * len(outcomes), \
        f"only {codes[0]} of {len(outcomes)} mutated inputs ran: do the seeds still run?"


@pytest.fixture
def executable(run_yarnfort) -> Path:
    """The program under test (the run_yarnfort fixture has checked that it exists)."""
    return Path(os.environ.get("YARNFORT_EXE", TOP / "build" / "yarnfort"))


@pytest.mark.parametrize("batch", range(CHECK_BATCHES))
def test_fuzz_check_only(executable, tmp_path, batch):
    """Mutated inputs, read and checked only: never a crash, an error iff exit code."""
    run_batch(executable, "check", batch, CHECK_CASES_PER_BATCH, tmp_path)


@pytest.mark.parametrize("batch", range(RUN_BATCHES))
def test_fuzz_full_run(executable, tmp_path, batch):
    """Mutated inputs, run in full: never a crash or a hang, no NaN in any output."""
    run_batch(executable, "run", batch, RUN_CASES_PER_BATCH, tmp_path)


# ---------------------------------------------------------------- damaged restart files

#: Restart cases per batch, and batches.
RESTART_BATCHES, RESTART_CASES_PER_BATCH = 2, 40
#: Byte offsets and types of the header fields of restart.dat (format version 4, see
#: src/yarnfort/output/restart_file.f90): after the 16-byte magic, the version and the
#: 16-byte fingerprint come n_nodes, n_elements, n_unknowns, n_passages, step, knot
#: (int32), time, next_step, previous_load (float64), the stepper (16 bytes),
#: n_channels (int32), load_old, time_old (float64), have_old (int32), then the factors of the
#: channels (float64; the seeds' first two channels: p_force and p_disp, or down and
#: side); the arrays follow.
RESTART_FIELDS = ([(36 + 4 * k, "<i") for k in range(6)]
                  + [(60 + 8 * k, "<d") for k in range(3)]
                  + [(100, "<i"), (104, "<d"), (112, "<d"), (120, "<i"), (124, "<d"),
                     (132, "<d")])
INT_DAMAGE = (0, -1, 1, 2, 7, 1000, 2**31 - 1, -2**31, 123456)
REAL_DAMAGE = (0.0, -1.0, 1e-300, 1e300, -1e300, float("nan"), float("inf"), 0.5, 2.0,
               1e8, -0.0)
#: Curve columns compared between an accepted restart and the uninterrupted run.
CURVE_RTOL = 1e-6


def output_folder(text: str) -> str:
    match = re.search(r"folder\s*=\s*'([^']*)'", text)
    return match.group(1) if match else "out"


def damage_restart(rng: random.Random, path: Path) -> str:
    """Overwrite a header field with a damaging value (its checksum made to match in
    half the cases: a file a faulty writer could have made, which the field checks must
    refuse), or change bytes anywhere (the checksum must refuse them); returns what was
    done."""
    data = bytearray(path.read_bytes())
    if rng.random() < 0.6:
        offset, kind = rng.choice(RESTART_FIELDS)
        value = rng.choice(INT_DAMAGE if kind == "<i" else REAL_DAMAGE)
        data[offset:offset + struct.calcsize(kind)] = struct.pack(kind, value)
        what = f"field at byte {offset} = {value}"
        if rng.random() < 0.5:
            data[-CHECKSUM_LENGTH:] = checksum(bytes(data[:-CHECKSUM_LENGTH]))
            what += " (checksum restamped)"
    else:
        offsets = [rng.randrange(len(data)) for _ in range(rng.randint(1, 4))]
        for offset in offsets:
            data[offset] = rng.randrange(256)
        what = f"bytes at {offsets} changed"
    if rng.random() < 0.1:
        data = data[:rng.randrange(len(data))]
        what += ", then truncated"
    path.write_bytes(bytes(data))
    return what


def curve_columns(folder: Path) -> dict[str, np.ndarray]:
    curve = read_curve(folder)
    return {name: np.asarray(curve[name]) for name in curve.columns
            if name in ("step", "p_force", "p_disp", "down", "side") or "_r" in name}


def run_restart_batch(executable: Path, batch: int, count: int, tmp_path: Path) -> None:
    rng = random.Random(f"{SEED}-restart-{batch}")
    references: dict[str, dict[str, np.ndarray]] = {}
    for name, text in SEEDS.items():
        folder = tmp_path / f"full_{name}"
        outcome = run_case(executable, Case("restart", batch, -1, name, [], text), folder)
        assert outcome.returncode == 0 and not outcome.problems, outcome.stderr
        references[name] = curve_columns(folder / output_folder(text))
    problems, codes, accepted = [], {0: 0, 1: 0, 2: 0}, 0
    for index in range(count):
        if Budget.remaining() <= 0:
            break
        seed_name = rng.choice(sorted(SEEDS))
        text = SEEDS[seed_name]
        folder = tmp_path / f"restart_{batch}_{index}"
        stop = run_case(executable, Case("restart", batch, index, seed_name, [],
                                         with_control(text, f"max_steps = {rng.randint(1, 8)}")),
                        folder)
        restart = folder / output_folder(text) / "restart.dat"
        if stop.returncode != 0 or not restart.exists():
            problems.append(f"case {index}: the stopping run failed: {stop.stderr[-300:]}")
            continue
        what = damage_restart(rng, restart)
        case = Case("restart", batch, index, seed_name, [what],
                    with_control(text, "restart = .true."))
        outcome = Outcome(case)
        start = time.monotonic()
        try:
            proc = subprocess.run([str(executable)], input=case.text.encode(),
                                  capture_output=True, cwd=folder, timeout=CASE_TIMEOUT)
        except subprocess.TimeoutExpired:
            problems.append(f"case {index} ({seed_name}, {what}): timeout")
            continue
        outcome.seconds = time.monotonic() - start
        stderr = proc.stderr.decode(errors="replace")
        codes[proc.returncode] = codes.get(proc.returncode, 0) + 1
        errors = ERROR_LINE.findall(stderr)
        bad = [f"exit code {proc.returncode}"] if proc.returncode not in (0, 1, 2) else []
        bad += [f"'{m}' on stderr" for m in CRASH_MARKERS if m in stderr]
        if (proc.returncode == 0) == bool(errors) or len(errors) > 1:
            bad.append(f"exit code {proc.returncode} with {len(errors)} error lines")
        bad += non_finite_in_outputs(folder)
        if proc.returncode == 0:
            accepted += 1
            got = curve_columns(folder / output_folder(text))
            want = references[seed_name]
            if any(got[k].shape != want[k].shape or not np.allclose(
                    got[k], want[k], rtol=CURVE_RTOL, atol=CURVE_RTOL * np.max(np.abs(want[k])))
                    for k in want):
                bad.append("accepted, but its curve is not the uninterrupted run's")
        if bad:
            problems.append(f"case {index} ({seed_name}, {what}): {'; '.join(bad)}; "
                            f"stderr: {stderr.strip()[-300:]}")
        else:
            shutil.rmtree(folder, ignore_errors=True)
    print(f"fuzz restart batch {batch}: {sum(codes.values())} damaged restarts, exit codes "
          f"{codes}, {accepted} accepted (each with the uninterrupted curve), "
          f"{len(problems)} failed")
    if not sum(codes.values()):
        pytest.skip("wall-clock budget used up before any restart case")
    assert not problems, "\n".join(problems[:8])
    assert codes.get(2, 0) > 0, "no damaged restart file was refused: does the damage reach?"


@pytest.mark.parametrize("batch", range(RESTART_BATCHES))
def test_fuzz_damaged_restart(executable, tmp_path, batch):
    """Damaged restart.dat files: refused with a message, or harmless; never a crash, a
    hang, or a silently different curve."""
    run_restart_batch(executable, batch, RESTART_CASES_PER_BATCH, tmp_path)


def test_fuzz_cases_are_reproducible():
    """The same seed gives the same cases (a failure can be replayed)."""
    first = make_cases("check", 0, 20)
    again = make_cases("check", 0, 20)
    assert [c.text for c in first] == [c.text for c in again]
    assert len({c.text for c in first}) > 15


if __name__ == "__main__":
    # python tests/cli/test_fuzz.py KIND BATCH INDEX: print one case's input.
    kind, batch, index = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
    sys.stdout.write(make_cases(kind, batch, index + 1)[index].text)
