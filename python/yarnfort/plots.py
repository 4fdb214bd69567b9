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

from pathlib import Path

import matplotlib
import numpy as np
from matplotlib.axes import Axes
from matplotlib.collections import LineCollection
from matplotlib.colors import Normalize
from matplotlib.figure import Figure

from .results import Curve, State

__all__ = ["plot_curve", "plot_hysteresis", "plot_fabric_hysteresis", "plot_network",
           "plot_fan", "save_figure", "supports", "reaction_component"]

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
    :func:`plot_hysteresis`.

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
    ax.set_ylabel("force per unit width (N/m)")
    ax.grid(True, alpha=0.3)
    if ax.get_legend_handles_labels()[0]:
        ax.legend()
    return ax


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


def plot_network(state: State, ax: Axes | None = None, projection: str = "xy",
                 cmap: str = "viridis", colorbar: bool = True) -> Axes:
    """The deformed network of ``state`` as line segments coloured by element tension.

    Parameters
    ----------
    state : State
        A converged state (``read_state``).
    ax : Axes, optional
        Where to draw; a new figure when omitted.
    projection : {'xy', 'xz', 'yz'}
        The two coordinates drawn (the other one is dropped).
    cmap : str
        Matplotlib colormap for the tension.
    colorbar : bool
        Add a colorbar labelled "tension (N)".

    Returns
    -------
    Axes
    """
    if len(projection) != 2 or not set(projection) <= set(COMPONENTS):
        raise ValueError(f"projection must be two of 'x', 'y', 'z', not {projection!r}")
    ax = _axes(ax)
    columns = [COMPONENTS[c] for c in projection]
    segments = state.position[:, columns][state.elements]
    tension = np.asarray(state.tension, dtype=float)
    low, high = (float(tension.min()), float(tension.max())) if tension.size else (0, 1)
    if high <= low:
        high = low + 1.0
    lines = LineCollection(segments, cmap=cmap, norm=Normalize(low, high), linewidths=2)
    lines.set_array(tension)
    ax.add_collection(lines)
    ax.plot(*state.position[:, columns].T, "k.", markersize=3)
    ax.autoscale_view()
    ax.set_aspect("equal", adjustable="datalim")
    ax.set_xlabel(f"{projection[0]} (m)")
    ax.set_ylabel(f"{projection[1]} (m)")
    if colorbar:
        ax.figure.colorbar(lines, ax=ax, label="tension (N)")
    return ax


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
    """
    figure = fig.figure if isinstance(fig, Axes) else fig
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    figure.savefig(path, format="png", dpi=dpi)
    return path
