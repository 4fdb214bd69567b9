# SPDX-License-Identifier: MIT
"""Mutation fuzz, family 'links in the output folder' (issue 39).

Each case (fixed seed) takes an example scene (``inputs/vnet.nml`` mostly, the capstan
scene for contacts.csv), optionally runs it a few steps into its output folder, then
plants one to three of: a symbolic link at a name the program writes (its files, their
``.tmp`` names, state files, the manifest, the lock, the write probe) pointing to a file
outside the folder, to nothing (dangling), to a folder outside, or to another file of the
folder; a link at a name it never writes; a hard link at a name it writes to a file
outside; the output folder itself made a link to a folder elsewhere. Then it runs the
scene again (anew or with ``restart = .true.``, a few steps). For every case:

- never a crash or a hang; one ``yarnfort: error`` line exactly when the exit code is
  not 0 (the rules of tests/cli/test_fuzz.py);
- nothing outside the output folder is written, created or removed: every file, link
  and folder of the case's folder outside it is as before (a dangling link's target
  is not created, a linked file keeps its bytes);
- a symbolic link at a name the program writes (or a hard-linked lock file) is
  refused with exit code 2 before the first step, the name in the message, and the
  output folder is left as it was; otherwise the run succeeds (exit code 0) and the
  links of other names are left as they were.

The cases share a wall-clock budget (later ones are skipped and counted, not failed).
``python tests/cli/test_fuzz_links.py INDEX`` prints what a case plants.
"""
from __future__ import annotations

import os
import random
import re
import shutil
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import pytest

from test_faults import WRITTEN_NAMES, tree
from test_fuzz import (CASE_TIMEOUT, CRASH_MARKERS, ERROR_LINE, SEED, SEEDS,  # noqa: F401
                       executable, with_control)

#: Cases, and the wall-clock seconds they may take together (about 0.2 s a case here).
LINK_CASES = 120
LINK_BUDGET = 90.0
#: Load steps of each run (&control max_steps): the links act before the first step.
MAX_STEPS = 3
#: Names the program never writes, where links of one's own are left alone.
OTHER_NAMES = ("notes.txt", "curve.csv.bak", "state_1.vtu", "states.pvd.old", "data",
               "restart.dat~")
#: What a symbolic link points to.
TARGETS = ("outside file", "dangling", "outside folder", "inside file", "parent folder")
#: Files a restart reads and checks (another file there is refused: no hard link).
READ_ON_RESTART = ("curve.csv", "restart.dat", "contacts.csv", "reactions.csv")
#: The output folder of every case (relative to the case's folder).
FOLDER = "out"


@dataclass
class Plan:
    """What a case does: its scene, the first run, what it plants, the second run."""
    index: int
    scene: str
    first_steps: int                    # 0: no first run
    plants: list[tuple[str, str, str]]  # (kind, name, target)
    folder_link: bool
    restart: bool
    planted: list[str] = field(default_factory=list)

    @property
    def refused(self) -> bool:
        """Whether the second run must refuse the folder (exit code 2)."""
        return any(kind == "symlink" and is_written_name(name) or
                   kind == "hardlink" and name == ".yarnfort-lock"
                   for kind, name, _ in self.plants)


def is_written_name(name: str) -> bool:
    """A name the program writes in an output folder (state files of any step)."""
    return name in WRITTEN_NAMES or re.fullmatch(r"state_\d{5,}\.vtu", name) is not None


def without_probe(content: dict[str, object]) -> dict[str, object]:
    """A folder's tree without a regular file at the write probe's name: one there is
    a leftover probe, replaced (never followed) before the folder is checked."""
    return {name: value for name, value in content.items()
            if not (name.endswith(".yarnfort-write-test") and not isinstance(value, tuple))}


def make_plan(index: int) -> Plan:
    rng = random.Random(f"{SEED}-links-{index}")
    scene = "capstan" if rng.random() < 0.2 else "vnet"
    first_steps = rng.choice((0, 1, 2, 3))
    restart = first_steps > 0 and rng.random() < 0.4
    folder_link = rng.random() < 0.25
    # A restart reads these: another file in their place is refused as not of the run.
    hard = [n for n in WRITTEN_NAMES if not (restart and n in READ_ON_RESTART)]
    plants = []
    for _ in range(rng.choice((1, 1, 2, 3))):
        kind = rng.choice(("symlink", "other", "hardlink"))
        if kind == "other":
            plants.append(("symlink", rng.choice(OTHER_NAMES), rng.choice(TARGETS)))
        elif kind == "symlink":
            name = rng.choice(WRITTEN_NAMES + (f"state_{rng.randrange(MAX_STEPS + 1):05d}.vtu",))
            plants.append(("symlink", name, rng.choice(TARGETS)))
        else:
            plants.append(("hardlink", rng.choice(hard), "outside file"))
    # A later plant at the same name replaces an earlier one.
    plants = list({name: (kind, name, target) for kind, name, target in plants}.values())
    return Plan(index, scene, first_steps, plants, folder_link, restart)


def scene_text(plan: Plan, control: str) -> str:
    text = SEEDS[plan.scene].replace(f"folder = 'out/{plan.scene}'", f"folder = '{FOLDER}'")
    assert f"folder = '{FOLDER}'" in text
    return with_control(text, control)


def run(executable: Path, text: str, cwd: Path) -> tuple[int, str, list[str]]:
    """Run yarnfort; its exit code, stderr and the broken rules of every run."""
    proc = subprocess.run([str(executable)], input=text.encode(), capture_output=True,
                          cwd=cwd, timeout=CASE_TIMEOUT)
    stderr = proc.stderr.decode(errors="replace")
    problems = [f"'{m}' on stderr" for m in CRASH_MARKERS if m in stderr]
    errors = len(ERROR_LINE.findall(stderr))
    if proc.returncode not in (0, 1, 2):
        problems.append(f"exit code {proc.returncode}")
    if errors != (proc.returncode != 0):
        problems.append(f"exit code {proc.returncode} with {errors} error lines")
    return proc.returncode, stderr, problems


def plant(plan: Plan, case: Path, out: Path) -> None:
    """Make the plan's links (outside things in case/outside)."""
    outside = case / "outside"
    outside.mkdir(exist_ok=True)
    (outside / "folder").mkdir(exist_ok=True)
    for n, (kind, name, target) in enumerate(plan.plants):
        path = out / name
        if path.is_symlink() or path.is_file():
            path.unlink()
        if kind == "hardlink":
            source = outside / f"hard_{n}.txt"
            source.write_bytes(b"precious %d\n" % n)
            os.link(source, path)
            continue
        if target == "outside file":
            source = outside / f"file_{n}.txt"
            source.write_bytes(b"precious %d\n" % n)
        elif target == "dangling":
            source = outside / f"missing_{n}.txt"
        elif target == "outside folder":
            source = outside / "folder"
        elif target == "inside file":
            source = Path("notes_inside.txt")
            (out / source).write_bytes(b"inside\n")
        else:
            source = Path("..")
        os.symlink(source, path)


def run_link_case(executable: Path, plan: Plan, case: Path) -> list[str]:
    case.mkdir(parents=True)
    out = case / FOLDER
    problems = []
    if plan.first_steps:
        code, stderr, bad = run(executable, scene_text(plan, f"max_steps = {plan.first_steps}"),
                                case)
        problems += bad
        if code != 0:
            return problems + [f"the first run failed: {stderr[-300:]}"]
    else:
        out.mkdir()
    real = out
    if plan.folder_link:
        real = case / "outside" / "real"
        real.parent.mkdir(exist_ok=True)
        out.rename(real)
        os.symlink(real, out)
    plant(plan, case, real)
    before = tree(case)
    control = f"max_steps = {MAX_STEPS}" + (", restart = .true." if plan.restart else "")
    code, stderr, bad = run(executable, scene_text(plan, control), case)
    problems += bad
    after = tree(case)
    inside = str(real.relative_to(case))
    outside_changed = sorted(name for name in set(before) | set(after)
                             if not (name == inside or name.startswith(inside + "/"))
                             and before.get(name, "missing") != after.get(name, "missing"))
    if outside_changed:
        problems.append(f"changed outside the output folder: {outside_changed[:5]}")
    planted = {name for _, name, _ in plan.plants}
    if plan.refused:
        if code != 2 or ("is a symbolic link" not in stderr
                         and "is not a regular file of its own" not in stderr):
            problems.append(f"a planted link was not refused (exit {code})")
        elif not any(f"'{FOLDER}/{name}'" in stderr for name in planted):
            problems.append("the refusal names no planted link")
        if without_probe(before) != without_probe(after):
            problems.append("a refused run changed the output folder")
    else:
        if code != 0:
            problems.append(f"exit {code} without a planted link at a name it writes")
        for kind, name, _ in plan.plants:
            if kind == "symlink" and before.get(f"{inside}/{name}") != after.get(
                    f"{inside}/{name}"):
                problems.append(f"the link {name} of one's own was changed")
    return [f"{p}; stderr: {stderr.strip()[-300:]}" for p in problems]


def describe(plan: Plan) -> str:
    return (f"case {plan.index} ({plan.scene}, first run {plan.first_steps} steps, "
            f"{'restart' if plan.restart else 'new run'}"
            f"{', folder is a link' if plan.folder_link else ''}): "
            + "; ".join(f"{kind} {name} -> {target}" for kind, name, target in plan.plants))


def test_fuzz_links_in_the_output_folder(executable, tmp_path):
    """Planted links never make a run write, create or remove anything outside its
    output folder; a link at a name it writes is refused before the first step."""
    try:
        os.symlink("target", tmp_path / "probe-link")
    except (OSError, NotImplementedError) as error:
        pytest.skip(f"cannot create symbolic links here: {error}")
    deadline = time.monotonic() + LINK_BUDGET
    failed, codes, skipped = [], {"refused": 0, "ran": 0}, 0
    for index in range(LINK_CASES):
        if time.monotonic() > deadline:
            skipped += 1
            continue
        plan = make_plan(index)
        case = tmp_path / f"links_{index}"
        problems = run_link_case(executable, plan, case)
        if problems:
            failed.append(describe(plan) + "\n    " + "\n    ".join(problems))
        else:
            codes["refused" if plan.refused else "ran"] += 1
            shutil.rmtree(case, ignore_errors=True)
    print(f"fuzz links: {LINK_CASES - skipped} cases, {skipped} skipped (budget), "
          f"{codes['refused']} refused, {codes['ran']} ran, {len(failed)} failed")
    assert not failed, "\n".join(failed[:8])
    assert codes["refused"] > 0 and codes["ran"] > 0, "a kind of case is missing: seeds?"


def test_fuzz_link_cases_are_reproducible():
    """The same seed gives the same cases, of every kind."""
    plans = [make_plan(i) for i in range(LINK_CASES)]
    assert [describe(p) for p in plans] == [describe(make_plan(i)) for i in range(LINK_CASES)]
    assert any(p.refused for p in plans) and not all(p.refused for p in plans)
    assert any(p.folder_link for p in plans) and any(p.restart for p in plans)
    assert any(kind == "hardlink" for p in plans for kind, _, _ in p.plants)


if __name__ == "__main__":
    # python tests/cli/test_fuzz_links.py INDEX: what a case plants.
    print(describe(make_plan(int(sys.argv[1]))))
