# SPDX-License-Identifier: MIT
"""The Python scene helpers for issue 11's input: per-element `length0` / `stretch` on a
yarn, load channels on loads, supports and the path. A scene built in Python writes the
namelist the program reads (checked by the library), reads back equal, and runs to the
curve columns the channels name; bad values raise SceneError naming the variable."""
from __future__ import annotations

import numpy as np
import pytest

import yarnfort
from yarnfort import SceneError


def ring_scene(folder) -> yarnfort.Scene:
    """A yarn A-R-B through a free ring R with a stub R-S (Coulomb), S pulled down on
    channel 'down' and then sideways on channel 'side'."""
    scene = yarnfort.Scene("channels from python")
    scene.nodes = [[-1.0, 0.4, 0.0], [-0.9, -0.2, 0.0], [1.0, 0.0, 0.0], [-0.9, -0.5, 0.0]]
    scene.add_material("yarn", "linear", stiffness=10.0)
    scene.add_material("stub", "linear", stiffness=10.0)
    scene.add_contact(("yarn", "stub"), "coulomb", friction_coefficient=0.3)
    scene.add_yarn("yarn", [1, 2, 3], elements_per_segment=2,
                   stretch=[1.0, 1.0, 1.0, 1.0])
    scene.add_yarn("stub", [2, 4])
    scene.add_support("a", [1])
    scene.add_support("b", [3])
    scene.add_load([4], [0.0, -1.0, 0.0], channel="down")
    scene.add_load([4], [0.3, 0.0, 0.0], channel="side")
    scene.path = yarnfort.LoadPath(time=[0.0, 1.0, 2.0], channels=["down", "side"],
                                   factors=[[0.05, 0.0], [1.0, 0.0], [1.0, 1.0]])
    scene.output.update(folder=str(folder), progress=False)
    return scene


def test_channels_and_element_lengths_round_trip_and_run(tmp_path):
    scene = ring_scene(tmp_path / "out")
    path = scene.write(tmp_path / "ring.nml")
    text = path.read_text()
    assert "channels = 'down', 'side'" in text and "channel = 'side'" in text
    again = yarnfort.Scene.read(path)
    np.testing.assert_array_equal(again.path.factors, scene.path.factors)
    assert again.path.channels == ["down", "side"]
    assert [load.channel for load in again.loads] == ["down", "side"]
    np.testing.assert_array_equal(again.yarns[0].stretch, [1.0] * 4)
    scene.check()
    result = scene.run()
    curve = result.curve
    assert curve.names[:4] == ["step", "time", "down", "side"]
    np.testing.assert_allclose(curve["side"][-1], 1.0)
    # The load's displacement is that of the stub's end; support displacements are 0.
    assert curve.displacement("load_1").shape == (len(curve), 3)
    np.testing.assert_array_equal(curve.displacement("load_1"), curve.displacement("load_2"))
    assert np.all(curve.displacement("a") == 0.0)
    with pytest.raises(KeyError, match="sets: a, b, load_1, load_2"):
        curve.displacement("c")


@pytest.mark.parametrize("make, message", [
    (lambda: yarnfort.LoadPath(time=[0, 1], channels=["a"], factors=[0, 1, 2]),
     "&path factors: 3 values for 2 knots x 1 channels"),
    (lambda: yarnfort.LoadPath(time=[0, 1], channels=["a", "a"], factors=[0] * 4),
     "a name is given twice"),
    (lambda: yarnfort.LoadPath(time=[0, 1], factors=[0, 1]), "given without channels"),
    (lambda: yarnfort.LoadPath(time=[0, 1], channels=["a"], factors=[0, 1],
                               p_force=[0, 1]), "p_force or p_disp together with channels"),
    (lambda: yarnfort.Yarn("y", [1, 2, 3], 2, length0=[1.0, 1.0]),
     "length0: 2 values for 4 elements"),
    (lambda: yarnfort.Yarn("y", [1, 2], length0=[0.0]), "every value must be > 0"),
    (lambda: yarnfort.Yarn("y", [1, 2], length0=[1.0], stretch=[1.0]),
     "length0 and stretch are both given"),
])
def test_bad_values_raise(make, message):
    with pytest.raises(SceneError, match=message.replace("(", r"\(").replace(")", r"\)")):
        make()


def test_curve_channels_and_plot_command(tmp_path):
    """Curve.channels lists the channels' columns, and `python -m yarnfort plot` draws
    a run on channels (its abscissa: the first channel that moves)."""
    import subprocess
    import sys

    scene = ring_scene(tmp_path / "out")
    scene.run()
    curve = yarnfort.read_curve(tmp_path / "out")
    assert curve.channels == ["down", "side"]
    done = subprocess.run([sys.executable, "-m", "yarnfort", "plot", str(tmp_path / "out"),
                           "--out", str(tmp_path / "ring.png")], capture_output=True, text=True,
                          timeout=300)
    assert done.returncode == 0, done.stderr
    assert (tmp_path / "ring.png").stat().st_size > 0


def test_general_law_from_python(tmp_path):
    """`critical_tension('general', rate_table=...)`: g = mu T (rows (0, 0), (1, mu),
    continued with the last slope) is the Coulomb law, T_min exp(mu alpha), to
    rounding; and a Scene with a 'general' contact writes rate_table and is accepted by
    the library's checks."""
    mu = 0.3
    table = tmp_path / "rates.csv"
    table.write_text(f"T,g\n0.0,0.0\n1.0,{mu!r}\n")
    t_min = np.array([0.01, 0.5, 2.0, 7.0])
    alpha = np.array([0.1, 1.0, 2.5, 4.0])
    critical, d_dt, d_da = yarnfort.critical_tension("general", t_min, alpha,
                                                     rate_table=str(table))
    exact = t_min * np.exp(mu * alpha)
    np.testing.assert_allclose(critical, exact, rtol=1e-14)
    np.testing.assert_allclose(d_dt, np.exp(mu * alpha), rtol=1e-13)
    np.testing.assert_allclose(d_da, mu * exact, rtol=1e-13)
    with pytest.raises(yarnfort.YarnfortError, match="rates_missing.csv"):
        yarnfort.critical_tension("general", 1.0, 1.0,
                                  rate_table=str(tmp_path / "rates_missing.csv"))
    scene = ring_scene(tmp_path / "out")
    scene.contacts.clear()
    contact = scene.add_contact(("yarn", "stub"), "general", rate_table=str(table))
    assert contact.rate_table == str(table) and not contact.extra
    assert f"rate_table = '{table}'" in scene.write(tmp_path / "general.nml").read_text()
    scene.check()


def test_echoed_inputs_read_back_as_scenes(tmp_path):
    """input.nml lists every entry (empty channel names, zero p_force and p_disp): a
    Scene reads it back, with and without channels, and writes the same run again."""
    scene = ring_scene(tmp_path / "out")
    scene.run()
    again = yarnfort.Scene.read(tmp_path / "out" / "input.nml")
    assert again.path.channels == ["down", "side"] and again.path.p_force is None
    np.testing.assert_array_equal(again.path.factors, scene.path.factors)
    assert [load.channel for load in again.loads] == ["down", "side"]
    assert [support.channel for support in again.supports] == [None, None]
    plain = yarnfort.Scene("no channels")
    plain.nodes = [[0.0, 0.0, 0.0], [1.0, -0.2, 0.0], [2.0, 0.0, 0.0]]
    plain.add_material("yarn", "linear", stiffness=10.0)
    plain.add_yarn("yarn", [1, 2, 3])
    plain.add_support("ends", [1, 3])
    plain.add_load([2], [0.0, -0.1, 0.0])
    plain.path = yarnfort.LoadPath(time=[0.0, 1.0], p_force=[0.0, 1.0])
    plain.output.update(folder=str(tmp_path / "plain"), progress=False)
    plain.run()
    echoed = yarnfort.Scene.read(tmp_path / "plain" / "input.nml")
    assert echoed.path.channels is None
    np.testing.assert_array_equal(echoed.path.p_force, [0.0, 1.0])
    assert echoed.loads[0].channel is None
