#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Held membrane forces: steps, Newton iterations and CPU of the force-controlled scenes,
and how closely each held force is met (markdown on stdout).

    benchmarks/force_control.py                        # build/yarnfort
    benchmarks/force_control.py --before /tmp/old/yarnfort

Scenes (default settings): the knit example with n11 held at p_disp * 100 N/m (p_disp
0.05 -> 1 -> 0.05), alone and with n22 held at 20 N/m too (the nested outer iterations);
the knit with n22 held at 20 N/m and e11 0 -> 0.5 -> 0; `inputs/knit_biaxial.nml` and
`inputs/weave_force.nml` as shipped. Each row is one run of the program (process CPU of
the child). `held error` is the largest |n - held| over the run, relative to the larger
membrane force of the state (the tolerance's scale). With --before, each figure of the
other build follows, and the ratios this / before.
"""
import argparse
import pathlib
import resource
import subprocess
import sys
import tempfile

import numpy as np

TOP = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(TOP / 'tests' / 'verification'))
from fabric_scenes import patched_scene  # noqa: E402

from yarnfort import read_curve  # noqa: E402

AXIAL = {'fabric.axial_control': 'force', 'fabric.axial_force': 100.0,
         'fabric.strain': None, 'path.time': [0.0, 1.0, 2.0],
         'path.p_disp': [0.05, 1.0, 0.05]}
LATERAL = {'fabric.lateral_control': 'force', 'fabric.lateral_force': 20.0,
           'fabric.lateral_strain': None}
#: name: (scene file, values, held n11 per p_disp or None, held n22 or None)
SCENES = {
    'knit, n11 held': ('inputs/knit.nml', AXIAL, 100.0, None),
    'knit, n11 and n22 held': ('inputs/knit.nml', {**AXIAL, **LATERAL}, 100.0, 20.0),
    'knit, n22 held': ('inputs/knit.nml', {**LATERAL, 'fabric.strain': 0.5,
                                           'path.time': [0.0, 1.0, 2.0],
                                           'path.p_disp': [0.0, 1.0, 0.0]}, None, 20.0),
    'inputs/knit_biaxial.nml': ('inputs/knit_biaxial.nml', {}, None, 20.0),
    'inputs/weave_force.nml': ('inputs/weave_force.nml', {}, 1.0e4, 50.0),
}


def run_scene(binary: str, name: str, folder: pathlib.Path, timeout: float) -> dict:
    """One run of `binary` on scene `name`: its figures, or {'failed': why}."""
    base, values, n11_held, n22_held = SCENES[name]
    text = patched_scene(base, {**values, 'output.vtk_every': 0}, folder)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    try:
        done = subprocess.run([binary], input=text, text=True, capture_output=True,
                              cwd=TOP, timeout=timeout)
    except subprocess.TimeoutExpired:
        return {'failed': f'over {timeout} s'}
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if done.returncode != 0:
        tail = done.stderr.strip().splitlines()
        return {'failed': tail[-1] if tail else f'exit {done.returncode}'}
    curve = read_curve(folder)
    column = {c: np.asarray(curve[c], dtype=float) for c in ('p_disp', 'n11', 'n22',
                                                             'newton_iterations',
                                                             'step_cuts')}
    scale = np.maximum(np.abs(column['n11']), np.abs(column['n22']))
    errors = []
    if n11_held is not None:
        errors.append(np.abs(column['n11'] - n11_held * column['p_disp']) / scale)
    if n22_held is not None:
        errors.append(np.abs(column['n22'] - n22_held) / scale)
    return {'steps': len(curve) - 1, 'cuts': int(column['step_cuts'].sum()),
            'newton': int(column['newton_iterations'].sum()),
            'cpu': (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime),
            'held': float(max(np.max(e) for e in errors))}


def cells(row: dict) -> list[str]:
    if 'failed' in row:
        return [f"failed: {row['failed']}", '', '', '', '']
    return [str(row['steps']), str(row['cuts']), f"{row['newton']:,}", f"{row['cpu']:.2f}",
            f"{row['held']:.1e}"]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--binary', default=str(TOP / 'build' / 'yarnfort'),
                        help='the program of this build (default: build/yarnfort)')
    parser.add_argument('--before', help='the program of another build')
    parser.add_argument('--timeout', type=float, default=600.0)
    args = parser.parse_args()
    builds = [('this', args.binary)] + ([('before', args.before)] if args.before else [])
    head = ['scene']
    for label, _ in builds:
        head += [f'{label}: steps', f'{label}: cuts', f'{label}: Newton',
                 f'{label}: CPU s', f'{label}: held error']
    if args.before:
        head += ['Newton this / before', 'CPU this / before']
    print('| ' + ' | '.join(head) + ' |')
    print('|---|' + '---:|' * (len(head) - 1))
    with tempfile.TemporaryDirectory(prefix='force_control_') as scratch:
        for k, name in enumerate(SCENES):
            rows = []
            for label, binary in builds:
                print(f'force_control: {name} ({label})', file=sys.stderr, flush=True)
                rows.append(run_scene(binary, name, pathlib.Path(scratch) / f'{k}{label}',
                                      args.timeout))
            line = [name] + [c for row in rows for c in cells(row)]
            if args.before:
                if any('failed' in row for row in rows):
                    line += ['', '']
                else:
                    line += [f"{rows[0]['newton'] / rows[1]['newton']:.3f}",
                             f"{rows[0]['cpu'] / rows[1]['cpu']:.3f}"]
            print('| ' + ' | '.join(line) + ' |', flush=True)


if __name__ == '__main__':
    main()
