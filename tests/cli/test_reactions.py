# SPDX-License-Identifier: MIT
"""reactions.csv (&output node_reactions): the reaction of every constrained node per
converged step, in long format. The rows of a support set add up to that set's reaction
columns of curve.csv; a restart keeps the rows up to its step and appends, as curve.csv
does; a run without the option deletes the file of an earlier run."""
from __future__ import annotations

import csv
from collections import defaultdict
from pathlib import Path

import numpy as np

from yarnfort.results import read_reactions as read_reactions_table

from test_restart import SCENES, compare_curves, read_rows, with_output

#: Per-node reactions summed vs the per-set sums of curve.csv: the same doubles added in
#: another order (relative to the largest reaction component of the set and step).
SUM_RTOL = 1e-12
OPTION = "node_reactions = .true."


def read_reactions(folder: Path) -> list[dict[str, str]]:
    with open(folder / "reactions.csv", newline="") as stream:
        rows = list(csv.DictReader(stream))
    assert rows and list(rows[0]) == ["step", "support", "node", "rx", "ry", "rz"]
    return rows


def check_sums(folder: Path) -> float:
    """Assert that each set's node rows add up to its curve.csv columns at every step;
    return the largest relative difference."""
    curve = read_rows(folder)
    sums: dict[tuple[int, str], np.ndarray] = defaultdict(lambda: np.zeros(3))
    nodes: dict[tuple[int, str], list[int]] = defaultdict(list)
    for row in read_reactions(folder):
        key = int(row["step"]), row["support"]
        sums[key] += [float(row[c]) for c in ("rx", "ry", "rz")]
        nodes[key].append(int(row["node"]))
    sets = [name[:-3] for name in curve[0] if name.endswith("_rx")]
    assert {k[0] for k in sums} == {int(r["step"]) for r in curve}
    worst = 0.0
    for row in curve:
        for name in sets:
            key = int(row["step"]), name
            assert key in sums, key
            assert len(set(nodes[key])) == len(nodes[key])   # each node once per set
            expected = np.array([float(row[f"{name}_r{c}"]) for c in "xyz"])
            scale = max(np.max(np.abs(expected)), 1e-300)
            difference = np.max(np.abs(sums[key] - expected)) / scale
            assert difference <= SUM_RTOL, (key, sums[key], expected)
            worst = max(worst, difference)
    return worst


def test_node_reactions_sum_to_the_set_reactions(run_yarnfort, tmp_path):
    text = SCENES["elastic_pegs"]
    run = run_yarnfort(with_output(text, "full", output=OPTION))
    assert run.returncode == 0, run.stderr
    worst = check_sums(tmp_path / "full")
    rows = read_reactions(tmp_path / "full")
    # Sets and nodes as the scene gives them; 'plane' fixes only z: rx = ry = 0.
    by_set = defaultdict(set)
    for row in rows:
        by_set[row["support"]].add(int(row["node"]))
        if row["support"] == "plane":
            assert float(row["rx"]) == 0.0 and float(row["ry"]) == 0.0
    assert by_set["plane"] == {2, 3, 4} and by_set["anchors"] == {6, 7, 8}
    assert any(float(r["rz"]) != 0.0 or float(r["rx"]) != 0.0 for r in rows)
    print(f"{len(rows)} rows, largest relative difference of the sums {worst:.1e}")
    # The package's reader gives the same table.
    table = read_reactions_table(tmp_path / "full")
    assert len(table) == len(rows) and list(table["support"]) == [r["support"] for r in rows]
    np.testing.assert_array_equal(table["rz"], [float(r["rz"]) for r in rows])
    assert table.to_array()["support"][0] == rows[0]["support"]
    # A run without the option deletes the earlier run's file.
    run = run_yarnfort(with_output(text, "full"))
    assert run.returncode == 0, run.stderr
    assert not (tmp_path / "full" / "reactions.csv").exists()


def test_node_reactions_on_restart(run_yarnfort, tmp_path):
    text = SCENES["elastic_pegs"]
    full = run_yarnfort(with_output(text, "full", output=OPTION))
    assert full.returncode == 0, full.stderr
    first = run_yarnfort(with_output(text, "parts", output=OPTION, control="max_steps = 19"))
    assert first.returncode == 0, first.stderr
    steps = {int(r["step"]) for r in read_reactions(tmp_path / "parts")}
    assert max(steps) == 19
    # Rows written after the restart step (as by a kill after a later step) are dropped.
    with open(tmp_path / "parts" / "reactions.csv", "a") as stream:
        stream.write("25,first,1,1.0,2.0,3.0\n25,first")
    second = run_yarnfort(with_output(text, "parts", output=OPTION,
                                      control="restart = .true."))
    assert second.returncode == 0, second.stderr
    check_sums(tmp_path / "parts")
    full_rows, parts_rows = (read_reactions(tmp_path / name) for name in ("full", "parts"))
    key = lambda r: (r["step"], r["support"], r["node"])   # noqa: E731
    assert [key(r) for r in parts_rows] == [key(r) for r in full_rows]
    # The forces as those of the uninterrupted run (tolerance: see test_restart).
    forces = lambda rows: [{c: r[c] for c in ("rx", "ry", "rz")} for r in rows]  # noqa: E731
    compare_curves(forces(full_rows), forces(parts_rows))


def test_restart_needs_the_file_it_continues(run_yarnfort, tmp_path):
    text = SCENES["capstan"]
    first = run_yarnfort(with_output(text, "parts", control="max_steps = 3"))
    assert first.returncode == 0, first.stderr
    second = run_yarnfort(with_output(text, "parts", output=OPTION,
                                      control="restart = .true."))
    assert second.returncode == 2
    assert "reactions.csv" in second.stderr
