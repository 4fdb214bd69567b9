# SPDX-License-Identifier: MIT
"""The &solver presets against exact references, model error included.

Runs every scene of ``tests/verification/test_defaults.py`` (capstans over 1..64 pins for
three laws, slip onsets, the one-pin hysteresis loops, frictionless and friction rings,
the pretensioned 8x8 cable net stuck and frictionless, unit scaling, stiff pins, zero
load, input order) once with the defaults (no ``&solver`` group) and once with each
preset (``&solver preset = '...'`` and nothing else), and compares every step with the
closed form or independent solution of that file (never with a run of this code). The
errors are the ones those tests print: forces relative to the step's largest tension,
positions and reference lengths as a fraction of the scene size. Prints a table per
setting (tests within 1e-8, worst force and position errors, wall time of the scenes)
and writes ``presets.txt`` next to this script. About 1.5 minutes on 2 cores.

    .venv/bin/python verification/speed_accuracy/presets.py
"""
from __future__ import annotations

import os
import re
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ElementTree
from pathlib import Path

HERE = Path(__file__).resolve().parent
TOP = HERE.parents[1]
TESTS = TOP / "tests" / "verification" / "test_defaults.py"
SETTINGS = ("defaults", "balanced", "accurate")
#: Keys of the printed errors that are forces (the others are positions or lengths).
FORCE_KEYS = {"tension", "reaction", "force", "gross_slip", "area", "sliding"}

#: A pytest plugin, run in a child process, that appends `&solver preset = ...` to every
#: namelist the module writes (its two builders of scene text).
PLUGIN = '''
import os, pytest
PRESET = os.environ["YARNFORT_STUDY_PRESET"]
SOLVER = f"&solver\\n    preset = '{PRESET}'\\n/\\n"

@pytest.hookimpl(trylast=True)
def pytest_collection_modifyitems(items):
    for module in {item.module for item in items}:
        if module.__name__ == "test_defaults" and PRESET != "defaults":
            build, strip = module.defaults_namelist, module.without_solver
            module.defaults_namelist = lambda *a, _b=build, **k: _b(*a, **k) + SOLVER
            module.without_solver = lambda text, _s=strip: _s(text) + SOLVER
'''

ERRORS = re.compile(r"errors ((?:[a-z_]+ [0-9.e+-]+(?:, )?)+)")
PAIR = re.compile(r"([a-z_]+) ([0-9.]+e[+-][0-9]+)")


def run_setting(name: str, folder: Path) -> list[dict]:
    """Run the file with one setting; per test: outcome, time, printed errors."""
    (folder / "study_plugin.py").write_text(PLUGIN)
    report = folder / f"{name}.xml"
    subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                    "-p", "study_plugin", "-o", "junit_logging=system-out",
                    f"--junitxml={report}", str(TESTS)],
                   cwd=TESTS.parent, env={**os.environ, "PYTHONPATH": str(folder),
                                          "YARNFORT_STUDY_PRESET": name},
                   capture_output=True, text=True, check=False)
    rows = []
    for case in ElementTree.parse(report).getroot().iter("testcase"):
        failed = case.find("failure") is not None or case.find("error") is not None
        out = case.findtext("system-out") or ""
        errors: dict[str, float] = {}
        for match in ERRORS.finditer(out):
            for key, value in PAIR.findall(match.group(1)):
                errors[key] = max(errors.get(key, 0.0), float(value))
        rows.append(dict(name=case.get("name"), failed=failed,
                         time=float(case.get("time")), errors=errors))
    return rows


def summarise(name: str, rows: list[dict]) -> str:
    force = max((v for r in rows for k, v in r["errors"].items() if k in FORCE_KEYS),
                default=0.0)
    position = max((v for r in rows for k, v in r["errors"].items()
                    if k not in FORCE_KEYS), default=0.0)
    passed = sum(not r["failed"] for r in rows)
    failed = [r["name"] for r in rows if r["failed"]]
    failures = (", ".join(f.replace("test_", "").replace("_with_defaults", "") for f in failed)
                if 0 < len(failed) <= 4 else "")
    return (f"| {name} | {passed}/{len(rows)} {failures} | {force:.1e} | {position:.1e} | "
            f"{sum(r['time'] for r in rows):.1f} s |")


def main() -> None:
    lines = ["| setting | scenes within 1e-8 | worst force error | worst position error "
             "| time |", "|---|---|---|---|---|"]
    detail = []
    with tempfile.TemporaryDirectory() as tmp:
        for name in SETTINGS:
            rows = run_setting(name, Path(tmp))
            lines.append(summarise(name, rows).rstrip("\n"))
            detail.append(f"\n## {name}\n")
            for r in rows:
                errors = ", ".join(f"{k} {v:.1e}" for k, v in r["errors"].items())
                detail.append(f"{'FAIL' if r['failed'] else 'ok  '} {r['time']:6.2f} s "
                              f"{r['name']}: {errors}")
            print(lines[-1], flush=True)
    text = "\n".join(lines) + "\n" + "\n".join(detail) + "\n"
    (HERE / "presets.txt").write_text(text)
    print(text)


if __name__ == "__main__":
    main()
