# SPDX-License-Identifier: MIT
"""Fit scene parameters to a measured force–strain curve (nonlinear least squares).

The residual is simulated minus measured force at the measured points. The simulated
curve (a reaction component of one support set against a load factor column) is split
into its loading and unloading branches by the ``direction`` column of ``curve.csv`` and
each measured point is interpolated linearly on the branch it belongs to, so a hysteresis
loop is matched branch by branch. Points beyond the simulated range take the branch's end
value. One load cycle (load, then release) is assumed.

Each residual evaluation is one run of the program (see :mod:`yarnfort.sweep`); the
Jacobian is by forward differences (``scipy.optimize.least_squares`` default) on the
parameters mapped to [0, 1] over their bounds, so ``diff_step`` is a fraction of each
parameter's range. Standard uncertainties are ``sqrt(diag(sigma^2 (J^T J)^-1))`` with
``sigma^2 = SSR / (m - n)`` (m points, n parameters): they assume independent errors of
equal variance and a model that fits.
"""
from __future__ import annotations

import csv
import os
import tempfile
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import f90nml
import numpy as np
from scipy.optimize import least_squares

from ._native import YarnfortError
from .results import Curve
from .address import parse_address
from .sweep import _check_support, run_patched
from .units import split_header, to_scene_unit

__all__ = ["CalibrationResult", "calibrate", "read_measured", "simulated_force",
           "plot_fit", "write_synthetic_curve"]

#: Default finite-difference step, as a fraction of each parameter's range.
DIFF_STEP = 1.0e-3
#: Names accepted for the branch column of a measured CSV.
BRANCH_COLUMNS = ("branch", "direction", "sign")
_COMPONENTS = {"x": 0, "y": 1, "z": 2}


@dataclass
class CalibrationResult:
    """Outcome of :func:`calibrate`.

    Attributes
    ----------
    names : tuple of str
        Parameter addresses, in the order of ``values``.
    values, uncertainty : numpy.ndarray
        Fitted values and their standard uncertainties.
    covariance : numpy.ndarray
        Covariance of the fitted values, sigma^2 (J^T J)^-1.
    residual_norm : float
        Euclidean norm of the residual at the fit, sqrt(SSR) (N).
    sigma : float
        Residual standard deviation sqrt(SSR / (m - n)) (N).
    n_runs : int
        Program runs made (the finite-difference runs included).
    success : bool
        ``least_squares`` reports convergence.
    message : str
        ``least_squares``'s message.
    strain, force, branch : numpy.ndarray
        The measured points; branch is +1 loading, -1 unloading.
    fitted_force : numpy.ndarray
        Simulated force at the measured points, with the fitted values.
    curve_strain, curve_force, curve_direction : numpy.ndarray
        The whole simulated curve with the fitted values.
    """

    names: tuple[str, ...]
    values: np.ndarray
    uncertainty: np.ndarray
    covariance: np.ndarray
    residual_norm: float
    sigma: float
    n_runs: int
    success: bool
    message: str
    strain: np.ndarray
    force: np.ndarray
    branch: np.ndarray
    fitted_force: np.ndarray
    curve_strain: np.ndarray
    curve_force: np.ndarray
    curve_direction: np.ndarray

    @property
    def parameters(self) -> dict[str, tuple[float, float]]:
        """Address -> (fitted value, standard uncertainty)."""
        return {name: (float(v), float(u))
                for name, v, u in zip(self.names, self.values, self.uncertainty)}

    def summary(self) -> str:
        """The fitted values with uncertainties, one line each, and the residual."""
        lines = [f"{name} = {v:.6g} ± {u:.2g}" for name, (v, u) in self.parameters.items()]
        lines.append(f"residual norm {self.residual_norm:.4g} N, sigma {self.sigma:.3g} N, "
                     f"{len(self.force)} points, {self.n_runs} runs")
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


def read_measured(path: str | os.PathLike) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Read a measured curve: CSV with a header, columns ``strain`` and ``force`` and
    optionally a branch column (``branch``: loading/unloading, or ``direction``/``sign``:
    +1/-1). Without one, the branch follows the sign of the strain increments. Lines
    starting with ``#`` are comments. A column header may state its unit as in a table
    file (``strain (%)``, ``force (cN)``; :mod:`yarnfort.units`): the values are
    converted to 1 and N; without one they are taken as 1 and N.

    Parameters
    ----------
    path : path
        The CSV file.

    Returns
    -------
    strain, force, branch : numpy.ndarray
        The points, branch +1 loading and -1 unloading.

    Raises
    ------
    ValueError
        For a file without data rows or the columns, a cell that is not a number (the
        message names the file and line), or an unknown unit (it names the column).
    """
    with open(path, newline="") as stream:
        numbered = [(number, line) for number, line in enumerate(stream, start=1)
                    if not line.startswith("#")]
    reader = csv.DictReader(line for _, line in numbered)
    rows = list(reader)
    # The file line of each data row (the header is the first uncommented line).
    lines = [number for number, line in numbered[1:] if line.strip()]
    if not rows:
        raise ValueError(f"{path}: no data rows")
    header = {split_header(name)[0].lower(): name for name in rows[0]}
    missing = [name for name in ("strain", "force") if name not in header]
    if missing:
        raise ValueError(f"{path}: missing column(s) {', '.join(missing)}")
    units = {name: split_header(header[name])[1] or default
             for name, default in (("strain", "1"), ("force", "N"))}
    column = next((header[name] for name in BRANCH_COLUMNS if name in header), None)
    strain, force, signs = [], [], []
    for number, row in zip(lines, rows):
        try:
            strain.append(_number(row[header["strain"]], "strain"))
            force.append(_number(row[header["force"]], "force"))
            if column is not None:
                signs.append(_branch_value(row[column] or ""))
        except ValueError as error:
            raise ValueError(f"{path}, line {number}: {error}") from None
    try:
        strain_array = to_scene_unit(np.array(strain), units["strain"], "strain")
        force_array = to_scene_unit(np.array(force), units["force"], "force")
    except ValueError as error:
        raise ValueError(f"{path}: {error}") from None
    branch = _infer_branch(strain_array) if column is None else np.array(signs)
    return strain_array, force_array, branch


def _number(text: str | None, name: str) -> float:
    """A finite number from a CSV cell, or a ValueError naming the column."""
    try:
        value = float(text if text is not None else "")
    except ValueError:
        raise ValueError(f"{name} {text!r} is not a number") from None
    if not np.isfinite(value):
        raise ValueError(f"{name} {text!r} is not finite")
    return value


def _branch_rows(direction: np.ndarray, sign: int) -> np.ndarray:
    """Rows of the simulated branch: loading is direction >= 0 (the initial state
    included); unloading is direction < 0 plus the turning point before it."""
    if sign > 0:
        return np.flatnonzero(direction >= 0)
    rows = np.flatnonzero(direction < 0)
    starts = rows[(rows > 0) & (direction[np.maximum(rows - 1, 0)] >= 0)]
    return np.union1d(rows, starts - 1)


def simulated_force(curve: Curve, strain: np.ndarray, branch: np.ndarray, *,
                    support: str, component: int, x_column: str = "p_disp",
                    x_scale: float = 1.0, force_scale: float = 1.0
                    ) -> np.ndarray:
    """The simulated force at measured points, interpolated on the matching branch.

    Parameters
    ----------
    curve : Curve
        The simulated curve.
    strain, branch : numpy.ndarray
        Measured strains and their branches (+1 loading, -1 unloading).
    support : str
        Support set whose reaction is the force.
    component : int
        Reaction component (0, 1, 2 for x, y, z).
    x_column, x_scale : str, float
        The simulated strain is ``x_scale * curve[x_column]``.
    force_scale : float
        The simulated force is ``force_scale * reaction`` (e.g. -1 for a pull along -y).
    """
    x = x_scale * curve[x_column]
    force = force_scale * curve.reaction(support)[:, component]
    direction = curve["direction"]
    result = np.empty_like(strain, dtype=float)
    for sign in (1, -1):
        wanted = branch == sign
        if not wanted.any():
            continue
        rows = _branch_rows(direction, sign)
        if rows.size < 2:
            rows = np.arange(x.size)
        order = np.argsort(x[rows], kind="stable")
        result[wanted] = np.interp(strain[wanted], x[rows][order], force[rows][order])
    return result


def calibrate(scene_path: str | os.PathLike, measured_csv: str | os.PathLike,
              parameters: Mapping[str, tuple[float, float, float]], *, support: str,
              component: str | int = "y", x_column: str = "p_disp", x_scale: float = 1.0,
              force_scale: float = 1.0, fixed: Mapping[str, Any] | None = None,
              diff_step: float = DIFF_STEP, max_nfev: int | None = None,
              tolerance: float = 1.0e-8, verbose: int = 0) -> CalibrationResult:
    """Fit scene parameters to a measured curve with ``scipy.optimize.least_squares``.

    Parameters
    ----------
    scene_path : path
        The namelist file of the scene.
    measured_csv : path
        The measured curve (see :func:`read_measured`).
    parameters : dict
        Address (``'contact[0].friction_coefficient'``) -> (initial, lower, upper).
    support : str
        Support set whose reaction is compared with the measured force.
    component : {'x', 'y', 'z', 0, 1, 2}
        Reaction component compared.
    x_column, x_scale : str, float
        The simulated strain is ``x_scale * curve[x_column]``.
    force_scale : float
        The simulated force is ``force_scale * reaction``.
    fixed : dict, optional
        Other parameters set for every run (e.g. a coarser ``solver.max_step``).
    diff_step : float
        Finite-difference step as a fraction of each parameter's range (lower, upper).
    max_nfev : int, optional
        Most residual evaluations (``least_squares``; finite-difference runs excluded).
    tolerance : float
        ``ftol``, ``xtol`` and ``gtol`` of ``least_squares``.
    verbose : int
        ``least_squares`` verbosity.

    Returns
    -------
    CalibrationResult

    Raises
    ------
    ValueError
        For bounds with lower >= upper or an initial value outside them, fewer measured
        points than parameters plus one, a malformed parameter address (an
        :class:`~yarnfort.AddressError`), an unknown component or support, or an
        unreadable measured curve.
    YarnfortError
        If a run fails; the message names the parameter values.
    """
    names = tuple(parameters)
    initial, lower, upper = (np.array([float(parameters[n][k]) for n in names])
                             for k in range(3))
    if np.any(lower >= upper) or np.any(initial < lower) or np.any(initial > upper):
        raise ValueError("each parameter needs lower < upper and initial within them")
    span = upper - lower
    index = _component_index(component)
    for name in names:
        parse_address(name)
    _check_support(f90nml.read(Path(scene_path)), support)
    strain, force, branch = read_measured(measured_csv)
    m, n = force.size, len(names)
    if m <= n:
        raise ValueError(f"{m} measured points cannot fit {n} parameters")
    runs = 0

    def simulate(values: np.ndarray) -> Curve:
        nonlocal runs
        runs += 1
        settings = dict(fixed or {})
        settings.update({name: float(v) for name, v in zip(names, values)})
        with tempfile.TemporaryDirectory(prefix="yarnfort-fit-") as folder:
            try:
                return run_patched(scene_path, settings, folder)
            except YarnfortError as error:
                raise YarnfortError(f"{error} (with {settings})", error.status) from error

    def model(curve: Curve) -> np.ndarray:
        if f"{support}_rx" not in curve.columns:
            known = [name[:-3] for name in curve.names if name.endswith("_rx")]
            raise ValueError(f"support {support!r}: the scene's curve has supports "
                             + (", ".join(known) or "none"))
        return simulated_force(curve, strain, branch, support=support, component=index,
                               x_column=x_column, x_scale=x_scale, force_scale=force_scale)

    def residual(z: np.ndarray) -> np.ndarray:
        return model(simulate(lower + span * z)) - force

    fit = least_squares(residual, (initial - lower) / span, bounds=(0.0, 1.0),
                        diff_step=diff_step, max_nfev=max_nfev, ftol=tolerance,
                        xtol=tolerance, gtol=tolerance, verbose=verbose)
    values = lower + span * fit.x
    ssr = float(fit.fun @ fit.fun)
    sigma2 = ssr / (m - n)
    jac = fit.jac / span  # d residual / d parameter
    covariance = sigma2 * np.linalg.pinv(jac.T @ jac)
    curve = simulate(values)
    return CalibrationResult(
        names=names, values=values, uncertainty=np.sqrt(np.diag(covariance)),
        covariance=covariance, residual_norm=float(np.sqrt(ssr)),
        sigma=float(np.sqrt(sigma2)), n_runs=runs, success=bool(fit.success),
        message=str(fit.message), strain=strain, force=force, branch=branch,
        fitted_force=model(curve), curve_strain=x_scale * curve[x_column],
        curve_force=force_scale * curve.reaction(support)[:, index],
        curve_direction=curve["direction"])


def plot_fit(result: CalibrationResult, path: str | os.PathLike,
             title: str = "measured vs fitted") -> Path:
    """Plot the measured points (by branch) and the fitted simulated curve to a file.

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

    fig, ax = plt.subplots(figsize=(6.4, 4.4))
    for sign, label, marker in ((1, "loading", "o"), (-1, "unloading", "s")):
        pick = result.branch == sign
        if pick.any():
            ax.plot(result.strain[pick], result.force[pick], marker, ms=4, mfc="none",
                    label=f"data ({label})")
    ax.plot(result.curve_strain, result.curve_force, "-", lw=1.5, label="fitted model")
    fitted = ", ".join(f"{name.split('.')[-1]} = {v:.4g} ± {u:.2g}"
                       for name, (v, u) in result.parameters.items())
    ax.set_title(f"{title}\n{fitted}", fontsize=9)
    ax.set_xlabel("strain")
    ax.set_ylabel("force (N)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    path = Path(path)
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def write_synthetic_curve(scene_path: str | os.PathLike, values: Mapping[str, Any],
                          path: str | os.PathLike, *, support: str,
                          component: str | int = "y", x_column: str = "p_disp",
                          x_scale: float = 1.0, force_scale: float = 1.0,
                          noise: float = 0.01, seed: int = 0) -> Path:
    """Write a SYNTHETIC curve in the measured-curve format, for tests and examples.

    Runs the scene with ``values`` set, takes every converged step except the unloaded
    initial state, and adds seeded Gaussian noise of standard deviation ``noise`` times
    each point's force. The file starts with ``#`` lines saying it is synthetic: it is
    not a measurement.

    Parameters
    ----------
    scene_path : path
        The scene.
    values : mapping
        Parameter address -> value of the "true" parameters.
    path : path
        The CSV to write.
    support, component, x_column, x_scale, force_scale
        As in :func:`calibrate`.
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
    with tempfile.TemporaryDirectory(prefix="yarnfort-synthetic-") as folder:
        curve = run_patched(scene_path, values, folder)
    strain = x_scale * curve[x_column][1:]
    force = force_scale * curve.reaction(support)[1:, index]
    branch = np.where(curve["direction"][1:] < 0, "unloading", "loading")
    rng = np.random.default_rng(seed)
    noisy = force + noise * np.abs(force) * rng.standard_normal(force.size)
    path = Path(path)
    with open(path, "w", newline="") as stream:
        stream.write(f"# SYNTHETIC curve, not a measurement: generated by yarnfort from "
                     f"{Path(scene_path).name} with {dict(values)}\n")
        stream.write(f"# plus Gaussian noise of {noise:g} x |force| (seed {seed})\n")
        writer = csv.writer(stream)
        writer.writerow(["strain", "force", "branch"])
        writer.writerows(zip((f"{v:.10g}" for v in strain), (f"{v:.10g}" for v in noisy),
                             branch))
    return path
