#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""The friction tables of issue 16 from one command (markdown on stdout).

    benchmarks/friction_table.py            # 1e3, 1e4, 1e5 and 1e6 unknowns
    benchmarks/friction_table.py --quick    # about 1e3 to 1e4 unknowns (a few minutes)
    benchmarks/friction_table.py --sides 6 22 --schemes monolithic
    benchmarks/friction_table.py --bench /tmp/old/bench_friction --max-border 16

build/benchmarks/bench_friction on crimped woven nets with 4 elements per segment, both
schemes, on the aligned net and on the skewed one (--skewed: crossings moved by small
fixed offsets, no element along an axis). The full cycle (load, unload to half, reload:
60 steps of 0.05) up to `--cycle-max` crossings per side; above it only the first
`--steps` load steps (default 1), without the timed factorisations of the `factors:`
line (they would take longer than the run). Each run goes through /usr/bin/time -v
(peak resident memory) and may be given a wall-time limit (--timeout; a run
that hits it is listed as such). Progress goes to stderr.
"""
import argparse
import math
import pathlib
import re
import subprocess
import sys
import time
import os

import blas_env

TOP = pathlib.Path(__file__).resolve().parent.parent
BENCH = TOP / 'build' / 'benchmarks' / 'bench_friction'
# Crossings per side and the unknowns they give with 4 elements per segment:
# 6: 840, 10: 2200, 14: 4200, 22: 10120, 69: about 1e5, 219: about 1e6.
SIDES = [6, 22, 69, 219]
QUICK = [6, 10, 14, 22]
COLUMNS = ('scheme unknowns passages steps newton_per_step factor_per_step ms_per_step '
           'assembly_pct factor_pct solve_pct other_pct max_slipping peak_MiB cpu_ms_per_step').split()


def run(side, scheme, skewed, steps, timeout, bench=BENCH, max_border=None):
    command = [str(bench), str(side), scheme, '4']
    if max_border is not None:
        command += ['--max-border', str(max_border)]
    if skewed:
        command.append('--skewed')
    if steps:
        command += ['--steps', str(steps), '--no-factor-times']
    start = time.time()
    try:
        done = subprocess.run(['nice', '/usr/bin/time', '-v'] + command, capture_output=True,
                              text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return {'command': ' '.join(command[1:]), 'failed': f'over {timeout} s wall'}
    row = {'command': 'bench_friction ' + ' '.join(command[1:]), 'wall_s': time.time() - start}
    if done.returncode != 0:
        tail = done.stderr.strip().splitlines()
        row['failed'] = f'exit {done.returncode}: ' + (tail[0] if tail else '')
        return row
    lines = done.stdout.strip().splitlines()
    main = next(line for line in lines if line.split()[0] == scheme)
    row.update(zip(COLUMNS, main.split()))
    factors = next((line for line in lines if line.startswith('factors:')), '')
    row['factors'] = factors
    row['bordered'] = next((line for line in lines if line.startswith('bordered:')), '')
    for key, pattern in (('lu_umfpack', r'umfpack +(\S+) \( *(\S+) ms\)'),
                         ('lu_klu', r'friction .*?klu-amd +(\S+) \( *(\S+) ms\)'),
                         ('cholmod', r'cholmod \( *(\S+) ms\)')):
        match = re.search(pattern, factors)
        row[key] = match.groups() if match else None
    match = re.search(r'zeros: friction +(\S+) % \(positions +(\S+) %, flow rows +(\S+) %, '
                      r'flow columns +(\S+) %\) elastic +(\S+) %', factors)
    row['zeros'] = match.groups() if match else None
    peak = re.search(r'Maximum resident set size \(kbytes\): (\d+)', done.stderr)
    row['rss_MiB'] = int(peak.group(1)) / 1024 if peak else float('nan')
    cpu = sum(float(m) for m in re.findall(r'(?:User|System) time \(seconds\): (\S+)',
                                           done.stderr))
    row['cpu_s'] = cpu
    return row


def slope(points):
    """Least-squares exponent of y against x on log scales."""
    points = [(math.log(x), math.log(y)) for x, y in points if x > 0 and y > 0]
    if len(points) < 2:
        return None
    mx = sum(p[0] for p in points) / len(points)
    my = sum(p[1] for p in points) / len(points)
    sxx = sum((p[0] - mx) ** 2 for p in points)
    return sum((p[0] - mx) * (p[1] - my) for p in points) / sxx if sxx > 0 else None


def main():
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--quick', action='store_true', help='sides 6 10 14 22')
    parser.add_argument('--sides', type=int, nargs='+', help='crossings per side')
    parser.add_argument('--schemes', nargs='+', default=['monolithic', 'staggered'])
    parser.add_argument('--nets', nargs='+', default=['aligned', 'skewed'],
                        choices=['aligned', 'skewed'])
    parser.add_argument('--cycle-max', type=int, default=22,
                        help='largest side run over the whole cycle (default %(default)s)')
    parser.add_argument('--steps', type=int, default=1,
                        help='load steps above --cycle-max (default %(default)s)')
    parser.add_argument('--timeout', type=float, default=None,
                        help='wall seconds per run (default: none)')
    parser.add_argument('--bench', default=str(BENCH),
                        help='bench_friction binary (e.g. a build of the commit before)')
    parser.add_argument('--max-border', type=int, default=None,
                        help="the bordered solver's limit (default: the build's)")
    args = parser.parse_args()
    blas_env.apply()
    sides = args.sides or (QUICK if args.quick else SIDES)
    # --tests: the benchmark programs are built with the unit tests.
    subprocess.run([str(TOP / 'tools' / 'bootstrap'), '--tests'], stdin=subprocess.DEVNULL,
                   check=True)
    blas = subprocess.run(['ldd', args.bench], capture_output=True, text=True).stdout
    blas = re.search(r'libblas\.so\S* => (\S+)', blas)
    print('# Friction tables (benchmarks/friction_table.py '
          + ' '.join(sys.argv[1:]) + ')')
    print()
    print(f'- {time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())}; load average at start '
          f'{" ".join(f"{x:.2f}" for x in os.getloadavg())}; {os.cpu_count()} cores')
    print(f'- BLAS: {os.path.realpath(blas.group(1)) if blas else "not linked"}; '
          + ', '.join(f'{k}={os.environ.get(k, "unset")}' for k in (
              'OMP_NUM_THREADS', 'OMP_THREAD_LIMIT', 'OPENBLAS_NUM_THREADS', 'OPENBLAS_CORETYPE')))
    print('- woven net, 4 elements per segment; full cycle = load, unload to half, reload, '
          f'60 steps; above {args.cycle_max} crossings per side the first {args.steps} load '
          'step(s) only')
    rows = []
    for net in args.nets:
        for scheme in args.schemes:
            for side in sides:
                steps = args.steps if side > args.cycle_max else 0
                print(f'# {net} {scheme} side {side} ...', file=sys.stderr, flush=True)
                row = run(side, scheme, net == 'skewed', steps, args.timeout, args.bench,
                          args.max_border)
                row.update(net=net, scheme=scheme, side=side, cycle=not steps)
                print(f'#   {row.get("failed") or row.get("ms_per_step") + " ms/step"}',
                      file=sys.stderr, flush=True)
                rows.append(row)
    print()
    print('| net | scheme | unknowns | passages | run | steps | Newton / step '
          '| factorisations / step | wall ms / step | CPU ms / step | factorisation share '
          '| peak RSS MiB |')
    print('|---|---|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|')
    for r in rows:
        if 'failed' in r:
            print(f'| {r["net"]} | {r["scheme"]} | side {r["side"]} | | '
                  f'{"cycle" if r["cycle"] else "load"} | | | | {r["failed"]} | | | |')
            continue
        steps = int(r['steps'])
        print(f'| {r["net"]} | {r["scheme"]} | {int(r["unknowns"]):,} | {int(r["passages"]):,} '
              f'| {"cycle" if r["cycle"] else "load"} | {steps} | {r["newton_per_step"]} '
              f'| {r["factor_per_step"]} | {float(r["ms_per_step"]):.1f} '
              f'| {float(r["cpu_ms_per_step"]):.1f} | {r["factor_pct"]} % '
              f'| {r["rss_MiB"]:.0f} |')
    print()
    print('Jacobians at the final state (`factors:` line; CPU ms per factorisation + solve, '
          'nonzeros of the factors; exact zeros among the stored entries):')
    print()
    print('| net | scheme | unknowns | friction LU nnz KLU (ms) | friction LU nnz UMFPACK (ms) '
          '| elastic CHOLMOD ms | CPU step / elastic CHOLMOD | zeros friction (positions, '
          'flow rows, flow columns) | zeros elastic |')
    print('|---|---|---:|---:|---:|---:|---:|---|---:|')
    for r in rows:
        if 'failed' in r or not r.get('zeros'):
            continue
        klu, umf, chol = r['lu_klu'], r['lu_umfpack'], r['cholmod']
        timed = chol and float(chol[0]) > 0
        ratio = f'{float(r["cpu_ms_per_step"]) / float(chol[0]):.0f}' if timed else '-'
        z = r['zeros']
        print(f'| {r["net"]} | {r["scheme"]} | {int(r["unknowns"]):,} '
              f'| {klu[0]} ({klu[1]}) | {umf[0]} ({umf[1]}) | '
              f'{chol[0] if timed else "-"} | {ratio} '
              f'| {z[0]} % ({z[1]}, {z[2]}, {z[3]} %) | {z[4]} % |'
              if timed else
              f'| {r["net"]} | {r["scheme"]} | {int(r["unknowns"]):,} | - | - | - | - '
              f'| {z[0]} % ({z[1]}, {z[2]}, {z[3]} %) | {z[4]} % |')
    print()
    print('Bordered solver of the reduced systems (`bordered:` line; border widths are the '
          'slipping flows of each factorisation):')
    print()
    for r in rows:
        if r.get('bordered'):
            print(f'- {r["net"]} {r["scheme"]} {int(r["unknowns"]):,}: '
                  + r['bordered'].removeprefix('bordered: '))
    print()
    print('Exponents (least-squares fit of CPU ms / step against unknowns, sizes run over '
          'the same kind of run; wall ms / step in brackets, which a loaded machine '
          'blurs):')
    print()
    for net in args.nets:
        for scheme in args.schemes:
            for cycle in (True, False):
                runs = [r for r in rows if r['net'] == net and r['scheme'] == scheme
                        and r['cycle'] == cycle and 'failed' not in r]
                if len(runs) < 2:
                    continue
                cpu = [(int(r['unknowns']), float(r['cpu_ms_per_step'])) for r in runs]
                wall = [(int(r['unknowns']), float(r['ms_per_step'])) for r in runs]
                text = f'- {net}, {scheme}, {"cycle" if cycle else "first load steps"}: ' \
                       f'n^{slope(cpu):.2f} (n^{slope(wall):.2f}) over ' \
                       f'{cpu[0][0]:,}-{cpu[-1][0]:,}'
                big = [k for k, p in enumerate(cpu) if p[0] >= 5000]
                if 2 <= len(big) < len(cpu):
                    text += f'; n^{slope([cpu[k] for k in big]):.2f} ' \
                            f'(n^{slope([wall[k] for k in big]):.2f}) from {cpu[big[0]][0]:,}'
                print(text)
    print()
    print('Commands:')
    print()
    for r in rows:
        print(f'    {r["command"]}')


if __name__ == '__main__':
    main()
