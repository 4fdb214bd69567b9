# SPDX-License-Identifier: MIT
"""Plots of a run's results: force–displacement curves, hysteresis loops, the deformed
network coloured by tension, and sensitivity fans.

Every plotting function takes an optional ``ax`` (a :class:`matplotlib.axes.Axes`); when
it is omitted a new :class:`matplotlib.figure.Figure` is made without ``pyplot``, so the
functions work on any backend, including Agg on a headless machine. Each returns the
Axes it drew on (``ax.figure`` is the Figure). No physics here: only what the output
files hold is drawn.
"""
from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import matplotlib
import numpy as np
from matplotlib.axes import Axes
from matplotlib.collections import LineCollection
from matplotlib.colors import Normalize
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator, ScalarFormatter

from .results import GAP_HOLDER, Curve, ResultError, State, read_curve, read_states

__all__ = ["plot_curve", "plot_hysteresis", "plot_fabric_hysteresis", "plot_network",
           "plot_states", "nearest_states", "plot_fan", "save_figure", "supports",
           "reaction_component", "Driver", "load_drivers", "choose_driver",
           "driver_response", "plot_load_displacement", "plot_history", "peak_step",
           "tension_norm", "membrane_pair", "plot_membrane_curve"]

#: Index of each Cartesian component in a reaction or position row.
COMPONENTS: dict[str, int] = {"x": 0, "y": 1, "z": 2}
#: Axis labels of the usual abscissae of ``curve.csv``.
X_LABELS: dict[str, str] = {
    "p_disp": "displacement factor p_disp",
    "p_force": "force factor p_force",
    "time": "pseudo-time",
    "step": "step",
}
#: Line styles of the loading and unloading branches in :func:`plot_hysteresis`.
BRANCH_STYLES: dict[str, dict[str, str]] = {
    "loading": {"color": "tab:blue", "linestyle": "-"},
    "unloading": {"color": "tab:red", "linestyle": "--"},
}
#: A target of :func:`nearest_states` may lie outside the values of the run by this
#: fraction of their range (rounding of the strain column).
TARGET_TOLERANCE = 1e-9
#: Value of the ``direction`` column for each branch.
BRANCH_DIRECTIONS: dict[str, int] = {"loading": 1, "unloading": -1}


def _axes(ax: Axes | None) -> Axes:
    """The given Axes, or the single Axes of a new pyplot-free Figure."""
    if ax is not None:
        return ax
    return Figure(layout="constrained").add_subplot()


def supports(curve: Curve) -> list[str]:
    """Names of the support sets with reaction columns in ``curve``.

    Parameters
    ----------
    curve : Curve
        A run's curve.

    Returns
    -------
    list of str
        In column order.
    """
    return [name[:-3] for name in curve.names
            if name.endswith("_rx") and f"{name[:-3]}_ry" in curve.columns
            and f"{name[:-3]}_rz" in curve.columns]


def reaction_component(curve: Curve, support: str, component: str = "y") -> np.ndarray:
    """One component (``'x'``, ``'y'``, ``'z'``) or the Euclidean ``'norm'`` of the
    reaction of a support set, per step.

    Parameters
    ----------
    curve : Curve
        A run's curve.
    support : str
        The support set.
    component : {'y', 'x', 'z', 'norm'}
        Which component.

    Returns
    -------
    numpy.ndarray
        One value per step (N).

    Raises
    ------
    KeyError
        If the curve has no support set of that name (the message lists those it has).
    ValueError
        If ``component`` is not one of ``'x'``, ``'y'``, ``'z'``, ``'norm'``.
    """
    known = supports(curve)
    if support not in known:
        raise KeyError(f"unknown support {support!r}; the curve has: {', '.join(known)}")
    reaction = curve.reaction(support)
    if component == "norm":
        return np.linalg.norm(reaction, axis=1)
    if component not in COMPONENTS:
        raise ValueError(f"component must be 'x', 'y', 'z' or 'norm', not {component!r}")
    return reaction[:, COMPONENTS[component]]


def _labels(ax: Axes, support: str, component: str, x: str) -> None:
    ax.set_xlabel(X_LABELS.get(x, x))
    which = "|R|" if component == "norm" else f"R{component}"
    ax.set_ylabel(f"reaction {which} of '{support}' (N)")
    ax.grid(True, alpha=0.3)


def plot_curve(curve: Curve, support: str, component: str = "y", x: str = "p_disp",
               ax: Axes | None = None, **line_kw) -> Axes:
    """Force–displacement curve: a reaction of ``support`` against column ``x``.

    Parameters
    ----------
    curve : Curve
        The run's ``curve.csv``.
    support : str
        Name of the support set whose reaction is drawn.
    component : {'y', 'x', 'z', 'norm'}
        Reaction component, or its Euclidean norm.
    x : str
        Column for the abscissa (``'p_disp'``, ``'time'``, ``'p_force'``, ...).
    ax : Axes, optional
        Where to draw; a new figure when omitted.
    **line_kw
        Passed to :meth:`Axes.plot`.

    Returns
    -------
    Axes
    """
    ax = _axes(ax)
    ax.plot(curve[x], reaction_component(curve, support, component), **line_kw)
    _labels(ax, support, component, x)
    return ax


def _runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """(start, stop) of each maximal run of True in ``mask``."""
    edges = np.diff(np.concatenate(([0], mask.astype(int), [0])))
    return list(zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)))


def plot_hysteresis(curve: Curve, support: str, component: str = "y", x: str = "p_disp",
                    ax: Axes | None = None) -> Axes:
    """Hysteresis loop: as :func:`plot_curve`, with the loading (``direction`` 1) and
    unloading (``direction`` -1) steps drawn in different colours and line styles
    (:data:`BRANCH_STYLES`) and a legend.

    Each branch segment starts at the step before its first step, so the loop is drawn
    without gaps. The lines carry the label and gid ``'loading'`` or ``'unloading'``
    (only the first segment of a branch is labelled, for the legend).

    Parameters
    ----------
    curve : Curve
        The run's ``curve.csv``.
    support, component, x
        As in :func:`plot_curve`.
    ax : Axes, optional
        Where to draw; a new figure when omitted.

    Returns
    -------
    Axes
    """
    ax = _axes(ax)
    _plot_branches(ax, curve[x], reaction_component(curve, support, component),
                   curve["direction"])
    _labels(ax, support, component, x)
    if ax.get_legend_handles_labels()[0]:
        ax.legend()
    return ax


def plot_fabric_hysteresis(curve: Curve, ax: Axes | None = None) -> Axes:
    """Effective curve of a generated fabric (``&fabric``): force per unit width
    against macroscopic strain, loading and unloading drawn as in
    :func:`plot_hysteresis`. The width is the reference (undeformed) one, as in
    ``force_per_width``: n11 (1 + e22) of a periodic cell, not n11.

    Parameters
    ----------
    curve : Curve
        The curve of a ``&fabric`` run (columns ``strain``, ``force_per_width``).
    ax : Axes, optional
        Where to draw; a new figure when omitted.

    Returns
    -------
    Axes
    """
    ax = _axes(ax)
    _plot_branches(ax, curve["strain"], curve["force_per_width"], curve["direction"])
    ax.set_xlabel("macroscopic strain (1)")
    # force_per_width is over the undeformed width; n11 (plot-membrane) is over the
    # current one: a cell that narrows shows two values, so the label says which.
    ax.set_ylabel("force per unit reference width (N/m)")
    ax.grid(True, alpha=0.3)
    if ax.get_legend_handles_labels()[0]:
        ax.legend()
    return ax


#: Columns a periodic-cell run's curve.csv has (plot_membrane).
MEMBRANE_COLUMNS = ("e11", "e22", "n11", "n22")
#: The membrane strain of a periodic cell, its conjugate force and the strain's unit.
MEMBRANE_PAIRS = (("e11", "n11", "1"), ("e22", "n22", "1"), ("gamma12", "n12", "rad"))


def membrane_pair(curve: Curve) -> tuple[str, str, str] | None:
    """The membrane strain that a periodic-cell run changes most, its force and the
    strain's unit: ``('gamma12', 'n12', 'rad')`` for a sheared cell, ``('e11', 'n11',
    '1')`` for one stretched along x, ``('e22', 'n22', '1')`` along y.

    Parameters
    ----------
    curve : Curve
        A run's curve.

    Returns
    -------
    tuple of str or None
        None for a curve without membrane columns or rows (not a periodic cell).
    """
    pairs = [pair for pair in MEMBRANE_PAIRS
             if pair[0] in curve.names and pair[1] in curve.names]
    if not pairs or len(curve) == 0:
        return None
    return max(pairs, key=lambda pair: float(np.ptp(curve[pair[0]])))


def plot_membrane_curve(curve: Curve, ax: Axes | None = None) -> Axes:
    """The membrane force of a periodic cell against the strain that drives it
    (:func:`membrane_pair`: n12 against gamma12 for a sheared cell), loading and
    unloading as in :func:`plot_hysteresis`. For a cell whose curve has no
    ``force_per_width`` (a shear run), the curve the summary plot draws.

    Parameters
    ----------
    curve : Curve
        The curve of a periodic-cell run.
    ax : Axes, optional
        Where to draw; a new figure when omitted.

    Returns
    -------
    Axes

    Raises
    ------
    ValueError
        The curve has no rows or no membrane columns (not a periodic-cell run).
    """
    pair = membrane_pair(curve)
    if pair is None:
        raise ValueError(f"{curve.path}: no rows or no membrane columns (not a"
                         " periodic-cell run)")
    strain, force, unit = pair
    ax = _axes(ax)
    _plot_branches(ax, curve[strain], curve[force], curve["direction"])
    ax.set_xlabel(f"{strain} ({unit})")
    ax.set_ylabel(f"membrane force {force} (N/m)")
    ax.grid(True, alpha=0.3)
    if ax.get_legend_handles_labels()[0]:
        ax.legend()
    return ax


def plot_membrane(curve: Curve, title: str = "") -> Figure:
    """Membrane forces of a periodic-cell run, one panel each: n11, n22 and e22 against
    e11; a shear run (gamma12 changes more than e11) draws n12 (with n22 tan(gamma12)
    dashed: the yarn tension turned by the shear), n11 and e22 against gamma12. Loading
    and unloading as in :func:`plot_hysteresis`; forces from zero, so that a held force
    is a flat line, not its rounding magnified.

    Parameters
    ----------
    curve : Curve
        The curve of a periodic-cell run (columns e11, e22, n11, n22, direction).
    title : str, optional
        Figure title.

    Returns
    -------
    Figure

    Raises
    ------
    ValueError
        The curve has no rows or no membrane columns (not a periodic-cell run).
    """
    missing = [c for c in MEMBRANE_COLUMNS if c not in curve.names]
    if missing or len(curve) == 0:
        raise ValueError(f"{curve.path}: no rows or no columns {', '.join(missing)} (not a"
                         " periodic-cell run)")
    figure = Figure(figsize=(13.2, 4.2), layout="constrained")
    panels = figure.subplots(1, 3)
    shear = ("gamma12" in curve.names
             and np.ptp(curve["gamma12"]) > np.ptp(curve["e11"]))
    x, first = ("gamma12", "n12") if shear else ("e11", "n11")
    unit = "rad" if shear else "1"
    second = "n11" if shear else "n22"
    for axes, name in zip(panels, (first, second, "e22")):
        _plot_branches(axes, curve[x], curve[name], curve["direction"])
        if name == "n12":
            gamma = np.asarray(curve["gamma12"])
            axes.plot(gamma, np.asarray(curve["n22"]) * np.tan(gamma), "k--", lw=1,
                      label="n22 tan(gamma12)")
        axes.set_xlabel(f"{x} ({unit})")
        axes.set_ylabel(f"{name} ({'1' if name == 'e22' else 'N/m'})")
        axes.grid(True, alpha=0.3)
        axes.legend()
        axes.ticklabel_format(axis="y", useOffset=False)
        if name != "e22":
            values = np.asarray(curve[name], dtype=float)
            axes.set_ylim(min(0.0, 1.1 * float(values.min())),
                          max(0.0, 1.1 * float(values.max())) or 1.0)
    if title:
        figure.suptitle(title)
    return figure


def _plot_branches(ax: Axes, abscissa: np.ndarray, ordinate: np.ndarray,
                   direction: np.ndarray) -> None:
    """Loading and unloading runs of a curve, each segment starting at the step
    before its first step so that the loop has no gaps."""
    for branch, value in BRANCH_DIRECTIONS.items():
        for number, (start, stop) in enumerate(_runs(direction == value)):
            first = max(start - 1, 0)
            line, = ax.plot(abscissa[first:stop], ordinate[first:stop],
                            label=branch if number == 0 else "_" + branch,
                            **BRANCH_STYLES[branch])
            line.set_gid(branch)


#: Width of one panel of :func:`plot_states` and the largest height of a row (inches).
PANEL_WIDTH = 4.2
ROW_HEIGHT = 3.6
#: Length units of the state plots: name -> metres per unit.
LENGTH_UNITS: dict[str, float] = {"m": 1.0, "mm": 1e-3, "um": 1e-6}
#: Length unit of every plot of positions and displacements (both plot commands).
DEFAULT_UNIT = "mm"
#: ``mode`` of a slipping passage (forward, backward; State.passages).
SLIP_MODES = (2, 3)


def _check_projection(projection: str) -> None:
    """A view of :func:`plot_network`: two different axes of 'x', 'y', 'z', or '3d'."""
    if projection != "3d" and (len(projection) != 2 or len(set(projection)) != 2
                               or not set(projection) <= set(COMPONENTS)):
        raise ValueError(f"projection must be two of 'x', 'y', 'z' or '3d', not"
                         f" {projection!r}")


def _image_shifts(state: State, images: tuple[int, ...]) -> np.ndarray:
    """Shifts (m) of the periodic images of ``state``: every combination of 0 ..
    images[k] - 1 times its period k (:meth:`State.periods`)."""
    counts = [int(n) for n in images]
    if any(n < 1 for n in counts):
        raise ValueError(f"images must be at least 1 per period, not {tuple(images)}")
    wanted = [k for k, n in enumerate(counts) if n > 1]
    if not wanted:
        return np.zeros((1, 3))
    periods = state.periods()
    if len(periods) <= max(wanted):
        raise ValueError(f"images {tuple(images)} need {max(wanted) + 1} periods; this state"
                         f" has {len(periods)} (the periodic links of a periodic cell)")
    counts = (counts + [1] * len(periods))[:len(periods)]
    grid = np.stack(np.meshgrid(*[np.arange(n) for n in counts], indexing="ij"), axis=-1)
    return grid.reshape(-1, len(periods)) @ periods


def plot_network(state: State, ax: Axes | None = None, projection: str = "xy",
                 cmap: str = "viridis", colorbar: bool = True, norm: Normalize | None = None,
                 images: tuple[int, ...] = (1, 1), unit: str = DEFAULT_UNIT,
                 gap_holders: bool = True,
                 nodes: bool = True, slipping: bool = False, depth_scale: float = 1.0) -> Axes:
    """The deformed network of ``state`` as line segments coloured by element tension.

    Parameters
    ----------
    state : State
        A converged state (``read_state``).
    ax : Axes, optional
        Where to draw (a 3D Axes for ``projection='3d'``); a new figure when omitted.
    projection : {'xy', 'xz', 'yz', '3d'}
        The two coordinates drawn (the other one is dropped), or a perspective view.
    cmap : str
        Matplotlib colormap for the tension.
    colorbar : bool
        Add a colorbar labelled "tension (N)".
    norm : Normalize, optional
        The tension range of the colours (default: this state's minimum to maximum,
        :func:`tension_norm`).
    images : tuple of int
        Periodic images drawn along each period of a periodic cell (its periodic links,
        :meth:`State.periods`), e.g. ``(3, 3)``; ``(1, 1)``: the cell alone.
    unit : {'mm', 'm', 'um'}
        Length unit of the axes.
    gap_holders : bool
        Draw the gap-holders as thin grey lines.
    nodes : bool
        Mark the nodes with small black dots.
    slipping : bool
        Circle in red the nodes whose passage slips (``mode`` point data forward or
        backward; see ``contacts.csv``).
    depth_scale : float
        How many times z is stretched in the drawing (``'3d'`` and the projections
        with z; the tick labels stay true lengths).

    Returns
    -------
    Axes

    Raises
    ------
    ValueError
        For an unknown projection or unit, or images of a state that is no periodic
        cell.
    """
    _check_projection(projection)
    three_d = projection == "3d"
    if unit not in LENGTH_UNITS:
        raise ValueError(f"unit must be one of {', '.join(LENGTH_UNITS)}, not {unit!r}")
    if ax is None:
        figure = Figure(layout="constrained")
        ax = figure.add_subplot(projection="3d") if three_d else figure.add_subplot()
    columns = [0, 1, 2] if three_d else [COMPONENTS[c] for c in projection]
    scale = 1.0 / LENGTH_UNITS[unit]
    shifts = _image_shifts(state, images)
    points = np.concatenate([state.position + shift for shift in shifts])[:, columns] * scale
    offsets = np.arange(len(shifts))[:, None, None] * len(state.position)
    elements = (state.elements[None, :, :] + offsets).reshape(-1, 2)
    tension = np.tile(np.asarray(state.tension, dtype=float), len(shifts))
    if norm is None:
        norm = tension_norm(tension)
    if three_d:
        from mpl_toolkits.mplot3d.art3d import Line3DCollection
        collection = Line3DCollection
    else:
        collection = LineCollection
    lines = collection(points[elements], cmap=cmap, norm=norm, linewidths=2)
    lines.set_array(tension)
    lines.set_gid("elements")
    holder = state.link_kind == GAP_HOLDER
    if gap_holders and np.any(holder):
        # A gap-holder to a periodic image (cell data `period`) is drawn to that image.
        period = np.asarray(state.link_data.get("period", np.zeros((len(holder), 3))),
                            dtype=float).reshape(-1, 3)[holder]
        ends = np.stack([state.position[state.links[holder, 0]],
                         state.position[state.links[holder, 1]] - period], axis=1)
        ends = (ends[None, :, :, :] + shifts[:, None, None, :]).reshape(-1, 2, 3)
        grey = collection(ends[:, :, columns] * scale, colors="0.55", linewidths=1)
        grey.set_gid("gap_holders")
        drawn = [grey, lines]
    else:
        drawn = [lines]
    for each in drawn:
        if three_d:
            ax.add_collection3d(each)
        else:
            ax.add_collection(each)
    if nodes:
        ax.plot(*points.T, "k.", markersize=3)
    mode = state.passages.get("mode")
    if slipping and mode is not None:
        # The nodes with a slipping passage (each once).
        slip = np.unique(np.ravel(state.passages["node"])[np.isin(np.ravel(mode),
                                                                  SLIP_MODES)] - 1)
        where = np.concatenate([slip + k * len(state.position) for k in range(len(shifts))])
        ax.plot(*points[where].T, "o", markersize=7, markerfacecolor="none",
                markeredgecolor="tab:red", label="slipping passage", gid="slipping")
    names = ["xyz"[c] for c in columns]
    ax.set_xlabel(f"{names[0]} ({unit})")
    ax.set_ylabel(f"{names[1]} ({unit})")
    if three_d:
        low, high = points.min(axis=0), points.max(axis=0)
        extent = np.where(high > low, high - low, 1.0)
        ax.set_xlim(low[0], low[0] + extent[0])
        ax.set_ylim(low[1], low[1] + extent[1])
        ax.set_zlim(low[2], low[2] + extent[2])
        ax.set_box_aspect((extent[0], extent[1], depth_scale * extent[2]))
        ax.zaxis.set_major_locator(MaxNLocator(3))
        ax.set_zlabel(f"z ({unit})")
    else:
        ax.autoscale_view()
        # z drawn depth_scale times: the aspect is the ratio of the vertical unit to the
        # horizontal one on the screen.
        aspect = 1.0
        if columns[1] == 2:
            aspect = depth_scale
        elif columns[0] == 2:
            aspect = 1.0 / depth_scale
        ax.set_aspect(aspect, adjustable="datalim")
        readable_ticks(ax)
    if colorbar:
        readable_colorbar(ax.figure.colorbar(lines, ax=ax, label="tension (N)"))
    return ax


def nearest_states(folder: str | Path, targets: tuple[float, ...] = (0.0, 0.5, 1.0),
                   by: str = "strain", of_peak: bool = False
                   ) -> list[tuple[State, float]]:
    """The saved states of a run nearest to given values of a curve column, on its
    first loading.

    The candidates are the states written (``states.pvd``) whose step is in
    ``curve.csv`` up to the first step where ``by`` reaches its largest magnitude (the
    first loading, so a cycle's unloading is not picked). For each target the nearest
    candidate is taken (the earlier one on a tie).

    Parameters
    ----------
    folder : str or Path
        A run's output folder.
    targets : tuple of float
        Values of ``by`` wanted (with ``of_peak``: fractions of its peak).
    by : str
        The curve column: ``'strain'`` for a fabric, ``'p_disp'``, ``'time'``, ...
    of_peak : bool
        Targets are fractions of the peak of ``by`` (its value of largest magnitude;
        ``1`` is the peak): for a fabric stretched less than the targets.

    Returns
    -------
    list of (State, float)
        Per target: the state and its value of ``by``.

    Raises
    ------
    ResultError
        If the folder is missing, holds no curve.csv, a curve without rows, or no
        states of steps in the curve.
    KeyError
        If the curve has no column ``by``.
    ValueError
        If there are no targets, or a target lies outside the values of ``by`` on the
        first loading (by more than :data:`TARGET_TOLERANCE` of their range).
    """
    folder = Path(folder)
    if not folder.is_dir():
        raise ResultError(f"no output folder {str(folder)!r}")
    if not (folder / "curve.csv").is_file():
        raise ResultError(f"{str(folder)!r} holds no curve.csv: not a yarnfort output folder")
    if len(targets) == 0:
        raise ValueError("no strains asked for")
    curve = read_curve(folder)
    if len(curve) == 0:
        raise ResultError(f"{folder / 'curve.csv'} has no rows: the run wrote no converged"
                          " step")
    if by not in curve.names:
        raise KeyError(f"curve has no column {by!r} (a &fabric run has 'strain'): choose"
                       f" one of {', '.join(curve.channels + ['time', 'step'])} (by,"
                       " --by)")
    values = curve[by]
    last = int(np.argmax(np.abs(values)))
    first_loading = {int(step): float(value)
                     for step, value in zip(curve["step"][:last + 1], values[:last + 1])}
    states = [state for state in read_states(folder) if state.step in first_loading]
    if not states:
        raise ResultError(f"{folder}: no VTK state of a step of the first loading (steps 0"
                          f" to {int(curve['step'][last])}); run with &output vtk_every > 0")
    found = np.array([first_loading[state.step] for state in states])
    peak = float(values[last])
    low, high = float(values[:last + 1].min()), float(values[:last + 1].max())
    slack = TARGET_TOLERANCE * max(high - low, abs(high), abs(low), np.finfo(float).tiny)
    chosen = []
    for target in targets:
        value = float(target) * peak if of_peak else float(target)
        if not low - slack <= value <= high + slack:
            raise ValueError(f"{by} = {value:g} is outside the run's first loading"
                             f" ({low:g} to {high:g})"
                             + ("" if of_peak else "; targets as fractions of the peak:"
                                " of_peak (--of-peak)"))
        k = int(np.argmin(np.abs(found - value)))
        chosen.append((states[k], float(found[k])))
    return chosen


def _row_height(ax: Axes) -> float:
    """Height (inches) of a row of 2D panels of width :data:`PANEL_WIDTH` that shows
    ``ax``'s limits at its aspect, with room for the title and labels."""
    width = np.ptp(ax.get_xlim())
    ratio = np.ptp(ax.get_ylim()) * ax.get_aspect() / width if width > 0 else 1.0
    return float(np.clip(PANEL_WIDTH * ratio, 0.4, ROW_HEIGHT) + 1.1)


def _common_limits(axes: list[Axes], three_d: bool, depth_scale: float) -> None:
    """The same limits on every Axes of a row (the union of what each shows), so that
    the panels compare at one scale."""
    if three_d:
        limits = [(min(getattr(ax, f"get_{k}lim")()[0] for ax in axes),
                   max(getattr(ax, f"get_{k}lim")()[1] for ax in axes)) for k in "xyz"]
        for ax in axes:
            for k, (low, high) in zip("xyz", limits):
                getattr(ax, f"set_{k}lim")(low, high)
            extent = [high - low for low, high in limits]
            ax.set_box_aspect((extent[0], extent[1], depth_scale * extent[2]))
        return
    bounds = np.array([ax.dataLim.extents for ax in axes])
    low, high = bounds[:, :2].min(axis=0), bounds[:, 2:].max(axis=0)
    margin = 0.04 * np.where(high > low, high - low, 1.0)
    for ax in axes:
        ax.set_xlim(low[0] - margin[0], high[0] + margin[0])
        ax.set_ylim(low[1] - margin[1], high[1] + margin[1])
        ax.set_adjustable("box")


def plot_states(folder: str | Path, strains: tuple[float, ...] = (0.0, 0.5, 1.0), *,
                by: str = "strain", of_peak: bool = False, images: tuple[int, ...] = (1, 1),
                projections: tuple[str, ...] = ("xy",), unit: str = "mm",
                cmap: str = "viridis", depth_scale: float = 1.0, slipping: bool = True,
                title: str | None = None) -> Figure:
    """Deformed states of a run, one panel per requested strain, coloured by tension on
    one common scale.

    The states drawn are those :func:`nearest_states` picks (the saved steps nearest to
    ``strains`` on the first loading); each panel is titled with the value it shows.
    One row of panels per entry of ``projections``, one colorbar (tension, N) for all.

    Parameters
    ----------
    folder : str or Path
        A run's output folder (curve.csv and VTK states).
    strains : tuple of float
        Values of ``by`` (with ``of_peak``: fractions of its peak).
    by, of_peak
        As in :func:`nearest_states`.
    images : tuple of int
        Periodic images per period, as in :func:`plot_network`.
    projections : tuple of str
        Views, one row each: ``'xy'``, ``'xz'``, ``'yz'`` or ``'3d'``.
    unit : {'mm', 'm', 'um'}
        Length unit of the axes.
    cmap : str
        Colormap of the tension.
    depth_scale : float
        z stretched this many times in ``'3d'`` views.
    slipping : bool
        Circle the nodes whose passage slips.
    title : str, optional
        Title of the figure.

    Returns
    -------
    Figure
        In every panel the elements are the collection of gid ``'elements'``; its
        ``norm`` is the common tension range (min to max over the states drawn).

    Raises
    ------
    ResultError, KeyError, ValueError
        As :func:`nearest_states` and :func:`plot_network`.
    """
    chosen = nearest_states(folder, strains, by=by, of_peak=of_peak)
    for projection in projections:  # before any drawing: a clear error
        _check_projection(projection)
    norm = tension_norm(np.concatenate([np.asarray(state.tension, dtype=float)
                                        for state, _ in chosen]))
    figure = Figure(figsize=(PANEL_WIDTH * len(chosen) + 1.2, ROW_HEIGHT * len(projections)),
                    layout="constrained")
    label = "strain" if by == "strain" else by
    lines = None
    heights = []
    for row, projection in enumerate(projections):
        for column, (state, value) in enumerate(chosen):
            ax = figure.add_subplot(len(projections), len(chosen),
                                    row * len(chosen) + column + 1,
                                    projection="3d" if projection == "3d" else None)
            plot_network(state, ax=ax, projection=projection, cmap=cmap, colorbar=False,
                         norm=norm, images=images, unit=unit, slipping=slipping,
                         depth_scale=depth_scale)
            if row == 0:
                ax.set_title(f"{label} {value:.3g} (step {state.step})")
            lines = [c for c in ax.collections if c.get_gid() == "elements"][0]
        row_axes = figure.axes[-len(chosen):]
        _common_limits(row_axes, projection == "3d", depth_scale)
        heights.append(ROW_HEIGHT if projection == "3d" else _row_height(row_axes[0]))
    # Rows as tall as their drawings (a flat weave seen from the side is a thin strip).
    figure.set_size_inches(PANEL_WIDTH * len(chosen) + 1.2, sum(heights))
    readable_colorbar(figure.colorbar(lines, ax=figure.axes, label="tension (N)",
                                      shrink=0.8))
    if title:
        figure.suptitle(title)
    return figure


def plot_fan(curves: dict[str, Curve], support: str, component: str = "y",
             x: str = "p_disp", ax: Axes | None = None, cmap: str = "viridis",
             title: str | None = None) -> Axes:
    """Sensitivity fan: several runs' curves on one Axes, one labelled line each
    (as the paper's Fig. 6, e.g. one curve per friction coefficient).

    Parameters
    ----------
    curves : dict[str, Curve]
        Legend label -> curve, drawn in this order with colours along ``cmap``.
    support, component, x
        As in :func:`plot_curve`.
    ax : Axes, optional
        Where to draw; a new figure when omitted.
    cmap : str
        Colormap sampled for the lines.
    title : str, optional
        Legend title (e.g. the parameter varied).

    Returns
    -------
    Axes
    """
    ax = _axes(ax)
    colormap = matplotlib.colormaps[cmap]
    positions = np.linspace(0.0, 0.9, max(len(curves), 1))
    for position, (label, curve) in zip(positions, curves.items()):
        ax.plot(curve[x], reaction_component(curve, support, component), label=label,
                color=colormap(position))
    _labels(ax, support, component, x)
    if curves:
        ax.legend(title=title)
    return ax


def save_figure(fig: Figure | Axes, path: str | Path, dpi: int = 150) -> Path:
    """Write a figure as a PNG.

    Parameters
    ----------
    fig : Figure or Axes
        The figure, or an Axes whose figure is written.
    path : str or Path
        The PNG to write; missing parent folders are created.
    dpi : int
        Resolution.

    Returns
    -------
    pathlib.Path
        The path written.

    Raises
    ------
    OSError
        If the file cannot be written (nothing is left at ``path`` then, or the old
        file stays).
    """
    figure = fig.figure if isinstance(fig, Axes) else fig
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    # Through a temporary file renamed over the target: a failed write leaves no
    # half-written PNG.
    partial = path.with_name(path.name + ".tmp")
    try:
        figure.savefig(partial, format="png", dpi=dpi)
        os.replace(partial, path)
    finally:
        partial.unlink(missing_ok=True)
    return path


# -- the summary of a run (``python -m yarnfort plot``) ----------------------------------
#: A tension range narrower than this fraction of its magnitude is one value (rounding):
#: the colour bar is widened by :data:`FLAT_PAD` of it instead of showing noise.
FLAT_RANGE = 1e-6
FLAT_PAD = 0.05
#: Ticks on the axes of a network panel (labels of lengths in mm stay apart).
NETWORK_TICKS = 5


@dataclass
class Driver:
    """What a load channel does to the scene: moves a support set or pushes a load.

    Attributes
    ----------
    channel : str
        The load channel (a column of ``curve.csv``).
    kind : {'displacement', 'force'}
        A ``&support`` with a prescribed displacement, or a ``&load``.
    name : str
        The support set, or ``'load_<k>'`` (``&load`` number k, from 1).
    direction : numpy.ndarray
        Unit vector of the displacement or force at factor 1.
    magnitude : float
        Length (m) of that displacement, or of the force on each node (N).
    nodes : int
        Nodes of the set.
    """

    channel: str
    kind: str
    name: str
    direction: np.ndarray
    magnitude: float
    nodes: int

    @property
    def label(self) -> str:
        return (f"support '{self.name}'" if self.kind == "displacement"
                else f"&load {self.name[5:]}")


def _groups(scene: Any, name: str) -> list[Any]:
    found = scene.get(name, []) if scene is not None else []
    return list(found) if isinstance(found, list) else [found]


def load_drivers(curve: Curve, scene: Any) -> list[Driver]:
    """The supports that move and the loads that push, with their channels.

    Parameters
    ----------
    curve : Curve
        The run's curve (its columns name the channels and the sets).
    scene : f90nml.Namelist or None
        The run's effective input (``input.nml``, :func:`yarnfort.read_scene`).

    Returns
    -------
    list of Driver
        Supports with a nonzero displacement, then loads with a nonzero force, in input
        order; only those whose channel and displacement columns are in the curve. Then
        the support sets of the curve that the input does not list (a generated fabric's)
        and that move: along their displacement at its largest, on the channel that
        moves supports (``p_disp`` without ``&path channels``).
    """
    default = {"displacement": "p_disp", "force": "p_force"}
    found = []
    for kind, group, key in (("displacement", "support", "displacement"),
                             ("force", "load", "force")):
        for number, entry in enumerate(_groups(scene, group), start=1):
            vector = np.zeros(3)
            values = [0.0 if v is None else float(v)
                      for v in np.atleast_1d(entry.get(key, [0.0] * 3))]
            vector[:min(3, len(values))] = values[:3]
            size = float(np.linalg.norm(vector))
            name = str(entry.get("name", "")) if kind == "displacement" else f"load_{number}"
            channel = str(entry.get("channel", "") or "") or default[kind]
            if size == 0.0 or channel not in curve.names or f"{name}_ux" not in curve.names:
                continue
            nodes = len(np.atleast_1d(entry.get("nodes", [])))
            found.append(Driver(channel, kind, name, vector / size, size, max(nodes, 1)))
    listed = {str(entry.get("name", "")) for entry in _groups(scene, "support")}
    channel = "p_disp" if "p_disp" in curve.channels else None
    for name in supports(curve):
        if name in listed or channel is None or f"{name}_ux" not in curve.names:
            continue
        moved = curve.displacement(name)
        lengths = np.linalg.norm(moved, axis=1)
        if len(lengths) and lengths.max() > 0.0:
            largest = moved[int(np.argmax(lengths))]
            found.append(Driver(channel, "displacement", name, largest / lengths.max(),
                                float(lengths.max()), 1))
    return found


def _changes(values: np.ndarray) -> int:
    return int(np.count_nonzero(np.diff(values))) if len(values) > 1 else 0


def choose_driver(curve: Curve, drivers: list[Driver], channel: str | None = None
                  ) -> Driver | None:
    """The driver to plot: of ``channel`` if given, else of the channel that changes in
    the most steps (the last stage of a staged path: the sideways cycles of a ring pulled
    down first), a moving support before a load.

    Parameters
    ----------
    curve : Curve
        The run's curve.
    drivers : list of Driver
        From :func:`load_drivers`.
    channel : str, optional
        The load channel wanted.

    Returns
    -------
    Driver or None
        None if nothing drives the run (no support moves, no load pushes).

    Raises
    ------
    ValueError
        If ``channel`` drives nothing (the message lists the channels that do).
    """
    if channel is not None:
        of_channel = [d for d in drivers if d.channel == channel]
        if not of_channel:
            driving = sorted({d.channel for d in drivers})
            raise ValueError(f"channel {channel!r} moves no support and pushes no load;"
                             f" channels that do: {', '.join(driving) or 'none'}")
        return of_channel[0]
    if not drivers:
        return None
    return max(drivers, key=lambda d: (_changes(curve[d.channel]),
                                       d.kind == "displacement"))


def driver_response(curve: Curve, driver: Driver, support: str | None = None
                    ) -> tuple[np.ndarray, np.ndarray]:
    """Displacement and force of a driver, per step, both along its direction.

    Parameters
    ----------
    curve : Curve
        The run's curve.
    driver : Driver
        From :func:`load_drivers`.
    support : str, optional
        Another support set whose force is wanted instead: its reaction on the net along
        the driver's direction.

    Returns
    -------
    displacement : numpy.ndarray
        Of the driver's set along its direction (m).
    force : numpy.ndarray
        N, positive in tension: a moving support's reaction on the net along its motion
        (a pull is positive, a push negative); a load's applied force on all its nodes.
    """
    displacement = curve.displacement(driver.name) @ driver.direction
    if support is not None and support != driver.name:
        force = curve.reaction(support) @ driver.direction
    elif driver.kind == "displacement":
        force = curve.reaction(driver.name) @ driver.direction
    else:
        force = curve[driver.channel] * driver.magnitude * driver.nodes
    return displacement, force


def plot_load_displacement(curve: Curve, driver: Driver, ax: Axes | None = None,
                           support: str | None = None, unit: str = DEFAULT_UNIT) -> Axes:
    """Force against displacement of a driver (a moving support or a load), loading and
    unloading drawn as in :func:`plot_hysteresis`, force positive in tension.

    Parameters
    ----------
    curve : Curve
        The run's curve.
    driver : Driver
        From :func:`load_drivers` / :func:`choose_driver`.
    ax : Axes, optional
        Where to draw; a new figure when omitted.
    support : str, optional
        Draw this support set's force against the driver (:func:`driver_response`).
    unit : {'mm', 'm', 'um'}
        Length unit of the displacement.

    Returns
    -------
    Axes
    """
    if unit not in LENGTH_UNITS:
        raise ValueError(f"unit must be one of {', '.join(LENGTH_UNITS)}, not {unit!r}")
    ax = _axes(ax)
    displacement, force = driver_response(curve, driver, support)
    _plot_branches(ax, displacement / LENGTH_UNITS[unit], force, curve["direction"])
    ax.set_xlabel(f"displacement of {driver.label} along {_direction_text(driver.direction)}"
                  f" ({unit})")
    ax.set_ylabel(force_label(driver, support))
    ax.grid(True, alpha=0.3)
    if ax.get_legend_handles_labels()[0]:
        ax.legend()
    return ax


def force_label(driver: Driver, support: str | None = None) -> str:
    """Axis label of :func:`driver_response`'s force, with its sign convention."""
    if support not in (None, driver.name):
        return (f"reaction of support '{support}' on the net along"
                f" {_direction_text(driver.direction)} (N)")
    if driver.kind == "displacement":
        return f"pulling force of {driver.label} (N, + = tension)"
    return f"applied force of {driver.label} along {_direction_text(driver.direction)} (N)"


def _direction_text(direction: np.ndarray) -> str:
    """'+x', '-y', or the unit vector for an oblique direction."""
    axis = int(np.argmax(np.abs(direction)))
    if abs(abs(direction[axis]) - 1.0) <= FLAT_RANGE:
        return ("+" if direction[axis] > 0 else "-") + "xyz"[axis]
    return "(" + ", ".join(f"{v:.2g}" for v in direction) + ")"


def tension_norm(tension: np.ndarray) -> Normalize:
    """The colour range of tensions: their minimum to maximum, widened by
    :data:`FLAT_PAD` of their magnitude when they are one value to rounding (a uniform
    string is one colour mid-bar, not a bar of rounding noise).

    Parameters
    ----------
    tension : array_like
        Element tensions (N).

    Returns
    -------
    Normalize
    """
    tension = np.asarray(tension, dtype=float)
    if tension.size == 0:
        return Normalize(0.0, 1.0)
    low, high = float(tension.min()), float(tension.max())
    scale = max(abs(low), abs(high))
    if high - low <= FLAT_RANGE * scale or scale == 0.0:
        pad = FLAT_PAD * scale if scale > 0.0 else 1.0
        return Normalize(low - pad, high + pad)
    return Normalize(low, high)


def readable_colorbar(colorbar: Any) -> None:
    """Plain tick labels on a colour bar: no offset ('1e-13+2e-2'), powers of ten only
    outside 1e-3 .. 1e4."""
    formatter = ScalarFormatter(useOffset=False)
    formatter.set_powerlimits((-3, 4))
    colorbar.formatter = formatter
    colorbar.update_ticks()


def readable_ticks(ax: Axes, count: int = NETWORK_TICKS) -> None:
    """At most ``count`` ticks per axis, without offsets, so labels stay apart."""
    for axis in (ax.xaxis, ax.yaxis):
        axis.set_major_locator(MaxNLocator(count))
        formatter = ScalarFormatter(useOffset=False)
        formatter.set_powerlimits((-3, 5))
        axis.set_major_formatter(formatter)


def peak_step(curve: Curve, force: np.ndarray, steps: list[int]) -> int:
    """The step of largest |force| among ``steps`` (those with a saved state); the
    earliest on a tie.

    Parameters
    ----------
    curve : Curve
        The run's curve.
    force : numpy.ndarray
        One value per row of the curve.
    steps : list of int
        The candidate steps.

    Returns
    -------
    int

    Raises
    ------
    ValueError
        If none of ``steps`` is in the curve.
    """
    index = {int(step): k for k, step in enumerate(curve["step"])}
    candidates = [step for step in steps if step in index]
    if not candidates:
        raise ValueError("no saved state of a step of the curve")
    return max(candidates, key=lambda step: (abs(force[index[step]]), -step))


def plot_history(curve: Curve, states: list[State], driver: Driver, scene: Any,
                 axes: list[Axes], unit: str = DEFAULT_UNIT) -> list[Axes]:
    """History of the rings and obstacles against the driver's load: the position of
    every ``&ring`` node (the components that move, from the saved states) and the
    reaction of every ``&obstacle`` (its components that are nonzero), drawn against
    the driver's force (a load) or displacement (a moving support).

    Parameters
    ----------
    curve, states
        The run's curve and saved states.
    driver : Driver
        The abscissa's driver.
    scene : f90nml.Namelist
        The effective input (``&ring`` nodes, ``&obstacle`` names).
    axes : list of Axes
        One for the rings (if the scene has any), then one for the obstacles.
    unit : {'mm', 'm', 'um'}
        Length unit.

    Returns
    -------
    list of Axes
        Those drawn on.
    """
    displacement, force = driver_response(curve, driver)
    by_step = {int(step): k for k, step in enumerate(curve["step"])}
    if driver.kind == "force":
        abscissa, x_label = force, force_label(driver)
    else:
        abscissa = displacement / LENGTH_UNITS[unit]
        x_label = (f"displacement of {driver.label} along"
                   f" {_direction_text(driver.direction)} ({unit})")
    used = []
    pending = list(axes)
    rings = _groups(scene, "ring")
    if rings and pending:
        ax = pending.pop(0)
        kept = [s for s in states if s.step in by_step]
        rows = [by_step[s.step] for s in kept]
        for ring in rings:
            for node in np.atleast_1d(ring.get("nodes", [])):
                path = np.array([s.position[int(node) - 1] for s in kept])
                for k in range(3):
                    if len(path) and np.ptp(path[:, k]) > 0.0:
                        ax.plot(abscissa[rows], path[:, k] / LENGTH_UNITS[unit], ".-",
                                markersize=3,
                                label=f"ring '{ring.get('name')}' node {int(node)}: {'xyz'[k]}")
        ax.set_xlabel(x_label)
        ax.set_ylabel(f"ring position ({unit})")
        ax.set_title("ring history")
        ax.grid(True, alpha=0.3)
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize="small")
        used.append(ax)
    obstacles = [o for o in _groups(scene, "obstacle") if f"{o.get('name')}_rx" in curve.names]
    if obstacles and pending:
        ax = pending.pop(0)
        for obstacle in obstacles:
            reaction = curve.reaction(str(obstacle.get("name")))
            for k in range(3):
                if np.any(reaction[:, k] != 0.0):
                    ax.plot(abscissa, reaction[:, k],
                            label=f"obstacle '{obstacle.get('name')}': R{'xyz'[k]}")
        ax.set_xlabel(x_label)
        ax.set_ylabel("reaction on the net (N)")
        ax.set_title("obstacle history")
        ax.grid(True, alpha=0.3)
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize="small")
        used.append(ax)
    return used
