#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Slip fronts (issue 42): the capstan rig over K pins, and clamped against periodic
knits, as ratios from one run (markdown on stdout).

    benchmarks/slip_fronts.py                          # K 4 .. 1024, knits 24
    benchmarks/slip_fronts.py --pins 4 16 64 --knits 8 16
    benchmarks/slip_fronts.py --before /tmp/old/steps_trace   # and another build

The capstan rig: a yarn (linear, EA = 10 N) from A = (-1, -1) up to K pins of an
&obstacle on the upper half of the unit circle (polar angles 180 .. 0 degrees, evenly
spaced), down to B = (1, -1); A held, B pulled down 0.3 m and released (`&path` 0 -> 1
-> 0), Coulomb friction mu = 0.25 at the pins, total wrap angle pi (the two straight
ends are vertical). No &solver group: default settings. Columns: the load steps'
Newton iterations, factorisations and CPU ms (the continuation alone, process CPU) summed
over the run (step 0, the unloaded state, apart), and each over the K = 4 row.
The knits: steps_table.knit_scene's periodic cell and the clamped sample with free
sides (default edge threads), loading to strain 1 (20 steps) and one stretch cycle;
Newton iterations per step, clamped over periodic.
Every row is one run of build/benchmarks/steps_trace (summary and timings lines).
"""
import argparse
import pathlib
import sys
import tempfile

import numpy as np

TOP = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(TOP / 'tests' / 'verification'))
sys.path.insert(0, str(TOP / 'benchmarks'))
from scenes import group  # noqa: E402
from steps_table import TRACE, knit_scene, run  # noqa: E402

import blas_env  # noqa: E402


def capstan_scene(k: int, folder: pathlib.Path) -> str:
    """The K-pin capstan rig (module notes) as namelist text."""
    theta = np.linspace(np.pi, 0.0, k)
    pins = np.column_stack([np.cos(theta), np.sin(theta), np.zeros(k)])
    nodes = np.vstack([[-1.0, -1.0, 0.0], pins, [1.0, -1.0, 0.0]])
    return (group('control', title=f'capstan over {k} pins')
            + group('material', name='yarn', law='linear', stiffness=10.0)
            + group('nodes', xyz=nodes)
            + group('yarn', material='yarn', nodes=list(range(1, k + 3)))
            + group('obstacle', name='pins', nodes=list(range(2, k + 2)))
            + group('support', name='fixed', nodes=[1])
            + group('support', name='pull', nodes=[k + 2], displacement=[0.0, -0.3, 0.0])
            + group('contact', at='pins', law='coulomb', friction_coefficient=0.25)
            + group('path', time=[0.0, 1.0, 2.0], p_disp=[0.0, 1.0, 0.0])
            + group('output', folder=str(folder), vtk_every=0, progress=False))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--trace', default=str(TRACE),
                        help='steps_trace of this build (default: build/benchmarks)')
    parser.add_argument('--before', help='steps_trace built from another commit')
    parser.add_argument('--pins', type=int, nargs='*', default=[4, 16, 64, 256, 1024])
    parser.add_argument('--knits', type=int, nargs='*', default=[24])
    parser.add_argument('--paths', nargs='*', default=['loading', 'cycle'])
    parser.add_argument('--timeout', type=float, default=1800)
    args = parser.parse_args()
    core = blas_env.apply()
    builds = [('after', pathlib.Path(args.trace))]
    if args.before:
        builds.append(('before', pathlib.Path(args.before)))
    work = pathlib.Path(tempfile.mkdtemp(prefix='slip_fronts_'))
    print(f'OPENBLAS_CORETYPE {core}')
    for name, binary in builds:
        print(f'\n### Capstan rig over K pins ({name})\n')
        print('| K | steps | Newton | factorisations | CPU ms | Newton / K=4 '
              '| factorisations / K=4 | CPU / K=4 |')
        print('|---:|---:|---:|---:|---:|---:|---:|---:|')
        first = None
        for k in args.pins:
            scene = work / f'capstan_{k}.nml'
            scene.write_text(capstan_scene(k, work / 'out'))
            print(f'slip_fronts: capstan K = {k} ({name})', file=sys.stderr, flush=True)
            row = run(binary, [str(scene)], args.timeout)
            if 'failed' in row:
                print(f'| {k} | failed: {row["failed"][:60]} |||||||', flush=True)
                continue
            steps = row['steps']
            whole = (row['newton'] * steps, row['factorisations'] * steps,
                     row["cpu_ms"] * steps)
            first = first or whole
            print(f'| {k} | {int(steps)}' + (f' ({int(row["cuts"])} cuts)' if row['cuts']
                                             else '')
                  + f' | {whole[0]:.0f} | {whole[1]:.0f} | {whole[2]:.2f} | '
                  + ' | '.join(f'{a / b:.2f}' for a, b in zip(whole, first)) + ' |',
                  flush=True)
        print(f'\n### Knits: clamped (free sides) against periodic ({name})\n')
        print('| knit | path | periodic Newton / step | clamped Newton / step | ratio '
              '| periodic CPU ms / step | clamped CPU ms / step |')
        print('|---|---|---:|---:|---:|---:|---:|')
        for path in args.paths:
            for n in args.knits:
                rows = {}
                for kind in ('periodic', 'default'):
                    scene = work / f'knit_{kind}_{n}_{path}.nml'
                    scene.write_text(knit_scene(n, kind, path, work / 'out'))
                    print(f'slip_fronts: knit {n} {kind} {path} ({name})', file=sys.stderr,
                          flush=True)
                    rows[kind] = run(binary, [str(scene)], args.timeout)
                p, c = rows['periodic'], rows['default']
                if 'failed' in p or 'failed' in c:
                    print(f'| {n} x {n} | {path} | {p.get("failed", "")[:40]} | '
                          f'{c.get("failed", "")[:40]} ||||', flush=True)
                    continue
                print(f'| {n} x {n} | {path} | {p["newton"]:.2f} | {c["newton"]:.2f} | '
                      f'{c["newton"] / p["newton"]:.2f} | {p["cpu_ms"]:.2f} | '
                      f'{c["cpu_ms"]:.2f} |', flush=True)


if __name__ == '__main__':
    main()
