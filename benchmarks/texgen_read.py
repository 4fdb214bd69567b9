#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The time to read a TexGen model with huge attributes (issue 39): inputs/texgen_knit.tg3
with one long attribute on its <Textile> (padding of the given sizes), or with many
attributes on that tag. Each case runs the program with check_only = .true. (read, check,
generate the net; nothing solved or written) and prints its wall time, exit code and the
end of its error line, if any. The time should grow linearly with the padding.

    .venv/bin/python benchmarks/texgen_read.py [--timeout 60]

Cases go to out/bench_texgen_read/ (git-ignored). Timings are on whatever else the machine
is doing: compare within one run.
"""
from __future__ import annotations

import argparse
import os
import re
import shutil
import subprocess
import time
from pathlib import Path

TOP = Path(__file__).resolve().parents[1]
EXECUTABLE = Path(os.environ.get("YARNFORT_EXE", TOP / "build" / "yarnfort"))
MODEL = (TOP / "inputs" / "texgen_knit.tg3").read_text()
SCENE = (TOP / "inputs" / "texgen_knit.nml").read_text()
#: (name, attribute text put into <Textile ...>)
CASES = [
    ("no padding", ""),
    ("one attribute of 100 kB", f' Padding="{"x" * 100_000}"'),
    ("one attribute of 1 MB", f' Padding="{"x" * 1_000_000}"'),
    ("one attribute of 2 MB", f' Padding="{"x" * 2_000_000}"'),
    ("one attribute of 1 MB of entities", f' Padding="{"&amp;" * 200_000}"'),
    ("one attribute of 2 MB of entities", f' Padding="{"&amp;" * 400_000}"'),
    ("one attribute of 1 MB of lone '&'", f' Padding="{"&" * 1_000_000}"'),
    ("900 attributes", "".join(f' a{k}="{k}"' for k in range(900))),
    ("50 000 attributes", "".join(f' a{k}="{k}"' for k in range(50_000))),
    ("100 000 attributes", "".join(f' a{k}="{k}"' for k in range(100_000))),
]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--timeout", type=float, default=60.0)
    args = parser.parse_args()
    folder = TOP / "out" / "bench_texgen_read"
    shutil.rmtree(folder, ignore_errors=True)
    folder.mkdir(parents=True)
    data = folder / "data"
    shutil.copytree(TOP / "inputs" / "data", data)
    for index, (name, extra) in enumerate(CASES):
        model = folder / f"model_{index}.tg3"
        model.write_text(MODEL.replace("<Textile ", f"<Textile{extra} ", 1))
        scene = SCENE.replace("inputs/texgen_knit.tg3", model.name)
        scene = scene.replace("inputs/data/", "data/")
        scene = re.sub(r"&control", "&control check_only = .true.,", scene, count=1)
        start = time.monotonic()
        try:
            proc = subprocess.run([str(EXECUTABLE)], input=scene.encode(), cwd=folder,
                                  capture_output=True, timeout=args.timeout)
            seconds = time.monotonic() - start
            error = re.findall(r"yarnfort: error.*", proc.stderr.decode(errors="replace"))
            outcome = f"exit {proc.returncode}" + (f": ...{error[0][-110:]}" if error else "")
        except subprocess.TimeoutExpired:
            seconds = time.monotonic() - start
            outcome = f"still running after {args.timeout:.0f} s (killed)"
        size = model.stat().st_size
        print(f"{name:36s} {size / 1e6:6.2f} MB {seconds:8.2f} s  {outcome}", flush=True)


if __name__ == "__main__":
    main()
