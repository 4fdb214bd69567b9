# SPDX-License-Identifier: MIT
"""Plots, the namelist helpers and ``python -m yarnfort plot`` on a capstan run."""
from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.image as mpimg  # noqa: E402
import numpy as np  # noqa: E402
import pytest  # noqa: E402

from yarnfort import AddressError, read_curve, read_run  # noqa: E402
from yarnfort.namelist import (get_parameter, read_scene, set_parameter,  # noqa: E402
                               write_scene)
from yarnfort.plots import (plot_curve, plot_fan, plot_hysteresis,  # noqa: E402
                            plot_network, save_figure)

TOP = Path(__file__).resolve().parents[2]
SCENE = TOP / "inputs" / "capstan.nml"
#: Folder of the capstan results relative to the run directory (kept from the scene).
OUT = Path("out/capstan")
#: A real plot is well above this size; a blank PNG is far below it.
MIN_PNG_BYTES = 5_000
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


@pytest.fixture
def capstan(run_yarnfort, tmp_path) -> Path:
    """Output folder of inputs/capstan.nml run in tmp_path."""
    run = run_yarnfort(SCENE.read_text(), cwd=tmp_path)
    assert run.returncode == 0, run.stderr
    return tmp_path / OUT


def assert_png(path: Path) -> None:
    assert path.is_file()
    assert path.read_bytes()[:8] == PNG_MAGIC
    assert path.stat().st_size > MIN_PNG_BYTES
    pixels = mpimg.imread(path)
    assert pixels.ndim == 3 and np.var(pixels[..., :3]) > 0


def test_plot_functions_write_pngs(capstan, tmp_path):
    run = read_run(capstan)
    curve, states = run.curve, run.states
    axes = {
        "curve": plot_curve(curve, "pull"),
        "norm": plot_curve(curve, "pull", component="norm", x="time"),
        "hysteresis": plot_hysteresis(curve, "pull"),
        "network": plot_network(states[-1]),
        "fan": plot_fan({"run a": curve, "run b": curve}, "pull", title="copies"),
    }
    for name, ax in axes.items():
        assert_png(save_figure(ax.figure, tmp_path / "png" / f"{name}.png"))


def test_hysteresis_branches_distinct(capstan):
    curve = read_curve(capstan)
    ax = plot_hysteresis(curve, "pull")
    branches = {gid: [line for line in ax.get_lines() if line.get_gid() == gid]
                for gid in ("loading", "unloading")}
    assert branches["loading"] and branches["unloading"]
    load, unload = branches["loading"][0], branches["unloading"][0]
    assert (load.get_color(), load.get_linestyle()) != \
        (unload.get_color(), unload.get_linestyle())
    labels = [text.get_text() for text in ax.get_legend().get_texts()]
    assert labels == ["loading", "unloading"]


def test_plot_network_has_colorbar(capstan):
    states = read_run(capstan).states
    ax = plot_network(states[-1], projection="xy")
    assert len(ax.collections[0].get_segments()) == len(states[-1].elements)
    assert len(ax.figure.axes) == 2  # the network and its colorbar


def test_unknown_support_raises(capstan):
    with pytest.raises(KeyError, match="nope"):
        plot_curve(read_curve(capstan), "nope")


def _cli(*args: str) -> subprocess.CompletedProcess:
    env = dict(os.environ, MPLBACKEND="Agg")
    return subprocess.run([sys.executable, "-m", "yarnfort", *args], capture_output=True,
                          text=True, env=env, timeout=60)


def test_cli_plot(capstan, tmp_path):
    run = _cli("plot", str(capstan))
    assert run.returncode == 0, run.stderr
    assert_png(capstan / "plot.png")
    out = tmp_path / "named.png"
    run = _cli("plot", str(capstan), "--support", "pull", "--out", str(out))
    assert run.returncode == 0, run.stderr
    assert_png(out)


def test_cli_errors(capstan, tmp_path):
    run = _cli("plot", str(tmp_path / "missing"))
    assert run.returncode == 2
    assert "no output folder" in run.stderr
    run = _cli("plot", str(capstan), "--support", "nope")
    assert run.returncode == 2
    assert "unknown support 'nope'" in run.stderr and "pull" in run.stderr
    assert _cli("--help").returncode == 0


def test_set_parameter_addressing():
    scene = read_scene(SCENE)
    set_parameter(scene, "contact[0].friction_coefficient", 0.2)
    set_parameter(scene, "solver.max_step", 1)
    set_parameter(scene, "support[pull].displacement", [0.0, -0.2, 0.0])
    set_parameter(scene, "yarn[-1].material", "yarn")
    assert get_parameter(scene, "contact.friction_coefficient") == 0.2
    assert get_parameter(scene, "solver[0].max_step") == 1.0
    assert isinstance(get_parameter(scene, "solver.max_step"), float)
    assert scene["support"][1]["displacement"] == [0.0, -0.2, 0.0]
    assert scene["yarn"][3]["material"] == "yarn"
    with pytest.raises(AddressError, match="appears 4 times"):
        set_parameter(scene, "yarn.material", "peg")
    with pytest.raises(AddressError, match="has 4 &yarn"):
        set_parameter(scene, "yarn[4].material", "peg")
    with pytest.raises(AddressError, match="no &support group named 'nope'; names: "):
        get_parameter(scene, "support[nope].nodes")
    with pytest.raises(AddressError, match="bad parameter address"):
        set_parameter(scene, "contact friction", 0.1)


def test_namelist_round_trip_runs_identically(run_yarnfort, capstan, tmp_path):
    written = write_scene(read_scene(SCENE), tmp_path / "again" / "scene.nml")
    run = run_yarnfort(written.read_text(), cwd=written.parent)
    assert run.returncode == 0, run.stderr
    original, again = read_curve(capstan), read_curve(written.parent / OUT)
    assert original.names == again.names
    for name in original.names:
        if name != "wall_time":
            np.testing.assert_array_equal(again[name], original[name], err_msg=name)


def test_changed_parameter_changes_run(run_yarnfort, capstan, tmp_path):
    scene = set_parameter(read_scene(SCENE), "contact[0].friction_coefficient", 0.1)
    written = write_scene(scene, tmp_path / "low_mu" / "scene.nml")
    run = run_yarnfort(written.read_text(), cwd=written.parent)
    assert run.returncode == 0, run.stderr
    effective = read_scene(written.parent / OUT / "input.nml")
    assert get_parameter(effective, "contact.friction_coefficient") == pytest.approx(0.1)
    peak = np.abs(read_curve(written.parent / OUT).reaction("pull")[:, 1]).max()
    assert peak < np.abs(read_curve(capstan).reaction("pull")[:, 1]).max()
