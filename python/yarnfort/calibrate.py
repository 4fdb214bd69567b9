# SPDX-License-Identifier: MIT
"""Fit scene parameters to a measured force–strain curve (nonlinear least squares).

What is compared
----------------
A fabric (``&fabric``) is compared by its ``force_per_width`` against ``strain``; any
scene by the reaction of one support (a clamp force) against a load factor column. The
measured CSV carries its units in the headers (``strain (%)``, ``force (cN)``,
``force (N/m)``: :mod:`yarnfort.units`); a force per sample is turned into a force per
width (or back) with the sample's ``width``. The simulated curve is converted to the
data's units, so residuals, sigma, the summary and the plot are in the data's units.

Cycles
------
Both curves are cut into monotone branches, loading and unloading, in order: the
measured one where its branch (given, or the sign of the strain increments) or its
``cycle`` column changes, the simulated one where its ``direction`` changes (steps of
direction 0, holds, belong to no branch). Measured branch k is interpolated linearly on
simulated branch k (from the point where that branch starts), so several load cycles
are matched cycle by cycle. The scene's path must have at least as many branches as the
data, starting the same way, and cover each branch's strains at the initial values (to
:data:`COVERAGE_TOLERANCE` of the branch's span); otherwise :func:`calibrate` says so.
Points that a fitted value's branch no longer reaches take its end value.

Uncertainty and identifiability
-------------------------------
Each residual evaluation is one run of the program (see :mod:`yarnfort.sweep`); the fit
(``scipy.optimize.least_squares``) works on the parameters mapped to [0, 1] over their
bounds with a forward-difference Jacobian, so ``diff_step`` is a fraction of each
parameter's range. With sigma^2 = SSR / (m - n) (m points, n parameters) the covariance
is sigma^2 (J^T J)^-1, J from the derivative check below, through the SVD of J with its
columns scaled to unit length; it assumes independent errors of equal variance and a
model that fits. Errors that grow with the force (a load cell's relative accuracy, noise
of a few % of the reading) break that assumption and misstate the uncertainties:
``errors='relative'`` divides each residual by its measured force (weighted least
squares), so that sigma is a relative error and the covariance holds. The condition
number of the scaled J measures how nearly one parameter's effect on the curve is a mix
of the others'. Beyond :data:`CONDITION_LIMIT` (1/sqrt(epsilon): J^T J, whose condition is the
square, has no digit left) the directions below it count as undetermined (infinite
variance). An :class:`IdentifiabilityWarning` is issued, and the problems listed in
:attr:`CalibrationResult.problems`, when an uncertainty exceeds its value, the
condition number exceeds the limit, or a parameter ends at a bound.

The derivative check
--------------------
A frictional curve can ripple with a parameter: nearby values take different load steps
(step cuts) and find different nearby frictional equilibria. A forward difference at a
small step then measures the ripple, not the trend, and the uncertainty from it can be
far too small. So after the fit, J is computed again by central differences at
:data:`CHECK_STEP_FACTOR` times ``diff_step`` (2 n more runs); the covariance comes from
that one, and a parameter whose two derivative columns differ by more than
:data:`SMOOTHNESS_TOLERANCE` is reported as not smooth.
"""
from __future__ import annotations

import contextlib
import csv
import os
import tempfile
import time
import warnings
from collections.abc import Iterator, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import f90nml
import numpy as np
from scipy.optimize import least_squares

from ._native import YarnfortError
from .address import check_address
from .results import Curve
from .sweep import _check_support, run_patched
from .units import force_factor, split_header, strain_factor

__all__ = ["CalibrationResult", "IdentifiabilityWarning", "Measured", "calibrate",
           "read_measured", "simulated_branches", "simulated_force", "plot_fit",
           "write_synthetic_curve"]

#: Default finite-difference step, as a fraction of each parameter's range.
DIFF_STEP = 1.0e-3
#: Condition number of the column-scaled Jacobian beyond which the fit is near-singular:
#: J^T J then has a condition number above 1/epsilon (no significant digit).
CONDITION_LIMIT = 1.0 / np.sqrt(np.finfo(float).eps)
#: With ``errors='relative'``, forces below this fraction of the largest count as that:
#: relative errors of forces near zero would otherwise dominate the fit.
RELATIVE_FLOOR = 1.0e-3
#: The uncertainty comes from central differences at this many times ``diff_step``,
#: checked against the fit's forward differences; a column differing by more than
#: SMOOTHNESS_TOLERANCE (relative) means the curve ripples with the parameter
#: (docs/decisions.md, "Calibration: relative errors, identifiability, the derivative
#: check").
CHECK_STEP_FACTOR = 10.0
SMOOTHNESS_TOLERANCE = 0.1
#: A measured point may lie this fraction of its branch's strain span beyond the
#: simulated branch (the test machine's overshoot at a turning point); further is refused.
COVERAGE_TOLERANCE = 0.01
#: Names accepted for the branch column of a measured CSV.
BRANCH_COLUMNS = ("branch", "direction", "sign")
#: The model quantity of a fabric, and its abscissa.
FABRIC_FORCE, FABRIC_STRAIN = "force_per_width", "strain"
_COMPONENTS = {"x": 0, "y": 1, "z": 2}


class IdentifiabilityWarning(UserWarning):
    """A fitted parameter that the data do not determine: its uncertainty exceeds its
    value, the Jacobian is near-singular, it ended at a bound, or the curve ripples with
    it (see the module notes)."""


@dataclass
class Measured:
    """A measured curve, in SI (strain 1, force N or N/m) with the units it came in.

    Attributes
    ----------
    strain, force : numpy.ndarray
        The points in SI: strain (1), force (N) or force per width (N/m).
    branch : numpy.ndarray
        +1 loading, -1 unloading.
    segment : numpy.ndarray
        Index of the monotone branch (0, 1, ...) each point belongs to, in order.
    strain_unit, force_unit : str
        The units of the data (``'%'``, ``'cN'``, ``'N/m'``, ...; ``'1'``, ``'N'`` when
        the file gives none).
    strain_factor, force_factor : float
        Data unit -> SI factors.
    per_width : bool
        The force is a force per width (N/m in SI).
    path : pathlib.Path or None
        The file read.
    """

    strain: np.ndarray
    force: np.ndarray
    branch: np.ndarray
    segment: np.ndarray
    strain_unit: str = "1"
    force_unit: str = "N"
    strain_factor: float = 1.0
    force_factor: float = 1.0
    per_width: bool = False
    path: Path | None = None

    @property
    def n_branches(self) -> int:
        """Number of monotone branches."""
        return int(self.segment.max()) + 1 if self.segment.size else 0

    @property
    def signs(self) -> list[int]:
        """The sign (+1 loading, -1 unloading) of each branch, in order."""
        return [int(self.branch[np.argmax(self.segment == k)])
                for k in range(self.n_branches)]


@dataclass
class CalibrationResult:
    """Outcome of :func:`calibrate`. Forces are in the data's units
    (:attr:`force_unit`), strains in SI (1) unless named ``*_data``.

    Attributes
    ----------
    names : tuple of str
        Parameter addresses, in the order of ``values``.
    values, uncertainty : numpy.ndarray
        Fitted values and their standard uncertainties (inf where undetermined).
    covariance, correlation : numpy.ndarray
        Covariance sigma^2 (J^T J)^-1 of the fitted values, and the correlation matrix.
    condition_number : float
        Of the Jacobian with its columns scaled to unit length.
    derivative_mismatch : numpy.ndarray
        Per parameter, the relative difference of the curve's derivative at the fit's
        finite-difference step and at the check's (see the module notes).
    problems : tuple of str
        Why a parameter is not identifiable (empty when all are); also warned about.
    residual_norm : float
        sqrt(sum of squared residuals), in the data's force unit (unweighted).
    sigma : float
        Standard deviation of the (weighted) residuals, sqrt(SSR / (m - n)): in the
        data's force unit, or a fraction of the force with ``errors='relative'``.
    errors : str
        ``'equal'`` or ``'relative'`` (see :func:`calibrate`).
    n_runs : int
        Program runs made (finite-difference runs included).
    wall_time : float
        Seconds the fit took.
    success : bool
        ``least_squares`` reports convergence.
    message : str
        ``least_squares``'s message.
    measured : Measured
        The data.
    strain_unit, force_unit : str
        The data's units.
    fitted_force : numpy.ndarray
        Simulated force at the measured points with the fitted values (data's unit).
    curve_strain, curve_force, curve_direction : numpy.ndarray
        The whole simulated curve with the fitted values (strain in SI, force in the
        data's unit).
    width : float or None
        The sample width (m) that converted between force and force per width.
    """

    names: tuple[str, ...]
    values: np.ndarray
    uncertainty: np.ndarray
    covariance: np.ndarray
    correlation: np.ndarray
    condition_number: float
    derivative_mismatch: np.ndarray
    problems: tuple[str, ...]
    residual_norm: float
    sigma: float
    errors: str
    n_runs: int
    wall_time: float
    success: bool
    message: str
    measured: Measured
    fitted_force: np.ndarray
    curve_strain: np.ndarray
    curve_force: np.ndarray
    curve_direction: np.ndarray
    width: float | None = None

    @property
    def strain_unit(self) -> str:
        """The data's strain unit."""
        return self.measured.strain_unit

    @property
    def force_unit(self) -> str:
        """The data's force unit."""
        return self.measured.force_unit

    @property
    def strain(self) -> np.ndarray:
        """Measured strains (1)."""
        return self.measured.strain

    @property
    def force(self) -> np.ndarray:
        """Measured forces, in the data's unit."""
        return self.measured.force / self.measured.force_factor

    @property
    def branch(self) -> np.ndarray:
        """+1 loading, -1 unloading, per measured point."""
        return self.measured.branch

    @property
    def parameters(self) -> dict[str, tuple[float, float]]:
        """Address -> (fitted value, standard uncertainty)."""
        return {name: (float(v), float(u))
                for name, v, u in zip(self.names, self.values, self.uncertainty)}

    def summary(self) -> str:
        """The fitted values with uncertainties, the correlations, the residual in the
        data's units, the runs, and the identifiability problems found."""
        lines = [f"{name} = {v:.6g} ± {u:.2g}" for name, (v, u) in self.parameters.items()]
        n = len(self.names)
        for i in range(n):
            for j in range(i + 1, n):
                lines.append(f"correlation({self.names[i]}, {self.names[j]}) = "
                             f"{self.correlation[i, j]:+.3f}")
        m = self.measured
        cycles = sum(1 for s in m.signs if s > 0)
        sigma = (f"{self.sigma:.3g} of the force" if self.errors == "relative" else
                 f"{self.sigma:.3g} {self.force_unit}")
        lines.append(f"residual norm {self.residual_norm:.4g} {self.force_unit}, sigma "
                     f"{sigma}, {self.force.size} points in "
                     f"{m.n_branches} branches ({cycles} loading), {self.n_runs} runs, "
                     f"{self.wall_time:.1f} s")
        lines.append(f"Jacobian condition number {self.condition_number:.3g} "
                     "(columns scaled to unit length); derivatives at two steps differ by "
                     + ", ".join(f"{d:.1%}" for d in self.derivative_mismatch))
        lines += [f"NOT IDENTIFIABLE: {text}" for text in self.problems]
        return "\n".join(lines)


def _component_index(component: str | int) -> int:
    """0, 1 or 2 for 'x', 'y', 'z' (or the index itself)."""
    if isinstance(component, str) and component.lower() in _COMPONENTS:
        return _COMPONENTS[component.lower()]
    if not isinstance(component, str) and component in (0, 1, 2):
        return int(component)
    raise ValueError(f"component {component!r}: expected 'x', 'y', 'z' or 0, 1, 2")


def _branch_value(text: str) -> int:
    word = text.strip().lower()
    if word.startswith("load"):
        return 1
    if word.startswith("unload"):
        return -1
    try:
        value = float(word)
    except ValueError:
        raise ValueError(f"branch {text!r}: expected loading/unloading or a sign") from None
    if value == 0:
        raise ValueError(f"branch value {text!r}: expected loading/unloading or a sign")
    return 1 if value > 0 else -1


def _infer_branch(strain: np.ndarray) -> np.ndarray:
    """+1 where the strain grows from the previous point, -1 where it falls."""
    step = np.sign(np.diff(strain, prepend=strain[0]))
    if step.size > 1:
        step[0] = step[1]
    for i in range(1, step.size):  # a repeated strain keeps the previous branch
        if step[i] == 0:
            step[i] = step[i - 1]
    step[step == 0] = 1
    return step.astype(int)


def _runs(keys: np.ndarray) -> np.ndarray:
    """0, 1, 2, ... numbering the runs of equal consecutive rows of ``keys``."""
    if keys.shape[0] == 0:
        return np.zeros(0, dtype=int)
    change = np.any(np.diff(keys, axis=0) != 0, axis=tuple(range(1, keys.ndim)))
    return np.concatenate([[0], np.cumsum(change)]).astype(int)


def _unit(given: str | None, header: str | None, column: str) -> str | None:
    """The unit from the header, or the argument; both given must agree."""
    if given is not None and header is not None and given.strip() != header.strip():
        raise ValueError(f"the {column} column says {header!r}, the argument {given!r}")
    return header if header is not None else given


def read_measured(path: str | os.PathLike, *, strain_unit: str | None = None,
                  force_unit: str | None = None) -> Measured:
    """Read a measured curve: a CSV with a header, columns ``strain`` and ``force``
    (units in the header, ``strain (%)``, ``force (cN)``, ``force (N/m)``), optionally a
    branch column (``branch``: loading/unloading, or ``direction``/``sign``: +1/-1) and
    a ``cycle`` column. Without a branch column, the branch follows the sign of the
    strain increments (so noisy strains need one). Lines starting with ``#`` are
    comments; one before the header that names the strain or force column with another
    unit than the one the column is read in is an error (its unit would be ignored).

    Parameters
    ----------
    path : path
        The CSV file.
    strain_unit, force_unit : str, optional
        Units for columns whose header gives none (default 1 and N); a header's unit
        must agree. See :mod:`yarnfort.units`.

    Returns
    -------
    Measured
        The points in SI, their branches and the data's units.

    Raises
    ------
    ValueError
        For a file without data rows or the columns, an unknown unit, a cell that is
        not a number, or a row with more cells than the header has names (a decimal comma
        or a thousands separator; the message names the file and line).
    """
    # utf-8-sig: a byte order mark (Excel's "CSV UTF-8") is not part of the first name.
    with open(path, newline="", encoding="utf-8-sig") as stream:
        every = list(enumerate(stream, start=1))
    numbered = [(number, line) for number, line in every if not line.startswith("#")]
    # Each non-blank row with its file line (the header is the first of them).
    records = [(number, row) for number, line in numbered
               for row in csv.reader([line]) if any(cell.strip() for cell in row)]
    lines = [number for number, _ in records[1:]]
    rows = [row for _, row in records]
    if len(rows) < 2:
        raise ValueError(f"{path}: no data rows")
    try:
        header = [split_header(cell) for cell in rows[0]]
    except ValueError as error:
        raise ValueError(f"{path}: {error}") from None
    position = {name.lower(): k for k, (name, _) in enumerate(header)}
    for name in ("strain", "force", "cycle", *BRANCH_COLUMNS):
        twice = [header[k][0] for k in range(len(header)) if header[k][0].lower() == name]
        if len(twice) > 1:  # the last would be read, the others dropped
            raise ValueError(f"{path}: the header names the column {name!r} "
                             f"{len(twice)} times ({', '.join(rows[0])}); keep one")
    missing = [name for name in ("strain", "force") if name not in position]
    if missing:
        raise ValueError(f"{path}: missing column(s) {', '.join(missing)}")
    given = {"strain": strain_unit, "force": force_unit}
    for column in ("strain", "force"):
        if header[position[column]][1] is None and given[column] is None:
            _check_comment_units(path, every, records[0][0], column)
    try:
        s_unit = _unit(strain_unit, header[position["strain"]][1], "strain")
        f_unit = _unit(force_unit, header[position["force"]][1], "force")
        s_factor = strain_factor(s_unit)
        f_factor, per_width = force_factor(f_unit)
    except ValueError as error:
        raise ValueError(f"{path}: {error}") from None
    branch_at = next((position[name] for name in BRANCH_COLUMNS if name in position), None)
    cycle_at = position.get("cycle")
    strain, force, signs, cycles = [], [], [], []
    for number, row in zip(lines, rows[1:]):
        if any(text.strip() for text in row[len(header):]):
            # A decimal comma or a thousands separator splits a number into two cells:
            # reading the cells under the header would shift every column after it.
            raise ValueError(f"{path}, line {number}: {len(row)} cells "
                             f"({','.join(row)!r}) but the header names {len(header)} "
                             "columns (a decimal comma or a thousands separator? write "
                             "numbers as 1234.5)")
        cell = row + [""] * (len(header) - len(row))  # a short row's missing cells
        try:
            strain.append(_number(cell[position["strain"]], "strain"))
            force.append(_number(cell[position["force"]], "force"))
            if branch_at is not None:
                signs.append(_branch_value(cell[branch_at]))
            if cycle_at is not None:
                cycles.append(_number(cell[cycle_at], "cycle"))
        except ValueError as error:
            raise ValueError(f"{path}, line {number}: {error}") from None
    strain_array = s_factor * np.array(strain)
    branch = _infer_branch(strain_array) if branch_at is None else np.array(signs)
    keys = branch[:, None] if cycle_at is None else np.column_stack([branch, cycles])
    return Measured(strain_array, f_factor * np.array(force), branch, _runs(keys),
                    strain_unit=s_unit or "1", force_unit=f_unit or "N",
                    strain_factor=s_factor, force_factor=f_factor, per_width=per_width,
                    path=Path(path))


def _check_comment_units(path: str | os.PathLike, lines: list[tuple[int, str]],
                         header_line: int, column: str) -> None:
    """A ValueError where a '#' comment before the header names ``column`` with a unit
    other than the default (1, N) that the header and the arguments do not state: it
    would be read in the default ('# strain (%),force (cN)' above 'strain,force')."""
    default = {"strain": "1", "force": "N"}[column]
    for number, line in lines:
        if number >= header_line:
            return
        if not line.startswith("#"):
            continue
        for cell in next(csv.reader([line[1:]]), []):
            name, unit = split_header(cell)
            if name.lower() != column or unit is None:
                continue
            try:  # the default's factor (1, or N and not per width) reads the same
                same = (strain_factor(unit) == 1.0 if column == "strain"
                        else force_factor(unit) == (1.0, False))
            except ValueError:  # not a unit: a note
                continue
            if not same:
                raise ValueError(f"{path}, line {number}: the comment names the {column} "
                                 f"column with the unit {unit!r}, but the header (line "
                                 f"{header_line}) gives none, so it would be read in "
                                 f"{default!r}: put the unit in the header "
                                 f"('{column} ({unit})') or give {column}_unit={unit!r}")


def _number(text: str | None, name: str) -> float:
    """A finite number from a CSV cell, or a ValueError naming the column."""
    try:
        value = float(text if text is not None else "")
    except ValueError:
        raise ValueError(f"{name} {text!r} is not a number") from None
    if not np.isfinite(value):
        raise ValueError(f"{name} {text!r} is not finite")
    return value


def simulated_branches(direction: np.ndarray) -> list[tuple[int, np.ndarray]]:
    """The monotone branches of a simulated curve, in order: (sign, rows) each, rows
    from the step where the branch starts (the turning point or the initial state) to
    its last step. Steps of direction 0 (holds) belong to no branch; branches of one
    sign on either side of a hold are one branch.

    Parameters
    ----------
    direction : numpy.ndarray
        The ``direction`` column of ``curve.csv``.

    Returns
    -------
    list of (int, numpy.ndarray)
    """
    moving = np.flatnonzero(direction != 0)
    branches: list[tuple[int, list[int]]] = []
    for row in moving:
        sign = 1 if direction[row] > 0 else -1
        if branches and branches[-1][0] == sign:
            branches[-1][1].append(int(row))
        else:
            branches.append((sign, [max(int(row) - 1, 0), int(row)]))
    return [(sign, np.array(rows)) for sign, rows in branches]


def _model_curve(curve: Curve, support: str | None, component: int, x_column: str | None,
                 x_scale: float, force_scale: float) -> tuple[np.ndarray, np.ndarray]:
    """The simulated (strain, force) columns: force per width of a fabric, or a
    support's reaction component."""
    if support is None:
        if FABRIC_FORCE not in curve.columns:
            raise ValueError("the scene's curve has no force_per_width (it is not a "
                             "&fabric): name the support whose reaction is compared "
                             "(support=...)")
        force = curve[FABRIC_FORCE]
        x_default = FABRIC_STRAIN
    else:
        if f"{support}_rx" not in curve.columns:
            known = [name[:-3] for name in curve.names if name.endswith("_rx")]
            raise ValueError(f"support {support!r}: the scene's curve has supports "
                             + (", ".join(known) or "none"))
        force = curve.reaction(support)[:, component]
        x_default = FABRIC_STRAIN if FABRIC_STRAIN in curve.columns else "p_disp"
    return x_scale * curve[x_column or x_default], force_scale * force


def simulated_force(curve: Curve, strain: np.ndarray, branch: np.ndarray, *,
                    support: str | None = None, component: int = 1,
                    x_column: str | None = None, x_scale: float = 1.0,
                    force_scale: float = 1.0, segment: np.ndarray | None = None
                    ) -> np.ndarray:
    """The simulated force (N or N/m) at measured points, branch by branch.

    Parameters
    ----------
    curve : Curve
        The simulated curve.
    strain, branch : numpy.ndarray
        Measured strains (1) and their branches (+1 loading, -1 unloading).
    support : str, optional
        Support set whose reaction is the force; None: ``force_per_width`` (a fabric).
    component : int
        Reaction component (0, 1, 2 for x, y, z).
    x_column, x_scale : str, float
        The simulated strain is ``x_scale * curve[x_column]`` (default column ``strain``
        for a fabric, else ``p_disp``).
    force_scale : float
        The simulated force is ``force_scale`` times the reaction or force per width.
    segment : numpy.ndarray, optional
        Branch index of each point (default: the runs of equal ``branch``).

    Returns
    -------
    numpy.ndarray

    Raises
    ------
    ValueError
        If the data have more branches than the simulation, or branch k of the data
        loads where the simulation's unloads (or the reverse).
    """
    x, force = _model_curve(curve, support, component, x_column, x_scale, force_scale)
    segment = _runs(np.asarray(branch)[:, None]) if segment is None else segment
    simulated = simulated_branches(curve["direction"])
    n_data = int(segment.max()) + 1 if segment.size else 0
    if n_data > len(simulated):
        raise ValueError(f"the data have {n_data} loading/unloading branches, the scene's "
                         f"path gives {len(simulated)}: give the &path as many load cycles"
                         " as the measurement")
    result = np.empty_like(strain, dtype=float)
    for k in range(n_data):
        wanted = segment == k
        sign, rows = simulated[k]
        data_sign = int(branch[np.argmax(wanted)])
        if data_sign != sign:
            words = {1: "loading", -1: "unloading"}
            raise ValueError(f"branch {k + 1} of the data is {words[data_sign]}, of the "
                             f"scene's path {words[sign]}: the path must start and turn "
                             "as the measurement does")
        order = np.argsort(x[rows], kind="stable")
        result[wanted] = np.interp(strain[wanted], x[rows][order], force[rows][order])
    return result


def _check_coverage(curve: Curve, data: Measured, support: str | None, component: int,
                    x_column: str | None, x_scale: float, force_scale: float) -> None:
    """A ValueError where a measured point lies beyond the strains of its simulated
    branch by more than COVERAGE_TOLERANCE of that branch's span."""
    x, _ = _model_curve(curve, support, component, x_column, x_scale, force_scale)
    simulated = simulated_branches(curve["direction"])
    for k in range(int(data.segment.max()) + 1 if data.segment.size else 0):
        strain = data.strain[data.segment == k]
        low, high = float(np.min(x[simulated[k][1]])), float(np.max(x[simulated[k][1]]))
        slack = COVERAGE_TOLERANCE * (high - low)
        if np.min(strain) >= low - slack and np.max(strain) <= high + slack:
            continue
        factor = data.strain_factor
        raise ValueError(
            f"branch {k + 1} of the data spans strain {np.min(strain) / factor:g} to "
            f"{np.max(strain) / factor:g} ({data.strain_unit}), the scene's path "
            f"{low / factor:g} to {high / factor:g}: points beyond would be compared with "
            "the branch's end value. Give the &path the test's range, or state the "
            "strain column's unit (a header 'strain (%)', or strain_unit='%')")


@contextlib.contextmanager
def _scene_file(scene: Any) -> Iterator[Path]:
    """A namelist path for a :class:`~yarnfort.Scene` or an f90nml namelist (written to a
    temporary folder), or for a path (as given)."""
    if isinstance(scene, (str, os.PathLike)):
        yield Path(scene)
        return
    if not isinstance(scene, f90nml.Namelist) and not hasattr(scene, "to_namelist"):
        raise TypeError(f"scene: expected a Scene, a namelist or a path, got "
                        f"{type(scene).__name__}")
    with tempfile.TemporaryDirectory(prefix="yarnfort-scene-") as folder:
        path = Path(folder) / "scene.nml"
        nml = scene if isinstance(scene, f90nml.Namelist) else scene.to_namelist()
        nml.write(str(path), force=True)
        yield path


#: Largest sample width (m) taken as a bare number: lab samples are centimetres wide, so
#: a larger number is a width in mm or cm given as metres (50 for 50 mm: 1000 times off).
PLAIN_WIDTH_LIMIT = 1.0


def sample_width(width: float | str | None) -> float | None:
    """A sample width in m: a number of metres, or a length with its unit (``'50 mm'``).

    Raises
    ------
    ValueError
        For a width that is not positive and finite, a bare number above
        :data:`PLAIN_WIDTH_LIMIT` (a width in mm or cm, the unit left out), or a string
        without a length unit.
    """
    if width is None:
        return None
    if isinstance(width, str):
        from .fabric_export import parse_length

        return parse_length(width, "width")
    if isinstance(width, (bool, np.bool_)) or not isinstance(width, (int, float, np.number)):
        raise ValueError(f"width {width!r}: expected a number of metres or a length with its"
                         " unit ('50 mm')")
    if not (np.isfinite(width) and width > 0):
        raise ValueError(f"width = {width!r}: must be positive and finite (m)")
    if width > PLAIN_WIDTH_LIMIT:
        raise ValueError(f"width = {width!r}: a sample {width!r} m wide? give it in metres"
                         f" ({width!r} mm is {width * 1e-3:g}) or with its unit"
                         f" (width='{width!r} mm')")
    return float(width)


def _conversion(measured: Measured, model_per_width: bool, width: float | None) -> float:
    """Factor from the model's SI quantity to the data's unit."""
    factor = 1.0 / measured.force_factor
    if measured.per_width == model_per_width:
        return factor
    if width is None or not width > 0:
        kinds = ("force per width", "force") if model_per_width else ("force",
                                                                      "force per width")
        raise ValueError(f"the model gives a {kinds[0]}, the data a {kinds[1]} "
                         f"({measured.force_unit}): give the sample's width (m), width=...")
    # Model N/m, data N per sample: times the width; model N, data N/m: over it.
    return factor * (width if model_per_width else 1.0 / width)


def _uncertainty(jac: np.ndarray, sigma2: float, limit: float
                 ) -> tuple[np.ndarray, np.ndarray, float]:
    """Covariance sigma^2 (J^T J)^-1, standard uncertainties and the condition number of
    J with unit columns; directions with singular values below s_max / limit have
    infinite variance."""
    norms = np.linalg.norm(jac, axis=0)
    scale = np.where(norms > 0, norms, 1.0)
    _, s, vt = np.linalg.svd(jac / scale, full_matrices=False)
    condition = float(s[0] / s[-1]) if s[-1] > 0 else np.inf
    kept = s > s[0] / limit
    inverse = np.full(s.shape, np.inf)
    inverse[kept] = 1.0 / s[kept]
    with np.errstate(invalid="ignore"):
        w = np.where(vt.T == 0, 0.0, vt.T * inverse)  # V S^-1, infinite where undetermined
        covariance = sigma2 * (w @ w.T) / np.outer(scale, scale)
    covariance[norms == 0, :] = np.inf
    covariance[:, norms == 0] = np.inf
    uncertainty = np.sqrt(np.diag(covariance))
    return covariance, uncertainty, condition


def _central_jacobian(residual: Any, z: np.ndarray, step: float) -> np.ndarray:
    """Central differences of ``residual`` at ``z`` (within [0, 1]; one-sided at a
    bound), 2 n evaluations."""
    columns = []
    for k in range(z.size):
        up, down = z.copy(), z.copy()
        up[k], down[k] = min(z[k] + step, 1.0), max(z[k] - step, 0.0)
        columns.append((residual(up) - residual(down)) / (up[k] - down[k]))
    return np.column_stack(columns)


def _mismatch(first: np.ndarray, second: np.ndarray) -> np.ndarray:
    """Per column, |a - b| / max(|a|, |b|) (0 for two zero columns)."""
    difference = np.linalg.norm(first - second, axis=0)
    size = np.maximum(np.linalg.norm(first, axis=0), np.linalg.norm(second, axis=0))
    return np.divide(difference, size, out=np.zeros_like(size), where=size > 0)


def _problems(names: tuple[str, ...], values: np.ndarray, uncertainty: np.ndarray,
              correlation: np.ndarray, condition: float, limit: float,
              active: np.ndarray) -> list[str]:
    found = []
    for k, name in enumerate(names):
        if not np.isfinite(uncertainty[k]):
            found.append(f"{name}: the data do not determine it (infinite uncertainty)")
        elif uncertainty[k] > abs(values[k]):
            found.append(f"{name} = {values[k]:.4g} has an uncertainty {uncertainty[k]:.2g}"
                         " larger than its value")
        if active[k]:
            found.append(f"{name} = {values[k]:.4g} is at its "
                         f"{'lower' if active[k] < 0 else 'upper'} bound: the uncertainty "
                         "assumes an optimum inside the bounds")
    if condition > limit:
        pairs = [f"{names[i]} and {names[j]} ({correlation[i, j]:+.4f})"
                 for i in range(len(names)) for j in range(i + 1, len(names))
                 if np.isfinite(correlation[i, j]) and abs(correlation[i, j]) > 0.99]
        found.append(f"the Jacobian is near-singular (condition number {condition:.3g} >"
                     f" {limit:.3g}): the curve changes the same way with several "
                     "parameters" + (f"; correlated: {', '.join(pairs)}" if pairs else ""))
    return found


def calibrate(scene: Any, measured: str | os.PathLike | Measured,
              parameters: Mapping[str, tuple[float, float, float]], *,
              support: str | None = None, component: str | int = "y",
              x_column: str | None = None, x_scale: float = 1.0, force_scale: float = 1.0,
              width: float | None = None, strain_unit: str | None = None,
              force_unit: str | None = None, errors: str = "equal",
              fixed: Mapping[str, Any] | None = None,
              diff_step: float = DIFF_STEP, max_nfev: int | None = None,
              tolerance: float = 1.0e-8, condition_limit: float = CONDITION_LIMIT,
              verbose: int = 0) -> CalibrationResult:
    """Fit scene parameters to a measured curve with ``scipy.optimize.least_squares``.

    Parameters
    ----------
    scene : Scene, f90nml.Namelist or path
        The scene: a :class:`~yarnfort.Scene`, a namelist (:func:`yarnfort.read_scene`)
        or a namelist file.
    measured : path or Measured
        The measured curve (see :func:`read_measured`).
    parameters : dict
        Address -> (initial, lower, upper): ``'contact[0].friction_coefficient'``,
        ``'contact[0].decay_start'``, ``'fabric.gap_factor[1]'`` (a knot value).
    support : str, optional
        Support whose reaction is compared (a clamp force); None compares a fabric's
        ``force_per_width``.
    component : {'x', 'y', 'z', 0, 1, 2}
        Reaction component compared (with ``support``).
    x_column, x_scale : str, float
        The simulated strain is ``x_scale * curve[x_column]`` (default column ``strain``
        for a fabric, else ``p_disp``).
    force_scale : float
        The simulated force is ``force_scale`` times the reaction (e.g. -1 for a pull
        along -y) or the force per width.
    width : float or str, optional
        Width of the measured sample, in m or with its unit (``'50 mm'``; a bare number
        above 1 is refused as a width in mm or cm), when the data are a force per sample
        and the model a force per width, or the reverse.
    strain_unit, force_unit : str, optional
        Units of columns whose header gives none (see :func:`read_measured`).
    errors : {'equal', 'relative'}
        The measurement errors' model: of equal variance (in the data's unit), or
        proportional to the measured force (each residual divided by the force, at
        least :data:`RELATIVE_FLOOR` times the largest).
    fixed : dict, optional
        Other parameters set for every run (e.g. a coarser ``solver.max_step``).
    diff_step : float
        Finite-difference step as a fraction of each parameter's range (lower, upper).
    max_nfev : int, optional
        Most residual evaluations (``least_squares``; finite-difference runs excluded).
    tolerance : float
        ``ftol``, ``xtol`` and ``gtol`` of ``least_squares``.
    condition_limit : float
        Condition number of the column-scaled Jacobian beyond which the fit counts as
        near-singular (default 1/sqrt(epsilon)).
    verbose : int
        ``least_squares`` verbosity.

    Returns
    -------
    CalibrationResult

    Raises
    ------
    ValueError
        For bounds with lower >= upper or an initial value outside them, fewer measured
        points than parameters plus one, a malformed parameter address or one of a
        group or variable the input does not have (an :class:`~yarnfort.AddressError`),
        an unknown component or support, an unreadable measured curve, a force per sample
        against a force per width without ``width``, data with more load cycles than the
        scene's path, or a branch of the data beyond the strains the path reaches at the
        initial values.
    YarnfortError
        If a run fails; the message names the parameter values.

    Warns
    -----
    IdentifiabilityWarning
        When a parameter is not identifiable (see the module notes).
    """
    started = time.perf_counter()
    width = sample_width(width)
    names = tuple(parameters)
    initial, lower, upper = (np.array([float(parameters[n][k]) for n in names])
                             for k in range(3))
    if np.any(lower >= upper) or np.any(initial < lower) or np.any(initial > upper):
        raise ValueError("each parameter needs lower < upper and initial within them")
    span = upper - lower
    index = _component_index(component)
    for name in (*names, *(fixed or {})):
        check_address(name)
    data = measured if isinstance(measured, Measured) else read_measured(
        measured, strain_unit=strain_unit, force_unit=force_unit)
    m, n = data.force.size, len(names)
    if m <= n:
        raise ValueError(f"{m} measured points cannot fit {n} parameters")
    target = data.force / data.force_factor  # in the data's unit
    if errors == "equal":
        weight = np.ones(m)
    elif errors == "relative":
        weight = 1.0 / np.maximum(np.abs(target), RELATIVE_FLOOR * np.max(np.abs(target)))
    else:
        raise ValueError(f"errors {errors!r}: expected 'equal' or 'relative'")
    runs = 0
    with _scene_file(scene) as scene_path:
        nml = f90nml.read(scene_path)
        if support is not None:
            _check_support(nml, support)
        elif "fabric" not in nml:
            raise ValueError("the scene has no &fabric (no force_per_width): name the "
                             "support whose reaction is compared (support=...)")
        to_data = _conversion(data, support is None, width)

        curves: dict[bytes, Curve] = {}  # the fit's own point is not run again

        def simulate(values: np.ndarray) -> Curve:
            nonlocal runs
            key = np.asarray(values, dtype=float).tobytes()
            if key in curves:
                return curves[key]
            runs += 1
            settings = dict(fixed or {})
            settings.update({name: float(v) for name, v in zip(names, values)})
            with tempfile.TemporaryDirectory(prefix="yarnfort-fit-") as folder:
                try:
                    curves[key] = run_patched(scene_path, settings, folder)
                    return curves[key]
                except YarnfortError as error:
                    raise YarnfortError(f"{error} (with {settings})",
                                        error.status) from error

        def model(curve: Curve) -> np.ndarray:
            return to_data * simulated_force(
                curve, data.strain, data.branch, support=support, component=index,
                x_column=x_column, x_scale=x_scale, force_scale=force_scale,
                segment=data.segment)

        def residual(z: np.ndarray) -> np.ndarray:
            return weight * (model(simulate(lower + span * z)) - target)

        # The data must lie on the branches the scene draws at the initial values: a
        # point beyond one would be compared with its end value (a strain column read in
        # the wrong unit, or a path shorter than the test).
        z0 = (initial - lower) / span
        start = simulate(lower + span * z0)  # the fit's first run, cached
        model(start)
        _check_coverage(start, data, support, index, x_column, x_scale, force_scale)
        fit = least_squares(residual, z0, bounds=(0.0, 1.0),
                            diff_step=diff_step, max_nfev=max_nfev, ftol=tolerance,
                            xtol=tolerance, gtol=tolerance, verbose=verbose)
        values = lower + span * fit.x
        curve = simulate(values)
        wide = _central_jacobian(residual, fit.x, CHECK_STEP_FACTOR * diff_step)
    ssr = float(fit.fun @ fit.fun)
    sigma2 = ssr / (m - n)
    fitted = model(curve)
    mismatch = _mismatch(fit.jac, wide)
    covariance, uncertainty, condition = _uncertainty(wide / span, sigma2, condition_limit)
    with np.errstate(divide="ignore", invalid="ignore"):
        correlation = covariance / np.outer(uncertainty, uncertainty)
    problems = _problems(names, values, uncertainty, correlation, condition,
                         condition_limit, fit.active_mask)
    problems += [f"{name}: the curve does not change smoothly with it (derivatives at "
                 f"steps {diff_step:g} and {CHECK_STEP_FACTOR * diff_step:g} of its range "
                 f"differ by {difference:.0%}), so the fit may sit on a step-to-step "
                 "ripple and the uncertainty is a rough guide (smaller load steps or "
                 "tighter solver tolerances may smooth the curve)"
                 for name, difference in zip(names, mismatch)
                 if difference > SMOOTHNESS_TOLERANCE]
    if problems:
        warnings.warn("calibration: " + "; ".join(problems), IdentifiabilityWarning,
                      stacklevel=2)
    x, force = _model_curve(curve, support, index, x_column, x_scale, force_scale)
    return CalibrationResult(
        names=names, values=values, uncertainty=uncertainty, covariance=covariance,
        correlation=correlation, condition_number=condition, derivative_mismatch=mismatch,
        problems=tuple(problems),
        residual_norm=float(np.linalg.norm(fitted - target)), sigma=float(np.sqrt(sigma2)),
        errors=errors, n_runs=runs,
        wall_time=time.perf_counter() - started, success=bool(fit.success),
        message=str(fit.message), measured=data, fitted_force=fitted,
        curve_strain=x, curve_force=to_data * force, curve_direction=curve["direction"],
        width=width if data.per_width != (support is None) else None)


def _force_label(measured: Measured, width: float | None) -> str:
    if measured.per_width:
        return f"force per width ({measured.force_unit})"
    sample = f" per sample {width * 1e3:.4g} mm wide" if width else ""
    return f"force{sample} ({measured.force_unit})"


def plot_fit(result: CalibrationResult, path: str | os.PathLike,
             title: str = "measured vs fitted") -> Path:
    """Plot the measured points (by cycle and branch) and the fitted simulated curve, in
    the data's units, to a file.

    Parameters
    ----------
    result : CalibrationResult
        The fit.
    path : path
        The image to write.
    title : str
        Title above the fitted values.

    Returns
    -------
    pathlib.Path
        The written image.
    """
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    data = result.measured
    to_unit = 1.0 / data.strain_factor
    fig, ax = plt.subplots(figsize=(6.4, 4.6))
    cycle = np.cumsum([s > 0 for s in data.signs]) if data.n_branches else []
    for k in range(data.n_branches):
        pick = data.segment == k
        sign = data.signs[k]
        label = f"data, cycle {max(int(cycle[k]), 1)} {'loading' if sign > 0 else 'unloading'}"
        ax.plot(to_unit * data.strain[pick], result.force[pick], "o" if sign > 0 else "s",
                ms=3.5, mfc="none", color=f"C{(int(cycle[k]) - 1) % 10 + 1}", label=label)
    ax.plot(to_unit * result.curve_strain, result.curve_force, "-", lw=1.3, color="C0",
            label="fitted model")
    fitted = ", ".join(f"{name.split('.')[-1]} = {v:.4g} ± {u:.2g}"
                       for name, (v, u) in result.parameters.items())
    ax.set_title(f"{title}\n{fitted}", fontsize=9)
    unit = data.strain_unit
    ax.set_xlabel("strain" if unit in ("1", "", "-") else f"strain ({unit})")
    ax.set_ylabel(_force_label(data, result.width))
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def write_synthetic_curve(scene: Any, values: Mapping[str, Any], path: str | os.PathLike,
                          *, support: str | None = None, component: str | int = "y",
                          x_column: str | None = None, x_scale: float = 1.0,
                          force_scale: float = 1.0, strain_unit: str = "1",
                          force_unit: str = "N", width: float | None = None,
                          noise: float = 0.01, seed: int = 0) -> Path:
    """Write a SYNTHETIC curve in the measured-curve format, for tests and examples.

    Runs the scene with ``values`` set, takes every converged step on a loading or
    unloading branch except the unloaded initial state, converts it to the units asked
    for and adds seeded Gaussian noise of standard deviation ``noise`` times each
    point's force. The file starts with ``#`` lines saying it is synthetic: it is not a
    measurement.

    Parameters
    ----------
    scene : Scene, f90nml.Namelist or path
        The scene.
    values : mapping
        Parameter address -> value of the "true" parameters.
    path : path
        The CSV to write.
    support, component, x_column, x_scale, force_scale
        As in :func:`calibrate`.
    strain_unit, force_unit : str
        Units of the written columns (in their headers), e.g. ``'%'`` and ``'cN'``.
    width : float or str, optional
        Sample width (m, or with its unit as in :func:`calibrate`), to write a fabric's
        force per width as a force per sample (or a support's force as a force per width).
    noise : float
        Relative standard deviation of the noise.
    seed : int
        Seed of the noise.

    Returns
    -------
    pathlib.Path
        The written CSV (columns strain, force, branch).
    """
    index = _component_index(component)
    width = sample_width(width)
    s_factor = strain_factor(strain_unit)
    f_factor, per_width = force_factor(force_unit)
    unit = Measured(np.zeros(0), np.zeros(0), np.zeros(0, int), np.zeros(0, int),
                    force_unit=force_unit, force_factor=f_factor, per_width=per_width)
    to_data = _conversion(unit, support is None, width)
    with _scene_file(scene) as scene_path, \
            tempfile.TemporaryDirectory(prefix="yarnfort-synthetic-") as folder:
        curve = run_patched(scene_path, values, folder)
        name = scene_path.name
    x, force = _model_curve(curve, support, index, x_column, x_scale, force_scale)
    rows = np.flatnonzero(curve["direction"] != 0)
    rows = rows[rows > 0]
    strain = x[rows] / s_factor
    force = to_data * force[rows]
    branch = np.where(curve["direction"][rows] < 0, "unloading", "loading")
    rng = np.random.default_rng(seed)
    noisy = force + noise * np.abs(force) * rng.standard_normal(force.size)
    path = Path(path)
    with open(path, "w", newline="") as stream:
        stream.write(f"# SYNTHETIC curve, not a measurement: generated by yarnfort from "
                     f"{name} with {dict(values)}"
                     + (f", sample width {width:g} m" if width else "") + "\n")
        stream.write(f"# plus Gaussian noise of {noise:g} x |force| (seed {seed})\n")
        writer = csv.writer(stream)
        writer.writerow([f"strain ({strain_unit})", f"force ({force_unit})", "branch"])
        writer.writerows(zip((f"{v:.10g}" for v in strain), (f"{v:.10g}" for v in noisy),
                             branch))
    return path
