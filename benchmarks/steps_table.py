#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Where friction load steps' Newton iterations and active-set rounds go (issue 16
item 2), before and after a change, in one run (markdown on stdout).

    benchmarks/steps_table.py --before /tmp/old/steps_trace        # both builds
    benchmarks/steps_table.py                                       # this build only
    benchmarks/steps_table.py --sides 6 22 --knits 4 8 16 --paths loading cycle

Runs build/benchmarks/steps_trace (and the `--before` binary, a build of the same
program from another commit) one after the other on
- the woven net of benchmarks/bench_friction (4 elements per segment, aligned and
  skewed, full cycle of 60 steps: load, unload to half, reload), `--sides` crossings
  per side;
- inputs/knit.nml (with inlay) as n x n samples, `--knits` n: the periodic cell, and
  clamped with free sides and the default edge threads, with a taut edge thread
  (verification/clamped/run_study.py's THREAD) and with rollers; `--paths`: loading to
  strain 1 (20 steps, as in verification/clamped) and/or one stretch cycle 0 -> 1 -> 0;
- inputs/knit_clamped.nml as shipped.
Columns per build: Newton iterations, active-set rounds (Newton solves) and residual
evaluations per step (a build with chord steps prints them too: `newton / chord`),
passages turned stick -> slip and slip -> stick per step, CPU ms
per step (the continuation alone, process CPU time), and that over the CPU ms of one
elastic Newton iteration of the same net at the final state, and the floor: the cost of
one friction Newton iteration of the run (one factorisation, one Jacobian, one solve and
one residual with its row levels, each the run's mean from the `timings` line, wall ms)
over that elastic iteration. A step that needs a new factorisation costs at least the
floor, so where the floor is above 4, item 2's target cannot be met by fewer iterations
or rounds alone. The load average is printed before and after. Progress goes to stderr.
"""
import argparse
import os
import pathlib
import re
import subprocess
import sys
import tempfile

TOP = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(TOP / 'tests' / 'verification'))
sys.path.insert(0, str(TOP / 'verification' / 'clamped'))
from fabric_scenes import LOADING, ONE_CYCLE, patched_scene  # noqa: E402
from run_study import THREAD  # noqa: E402  (the taut edge thread of the clamped study)

import blas_env  # noqa: E402

TRACE = TOP / 'build' / 'benchmarks' / 'steps_trace'
SUMMARY = ('unknowns passages steps cuts newton chords rounds residuals to_slip to_stick '
           'cpu_ms elastic_ms ratio').split()


def knit_scene(n, kind, path, folder):
    values = {**(LOADING if path == 'loading' else ONE_CYCLE), 'output.vtk_every': 0,
              'fabric.cells': [n, n]}
    if kind != 'periodic':
        values.update({'fabric.boundary': 'clamped', 'fabric.lateral_strain': None,
                       'fabric.sides': 'rollers' if kind == 'rollers' else 'free'})
    if kind == 'taut':
        values['fabric.edge_material'] = 'thread'
    text = patched_scene('inputs/knit.nml', values, folder)
    return text + (THREAD if kind == 'taut' else '')


def run(binary, arguments, timeout):
    try:
        done = subprocess.run([str(binary)] + arguments, capture_output=True, text=True,
                              cwd=TOP, timeout=timeout)
    except subprocess.TimeoutExpired:
        return {'failed': f'over {timeout} s'}
    lines = [line for line in done.stdout.splitlines() if line.startswith('summary')]
    if done.returncode != 0 or not lines:
        tail = done.stderr.strip().splitlines()
        return {'failed': tail[-1] if tail else f'exit {done.returncode}'}
    values = [float(x) for x in lines[-1].split()[1:]]
    if len(values) == len(SUMMARY) - 1:
        values.insert(SUMMARY.index('chords'), 0.0)   # a build without chord steps
    row = dict(zip(SUMMARY, values))
    row['floor'] = floor(done.stdout, row)
    row['factorisations'] = factorisations(done.stdout)
    return row


def factorisations(stdout):
    """Factorisations per load step from the `timings` line (NaN without)."""
    lines = [line for line in stdout.splitlines() if line.startswith('timings')]
    if not lines:
        return float('nan')
    return float(re.findall(r'\s(-?\d+\.\d+)', lines[-1])[1])


def floor(stdout, row):
    """One friction Newton iteration of the run over the elastic iteration (module
    notes), or None without a `timings` line (older builds lack the levels column: 0)."""
    lines = [line for line in stdout.splitlines() if line.startswith('timings')]
    if not lines:
        return None
    numbers = [float(x) for x in re.findall(r'\s(-?\d+\.\d+)', lines[-1])]
    jacobians, factorisations, solves, residual, jacobian, _, factor, solve = numbers[:8]
    levels = numbers[8] if len(numbers) > 8 else 0.0
    if min(jacobians, factorisations, solves, row['residuals']) <= 0:
        return None
    one = (factor / factorisations + jacobian / jacobians + solve / solves
           + (residual + levels) / row['residuals'])
    return one / row['elastic_ms']


def cells(row):
    if 'failed' in row:
        return ['failed: ' + row['failed'][:40]] + [''] * 7
    steps = row['steps']
    newton = f"{row['newton']:.2f}" + (f" / {row['chords']:.2f}" if row['chords'] else '')
    floor_cell = '-' if row['floor'] is None else f"{row['floor']:.2f}"
    return [newton, f"{row['rounds']:.2f}", f"{row['residuals']:.2f}",
            f"{row['to_slip']:.2f} / {row['to_stick']:.2f}", f"{row['cpu_ms']:.2f}",
            f"{row['ratio']:.2f}", floor_cell,
            f"{int(steps)}" + (f" ({int(row['cuts'])} cuts)" if row['cuts'] else '')]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--trace', default=str(TRACE),
                        help='steps_trace of this build (default: build/benchmarks)')
    parser.add_argument('--before', help='steps_trace built from the commit before')
    parser.add_argument('--also', nargs='*', default=[], metavar='NAME=PATH',
                        help='more builds of steps_trace to compare (a variant)')
    parser.add_argument('--sides', type=int, nargs='*', default=[6, 10, 14, 22])
    parser.add_argument('--knits', type=int, nargs='*', default=[4, 8])
    parser.add_argument('--paths', nargs='*', default=['loading', 'cycle'])
    parser.add_argument('--timeout', type=float, default=1800)
    args = parser.parse_args()
    core = blas_env.apply()
    builds = [('after', pathlib.Path(args.trace))] + ([('before', pathlib.Path(args.before))]
                                   if args.before else [])
    builds += [(name, pathlib.Path(path)) for name, path in
               (item.split('=', 1) for item in args.also)]
    cases = []
    for side in args.sides:
        for net in ('aligned', 'skewed'):
            extra = ['--skewed'] if net == 'skewed' else []
            cases.append((f'woven {net} {side}', ['--woven', str(side)] + extra))
    work = pathlib.Path(tempfile.mkdtemp(prefix='steps_table_'))
    for path in args.paths:
        for n in args.knits:
            for kind in ('periodic', 'default', 'taut', 'rollers'):
                scene = work / f'knit_{kind}_{n}_{path}.nml'
                scene.write_text(knit_scene(n, kind, path, work / 'out'))
                cases.append((f'knit {n} x {n} {kind} ({path})', [str(scene)]))
    cases.append(('inputs/knit_clamped.nml', ['inputs/knit_clamped.nml']))

    def load():
        return ' '.join(f'{x:.2f}' for x in os.getloadavg())

    print(f'Load average at the start: {load()}; OPENBLAS_CORETYPE {core}')
    print()
    header = ['case']
    for name, _ in builds:
        header += [f'{name}: {c}' for c in ('Newton / step', 'rounds / step',
                                              'residual evals / step',
                                              'to slip / to stick per step',
                                              'CPU ms / step', 'step / elastic iteration',
                                              'floor: iteration / elastic', 'steps')]
    print('| ' + ' | '.join(header) + ' |')
    print('|' + '---|' + '---:|' * (len(header) - 1))
    for label, arguments in cases:
        row = [label]
        for name, binary in builds:
            print(f'steps_table: {label} ({name})', file=sys.stderr, flush=True)
            row += cells(run(binary, arguments, args.timeout))
        print('| ' + ' | '.join(row) + ' |', flush=True)
    print()
    print(f'Load average at the end: {load()}')


if __name__ == '__main__':
    main()
