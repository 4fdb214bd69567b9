# SPDX-License-Identifier: MIT
"""Effective loading and unloading curves of a periodic fabric cell for macro models
(``python -m yarnfort export-fabric``, issue 40).

A run of a periodic cell (``&fabric boundary = 'periodic'``) gives, per step, a
macroscopic strain and the membrane force per unit width that goes with it. This module
cuts that history into the curves a macro material model takes:

- the **loading** curve: the primary (virgin) loading, the steps where the strain
  reaches a value larger than every earlier one, from the first step on;
- one **unloading** curve per peak of the primary loading the run turns back from: the
  steps from that peak while the strain decreases. Unloadings that start below the
  largest strain reached so far (from a reloading) are not on the primary curve and are
  left out (:attr:`ComponentCurves.skipped` counts them).

Components (the names of Abaqus ``*UNIAXIAL, COMPONENT=``): ``'1'`` and ``'2'``, the
two in-plane directions, and ``'12'``, the in-plane shear. Where ``curve.csv`` has the
membrane columns (``e11``, ``e22``, ``gamma12``; ``n11``, ``n22``, ``n12``) the component
takes its own pair; otherwise components 1 and 2 take the uniaxial columns ``strain``
and ``force_per_width`` (the cell stretched along x: give the run of the cell turned by
90 degrees, or stretched in its other direction, as component 2). Shear has no such
fallback. Its force is the shear in the yarns' frame, ``n12 cos(gamma12) - n22
sin(gamma12)`` (the fabric models take their shear response apart from the tension
along the yarns, which turns with the yarns by itself); a run where that is zero (a
string net's crossings are pins: inputs/REFERENCE.md, *Shear*) is refused.

Three formats (:func:`export_fabric`): an Abaqus/Explicit ``*FABRIC`` material block,
LS-DYNA ``*DEFINE_CURVE_TITLE`` blocks, and a plain CSV. The keyword layouts, and where
they come from, are in ``docs/fabric_export.md``. Files are written through a temporary
file renamed over the target, and an existing file is refused unless ``overwrite``.
"""
from __future__ import annotations

import csv
import io
import os
import re
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Iterable, Mapping, Sequence

import numpy as np

from .namelist import read_scene
from .results import Curve, incomplete_reason, read_curve
from .units import UNITS, WIDTH_UNITS, find_unit

__all__ = ["FabricExportError", "Branch", "ComponentCurves", "fabric_curves",
           "export_fabric", "parse_units", "parse_length", "FORMATS", "COMPONENTS"]

#: Output formats.
FORMATS = ("abaqus", "lsdyna", "csv")
#: Components: the two in-plane directions and the in-plane shear.
COMPONENTS = ("1", "2", "12")
#: The (strain, membrane force) columns of each component in curve.csv, and the uniaxial
#: columns components 1 and 2 fall back to.
MEMBRANE_COLUMNS = {"1": ("e11", "n11"), "2": ("e22", "n22"), "12": ("gamma12", "n12")}
UNIAXIAL_COLUMNS = ("strain", "force_per_width")
#: Component 12's force: the shear in the yarns' frame, from these columns.
FRAME_SHEAR = "n12 cos(gamma12) - n22 sin(gamma12)"
#: A frame shear below this fraction of the largest n11, n22 is zero (the solver's
#: rounding; the program's note on a sheared run uses the same bound).
ZERO_SHEAR = 1e-8
#: Abaqus names the shear component SHEAR (Keywords Guide, *UNIAXIAL).
ABAQUS_COMPONENT = {"1": "1", "2": "2", "12": "SHEAR"}
#: A strain change smaller than this fraction of the component's strain range is no
#: change (steps that hold the strain, rounding of the path's knots).
STRAIN_NOISE = 1e-12
#: LS-DYNA fixed-width fields: card 1 has 8 fields of 10 characters, the points 2 of 20
#: (Keyword User's Manual Vol. I, *DEFINE_CURVE).
LSDYNA_HEADER_WIDTH = 10
LSDYNA_POINT_WIDTH = 20
#: Significant digits written: a value read back equals the run's to 1e-12 relative.
DIGITS = 13


class FabricExportError(ValueError):
    """A run or an option the export cannot use; the message names the run, component
    or option and what is wrong."""


@dataclass
class Branch:
    """One curve of a component, in SI units.

    Attributes
    ----------
    kind : str
        ``'loading'`` or ``'unloading'``.
    strain : numpy.ndarray
        Engineering strain (1), or shear strain (rad) for component 12, in path order.
    force_per_width : numpy.ndarray
        Membrane force per unit width, N/m, in path order.
    steps : numpy.ndarray
        The run's step numbers of the points.
    peak_strain : float
        The strain the branch ends (loading) or starts (unloading) at.
    """

    kind: str
    strain: np.ndarray
    force_per_width: np.ndarray
    steps: np.ndarray
    peak_strain: float


@dataclass
class ComponentCurves:
    """The curves of one component taken from one run.

    Attributes
    ----------
    component : str
        ``'1'``, ``'2'`` or ``'12'``.
    run : pathlib.Path
        The output folder read.
    columns : tuple of str
        The (strain, force per width) columns of curve.csv used.
    loading : Branch
    unloading : list of Branch
        One per peak of the primary loading the run unloads from, in path order.
    skipped : int
        Unloadings left out because they start below the largest strain reached before
        (after a reloading: not on the primary loading curve).
    """

    component: str
    run: Path
    columns: tuple[str, str]
    loading: Branch
    unloading: list[Branch] = field(default_factory=list)
    skipped: int = 0


# -- reading a run -------------------------------------------------------------------

def _check_periodic(folder: Path) -> None:
    """Refuse a run that is not a periodic fabric cell (its input.nml tells)."""
    scene_file = folder / "input.nml"
    if not scene_file.is_file():
        raise FabricExportError(f"run {str(folder)!r} has no input.nml: cannot tell whether"
                                " it is a periodic fabric cell")
    try:
        scene = read_scene(scene_file)
    except Exception as error:  # f90nml raises several types for a damaged file
        raise FabricExportError(f"run {str(folder)!r}: input.nml is not readable ({error})"
                                ) from None
    fabric = scene.get("fabric")
    if fabric is None or isinstance(fabric, list):
        raise FabricExportError(f"run {str(folder)!r} is not a periodic fabric cell (its"
                                " input has no &fabric group): its forces are no membrane"
                                " forces of a fabric")
    boundary = str(fabric.get("boundary", "periodic")).strip().lower()
    if boundary != "periodic":
        raise FabricExportError(f"run {str(folder)!r} is not a periodic cell (&fabric"
                                f" boundary = {boundary!r}): a clamped sample's force per"
                                " width includes its edges, export a periodic cell")


def _columns(curve: Curve, component: str, folder: Path, uniaxial: bool) -> tuple[str, str]:
    strain, force = MEMBRANE_COLUMNS[component]
    if uniaxial and component == "12":
        raise FabricExportError("the uniaxial columns (strain, force_per_width) are a"
                                " normal direction: they cannot give component 12")
    if not uniaxial and strain in curve.columns and force in curve.columns:
        return strain, force
    if component != "12" and all(name in curve.columns for name in UNIAXIAL_COLUMNS):
        return UNIAXIAL_COLUMNS
    needed = f"{strain} and {force}" + ("" if component == "12"
                                        else " (or strain and force_per_width)")
    raise FabricExportError(f"run {str(folder)!r} has no data for component {component}:"
                            f" curve.csv has no columns {needed}")


def _frame_shear(curve: Curve, folder: Path) -> np.ndarray:
    """The shear in the yarns' frame (N/m) at every step; refused where it is zero."""
    missing = [c for c in ("n11", "n22") if c not in curve.columns]
    if missing:
        raise FabricExportError(f"run {str(folder)!r} has no data for component 12:"
                                f" curve.csv has no columns {' and '.join(missing)}")
    gamma, n12, n22, n11 = (np.asarray(curve[c], dtype=float)
                            for c in ("gamma12", "n12", "n22", "n11"))
    shear = n12 * np.cos(gamma) - n22 * np.sin(gamma)
    scale = max(float(np.abs(n11).max()), float(np.abs(n22).max()))
    if np.all(np.isfinite(shear)) and np.abs(shear).max() <= ZERO_SHEAR * scale:
        raise FabricExportError(
            f"run {str(folder)!r}, component 12: no shear stiffness: the shear in the"
            f" yarns' frame, {FRAME_SHEAR}, is zero at every step (at most"
            f" {np.abs(shear).max() / max(scale, np.finfo(float).tiny):.1e} of n11, n22):"
            " the cell carries tension along its yarns only (n12 = n22 tan(gamma12)),"
            " which the macro model's components 1 and 2 carry; a string net's crossings"
            " are pins (inputs/REFERENCE.md, Shear)")
    return shear


def _primary_and_unloading(strain: np.ndarray) -> tuple[list[int], list[list[int]], int]:
    """Rows of the primary loading, rows of each unloading from a new peak, and the
    number of unloadings from below the largest strain reached before."""
    noise = STRAIN_NOISE * max(float(np.ptp(strain)), float(np.abs(strain).max()), 1.0)
    loading = [0]
    largest = strain[0]
    unloadings: list[list[int]] = []
    skipped = 0
    used = -1  # the primary peak (row) already unloaded from
    n = len(strain)
    i = 1
    while i < n:
        if strain[i] > largest + noise:
            loading.append(i)
            largest = strain[i]
            i += 1
            continue
        if strain[i] < strain[i - 1] - noise:
            # An unloading starts at row i - 1: follow it while the strain does not grow.
            start = i - 1
            rows = [start]
            while i < n and strain[i] <= strain[rows[-1]] + noise:
                rows.append(i)
                i += 1
            if strain[start] >= largest - noise and used != loading[-1]:
                unloadings.append(rows)
                used = loading[-1]
            else:
                skipped += 1
            continue
        i += 1
    return loading, unloadings, skipped


def fabric_curves(folder: str | Path, component: str = "1", *,
                  uniaxial: bool = False) -> ComponentCurves:
    """The loading and unloading curves of one component of a periodic-cell run.

    Parameters
    ----------
    folder : str or Path
        The run's output folder (curve.csv and input.nml).
    component : str
        ``'1'``, ``'2'`` or ``'12'`` (see the module notes for the columns used).
    uniaxial : bool
        Read ``strain`` and ``force_per_width`` (the cell stretched along x) for
        component 1 or 2 even where curve.csv has the membrane columns: the run of a
        cell turned by 90 degrees given as component 2.

    Returns
    -------
    ComponentCurves

    Raises
    ------
    FabricExportError
        For an unknown component, a run that is no periodic fabric cell, a curve
        without the component's columns or rows, or a strain that never grows.
    ResultError, OSError
        If curve.csv cannot be read.

    Warns
    -----
    RuntimeWarning
        If the run stopped before the end of its load path (its curves are cut short).
    """
    component = str(component)
    if component not in COMPONENTS:
        raise FabricExportError(f"unknown component {component!r}; the components are"
                                " 1, 2 and 12")
    folder = Path(folder)
    if not folder.is_dir():
        raise FabricExportError(f"no output folder {str(folder)!r}")
    _check_periodic(folder)
    curve = read_curve(folder)
    if reason := incomplete_reason(folder, curve):
        warnings.warn(f"{folder}: {reason}; the exported curves end there", RuntimeWarning,
                      stacklevel=2)
    strain_column, force_column = _columns(curve, component, folder, uniaxial)
    if len(curve) < 2:
        raise FabricExportError(f"run {str(folder)!r}: curve.csv has {len(curve)} rows,"
                                " a curve needs at least 2 steps")
    strain = np.asarray(curve[strain_column], dtype=float)
    force = np.asarray(curve[force_column], dtype=float)
    steps = np.asarray(curve["step"]) if "step" in curve.columns else np.arange(len(curve))
    if not (np.all(np.isfinite(strain)) and np.all(np.isfinite(force))):
        raise FabricExportError(f"run {str(folder)!r}: {strain_column} or {force_column}"
                                " has a value that is not finite")
    loading, unloadings, skipped = _primary_and_unloading(strain)
    if len(loading) < 2:
        raise FabricExportError(
            f"run {str(folder)!r}, component {component}: {strain_column} never grows"
            f" beyond its first value {strain[0]:.6g} (the run loads another component or"
            " is compressed); give the run that loads this component"
            + ("" if strain_column == UNIAXIAL_COLUMNS[0] or component == "12" else
               ", or read a turned cell's x direction with --uniaxial"))
    if component == "12":
        force, force_column = _frame_shear(curve, folder), FRAME_SHEAR

    def branch(kind: str, rows: list[int], peak: int) -> Branch:
        index = np.array(rows)
        return Branch(kind, strain[index].copy(), force[index].copy(), steps[index].copy(),
                      float(strain[peak]))

    return ComponentCurves(
        component, folder, (strain_column, force_column),
        branch("loading", loading, loading[-1]),
        [branch("unloading", rows, rows[0]) for rows in unloadings], skipped)


# -- units ---------------------------------------------------------------------------

def parse_units(text: str) -> tuple[str, str]:
    """``'N,mm'`` as (force unit, length unit); each a spelling of :data:`UNITS`.

    Parameters
    ----------
    text : str
        A force unit and a length unit, separated by a comma, blank or ``/``.

    Returns
    -------
    tuple of str
        The two units' spellings.

    Raises
    ------
    FabricExportError
        Unless the text is a force unit then a length unit (the message lists them).
    """
    parts = [part.strip() for part in re.split(r"[,\s/]+", text.strip()) if part.strip()]
    force = find_unit(parts[0]) if parts else None
    if (len(parts) != 2 or force is None or UNITS[force][0] != "force"
            or parts[1] not in WIDTH_UNITS):
        forces = ", ".join(u for u, (k, _, _) in UNITS.items() if k == "force")
        raise FabricExportError(
            f"--units {text!r}: give the macro model's force unit then its length unit,"
            f" e.g. 'N,mm' (force: {forces}; length: {', '.join(WIDTH_UNITS)})")
    return force, parts[1]


def parse_length(text: str | float, what: str = "--thickness") -> float:
    """A length with its unit (``'0.6 mm'``, ``'6e-4m'``) in metres.

    Parameters
    ----------
    text : str
        The number and its unit.
    what : str
        The option named in messages.

    Returns
    -------
    float
        The length in m.

    Raises
    ------
    FabricExportError
        For a number without a unit (the unit would be a guess), an unknown or non-length
        unit, or a length that is not positive and finite.
    """
    match = re.fullmatch(r"\s*([-+0-9.eE]+)\s*([^\s0-9.+-][^\s]*)?\s*", str(text))
    if isinstance(text, (int, float)) or not match or match.group(2) is None:
        raise FabricExportError(f"{what} {text!r}: give the length with its unit, e.g."
                                " '0.6mm' (a bare number would mix the run's metres with"
                                " the model's length unit)")
    unit = match.group(2)
    if unit not in WIDTH_UNITS:
        raise FabricExportError(f"{what} {text!r}: {unit!r} is not a length unit"
                                f" ({', '.join(WIDTH_UNITS)})")
    try:
        value = float(match.group(1))
    except ValueError:
        raise FabricExportError(f"{what} {text!r}: {match.group(1)!r} is not a number"
                                ) from None
    metres = value * WIDTH_UNITS[unit]
    if not (np.isfinite(metres) and metres > 0):
        raise FabricExportError(f"{what} {text!r}: must be positive and finite")
    return metres


@dataclass
class _Scale:
    """Conversion of the run's SI values to the macro model's units."""

    force_unit: str
    length_unit: str
    thickness: float | None      # m

    @property
    def newtons(self) -> float:
        return UNITS[self.force_unit][1] / UNITS[self.force_unit][2]

    @property
    def metres(self) -> float:
        return WIDTH_UNITS[self.length_unit]

    def force_per_width(self, values: np.ndarray) -> np.ndarray:
        """N/m in force unit per length unit."""
        return np.asarray(values) * self.metres / self.newtons

    def stress(self, values: np.ndarray) -> np.ndarray:
        """N/m over the thickness, in force unit per length unit squared."""
        assert self.thickness is not None
        return np.asarray(values) / self.thickness * self.metres ** 2 / self.newtons

    @property
    def stress_unit(self) -> str:
        return f"{self.force_unit}/{self.length_unit}^2"

    @property
    def width_unit(self) -> str:
        return f"{self.force_unit}/{self.length_unit}"


# -- writers -------------------------------------------------------------------------

def _number(value: float) -> str:
    return f"{value:.{DIGITS - 1}e}"


def _describe(curves: ComponentCurves, scale: _Scale, comment: str) -> list[str]:
    """Comment lines: where each component's curves come from."""
    from .__main__ import _ranges  # '0-20, 51-60': one formatter of step lists

    loading = curves.loading
    lines = [f"{comment} component {curves.component}: run {curves.run},"
             f" columns {curves.columns[0]} and {curves.columns[1]}",
             f"{comment}   loading: steps {_ranges([int(s) for s in loading.steps])},"
             f" strain {loading.strain[0]:.6g} to {loading.peak_strain:.6g};"
             f" {curves.columns[1]} at the first step {loading.force_per_width[0]:.6g} N/m"]
    for k, branch in enumerate(curves.unloading, start=1):
        lines.append(f"{comment}   unloading {k}: steps {int(branch.steps[0])}-"
                     f"{int(branch.steps[-1])}, from strain {branch.peak_strain:.6g} to"
                     f" {branch.strain[-1]:.6g}")
    if curves.skipped:
        lines.append(f"{comment}   {curves.skipped} unloading(s) after a reloading left out"
                     " (not from the primary loading curve)")
    return lines


def _header(scale: _Scale, comment: str) -> list[str]:
    lines = [f"{comment} yarnfort export-fabric: effective curves of a periodic fabric cell",
             f"{comment} units: force {scale.force_unit}, length {scale.length_unit}"]
    if scale.thickness is not None:
        lines.append(f"{comment} stress = membrane force per width / thickness"
                     f" {scale.thickness / scale.metres:.6g} {scale.length_unit}, in"
                     f" {scale.stress_unit}; strains engineering (1), shear strain in rad")
    return lines


def _abaqus(all_curves: Sequence[ComponentCurves], scale: _Scale, name: str,
            unloading: bool) -> str:
    lines = _header(scale, "**")
    lines += ["** Layout: Abaqus Keywords Guide, *FABRIC, *UNIAXIAL, *LOADING DATA,",
              "** *UNLOADING DATA (see docs/fabric_export.md). Data lines: stress, strain.",
              "** Unloading curves: DEFINITION=INTERPOLATED CURVE, each curve from its lowest",
              "** strain up to its peak on the loading curve, one after the other.",
              "** Not found in the manual pages we could read: the order of stress and strain",
              "** in a fabric data line and how the unloading curves are told apart: check",
              "** in your Abaqus version (docs/fabric_export.md, Check before use)."]
    for curves in all_curves:
        lines += _describe(curves, scale, "**")
    for curves in all_curves:
        branches = [curves.loading] + (curves.unloading if unloading else [])
        lowest = min(float(branch.strain.min()) for branch in branches)
        if lowest < 0:
            raise FabricExportError(
                f"run {str(curves.run)!r}, component {curves.component}: strain {lowest:.6g}"
                " < 0 (compression); the Abaqus curves are written as tension data"
                " (DIRECTION=TENSION, positive strains): export a run that stays in"
                " tension, or use --format csv")
        # This writer's layout (not confirmed by the manual, docs/fabric_export.md): each
        # unloading curve from the start strain up to its peak, a new curve where the
        # strain drops. A partial release fits it with no start of its own: refused.
        start = float(curves.loading.strain[0])
        tolerance = STRAIN_NOISE * max(1.0, curves.loading.peak_strain)
        for k, branch in enumerate(curves.unloading if unloading else [], start=1):
            if branch.strain.min() > start + tolerance:
                raise FabricExportError(
                    f"run {str(curves.run)!r}, component {curves.component}: unloading {k}"
                    f" (from strain {branch.peak_strain:.6g}) stops at strain"
                    f" {branch.strain.min():.6g}, not at the start {start:.6g}; the Abaqus"
                    " unloading curves are written from the start strain up to their peak:"
                    " release the cell fully, or use --format lsdyna or csv")
    lines += [f"*MATERIAL, NAME={name}", "*FABRIC"]
    for curves in all_curves:
        lines.append(f"*UNIAXIAL, COMPONENT={ABAQUS_COMPONENT[curves.component]}")
        damage = unloading and bool(curves.unloading)
        # REGULARIZE=OFF: Abaqus uses the points as given (the run's steps), not a
        # regularized table (default RTOL=0.03); it applies to the unloading data too.
        lines.append("*LOADING DATA, TYPE=DAMAGE, DIRECTION=TENSION, REGULARIZE=OFF"
                     if damage else "*LOADING DATA, DIRECTION=TENSION, REGULARIZE=OFF")
        loading = curves.loading
        for stress, strain in zip(scale.stress(loading.force_per_width), loading.strain):
            lines.append(f"{_number(stress)}, {_number(strain)}")
        if damage:
            lines.append("*UNLOADING DATA, DEFINITION=INTERPOLATED CURVE")
            for branch in curves.unloading:
                order = np.argsort(branch.strain, kind="stable")
                for stress, strain in zip(scale.stress(branch.force_per_width)[order],
                                          branch.strain[order]):
                    lines.append(f"{_number(stress)}, {_number(strain)}")
    return "\n".join(lines) + "\n"


def _lsdyna_field(value: float, width: int) -> str:
    text = f"{value:.{width - 8}e}"
    assert len(text) <= width, text
    return text.rjust(width)


def _lsdyna(all_curves: Sequence[ComponentCurves], scale: _Scale, first_id: int,
            unloading: bool) -> str:
    lines = ["*KEYWORD"] + _header(scale, "$")
    lines += ["$ Layout: LS-DYNA Keyword User's Manual, *DEFINE_CURVE_TITLE: title line,",
              "$ card 1 = LCID SIDR SFA SFO OFFA OFFO DATTYP (8 fields of 10 characters),",
              "$ then one point per line, A (strain) and O (stress) in 2 fields of 20.",
              "$ Curves for *MAT_FABRIC (MAT_034) FORM=14 card 6: loading curves in LCA (1),",
              "$ LCB (2), LCAB (12); an unloading curve in LCUA, LCUB, LCUAB."]
    for curves in all_curves:
        lines += _describe(curves, scale, "$")
    lcid = first_id
    directions = {"1": "LCA/LCUA", "2": "LCB/LCUB", "12": "LCAB/LCUAB"}
    for curves in all_curves:
        branches = [curves.loading] + (curves.unloading if unloading else [])
        for k, branch in enumerate(branches):
            title = (f"yarnfort component {curves.component} loading" if k == 0 else
                     f"yarnfort component {curves.component} unloading {k} from strain"
                     f" {branch.peak_strain:.6g}")
            lines += [f"$ {directions[curves.component]}: {title}",
                      "*DEFINE_CURVE_TITLE", title[:80],
                      "$" + "".join(name.rjust(LSDYNA_HEADER_WIDTH) for name in
                                    ("LCID", "SIDR", "SFA", "SFO", "OFFA", "OFFO",
                                     "DATTYP"))[1:],
                      f"{lcid:>{LSDYNA_HEADER_WIDTH}d}{0:>{LSDYNA_HEADER_WIDTH}d}"
                      + "".join(f"{v:>{LSDYNA_HEADER_WIDTH}.1f}" for v in (1, 1, 0, 0))
                      + f"{0:>{LSDYNA_HEADER_WIDTH}d}",
                      "$" + "A1".rjust(LSDYNA_POINT_WIDTH - 1) + "O1".rjust(LSDYNA_POINT_WIDTH)]
            # A curve's abscissae increase (the manual's load curves are functions of A).
            order = np.argsort(branch.strain, kind="stable")
            for strain, stress in zip(branch.strain[order],
                                      scale.stress(branch.force_per_width)[order]):
                lines.append(_lsdyna_field(strain, LSDYNA_POINT_WIDTH)
                             + _lsdyna_field(stress, LSDYNA_POINT_WIDTH))
            lcid += 1
    lines.append("*END")
    return "\n".join(lines) + "\n"


def _csv(all_curves: Sequence[ComponentCurves], scale: _Scale, unloading: bool) -> str:
    stream = io.StringIO()
    writer = csv.writer(stream, lineterminator="\n")
    # The force is n11, n22, the frame shear or force_per_width by run and component:
    # one neutral name, and each row names its source (n11 is over the current width,
    # curve.csv's force_per_width over the undeformed one).
    header = ["component", "branch", "curve", "peak_strain", "step", "strain",
              f"membrane_force ({scale.width_unit})"]
    if scale.thickness is not None:
        header.append(f"stress ({scale.stress_unit})")
    header.append("force_from")
    writer.writerow(header)
    for curves in all_curves:
        branches = [curves.loading] + (curves.unloading if unloading else [])
        for k, branch in enumerate(branches):
            widths = scale.force_per_width(branch.force_per_width)
            stresses = (scale.stress(branch.force_per_width) if scale.thickness is not None
                        else [None] * len(widths))
            for step, strain, width, stress in zip(branch.steps, branch.strain, widths,
                                                   stresses):
                row = [curves.component, branch.kind, k, _number(branch.peak_strain),
                       int(step), _number(strain), _number(width)]
                if stress is not None:
                    row.append(_number(stress))
                row.append(curves.columns[1])
                writer.writerow(row)
    return stream.getvalue()


def _write_atomic(path: Path, text: str, overwrite: bool) -> None:
    if path.exists() and not overwrite:
        raise FabricExportError(f"{str(path)!r} exists: choose another output file or"
                                " overwrite it (--force)")
    if path.is_dir():
        raise FabricExportError(f"{str(path)!r} is a folder, not an output file")
    partial = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        with open(partial, "w", newline="") as stream:
            stream.write(text)
        os.replace(partial, path)
    finally:
        partial.unlink(missing_ok=True)


def export_fabric(runs: Mapping[str, str | Path] | Iterable[tuple[str, str | Path]],
                  out: str | Path, *, format: str = "abaqus",
                  thickness: str | None = None, units: str = "N,mm",
                  unloading: bool = True, uniaxial: bool = False,
                  name: str = "YARNFORT_FABRIC",
                  first_curve_id: int = 1, overwrite: bool = False) -> Path:
    """Write the effective curves of a fabric's periodic-cell runs for a macro model.

    Parameters
    ----------
    runs : mapping or iterable of (component, run folder)
        Which run gives which component: ``{'1': 'out/knit', '2': 'out/knit_wale'}``
        (with ``uniaxial=True`` when ``out/knit_wale`` is the cell turned by 90 degrees).
        One folder may give several components when its curve.csv has the membrane
        columns (see the module notes).
    out : str or Path
        File to write (its folder must exist).
    format : str
        ``'abaqus'`` (a ``*MATERIAL`` with ``*FABRIC``, ``*UNIAXIAL``, ``*LOADING DATA``,
        ``*UNLOADING DATA, DEFINITION=INTERPOLATED CURVE``), ``'lsdyna'``
        (``*DEFINE_CURVE_TITLE`` blocks, strain against stress) or ``'csv'`` (one row
        per point: component, branch, curve, peak strain, step, strain, membrane
        force, with a thickness stress, and the curve.csv column the force is from).
    thickness : str, optional
        The fabric's thickness with its unit (``'0.6mm'``): stress is the membrane force
        per width divided by it. Required for ``abaqus`` and ``lsdyna`` (their curves
        are stress against strain).
    units : str
        The macro model's force and length units, ``'N,mm'`` (stress in MPa), ``'N,m'``
        (Pa), ``'lbf,in'`` (psi): the force units of :data:`yarnfort.units.UNITS`
        and the lengths of :data:`yarnfort.units.WIDTH_UNITS` (with the inch).
    unloading : bool
        Write the unloading curves; each component's run must then have at least one
        unloading from its primary loading curve.
    uniaxial : bool
        Components 1 and 2 from ``strain`` and ``force_per_width`` of each run, even
        where curve.csv has the membrane columns (see :func:`fabric_curves`).
    name : str
        The Abaqus material name.
    first_curve_id : int
        The LS-DYNA LCID of the first curve (the others follow in order).
    overwrite : bool
        Replace an existing ``out`` (else it is refused, nothing written).

    Returns
    -------
    pathlib.Path
        The file written.

    Raises
    ------
    FabricExportError
        For a bad option, a component given twice, a run that is no periodic cell or
        has no data for its component, no unloading where unloading is asked, or an
        existing output file (the message says which).
    """
    if format not in FORMATS:
        raise FabricExportError(f"unknown format {format!r}; the formats are "
                                + ", ".join(FORMATS))
    force_unit, length_unit = parse_units(units)
    metres = parse_length(thickness) if thickness is not None else None
    if metres is None and format != "csv":
        raise FabricExportError(f"--format {format} writes stress against strain: give the"
                                " fabric's --thickness with its unit (stress = force per"
                                " width / thickness)")
    if not re.fullmatch(r"[A-Za-z][A-Za-z0-9_\-]{0,79}", name):
        raise FabricExportError(f"material name {name!r}: a letter, then letters, digits,"
                                " '_' or '-', at most 80 characters")
    if first_curve_id < 1 or first_curve_id > 99999999:
        raise FabricExportError(f"first curve id {first_curve_id}: from 1 to 99999999")
    pairs = list(runs.items()) if isinstance(runs, Mapping) else list(runs)
    if not pairs:
        raise FabricExportError("no runs given")
    seen: dict[str, Path] = {}
    all_curves = []
    for component, folder in pairs:
        component = str(component)
        if component in seen:
            raise FabricExportError(f"component {component} given twice (runs"
                                    f" {str(seen[component])!r} and {str(folder)!r})")
        seen[component] = Path(folder)
        curves = fabric_curves(folder, component, uniaxial=uniaxial)
        if curves.columns == UNIAXIAL_COLUMNS:
            # The uniaxial columns are one direction of one run: never two components.
            same = [c for c in all_curves if c.run.resolve() == curves.run.resolve()]
            if same:
                raise FabricExportError(
                    f"run {str(folder)!r} given for components {same[0].component} and"
                    f" {component}, but it has only the uniaxial columns strain and"
                    " force_per_width (one direction): give a run per component")
        if unloading and not curves.unloading:
            raise FabricExportError(
                f"run {str(folder)!r}, component {component}: no unloading from the"
                f" primary loading curve ({curves.columns[0]} only grows"
                + (f"; {curves.skipped} unloading(s) after reloadings" if curves.skipped
                   else "") + "): load and release the cell, or export without unloading"
                " (--no-unloading)")
        all_curves.append(curves)
    all_curves.sort(key=lambda c: COMPONENTS.index(c.component))
    scale = _Scale(force_unit, length_unit, metres)
    if format == "abaqus":
        text = _abaqus(all_curves, scale, name, unloading)
    elif format == "lsdyna":
        text = _lsdyna(all_curves, scale, first_curve_id, unloading)
    else:
        text = _csv(all_curves, scale, unloading)
    out = Path(out)
    _write_atomic(out, text, overwrite)
    return out
