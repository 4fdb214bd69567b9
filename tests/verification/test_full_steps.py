# SPDX-License-Identifier: MIT
"""Full Newton steps first, the line search only where they fail, and the failure found
early: a pretensioned square cable net (the net of benchmarks/bench_newton) loaded
transversely and pulled outward by 2 % in one load step. From the flat start the full
Newton steps jump far from the solution and wander there (plain Newton, line_search =
.false., needs over 200 iterations); the solver must give them up after a few
iterations without progress and converge with the line search, instead of spending all
max_iterations on them first.

Checks: the step converges; its Newton iterations stay far below max_iterations (200
here: before the fix the count was at least 200); the supports carry the applied load
(the z reactions sum to the total transverse force, relative to it).
"""
import csv

SIDE = 10
MAX_ITERATIONS = 200
#: Newton iterations of the step allowed: the full steps' patience (5), the line-search
#: solve (about 10 on this net) and margin; far below MAX_ITERATIONS.
ITERATION_BOUND = 50
NODE_FORCE = 0.01
#: Relative: the reactions are sums of element forces converged to 1e-10 of the forces
#: at each node.
FORCE_RTOL = 1e-8


def cable_net(side: int) -> str:
    ids = {}
    xyz = []
    for j in range(side + 2):
        for i in range(side + 2):
            if i in (0, side + 1) and j in (0, side + 1):
                continue
            ids[i, j] = len(xyz) + 1
            xyz.append(f"{i}, {j}, 0.0")
    groups = ["&material\n name = 'cable'\n law = 'neo_hookean'\n modulus = 2.0e6\n"
              " area = 5.0e-6\n/",
              "&nodes\n xyz = " + ",\n  ".join(xyz) + "\n/"]
    for j in range(1, side + 1):
        groups.append("&yarn\n material = 'cable'\n nodes = "
                      + ", ".join(str(ids[i, j]) for i in range(side + 2)) + "\n/")
    for i in range(1, side + 1):
        groups.append("&yarn\n material = 'cable'\n nodes = "
                      + ", ".join(str(ids[i, j]) for j in range(side + 2)) + "\n/")
    pull = 0.02 * (side + 1)
    edges = {"west": ([ids[0, j] for j in range(1, side + 1)], (-pull, 0.0)),
             "east": ([ids[side + 1, j] for j in range(1, side + 1)], (pull, 0.0)),
             "south": ([ids[i, 0] for i in range(1, side + 1)], (0.0, -pull)),
             "north": ([ids[i, side + 1] for i in range(1, side + 1)], (0.0, pull))}
    for name, (nodes, (dx, dy)) in edges.items():
        groups.append(f"&support\n name = '{name}'\n nodes = "
                      + ", ".join(map(str, nodes))
                      + f"\n fix = 'xyz'\n displacement = {dx}, {dy}, 0.0\n/")
    interior = [ids[i, j] for j in range(1, side + 1) for i in range(1, side + 1)]
    groups.append("&load\n nodes = " + ", ".join(map(str, interior))
                  + f"\n force = 0.0, 0.0, {-NODE_FORCE}\n/")
    groups.append("&path\n time = 0.0, 1.0\n p_force = 0.0, 1.0\n p_disp = 0.0, 1.0\n/")
    groups.append(f"&solver\n initial_step = 1.0\n max_step = 1.0\n"
                  f" max_iterations = {MAX_ITERATIONS}\n/")
    groups.append("&output\n folder = 'out'\n/")
    return "\n".join(groups) + "\n"


def test_diverging_full_steps_are_given_up_early(run_yarnfort):
    run = run_yarnfort(cable_net(SIDE))
    assert run.returncode == 0, run.stderr
    with open(run.folder / "out" / "curve.csv", newline="") as handle:
        rows = list(csv.DictReader(handle))
    step = rows[-1]
    assert float(step["p_force"]) == 1.0
    assert int(step["step_cuts"]) == 0
    iterations = int(step["newton_iterations"])
    assert iterations <= ITERATION_BOUND, (
        f"{iterations} Newton iterations for one step (max_iterations = {MAX_ITERATIONS}):"
        " the diverging full steps were not given up early")
    total = SIDE * SIDE * NODE_FORCE
    reaction = sum(float(step[f"{edge}_rz"]) for edge in ("west", "east", "south", "north"))
    assert abs(reaction - total) <= FORCE_RTOL * total, (reaction, total)
