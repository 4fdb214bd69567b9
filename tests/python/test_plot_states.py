# SPDX-License-Identifier: MIT
"""plot_states and ``python -m yarnfort plot-states``: which states are drawn, their
colour range, the periodic images, and the errors.

The expected values come from the files, read here without the package's readers
(``csv`` and ``xml.etree`` on ASCII VTK states), or from the scene's parameters.
"""
from __future__ import annotations

import csv
import os
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pytest  # noqa: E402

from yarnfort import ResultError, read_states  # noqa: E402
from yarnfort.__main__ import main  # noqa: E402
from yarnfort.namelist import read_scene, set_parameter, write_scene  # noqa: E402
from yarnfort.plots import nearest_states, plot_states, save_figure  # noqa: E402

from test_plots import assert_png  # noqa: E402

TOP = Path(__file__).resolve().parents[2]


def run_example(run_yarnfort, name: str, folder: Path, **values) -> Path:
    """inputs/<name>.nml run from the repository top (its tables are relative to it)
    into ``folder``, with ASCII VTK states and the given ``group.variable`` values."""
    scene = read_scene(TOP / "inputs" / f"{name}.nml")
    settings = {"output.folder": str(folder), "output.vtk_format": "ascii",
                "output.progress": False, **values}
    for address, value in settings.items():
        set_parameter(scene, address, value)
    text = write_scene(scene, folder.parent / f"{folder.name}.nml").read_text()
    run = run_yarnfort(text, cwd=TOP)
    assert run.returncode == 0, run.stderr
    return folder


@pytest.fixture
def knit(run_yarnfort, tmp_path) -> Path:
    """inputs/knit.nml, one cycle, a VTK state every third step (steps 0, 3, ..., 18,
    and the last, 40)."""
    return run_example(run_yarnfort, "knit", tmp_path / "knit", **{
        "path.time": [0.0, 1.0, 2.0], "path.p_disp": [0.0, 1.0, 0.0],
        "output.vtk_every": 3})


def curve_column(folder: Path, name: str) -> dict[int, float]:
    with open(folder / "curve.csv", newline="") as stream:
        return {int(row["step"]): float(row[name]) for row in csv.DictReader(stream)}


def element_tensions(path: Path) -> np.ndarray:
    """Tensions of the yarn elements (every cell of the yarns' file) of an ASCII VTK
    state."""
    piece = ET.parse(path).getroot().find("UnstructuredGrid/Piece")
    arrays = {node.get("Name"): np.array(node.text.split(), dtype=float)
              for node in piece.iterfind("CellData/DataArray")}
    return arrays["tension"]


def saved_steps(folder: Path) -> list[int]:
    return sorted(int(p.stem[len("state_"):]) for p in folder.glob("state_*.vtu"))


def test_chosen_states_are_the_nearest_on_the_first_loading(knit):
    strain = curve_column(knit, "strain")
    peak = max(strain, key=lambda step: (strain[step], -step))  # first step at the peak
    candidates = [step for step in saved_steps(knit) if step <= peak]
    assert candidates == [0, 3, 6, 9, 12, 15, 18]
    targets = (0.0, 0.37, 0.5, 1.0)
    chosen = nearest_states(knit, targets)
    for target, (state, value) in zip(targets, chosen):
        expected = min(candidates, key=lambda step: abs(strain[step] - target))
        assert state.step == expected
        assert value == strain[expected]
    # Step 40 (unloaded, strain 0) and the unloading are never picked: 0 is step 0.
    assert [state.step for state, _ in chosen] == [0, 6, 9, 18]
    fractions = nearest_states(knit, (0.5,), of_peak=True)
    assert fractions[0][0].step == 9  # 0.5 of the peak strain 1: strain 0.45 at step 9


def test_colour_range_is_that_of_the_states_drawn(knit):
    figure = plot_states(knit, (0.0, 0.5, 1.0))
    tensions = np.concatenate([element_tensions(knit / f"state_{step:05d}.vtu")
                               for step in (0, 9, 18)])
    panels = [ax for ax in figure.axes if ax.get_label() != "<colorbar>"]
    assert len(panels) == 3
    for ax, step in zip(panels, (0, 9, 18)):
        lines = [c for c in ax.collections if c.get_gid() == "elements"][0]
        # The same decimal text parsed to the same double: equal, not close.
        assert lines.norm.vmin == tensions.min()
        assert lines.norm.vmax == tensions.max()
        assert f"(step {step})" in ax.get_title()
    assert tensions.max() > 10 * tensions.min() > 0  # a real range, not a default one
    colorbar = [ax for ax in figure.axes if ax.get_label() == "<colorbar>"]
    assert len(colorbar) == 1 and colorbar[0].get_ylabel() == "tension (N)"


def test_images_and_periods(knit, run_yarnfort, tmp_path):
    states = {state.step: state for state in read_states(knit)}
    # inputs/knit.nml: 2 x 2 cells of 1.0 mm x 0.8 mm, strain 1 at p_disp 1, height held.
    for step, strain in ((0, 0.0), (9, 0.45), (18, 0.9)):
        np.testing.assert_allclose(states[step].periods(),
                                   [[2e-3 * (1 + strain), 0, 0], [0, 1.6e-3, 0]],
                                   rtol=1e-12, atol=1e-12 * 2e-3)
    figure = plot_states(knit, (1.0,), images=(3, 2))
    lines = [c for c in figure.axes[0].collections if c.get_gid() == "elements"][0]
    segments = np.array(lines.get_segments())
    assert len(segments) == 6 * len(states[18].elements)
    # The images are the cell shifted by the periods (mm on the axes).
    first = segments[:len(states[18].elements)]
    np.testing.assert_allclose(segments[len(first):2 * len(first)] - first,
                               np.broadcast_to([0.0, 1.6], first.shape), atol=1e-12)
    # A one-loop 3D knit has no periodic link along y: its y period is that of its
    # gap-holders to the loop above (cell data `period`).
    knit3d = run_example(run_yarnfort, "knit3d", tmp_path / "knit3d",
                         **{"path.time": [0.0, 1.0], "path.p_disp": [0.0, 1.0]})
    last = read_states(knit3d)[-1]
    np.testing.assert_allclose(last.periods(), [[2.4e-3, 0, 0], [0, 1.0e-3, 0]],
                               rtol=1e-12, atol=1e-15)
    with pytest.raises(ValueError, match="need 3 periods; this state has 2"):
        plot_states(knit, (1.0,), images=(1, 1, 2))


def test_gap_holders_to_images_drawn_at_their_length(run_yarnfort, tmp_path):
    """TexGen's weave joins nodes to the images of their partners: the periods come from
    those gap-holders' `period`, and each is drawn to the image, as long as the gap."""
    weave = run_example(run_yarnfort, "texgen_weave", tmp_path / "weave",
                        **{"path.time": [0.0, 1.0], "path.p_disp": [0.0, 1.0]})
    last = read_states(weave)[-1]
    # inputs/texgen_weave.tg3: a 2 x 2 cell of 1 mm spacing; strain 0.15 along x.
    np.testing.assert_allclose(last.periods(), [[2.3e-3, 0, 0], [0, 2.0e-3, 0]],
                               rtol=1e-12, atol=1e-15)
    wide = last.position[last.links[:, 1]] - last.position[last.links[:, 0]]
    assert np.linalg.norm(wide, axis=1).max() > 1e-3  # some links do cross the cell
    ax = plot_states(weave, (1.0,), of_peak=True, images=(2, 2)).axes[0]
    holders = [c for c in ax.collections if c.get_gid() == "gap_holders"][0]
    drawn = np.linalg.norm(np.diff(np.array(holders.get_segments()), axis=1)[:, 0], axis=1)
    assert len(drawn) == 4 * np.sum(last.link_kind == 1)
    # The axis gap at a crossing is 0.2 mm (yarn centres, texgen_weave.nml): in the x-y
    # view a holder is at most that long, far below the 1 mm spacing.
    assert drawn.max() <= 0.2 * (1 + 1e-9)


def test_errors(knit, run_yarnfort, tmp_path):
    with pytest.raises(ResultError, match="no output folder"):
        nearest_states(tmp_path / "missing")
    with pytest.raises(KeyError, match="no column 'nope'"):
        nearest_states(knit, by="nope")
    with pytest.raises(ValueError, match=r"strain = 1.5 is outside the run's first loading"
                       r" \(0 to 1\)"):
        nearest_states(knit, (0.0, 1.5))
    with pytest.raises(ValueError, match="projection must be"):
        plot_states(knit, (0.0,), projections=("xw",))
    bare = run_example(run_yarnfort, "knit3d", tmp_path / "bare",
                       **{"output.vtk_every": 0})
    with pytest.raises(ResultError, match="no VTK state of a step of the first loading"):
        nearest_states(bare)


def _cli(*args: str) -> subprocess.CompletedProcess:
    env = dict(os.environ, MPLBACKEND="Agg")
    return subprocess.run([sys.executable, "-m", "yarnfort", *args], capture_output=True,
                          text=True, env=env, timeout=120)


def test_cli_plot_states(knit, tmp_path, capsys):
    run = _cli("plot-states", str(knit))
    assert run.returncode == 0, run.stderr
    assert_png(knit / "states.png")
    run = _cli("plot-states", str(tmp_path / "missing"))
    assert run.returncode == 2 and "no output folder" in run.stderr
    # The rest in process (the same main() the module runs).
    out = tmp_path / "png" / "three.png"
    assert main(["plot-states", str(knit), "-o", str(out), "--strains", "0", "1",
                 "--images", "2", "2", "--projection", "xy", "xz",
                 "--depth-scale", "3"]) == 0
    assert_png(out)
    assert f"wrote {out}" in capsys.readouterr().out


@pytest.mark.parametrize("args, message", [
    (["--strains", "2"], "strain = 2 is outside the run's first loading (0 to 1)"),
    (["--by", "nope"], "curve has no column 'nope'"),
    (["--images", "0", "1"], "images must be at least 1 per period"),
    (["--projection", "3d", "zz"], "projection must be two of"),
])
def test_cli_plot_states_errors(knit, capsys, args, message):
    assert main(["plot-states", str(knit), *args]) == 2
    assert f"yarnfort plot-states: error: {message}" in capsys.readouterr().err
    assert not (knit / "states.png").exists()


def test_cli_unwritable_target(knit, tmp_path, capsys):
    blocked = tmp_path / "file"
    blocked.write_text("not a folder")
    assert main(["plot-states", str(knit), "-o", str(blocked / "states.png")]) == 2
    assert "yarnfort plot-states: error: " in capsys.readouterr().err
    assert blocked.read_text() == "not a folder"


def test_save_figure_leaves_no_partial_file(knit, tmp_path, monkeypatch):
    figure = plot_states(knit, (0.0,))
    target = tmp_path / "keep.png"
    save_figure(figure, target)
    before = target.read_bytes()

    def fail(*args, **kwargs):
        Path(args[0]).write_bytes(b"\x89PNG half")
        raise OSError("disk full")

    monkeypatch.setattr(figure, "savefig", fail)
    with pytest.raises(OSError, match="disk full"):
        save_figure(figure, target)
    assert target.read_bytes() == before
    assert not (tmp_path / "keep.png.tmp").exists()
