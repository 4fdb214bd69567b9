#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""yarnfort against the bare SuiteSparse floor and OpenSeesPy, in one run.

    benchmarks/compare.py                 # 1e3, 1e4, 1e5 and 1e6 unknowns
    benchmarks/compare.py --quick         # 1e3 and 1e4
    benchmarks/compare.py --sides 18 58   # chosen sizes (interior nodes per side)

The net is bench_newton's pretensioned cable net in its `linear` variant: side x side
interior nodes at unit spacing, cables along x and y (EA = 10 N, linear strings), the
anchors at the cable ends moved outward by 2 % of the net's width (a 4 % pre-stretch),
-0.01 N along z on every interior node, all at once in one load step. Both codes start
from the interior nodes at the homogeneous pre-stretch (at the flat stress-free net the
transverse stiffness of a truss model is zero). OpenSeesPy builds the same net from the
same numbering: corotTruss elements between the nodes of that first guess, on an Elastic
material with an initial strain per element that makes the tension EA (l / L - 1) of
the original length L (yarnfort's linear law; the anchors are fixed there, at their prescribed
places: OpenSees takes initial displacements set on nodes as stress-free), Newton in one
LoadControl step with the loads in a Linear pattern, and
a max-norm test on the unbalance at residual_tolerance (1e-10, yarnfort's default) times
the pre-tension (0.4 N): yarnfort's row test is |F_i| <= 1e-10 times the largest force
at the node, which is at least the pre-tension. The z displacement of the centre node is
compared between the two.

yarnfort runs through build/benchmarks/bench_newton (its default elastic solver,
CHOLMOD with KLU as fallback; floor columns: bare CHOLMOD, UMFPACK and KLU on the
Jacobian at the solution, bench_floor). OpenSeesPy (a benchmark-only dependency, PyPI
`openseespy`, pinned in benchmarks/requirements-bench.txt) is installed by this script
into a virtual environment of its own, .venv-bench, never into .venv or the test path.
Times are process CPU times of the solve alone (model building excluded in both), the
fastest of --repeat runs below 1e5 unknowns;
peak memory is each process's peak resident set (/usr/bin/time -v), model building
included. The tables are printed as markdown.
"""
import argparse
import json
import math
import os
import pathlib
import re
import resource
import subprocess
import sys
import time

import blas_env

TOP = pathlib.Path(__file__).resolve().parent.parent
BENCH = TOP / 'build' / 'benchmarks' / 'bench_newton'
VENV = TOP / '.venv-bench'
REQUIREMENTS = TOP / 'benchmarks' / 'requirements-bench.txt'
EA = 10.0
STRETCH = 0.04
LOAD = -0.01
TOLERANCE = 1e-10
SIDES = [18, 58, 183, 577]
QUICK = [18, 58]
# OpenSees linear systems tried (the faster one per size is compared).
SYSTEMS = ['UmfPack', 'SparseSYM']


def grid_ids(side):
    """bench_common's number_grid_nodes: ids 1..n row by row, corners left out (0)."""
    ids = {}
    n = 0
    for j in range(side + 2):
        for i in range(side + 2):
            if i in (0, side + 1) and j in (0, side + 1):
                continue
            n += 1
            ids[i, j] = n
    return ids


def run_opensees(side, system):
    """In .venv-bench: build the net, solve, print one JSON line."""
    import openseespy.opensees as ops
    ids = grid_ids(side)
    centre = 0.5 * (side + 1)
    start = time.process_time()
    ops.wipe()
    ops.model('basic', '-ndm', 3, '-ndf', 3)
    # Interior nodes at the pre-stretched first guess, anchors at their final places
    # (moved outward, normal to their edge only).
    for (i, j), tag in ids.items():
        x = centre + (1 + STRETCH) * (i - centre) if j not in (0, side + 1) else i
        y = centre + (1 + STRETCH) * (j - centre) if i not in (0, side + 1) else j
        ops.node(tag, float(x), float(y), 0.0)
    # corotTruss measures strain on the length Lo between its nodes as placed; for the
    # original length L = 1, E' = Lo EA and an initial strain 1 - 1 / Lo give
    # T = EA (l / L - 1), yarnfort's linear law. Interior elements share Lo = 1 + s.
    materials = {}

    def material(a, b):
        length = math.dist(ops.nodeCoord(a), ops.nodeCoord(b))
        key = round(length, 15)
        if key not in materials:
            tag = 2 * len(materials) + 1
            ops.uniaxialMaterial('Elastic', tag + 1, length * EA)
            ops.uniaxialMaterial('InitStrainMaterial', tag, tag + 1, 1 - 1 / length)
            materials[key] = tag
        return materials[key]

    element = 0
    for j in range(1, side + 1):
        for i in range(side + 1):
            element += 1
            a, b = ids[i, j], ids[i + 1, j]
            ops.element('corotTruss', element, a, b, 1.0, material(a, b))
    for i in range(1, side + 1):
        for j in range(side + 1):
            element += 1
            a, b = ids[i, j], ids[i, j + 1]
            ops.element('corotTruss', element, a, b, 1.0, material(a, b))
    for k in range(1, side + 1):
        for i, j in ((0, k), (side + 1, k), (k, 0), (k, side + 1)):
            ops.fix(ids[i, j], 1, 1, 1)
    ops.timeSeries('Linear', 1)
    ops.pattern('Plain', 1, 1)
    for j in range(1, side + 1):
        for i in range(1, side + 1):
            ops.load(ids[i, j], 0.0, 0.0, LOAD)
    ops.constraints('Plain')
    ops.numberer('Plain' if system == 'UmfPack' else 'RCM')
    ops.system(system)
    ops.test('NormUnbalance', TOLERANCE * EA * STRETCH, 100, 0, 0)
    ops.algorithm('Newton')
    ops.integrator('LoadControl', 1.0)
    ops.analysis('Static')
    build = time.process_time() - start
    wall = time.perf_counter()
    start = time.process_time()
    status = ops.analyze(1)
    cpu = time.process_time() - start
    wall = time.perf_counter() - wall
    c = (side + 1) // 2
    result = {'status': status, 'iterations': ops.testIter(), 'cpu_s': cpu,
              'wall_s': wall, 'build_cpu_s': build, 'w_centre': ops.nodeDisp(ids[c, c], 3),
              'unknowns': 3 * side * side, 'libraries': loaded_libraries(),
              'peak_MiB': resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024}
    print(json.dumps(result), flush=True)


def loaded_libraries():
    """BLAS / LAPACK / OpenMP libraries mapped into this process."""
    names = set()
    with open('/proc/self/maps') as maps:
        for line in maps:
            path = line.split()[-1]
            if re.search(r'lib(open)?blas|liblapack|libgomp|libomp', path):
                names.add(os.path.realpath(path))
    return sorted(names)


def ensure_venv():
    """.venv-bench with the pinned OpenSeesPy (created or updated when needed)."""
    stamp = VENV / '.requirements-installed'
    python = VENV / 'bin' / 'python'
    if not python.exists():
        print('# creating .venv-bench (OpenSeesPy, benchmark only)', file=sys.stderr)
        subprocess.run([sys.executable, '-m', 'venv', str(VENV)], check=True)
    if not stamp.exists() or stamp.read_text() != REQUIREMENTS.read_text():
        subprocess.run([str(python), '-m', 'pip', 'install', '-q', '-r', str(REQUIREMENTS)],
                       check=True)
        stamp.write_text(REQUIREMENTS.read_text())
    return python


def timed(command):
    """Run under /usr/bin/time -v: (stdout, peak RSS MiB)."""
    done = subprocess.run(['/usr/bin/time', '-v'] + command, capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f'{" ".join(command)} failed ({done.returncode}):\n'
                           f'{done.stdout}{done.stderr}')
    peak = re.search(r'Maximum resident set size \(kbytes\): (\d+)', done.stderr)
    return done.stdout, int(peak.group(1)) / 1024 if peak else float('nan')


def run_yarnfort(side, header):
    out, peak = timed([str(BENCH), str(side), 'cholmod+klu', '1', 'linear'])
    print(f'# bench_newton {side} cholmod+klu 1 linear: {out.strip()}', file=sys.stderr,
          flush=True)
    if len(out.split()) != len(header):
        raise RuntimeError(f'bench_newton printed {len(out.split())} fields for '
                           f'{len(header)} columns: {out}')
    row = dict(zip(header, out.split()))
    row['peak_rss_MiB'] = peak
    return row


def thread_state(python):
    blas = subprocess.run(['ldd', str(BENCH)], capture_output=True, text=True).stdout
    blas = re.search(r'libblas\.so\S* => (\S+)', blas)
    ops_libs = subprocess.run(
        [str(python), '-c', 'import openseespy.opensees, sys; sys.path.insert(0, "'
         + str(TOP / 'benchmarks') + '"); import compare; print(compare.loaded_libraries())'],
        capture_output=True, text=True).stdout.strip()
    lines = [
        f'- yarnfort BLAS: {os.path.realpath(blas.group(1)) if blas else "not linked"}',
        f'- OpenSeesPy libraries loaded: {ops_libs}',
        '- environment: ' + ', '.join(f'{k}={os.environ.get(k, "unset")}' for k in (
            'OMP_NUM_THREADS', 'OMP_THREAD_LIMIT', 'OPENBLAS_NUM_THREADS', 'OPENBLAS_CORETYPE')),
        '- yarnfort thread policy (src/yarnfort/linalg/process/threads.f90; applies where the '
        'variables are unset): the libraries\' OpenMP regions and OpenBLAS on one thread',
        f'- load average at start: {" ".join(f"{x:.2f}" for x in os.getloadavg())}; '
        f'{os.cpu_count()} cores',
    ]
    return '\n'.join(lines)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--sides', type=int, nargs='+', help='interior nodes per side')
    parser.add_argument('--quick', action='store_true', help='sides 18 and 58 only')
    parser.add_argument('--opensees', nargs=2, metavar=('SIDE', 'SYSTEM'),
                        help=argparse.SUPPRESS)
    parser.add_argument('--repeat', type=int, default=5,
                        help='runs per code below 1e5 unknowns, the fastest (CPU) kept '
                             '(default %(default)s: a few ms move with the machine\'s load)')
    parser.add_argument('--systems', nargs='+', default=SYSTEMS,
                        help='OpenSees linear systems to try (default: %(default)s)')
    args = parser.parse_args()
    blas_env.apply()
    if args.opensees:
        run_opensees(int(args.opensees[0]), args.opensees[1])
        return
    sides = args.sides or (QUICK if args.quick else SIDES)
    # --tests: the benchmark programs are built with the unit tests.
    subprocess.run([str(TOP / 'tools' / 'bootstrap'), '--tests'], stdin=subprocess.DEVNULL,
                   check=True)
    python = ensure_venv()
    print('# yarnfort against the SuiteSparse floor and OpenSeesPy (benchmarks/compare.py)')
    print(time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime()))
    print(thread_state(python))
    header = subprocess.run([str(BENCH), '--header'], capture_output=True, text=True,
                            check=True).stdout.split()
    rows = []
    for side in sides:
        repeats = args.repeat if side < 100 else 1
        yf = min((run_yarnfort(side, header) for _ in range(repeats)),
                 key=lambda row: float(row['cpu_s']))
        ops_runs = {}
        for system in args.systems:
            results = []
            for _ in range(repeats):
                out, peak = timed([str(python), str(pathlib.Path(__file__).resolve()),
                                   '--opensees', str(side), system])
                print(f'# OpenSeesPy {side} {system}: {out.strip().splitlines()[-1]}',
                      file=sys.stderr, flush=True)
                result = json.loads(out.strip().splitlines()[-1])
                result['peak_rss_MiB'] = peak
                results.append(result)
            result = min(results, key=lambda r: r['cpu_s'])
            ops_runs[system] = result
            print(f'# side {side}: OpenSeesPy {system}: {result["iterations"]} iterations, '
                  f'{result["cpu_s"]:.3f} s CPU (status {result["status"]})',
                  file=sys.stderr, flush=True)
        print(f'# side {side}: yarnfort {yf["iters"]} iterations, {yf["cpu_s"]} s CPU',
              file=sys.stderr, flush=True)
        rows.append((side, yf, ops_runs))
    print_tables(rows)


def print_tables(rows):
    print()
    print('Per Newton iteration (CPU ms): yarnfort whole iteration and its factor + solve; '
          'bare CHOLMOD / UMFPACK / KLU factor + solve on the Jacobian at the solution '
          '(bench_floor); OpenSeesPy whole iteration.')
    print()
    print('| unknowns | nnz | yf iterations | yf ms / iteration | yf factor + solve ms '
          '| bare CHOLMOD | bare UMFPACK | bare KLU | yf iteration / fastest bare '
          '| OpenSeesPy system | OpenSeesPy iterations | OpenSeesPy ms / iteration '
          '| yf / OpenSeesPy per iteration |')
    print('|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|---:|---:|')
    for side, yf, runs in rows:
        best = min((r for r in runs.values() if r['status'] == 0),
                   key=lambda r: r['cpu_s'], default=None)
        name = next((k for k, r in runs.items() if r is best), '-')
        iters = int(yf['iters'])
        per = 1e3 * float(yf['cpu_s']) / iters
        ops_per = 1e3 * best['cpu_s'] / max(best['iterations'], 1) if best else float('nan')
        print(f'| {yf["unknowns"]} | {yf["nnz"]} | {iters} | {per:.2f} | {yf["yf_ms"]} '
              f'| {yf["chol_ms"]} | {yf["umf_ms"]} | {yf["klu_ms"]} | {yf["iter_x_floor"]} '
              f'| {name} | {best["iterations"] if best else "-"} | {ops_per:.2f} '
              f'| {per / ops_per:.2f} |')
    print()
    print('Whole solve (CPU s, model building excluded), agreement and peak memory:')
    print()
    systems = list(rows[0][2])
    print('| unknowns | yarnfort s | ' + ' | '.join(f'OpenSeesPy {s} s' for s in systems)
          + ' | yarnfort / fastest OpenSeesPy | w_centre yarnfort (m) | rel. difference '
          '| yarnfort peak MiB | OpenSeesPy peak MiB |')
    print('|---:|---:|' + '---:|' * len(systems) + '---:|---:|---:|---:|---:|')
    for side, yf, runs in rows:
        ok = {k: r for k, r in runs.items() if r['status'] == 0}
        best = min(ok.values(), key=lambda r: r['cpu_s']) if ok else None
        cpu = float(yf['cpu_s'])
        w = float(yf['w_centre'])
        cells = ' | '.join(f'{r["cpu_s"]:.4f}' if r['status'] == 0 else
                           f'failed ({r["status"]})' for r in runs.values())
        if best:
            diff = abs(w - best['w_centre']) / abs(best['w_centre'])
            tail = (f'{cpu / best["cpu_s"]:.2f} | {w:.12e} | {diff:.1e} '
                    f'| {yf["peak_rss_MiB"]:.0f} | {best["peak_rss_MiB"]:.0f}')
        else:
            tail = f'- | {w:.12e} | - | {yf["peak_rss_MiB"]:.0f} | -'
        print(f'| {yf["unknowns"]} | {cpu:.4f} | {cells} | {tail} |')


if __name__ == '__main__':
    main()
