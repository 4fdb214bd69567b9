# SPDX-License-Identifier: MIT
"""Why the knit-inlay friction changes nothing in the periodic knit cell (issue 13).

(a) The knit-inlay law reaches the inlay crossings: with ikmu, ikbeta set apart from
    kmu, kbeta, every passage at an inlay crossing reports the critical tension of the
    adhesion law with ikmu, ikbeta (closed form, paper eqs. 34-36, written here), not
    with the knit-knit parameters.
(b) In the periodic cell the tension is the same on both sides of every such passage at
    every step (to round-off), so they all stick and their friction never acts. Each
    yarn meets the other at right angles: the partner's force has no component along
    the yarn, and the crossing node is free to move along it until both sides are
    equally stretched (equal reference lengths, the same law).
(c) A clamped sample with rollers breaks that symmetry: inlay passages slip, and ikbeta
    changes the curve (0.6 % of the peak measured, verification/fabrics/README.md). With
    free sides, whose edge courses are sewn to cast-on and bind-off threads stretched
    evenly between the clamps, every inlay passage sticks again, as in the cell.
"""
from __future__ import annotations

import numpy as np

from fabric_scenes import ONE_CYCLE, patched_scene, TOP
from yarnfort import read_curve
from yarnfort.results import read_contacts

KNIT = "inputs/knit.nml"
#: Identities computed in floating point (a tension against itself, a closed form).
ROUND_OFF = 1e-12
#: `&solver residual_tolerance` by default (inputs/REFERENCE.md).
DEFAULT_RESIDUAL_TOLERANCE = 1e-10
#: knit.nml's knit-knit law (kmu, kbeta) and knit-inlay parameters set apart from it.
KMU, KBETA = 0.3999, 0.015
IKMU, IKBETA = 0.3333, 0.05
#: A clamped 4 x 2 sample with rollers: ikbeta 0.015 against 0.05 changes the curve by
#: 0.57 % of its peak (measured); the test asks for more than 0.2 %.
CLAMPED_EFFECT = 0.002


def adhesion_critical(t_min: np.ndarray, alpha: np.ndarray, mu: float, beta: float):
    """T(alpha) of T' = max(mu T, beta), T(0) = t_min (paper eqs. 34-36)."""
    t_min, alpha = np.asarray(t_min, float), np.asarray(alpha, float)
    linear_end = np.maximum(1.0 / mu - t_min / beta, 0.0)  # angle where mu T = beta
    return np.where(alpha <= linear_end, t_min + beta * alpha,
                    np.maximum(t_min, beta / mu) * np.exp(mu * (alpha - linear_end)))


def run(run_yarnfort, values, folder):
    result = run_yarnfort(patched_scene(KNIT, {"output.vtk_every": 0, **values}, folder),
                          cwd=TOP)
    assert result.returncode == 0, result.stderr
    return read_curve(folder), read_contacts(folder)


def inlay_passages(contacts, n_courses: int):
    """Passage ids on the inlay yarns (yarns listed per course: knit, then its inlay)."""
    inlay_yarns = np.arange(2, 2 * n_courses + 1, 2)
    return np.unique(contacts["passage"][np.isin(contacts["yarn"], inlay_yarns)])


def test_periodic_cell_inlay_crossings_carry_equal_tensions(run_yarnfort, tmp_path):
    ik = {"contact[1].friction_coefficient": IKMU, "contact[1].adhesion": IKBETA}
    _, contacts = run(run_yarnfort, {**ONE_CYCLE, **ik}, tmp_path / "cell")
    t_min, t_max = contacts["tension_min"], contacts["tension_max"]
    alpha, t_crit = contacts["wrap_angle"], contacts["critical_tension"]
    with_ik = adhesion_critical(t_min, alpha, IKMU, IKBETA)
    with_k = adhesion_critical(t_min, alpha, KMU, KBETA)
    is_ik = np.abs(t_crit - with_ik) <= ROUND_OFF * t_crit
    is_k = np.abs(t_crit - with_k) <= ROUND_OFF * t_crit
    assert np.all(is_ik | is_k)       # every passage has one of the two laws
    assert not np.any(is_ik & is_k)   # and the two are told apart
    # (a) 16 knit-inlay passages (8 on the legs, 8 on the inlays of the 2 x 2 cell),
    # the inlay yarns' passages among them.
    ik_passages = np.unique(contacts["passage"][is_ik])
    assert len(ik_passages) == 16
    assert set(inlay_passages(contacts, 2)) <= set(ik_passages)
    # (b) equal tensions on both sides at every step, so they stick (no flow).
    assert np.max(np.abs(t_max - t_min)[is_ik] / t_max[is_ik]) < ROUND_OFF
    assert set(contacts["mode"][is_ik]) == {"stick"}
    assert np.max(np.abs(contacts["flow"][is_ik])) == 0.0
    # The knit-knit passages do slip (the check above is not vacuous).
    assert np.any(contacts["mode"][is_k] != "stick")


def test_clamped_sample_brings_knit_inlay_adhesion_into_play(run_yarnfort, tmp_path):
    clamped = {**ONE_CYCLE, "fabric.boundary": "clamped", "fabric.cells": [4, 2],
               "fabric.lateral_strain": None, "fabric.sides": "rollers"}
    curves = []
    for beta in (KBETA, IKBETA):
        curve, contacts = run(run_yarnfort, {**clamped, "contact[1].adhesion": beta},
                              tmp_path / f"beta{beta}")
        inlay = np.isin(contacts["passage"], inlay_passages(contacts, 2))
        assert np.any(contacts["mode"][inlay] != "stick")
        curves.append(curve)
    nominal, sticky = curves
    # Compared at the times both runs reached (the knots and most steps; a step cut in
    # one run need not happen in the other).
    _, i, j = np.intersect1d(nominal["time"], sticky["time"], return_indices=True)
    assert len(i) >= 0.5 * min(len(nominal["time"]), len(sticky["time"]))
    difference = np.abs(sticky["force_per_width"][j] - nominal["force_per_width"][i])
    print(f"clamped 4 x 2, rollers: ikbeta {KBETA} -> {IKBETA} changes force_per_width by "
          f"{difference.max() / nominal['force_per_width'].max():.2%} of its peak at "
          f"{len(i)} common times")
    assert difference.max() > CLAMPED_EFFECT * nominal["force_per_width"].max()


def test_free_sided_sample_inlay_crossings_stick(run_yarnfort, tmp_path):
    """With free sides the cast-on and bind-off threads keep the legs at right angles to
    the inlay, as the cell's symmetry does: no inlay passage slips at any step."""
    values = {**ONE_CYCLE, "fabric.boundary": "clamped", "fabric.cells": [4, 2],
              "fabric.lateral_strain": None}
    _, contacts = run(run_yarnfort, values, tmp_path / "free")
    inlay = np.isin(contacts["passage"], inlay_passages(contacts, 2))
    assert np.any(inlay)
    assert set(contacts["mode"][inlay]) == {"stick"}
    assert np.any(contacts["mode"][~inlay] != "stick")  # the knit-knit ones do slip


def test_three_dimensional_cell_inlay_crossings_stick(run_yarnfort, tmp_path):
    """The periodic cell in depth (`knit_depth`): the legs now slope through the inlay's
    depth, but the cell's symmetry still keeps the inlay at right angles to the legs in
    the x-y plane, so the inlay passages carry equal tensions and ikbeta changes the
    curve by nothing (measured: 0.0 N/m; the knit-knit passages slip)."""
    depth = {**ONE_CYCLE, "fabric.knit_depth": 0.2e-3}
    curves = []
    for beta in (KBETA, IKBETA):
        curve, contacts = run(run_yarnfort, {**depth, "contact[1].adhesion": beta},
                              tmp_path / f"beta{beta}")
        inlay = np.isin(contacts["passage"], inlay_passages(contacts, 2))
        t_min, t_max = contacts["tension_min"][inlay], contacts["tension_max"][inlay]
        assert np.any(inlay)
        # Equal here by equilibrium, not by an identity: to the solve's default
        # residual tolerance relative to the forces at the node (measured 5.9e-12).
        assert np.max(np.abs(t_max - t_min) / t_max) < DEFAULT_RESIDUAL_TOLERANCE
        assert set(contacts["mode"][inlay]) == {"stick"}
        assert np.any(contacts["mode"][~inlay] != "stick")
        curves.append(curve)
    nominal, sticky = curves
    assert np.array_equal(nominal["time"], sticky["time"])
    peak = np.max(np.abs(nominal["force_per_width"]))
    assert np.max(np.abs(sticky["force_per_width"] - nominal["force_per_width"])) \
        <= ROUND_OFF * peak
