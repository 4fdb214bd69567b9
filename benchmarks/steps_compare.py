#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Do two builds of the program give the same answers? (issue 16 item 2: a change to
the friction steps must not change the curves)

    benchmarks/steps_compare.py /tmp/old/yarnfort build/yarnfort            # inputs/*.nml
    benchmarks/steps_compare.py OLD NEW --knits 4 8 --paths loading cycle   # + the knits

Runs each scene with both programs (vtk output off, output to a temporary folder) and
compares the force columns of curve.csv (reactions *_rx, *_ry, *_rz and
force_per_width*) at the times both runs reached: per scene, the largest difference over
the largest magnitude of those columns, and the steps of each run. The knit scenes are those of
benchmarks/steps_table.py. Markdown on stdout, progress on stderr.
"""
import argparse
import csv
import pathlib
import subprocess
import sys
import tempfile

TOP = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(TOP / 'tests' / 'verification'))
sys.path.insert(0, str(TOP / 'benchmarks'))
from fabric_scenes import patched_scene  # noqa: E402
from steps_table import knit_scene  # noqa: E402

def read_curve(folder):
    with open(folder / 'curve.csv') as handle:
        rows = list(csv.DictReader(line for line in handle if not line.startswith('#')))
    return {float(row['time']): row for row in rows}


def run(binary, text, folder):
    done = subprocess.run([str(binary)], input=text, capture_output=True, text=True,
                          cwd=TOP)
    if done.returncode != 0:
        return None, done.stderr.strip().splitlines()[-1:]
    return read_curve(folder), None


def compare(old, new):
    times = sorted(set(old) & set(new))
    columns = [c for c in old[times[0]] if c in new[times[0]]]
    forces = [c for c in columns if c.endswith(('_rx', '_ry', '_rz'))
              or c.startswith('force_per_width')]
    peak = max(abs(float(old[t][c])) for t in times for c in forces) or 1.0
    worst, where = 0.0, ''
    for t in times:
        for c in forces:
            d = abs(float(old[t][c]) - float(new[t][c]))
            if d > worst:
                worst, where = d, f'{c} at t = {t:g}'
    return worst / peak, where, len(times)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('old')
    parser.add_argument('new')
    parser.add_argument('--knits', type=int, nargs='*', default=[])
    parser.add_argument('--paths', nargs='*', default=['loading', 'cycle'])
    parser.add_argument('--inputs', nargs='*',
                        default=sorted(str(p.relative_to(TOP))
                                       for p in (TOP / 'inputs').glob('*.nml')))
    args = parser.parse_args()
    work = pathlib.Path(tempfile.mkdtemp(prefix='steps_compare_'))
    scenes = []
    for name in args.inputs:
        scenes.append((name, lambda folder, name=name: patched_scene(
            name, {'output.vtk_every': 0}, folder)))
    for path in args.paths:
        for n in args.knits:
            for kind in ('periodic', 'default', 'taut', 'rollers'):
                scenes.append((f'knit {n} x {n} {kind} ({path})',
                               lambda folder, n=n, kind=kind, path=path:
                               knit_scene(n, kind, path, folder)))
    print('| scene | steps old / new | shared times | largest difference / peak force | where |')
    print('|---|---:|---:|---:|---|')
    for k, (label, make) in enumerate(scenes):
        print(f'steps_compare: {label}', file=sys.stderr, flush=True)
        curves = []
        for tag, binary in (('old', args.old), ('new', args.new)):
            folder = work / f'{k}_{tag}'
            curves.append(run(binary, make(folder), folder))
        (old, old_err), (new, new_err) = curves
        if old is None or new is None:
            print(f'| {label} | failed: old {old_err} new {new_err} | | | |', flush=True)
            continue
        ratio, where, shared = compare(old, new)
        print(f'| {label} | {len(old)} / {len(new)} | {shared} | {ratio:.1e} | {where} |',
              flush=True)


if __name__ == '__main__':
    main()
