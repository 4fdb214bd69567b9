# SPDX-License-Identifier: MIT
"""`python -m yarnfort plot` (issue 38 item 3): the network at the peak (or a chosen
step), force positive in tension against a displacement in mm, one unit for both plot
commands, readable colour bars, the channel selectable, and the history of rings and
obstacles. Expected values are taken from curve.csv by hand (sign and unit
conversions), not from the plotting code."""
from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402

import yarnfort  # noqa: E402
from yarnfort import read_curve  # noqa: E402
from yarnfort.__main__ import summary_figure  # noqa: E402
from yarnfort.plots import plot_states, tension_norm  # noqa: E402

TOP = Path(__file__).resolve().parents[2]
MM = 1e3  # millimetres per metre


@pytest.fixture(scope="module")
def runs(tmp_path_factory) -> Path:
    """vnet, capstan_pins, ring_sideways, knit, weave_shear and knit_biaxial run in one
    folder (out/<name>)."""
    where = tmp_path_factory.mktemp("runs")
    shutil.copytree(TOP / "inputs", where / "inputs")  # the knit's tables
    for name in ("vnet", "capstan_pins", "ring_sideways", "knit", "weave_shear",
                 "knit_biaxial"):
        with open(TOP / "inputs" / f"{name}.nml") as scene:
            done = subprocess.run([str(yarnfort.program_path())], stdin=scene,
                                  capture_output=True, text=True, cwd=where, timeout=600)
        assert done.returncode == 0, done.stderr
    return where / "out"


def branches(ax) -> tuple[np.ndarray, np.ndarray]:
    """The (x, y) of every loading and unloading line of an Axes, in drawing order."""
    lines = [line for line in ax.get_lines() if line.get_gid() in ("loading", "unloading")]
    return (np.concatenate([line.get_xdata() for line in lines]),
            np.concatenate([line.get_ydata() for line in lines]))


def shown_step(figure) -> int:
    title = figure.axes[1].get_title()
    return int(title.rsplit("step", 1)[1])


def colorbar_labels(figure) -> list[str]:
    bar = [ax for ax in figure.axes if ax.get_ylabel() == "tension (N)"][0]
    figure.canvas.draw()
    return [t.get_text() for t in bar.get_yticklabels()] + [bar.yaxis.get_offset_text()
                                                             .get_text()]


def test_pulled_support_is_positive_in_tension_against_mm(runs):
    """capstan_pins pulls its end down (-y): the plotted force is the reaction along the
    motion, -R_y, positive; the displacement -u_y in mm; the network is drawn at the
    step of the largest pull, and the obstacle's reaction has its own panel."""
    curve = read_curve(runs / "capstan_pins")
    figure = summary_figure(runs / "capstan_pins")
    left = figure.axes[0]
    x, y = branches(left)
    assert "(mm)" in left.get_xlabel() and "'pull'" in left.get_xlabel()
    assert "+ = tension" in left.get_ylabel()
    peak = np.argmax(-curve["pull_ry"])
    assert y.max() == pytest.approx(-curve["pull_ry"][peak], rel=1e-12)
    assert y.max() > 0
    assert x.max() == pytest.approx(-curve["pull_uy"][peak] * MM, rel=1e-12)
    assert shown_step(figure) == curve["step"][peak]
    assert figure.axes[1].get_xlabel().endswith("(mm)")
    titles = [ax.get_title() for ax in figure.axes]
    assert "obstacle history" in titles
    obstacle = figure.axes[titles.index("obstacle history")]
    ry = [line for line in obstacle.get_lines() if line.get_label().endswith("Ry")][0]
    np.testing.assert_array_equal(ry.get_ydata(), curve["pins_ry"])


def test_load_driven_scene_shows_the_loaded_peak_not_the_release(runs):
    """vnet is loaded to 0.5 N and released: the network shown is the loaded one (its
    tensions > 0, not the final released state), force = p_force * 0.5 N against the
    sag of the loaded node in mm."""
    curve = read_curve(runs / "vnet")
    figure = summary_figure(runs / "vnet")
    loading = [line for line in figure.axes[0].get_lines() if line.get_gid() == "loading"][0]
    rows = len(loading.get_ydata())
    assert rows > 2
    np.testing.assert_allclose(loading.get_ydata(), curve["p_force"][:rows] * 0.5,
                               rtol=1e-12)
    np.testing.assert_allclose(loading.get_xdata(), -curve["load_1_uy"][:rows] * MM,
                               rtol=1e-12)
    step = shown_step(figure)
    assert curve["p_force"][curve["step"] == step][0] == 1.0
    network = [c for c in figure.axes[1].collections if c.get_gid() == "elements"][0]
    assert np.all(network.get_array() > 0)
    labels = colorbar_labels(figure)
    assert not any("+" in label or "e" in label.lower() for label in labels), labels


def test_chosen_step_and_unknown_step(runs):
    figure = summary_figure(runs / "vnet", step=3)
    assert shown_step(figure) == 3
    run = subprocess.run([sys.executable, "-m", "yarnfort", "plot", str(runs / "vnet"),
                          "--step", "9999"], capture_output=True, text=True,
                         env=dict(os.environ, MPLBACKEND="Agg"), timeout=120)
    assert run.returncode == 2 and "no saved state of step 9999" in run.stderr


def test_ring_history_and_channel_choice(runs):
    """ring_sideways: by default the sideways channel (it changes in the most steps),
    with the ring's position against the sideways force; --channel down picks the
    downward load."""
    curve = read_curve(runs / "ring_sideways")
    figure = summary_figure(runs / "ring_sideways")
    assert "(side)" in figure.axes[0].get_title()
    assert "+x" in figure.axes[0].get_xlabel()
    titles = [ax.get_title() for ax in figure.axes]
    history = figure.axes[titles.index("ring history")]
    ring_x = [line for line in history.get_lines() if line.get_label().endswith(": x")][0]
    # Applied sideways force: side factor * 0.3 N (one node).
    np.testing.assert_allclose(ring_x.get_xdata(), curve["side"] * 0.3, rtol=1e-12)
    assert "(mm)" in history.get_ylabel()
    down = summary_figure(runs / "ring_sideways", channel="down")
    assert "(down)" in down.axes[0].get_title() and "-y" in down.axes[0].get_xlabel()
    run = subprocess.run([sys.executable, "-m", "yarnfort", "plot",
                          str(runs / "ring_sideways"), "--channel", "nope"],
                         capture_output=True, text=True, timeout=120,
                         env=dict(os.environ, MPLBACKEND="Agg"))
    assert run.returncode == 2 and "down, side" in run.stderr


def test_both_plot_commands_draw_lengths_in_mm(runs):
    states = plot_states(runs / "vnet", (0.0, 1.0), by="p_force")
    assert all(ax.get_xlabel().endswith("(mm)") for ax in states.axes[:2])
    assert summary_figure(runs / "vnet").axes[1].get_ylabel().endswith("(mm)")


def test_uniform_tension_has_a_plain_colour_range():
    """A uniform tension (one value to rounding) gets a range around it, not one of
    rounding noise that the colour bar would print as an offset."""
    value = 2e-2
    norm = tension_norm(np.array([value, value * (1 + 1e-13)]))
    assert norm.vmin < value < norm.vmax
    assert norm.vmax - norm.vmin == pytest.approx(0.1 * value, rel=1e-6)
    spread = tension_norm(np.array([1.0, 3.0]))
    assert (spread.vmin, spread.vmax) == (1.0, 3.0)


def test_another_support_and_a_fabric_support(runs):
    """--support names a support that does not move: its reaction on the net along the
    driver's direction (-y: minus R_y); a fabric's generated support that moves gives a
    displacement axis in mm (the default stays force per width against strain)."""
    curve = read_curve(runs / "capstan_pins")
    figure = summary_figure(runs / "capstan_pins", support="fixed")
    loading = [line for line in figure.axes[0].get_lines() if line.get_gid() == "loading"][0]
    rows = len(loading.get_ydata())
    np.testing.assert_allclose(loading.get_ydata(), -curve["fixed_ry"][:rows], rtol=1e-12)
    assert "'fixed'" in figure.axes[0].get_ylabel() and "-y" in figure.axes[0].get_ylabel()
    knit = read_curve(runs / "knit")
    assert summary_figure(runs / "knit").axes[0].get_xlabel() == "macroscopic strain (1)"
    pulled = summary_figure(runs / "knit", support="stretch").axes[0]
    x, y = branches(pulled)
    assert "(mm)" in pulled.get_xlabel() and "+x" in pulled.get_xlabel()
    assert x.max() == pytest.approx(knit["stretch_ux"].max() * MM, rel=1e-12)
    assert y.max() == pytest.approx(knit["stretch_rx"].max(), rel=1e-12)


def test_sheared_cell_shows_its_shear_curve_not_anchor_noise(runs):
    """inputs/weave_shear.nml has no force_per_width (no x stretch) and no moving support:
    the summary draws n12 against gamma12, not its anchor's reaction (rounding, 1e-13 N),
    and shows the state at full shear (p_disp = 1 at t = 1, the path's peak), where the
    pin-jointed net carries n12 = n22 tan(gamma12) with n22 held at 50 N/m and
    gamma12 = atan(0.4 / (1 + e22)) (REFERENCE.md, *Shear*)."""
    curve = read_curve(runs / "weave_shear")
    figure = summary_figure(runs / "weave_shear")
    left = figure.axes[0]
    assert left.get_xlabel() == "gamma12 (rad)"
    assert "n12 (N/m)" in left.get_ylabel()
    peak = int(np.flatnonzero(curve["time"] == 1.0)[0])
    assert shown_step(figure) == curve["step"][peak]
    gamma = np.arctan(0.4 / (1.0 + curve["e22"][peak]))
    marker = [line for line in left.get_lines() if line.get_gid() == "shown_step"][0]
    assert marker.get_xdata()[0] == pytest.approx(gamma, rel=1e-12)
    assert marker.get_ydata()[0] == pytest.approx(50.0 * np.tan(gamma), rel=1e-6)
    x, y = branches(left)
    np.testing.assert_allclose(y, 50.0 * np.tan(x), rtol=1e-6, atol=1e-6 * 50.0)


def test_fabric_curve_is_labelled_per_reference_width(runs):
    """knit_biaxial narrows to e22 = -0.44 with n22 held: its force per width is over the
    undeformed width, n11 (per current width) times (1 + e22), 0.56 n11 at the peak; the
    label says so, since plot-membrane draws n11 for the same run."""
    curve = read_curve(runs / "knit_biaxial")
    left = summary_figure(runs / "knit_biaxial").axes[0]
    assert left.get_ylabel() == "force per unit reference width (N/m)"
    x, y = branches(left)
    loading = [line for line in left.get_lines() if line.get_gid() == "loading"][0]
    rows = len(loading.get_ydata())
    per_reference = curve["n11"][:rows] * (1.0 + curve["e22"][:rows])
    np.testing.assert_allclose(loading.get_ydata(), per_reference, rtol=1e-9)
    assert curve["e22"].min() < -0.4  # the widths differ: the label matters here


def test_a_peak_without_a_saved_state_is_said(tmp_path):
    # vnet in steps of 0.1 peaks at step 10 (p_force = 1, 0.5 N); with vtk_every = 4
    # the states are steps 0, 4, 8, 12, ...: the network shown is step 8 (0.4 N).
    scene = yarnfort.read_scene(TOP / "inputs" / "vnet.nml")
    yarnfort.set_parameter(scene, "output.folder", str(tmp_path / "out"))
    yarnfort.set_parameter(scene, "output.vtk_every", 4)
    yarnfort.run_scene(yarnfort.write_scene(scene, tmp_path / "vnet.nml"))
    figure = summary_figure(tmp_path / "out")
    assert figure.axes[1].get_title() == ("largest force of the saved states: step 8\n"
                                          "(the peak, step 10, has no saved state)")
    marker = [line for line in figure.axes[0].get_lines() if line.get_gid() == "shown_step"]
    assert marker[0].get_ydata()[0] == pytest.approx(0.8 * 0.5, rel=1e-12)
