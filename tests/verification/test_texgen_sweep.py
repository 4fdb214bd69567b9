# SPDX-License-Identifier: MIT
"""TexGen models as TexGen users make them (tests/verification/texgen_sweep.py): every
case imports and runs, with the contacts its pattern implies, or is refused with a message
in TexGen's terms (texgen_sweep.REFUSED: the TexGen yarn, what to change), nothing written.

(a) Contact counts: a weave of nx x ny crossings has nx * ny contacts (one per crossing)
    whatever its yarn width: yarns as wide as the spacing (TexGen's default without
    SetYarnWidths) touch their neighbours side by side, which is not a crossing. Two
    plain layers stacked touching: each layer's crossings, and at each crossing the lower
    layer's upper yarn on the upper layer's lower yarn, 3 nx ny. TexGen's weft knit cell:
    2 (the loop's head around the feet of the loop above).
(b) TexGen places the centre lines from spacing and thickness only (the width changes the
    sections), so a weave with the default width and one with SetYarnWidths(0.8) give the
    same curve (to Newton's tolerance, 1e-10 of the force scale).
(c) Two identical plain layers stacked: each layer stretches as the single one (the
    stacked crossings move together), so the force per width is twice the single layer's.

With pytexgen in .venv-texgen every case is made with it; without, the shipped files
(tests/data/texgen/*.tg3.gz, made the same way) are used.
"""
from __future__ import annotations

import gzip
from pathlib import Path

import numpy as np
import pytest

import texgen_sweep as sweep
from conftest import EXECUTABLE
from fabric_scenes import TOP
from yarnfort import read_curve

#: Newton's residual tolerance, relative to the force scale.
SAME_CURVE = 1e-10


@pytest.fixture(scope="module")
def models(tmp_path_factory):
    """Case name -> model file: made with pytexgen where installed, else shipped."""
    folder = tmp_path_factory.mktemp("texgen_models")
    make = sweep.have_pytexgen()
    found = {name: sweep.model(name, folder, make) for name in sweep.CASES}
    return {name: path for name, path in found.items() if path is not None}


def expected_counts(name: str) -> tuple[int, int] | None:
    kind, values = sweep.CASES[name]
    if kind == "knit":
        # A loop longer than the wale height (values[1] > values[0]) reaches further
        # into the loops above: more touches than the head's two, not counted here.
        return None if values[1] > values[0] else (1, 2)
    nx, ny = int(values[0]), int(values[1])
    if kind == "layered":
        return 2 * (nx + ny), 3 * nx * ny
    return nx + ny, nx * ny


@pytest.mark.parametrize("name", list(sweep.CASES))
def test_case_imports_and_runs(models, tmp_path, name):
    if name not in models:
        pytest.skip(f"pytexgen is not installed and {name} is not shipped")
    outcome = sweep.run_case(EXECUTABLE, name, models[name], tmp_path / "run")
    if name in sweep.REFUSED:
        assert not outcome.ok and outcome.detail.startswith("exit 2:"), outcome.detail
        assert sweep.TEXGEN_TERMS.search(outcome.detail), outcome.detail
        assert sweep.REFUSED[name] in outcome.detail, outcome.detail
        assert not (tmp_path / "run" / "curve.csv").exists()
        return
    assert outcome.ok, outcome.detail
    counts = expected_counts(name)
    if counts is not None:
        assert outcome.detail == "{} yarns, {} contacts".format(*counts)
    force = read_curve(tmp_path / "run")["force_per_width"]
    assert np.all(np.isfinite(force)) and force[-1] > 0


@pytest.mark.parametrize("default, narrow", [
    ("plain_2x2_s1_t0.4", "plain_2x2_s1_t0.4_w0.8"),
    ("twill_4x4_s1_t0.2", "twill_4x4_s1_t0.2_w0.8")])
def test_default_width_gives_the_curve_of_narrower_yarns(models, tmp_path, default, narrow):
    if not {default, narrow} <= models.keys():
        pytest.skip("needs pytexgen (.venv-texgen) to make the narrower model")
    curves = []
    for name in (default, narrow):
        assert sweep.run_case(EXECUTABLE, name, models[name], tmp_path / name).ok
        curves.append(read_curve(tmp_path / name)["force_per_width"])
    scale = np.max(np.abs(curves[1]))
    assert np.max(np.abs(curves[0] - curves[1])) < SAME_CURVE * scale


def test_two_stacked_layers_carry_twice_the_force(models, tmp_path):
    single, stacked = "plain_2x2_s1_t0.4", "layered_2x2_s1_t0.4"
    curves = []
    for name in (single, stacked):
        assert sweep.run_case(EXECUTABLE, name, models[name], tmp_path / name).ok
        curves.append(read_curve(tmp_path / name)["force_per_width"])
    scale = np.max(np.abs(curves[1]))
    assert np.max(np.abs(curves[1] - 2 * curves[0])) < SAME_CURVE * scale


def test_repeated_master_node_is_dropped(run_yarnfort, tmp_path):
    """A master node repeated at the same position (TexGen accepts it: a span of no
    length) imports as the model without it: the same contacts and curve."""
    original = (TOP / "inputs" / "texgen_weave.tg3").read_text()
    start = original.index("<MasterNode")
    node = original[start:original.index("/>", start) + 2]
    repeated = tmp_path / "repeated.tg3"
    repeated.write_text(original.replace(node, node + "\n" + node, 1))
    curves = []
    for path in (TOP / "inputs" / "texgen_weave.tg3", repeated):
        folder = tmp_path / path.stem
        outcome = sweep.run_case(EXECUTABLE, "plain_2x2_s1_t0.4_w0.8", path, folder)
        assert outcome.ok and outcome.detail == "4 yarns, 4 contacts", outcome.detail
        curves.append(read_curve(folder)["force_per_width"])
    assert np.array_equal(curves[0], curves[1])


def test_shipped_files_are_the_sweep_cases():
    for path in (TOP / "tests" / "data" / "texgen").glob("*.tg3.gz"):
        name = path.name.removesuffix(".tg3.gz")
        assert name in sweep.CASES
        assert gzip.decompress(path.read_bytes()).lstrip().startswith(b"<?xml")
