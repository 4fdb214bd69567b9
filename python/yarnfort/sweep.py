# SPDX-License-Identifier: MIT
"""Parameter sweeps: run one scene for many parameter values, in parallel.

How runs are made
-----------------
Each run is the installed program (:func:`yarnfort.program_path`) started as a subprocess (not the in-process
f2py facade): one process per run keeps runs independent (no shared Fortran module
state), lets a run that crashes or hangs fail alone (a row with its error, or a
timeout), and parallelises the same way on local worker processes and on Dask workers.
A run costs a process start (milliseconds) on top of the solve. Each run gets
``OMP_NUM_THREADS=1`` unless the environment sets it (runs, not threads, share the cores).

For every run the scene is read with f90nml, patched (the swept parameters, an own
``&output`` folder, no progress lines) and written as ``input.nml`` into its own folder;
the program reads it on standard input with the caller's working directory as its own,
so relative file names of the scene (``table_file``, ``&geometry``) mean what they mean
for ``yarnfort < scene.nml`` and :func:`yarnfort.run_scene` run from there.

Parameter addresses
-------------------
The grammar of :mod:`yarnfort.address`: ``'solver.max_step'``,
``'contact[0].friction_coefficient'``, ``'support[pull].displacement'``. Addresses (their
form, and that the group and variable are input variables) and the summarised support
are checked before any run starts (:class:`ValueError`); a value the
program rejects gives a row with status ``'bad_input'`` and its message.

Dask
----
With ``scheduler='tcp://host:port'`` the tasks go through
``distributed.Client(scheduler).get_executor()``. Workers must have this package
installed and see the scene's files at the same paths (and working directory).
"""
from __future__ import annotations

import concurrent.futures as cf
import itertools
import os
import shutil
import subprocess
import sys
import tempfile
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import f90nml
import numpy as np

from ._native import YarnfortError
from ._program import program_path
from .address import AddressError, check_address, set_parameter
from .results import Curve, incomplete_reason, read_curve

__all__ = ["run_sweep", "run_patched", "parameter_grid"]

#: Seconds a single run may take before it is stopped and reported as failed.
DEFAULT_TIMEOUT = 600.0
#: Status of a row: success, failed solve (exit 1), bad input (exit 2), anything else.
STATUS = {0: "ok", 1: "solve_failed", 2: "bad_input"}

_COMPONENTS = {"x": 0, "y": 1, "z": 2}
#: Row key set when the summarised support is not in a run's curve.
_UNKNOWN_SUPPORT = "_unknown_support"


def _patched_text(scene: f90nml.Namelist, values: Mapping[str, Any], folder: Path,
                  vtk: bool) -> str:
    """The scene with ``values`` set and its output sent to ``folder``, as text."""
    patched = f90nml.reads(str(scene))  # an independent copy
    for address, value in values.items():
        try:
            set_parameter(patched, address, value)
        except AddressError as error:
            raise ValueError(str(error)) from None
    set_parameter(patched, "output.folder", str(folder))
    set_parameter(patched, "output.progress", False)
    if not vtk:
        set_parameter(patched, "output.vtk_every", 0)
    return str(patched) + "\n"


@dataclass(frozen=True)
class _Task:
    """One run, self-contained and picklable (sent to worker processes)."""

    program: str | None  # None: the worker's own installation
    cwd: str
    text: str
    folder: str | None
    support: str
    component: int | None
    timeout: float | None


def _summary(curve: Curve, support: str, component: int | None) -> tuple[float, float]:
    force = curve.reaction(support)
    value = np.linalg.norm(force, axis=1) if component is None else force[:, component]
    return float(value[-1]), float(value[np.argmax(np.abs(value))])


def _stamp(path: Path) -> tuple[int, int, int] | None:
    """Identity of a file (inode, modification time, size), None if there is none: the
    program writes curve.csv as a new file, so a run that wrote one changes it."""
    try:
        info = path.stat()
    except OSError:
        return None
    return info.st_ino, info.st_mtime_ns, info.st_size


def _execute(task: _Task) -> dict[str, Any]:
    """Run one task and summarise it; never raises (errors become the row's message)."""
    start = time.perf_counter()
    row: dict[str, Any] = {"status": "error", "error": "", "n_steps": 0,
                           "final_reaction": np.nan, "max_reaction": np.nan}
    owned = task.folder is None
    folder = Path(tempfile.mkdtemp(prefix="yarnfort-run-")) if owned else Path(task.folder)
    try:
        folder.mkdir(parents=True, exist_ok=True)
        text = task.text.replace("@FOLDER@", str(folder / "out"))
        (folder / "input.nml").write_text(text)
        curve_file = folder / "out" / "curve.csv"
        before = _stamp(curve_file)  # a kept work_dir may hold an earlier sweep's curve
        env = dict(os.environ)
        env.setdefault("OMP_NUM_THREADS", "1")  # one core per run: runs are the parallelism
        program = task.program or str(program_path())
        proc = subprocess.run([program], input=text, capture_output=True, text=True,
                              cwd=task.cwd, timeout=task.timeout, env=env)
        row["status"] = STATUS.get(proc.returncode, "error")
        if proc.returncode != 0:
            lines = [ln for ln in proc.stderr.strip().splitlines() if ln.strip()]
            row["error"] = lines[-1] if lines else f"exit code {proc.returncode}"
        # Exit 2 writes nothing, and a curve this run did not replace is an earlier one.
        if proc.returncode != 2 and curve_file.is_file() and _stamp(curve_file) != before:
            curve = read_curve(curve_file)
            row["n_steps"] = len(curve["step"])
            known = [name[:-3] for name in curve.names if name.endswith("_rx")]
            if proc.returncode == 0 and task.support not in known:
                # Only a generated &fabric names supports the scene file does not list.
                row["status"] = "error"
                row["error"] = (f"support {task.support!r} is not in the curve; supports: "
                                + ", ".join(known))
                row[_UNKNOWN_SUPPORT] = known
            elif proc.returncode == 0:
                row["final_reaction"], row["max_reaction"] = _summary(
                    curve, task.support, task.component)
                # Exit 0 also ends a run at &control max_steps: its last step is not
                # the path's end.
                if reason := incomplete_reason(curve_file.parent, curve):
                    row["status"], row["error"] = "max_steps", reason
    except subprocess.TimeoutExpired:
        row["status"], row["error"] = "error", f"timed out after {task.timeout} s"
    except Exception as error:  # noqa: BLE001 - a row reports any failure of its run
        row["status"], row["error"] = "error", f"{type(error).__name__}: {error}"
    finally:
        if owned:
            shutil.rmtree(folder, ignore_errors=True)
    row["wall_time"] = time.perf_counter() - start
    return row


def run_patched(scene_path: str | os.PathLike, values: Mapping[str, Any],
                folder: str | os.PathLike, *, timeout: float | None = DEFAULT_TIMEOUT,
                vtk: bool = False) -> Curve:
    """Run the scene once with some parameters changed and return its curve.

    Parameters
    ----------
    scene_path : path
        The namelist file of the scene.
    values : mapping
        Parameter address -> value (see the module notes).
    folder : path
        Folder for ``input.nml`` and the output folder ``out/``.
    timeout : float or None
        Seconds before the run is stopped.
    vtk : bool
        Also write the VTK states.

    Returns
    -------
    Curve
        The run's ``curve.csv``.

    Raises
    ------
    YarnfortError
        If the program fails (status 1 failed solve, 2 bad input; the message is the
        program's), or stops before the end of the load path (status 1: ``&control
        max_steps``).
    """
    scene = f90nml.read(Path(scene_path))
    folder = Path(folder).resolve()
    text = _patched_text(scene, values, folder / "out", vtk)
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "input.nml").write_text(text)
    try:
        proc = subprocess.run([str(program_path())], input=text, capture_output=True,
                              text=True, cwd=os.getcwd(), timeout=timeout)
    except subprocess.TimeoutExpired as error:
        raise YarnfortError(f"timed out after {timeout} s", 1) from error
    if proc.returncode != 0:
        lines = [ln for ln in proc.stderr.strip().splitlines() if ln.strip()]
        raise YarnfortError(lines[-1] if lines else f"exit code {proc.returncode}",
                            proc.returncode)
    curve = read_curve(folder / "out")
    # Exit 0 also ends a run at &control max_steps: a fit would compare a cut curve.
    if reason := incomplete_reason(folder / "out", curve):
        raise YarnfortError(f"{reason} (&control max_steps in the scene?)", 1)
    return curve


def parameter_grid(parameters: Mapping[str, Sequence[Any]] | Sequence[Mapping[str, Any]]
                   ) -> list[dict[str, Any]]:
    """The runs of a sweep.

    Parameters
    ----------
    parameters : dict of lists, or list of dicts
        Address -> values (every combination; the first key varies slowest), or an
        explicit list of runs.

    Returns
    -------
    list of dict
        One dict address -> value per run.

    Raises
    ------
    TypeError
        If the values of an address are a string (not a list of values).
    """
    if isinstance(parameters, Mapping):
        names = list(parameters)
        for name in names:
            # A string is a sequence too: 'table' would be swept as 't', 'a', 'b', ...
            if isinstance(parameters[name], (str, bytes)):
                raise TypeError(f"{name!r}: expected a list of values, got the string"
                                f" {parameters[name]!r} (for one value: [{parameters[name]!r}])")
        return [dict(zip(names, combo))
                for combo in itertools.product(*(list(parameters[n]) for n in names))]
    return [dict(values) for values in parameters]


def _column(values: list[Any]) -> np.ndarray:
    try:
        column = np.array(values)
    except ValueError:
        column = np.empty(len(values), dtype=object)
        column[:] = values
    return column if column.ndim == 1 else np.array(values, dtype=object)


def _support_names(scene: f90nml.Namelist) -> list[str]:
    """Names of the reaction sets: the &support groups, then the &obstacle groups (an
    obstacle holds its nodes and reports its reaction like a support)."""
    names: list[str] = []
    for key in ("support", "obstacle"):
        groups = scene.get(key)
        if groups is None:
            continue
        groups = [groups] if isinstance(groups, f90nml.Namelist) else list(groups)
        names += [str(group["name"]) for group in groups if "name" in group]
    return names


def _moving_support(scene: f90nml.Namelist) -> str | None:
    """The first ``&support`` with a nonzero prescribed displacement, or None."""
    groups = scene.get("support")
    groups = [] if groups is None else (
        [groups] if isinstance(groups, f90nml.Namelist) else list(groups))
    for group in groups:
        values = [0.0 if v is None else float(v)
                  for v in np.atleast_1d(group.get("displacement", [0.0]))]
        if "name" in group and any(v != 0.0 for v in values):
            return str(group["name"])
    return None


def _check_support(scene: f90nml.Namelist, support: str | None) -> str:
    """The support to summarise: checked against the scene's ``&support`` names (a
    generated ``&fabric`` names its own, which are checked on the first curve). By
    default the first that moves, as ``plot`` draws: the first listed is often a fixed
    end, whose reaction is not the force that drives the run."""
    names = _support_names(scene)
    if support is None:
        if not names:
            raise ValueError("the scene has no &support: name the support whose reaction"
                             " is summarised (support=...)")
        return _moving_support(scene) or names[0]
    if names and "fabric" not in scene and support not in names:
        raise ValueError(f"support {support!r}: the scene's supports are "
                         + ", ".join(names))
    return support


class _Progress:
    """tqdm on stderr when installed, else a plain counter line."""

    def __init__(self, total: int, enabled: bool) -> None:
        self.total, self.done, self.enabled, self.bar = total, 0, enabled, None
        if enabled:
            try:
                from tqdm import tqdm
                self.bar = tqdm(total=total, desc="yarnfort sweep", unit="run",
                                file=sys.stderr)
            except ImportError:
                pass

    def update(self) -> None:
        self.done += 1
        if self.bar is not None:
            self.bar.update(1)
        elif self.enabled:
            end = "\n" if self.done == self.total else ""
            print(f"\ryarnfort sweep: {self.done}/{self.total} runs", end=end,
                  file=sys.stderr, flush=True)

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()


def _run_tasks(tasks: list[_Task], executor: cf.Executor, progress: _Progress
               ) -> list[dict[str, Any]]:
    futures = {executor.submit(_execute, task): i for i, task in enumerate(tasks)}
    rows: list[dict[str, Any]] = [{} for _ in tasks]
    for future in cf.as_completed(futures):
        i = futures[future]
        try:
            rows[i] = future.result()
        except Exception as error:  # noqa: BLE001 - e.g. a lost worker
            rows[i] = {"status": "error", "error": f"{type(error).__name__}: {error}",
                       "n_steps": 0, "final_reaction": np.nan, "max_reaction": np.nan,
                       "wall_time": np.nan}
        progress.update()
    return rows


def run_sweep(scene_path: str | os.PathLike,
              parameters: Mapping[str, Sequence[Any]] | Sequence[Mapping[str, Any]], *,
              workers: int | None = None, scheduler: str | None = None,
              progress: bool = True, support: str | None = None,
              component: str | int | None = None, work_dir: str | os.PathLike | None = None,
              timeout: float | None = DEFAULT_TIMEOUT, vtk: bool = False
              ) -> dict[str, np.ndarray]:
    """Run a scene for each parameter combination and tabulate the outcomes.

    Parameters
    ----------
    scene_path : path
        The namelist file of the scene.
    parameters : dict of lists, or list of dicts
        Address -> values: every combination is run (grid, first key slowest). Or an
        explicit list of runs, each a dict address -> value (same keys in each).
    workers : int, optional
        Local worker processes (default: the CPU count). Ignored with ``scheduler``.
    scheduler : str, optional
        Address of a Dask distributed scheduler (``'tcp://host:port'``): run there.
    progress : bool
        Show a progress bar on stderr.
    support : str, optional
        Support set whose reaction is summarised (default: the scene's first &support
        with a nonzero displacement, else its first &support; the ``support`` column
        names it).
    component : {'x', 'y', 'z', 0, 1, 2}, optional
        Reaction component summarised; default the magnitude |R|.
    work_dir : path, optional
        Keep each run's ``input.nml`` and ``out/`` in ``work_dir/run_NNNNN``; by default
        each run uses a temporary folder removed afterwards.
    timeout : float or None
        Seconds a run may take before it is stopped and reported as failed.
    vtk : bool
        Write the VTK states too (off by default: the table needs only the curve).

    Returns
    -------
    dict of str to numpy.ndarray
        One entry per run, in the order of the runs: a column per parameter address, and
        ``status`` (``'ok'``, ``'max_steps'`` (stopped before the path's end by
        ``&control max_steps``; its reactions are those of its last step),
        ``'solve_failed'``, ``'bad_input'`` or ``'error'``),
        ``error`` (the program's message, ``''`` when ok), ``n_steps`` (converged steps
        written, initial state included), ``final_reaction`` and ``max_reaction`` (the
        summarised reaction at the last step and the one of largest magnitude, N; NaN for
        a failed run), ``support`` (the set summarised), ``wall_time`` (s, per run,
        process start included).

    Raises
    ------
    ValueError
        For a malformed parameter address or one of a group or variable the input does
        not have, or a value of ``output.folder``, ``output.progress`` or (without
        ``vtk``) ``output.vtk_every`` other than the sweep sets; an unknown component, or a
        support the scene does not have (checked before any run against its ``&support``
        groups; for a generated ``&fabric``, on the runs' curves); the program's failures
        do not raise (they are rows).
    FileNotFoundError
        If the installation has no program.
    """
    scene = f90nml.read(Path(scene_path))
    runs = parameter_grid(parameters)
    names = list(dict.fromkeys(name for run in runs for name in run))
    for name in names:
        try:
            where = check_address(name)
        except AddressError as error:
            raise ValueError(str(error)) from None
        # The sweep sets these for every run: a swept value other than its own would be
        # overwritten (every folder is: the sentinel equals no value).
        own = {"folder": object(), "progress": False, "vtk_every": 0}
        if (where.group == "output" and where.variable in own
                and not (where.variable == "vtk_every" and vtk)
                and any(name in run and run[name] != own[where.variable] for run in runs)):
            raise ValueError(f"{name!r}: the sweep sets &output {where.variable} of every"
                             " run itself (its own folder, no progress lines, vtk_every ="
                             " 0 unless vtk=True)")
    support = _check_support(scene, support)
    if isinstance(component, str):
        if component.lower() not in _COMPONENTS:
            raise ValueError(f"component {component!r}: expected 'x', 'y' or 'z'")
        component = _COMPONENTS[component.lower()]
    elif component is not None and component not in (0, 1, 2):
        raise ValueError(f"component {component!r}: expected 0, 1 or 2")
    program = None if scheduler is not None else str(program_path())
    cwd = os.getcwd()
    tasks = []
    for i, run in enumerate(runs):
        folder = None if work_dir is None else str(Path(work_dir).resolve() / f"run_{i:05d}")
        text = _patched_text(scene, run, Path("@FOLDER@"), vtk)
        tasks.append(_Task(program, cwd, text, folder, support, component, timeout))
    bar = _Progress(len(tasks), progress)
    try:
        if scheduler is not None:
            from ._extras import import_extra

            distributed = import_extra("distributed", "dask", "run_sweep(scheduler=...)")
            with distributed.Client(scheduler) as client:
                rows = _run_tasks(tasks, client.get_executor(), bar)
        else:
            with cf.ProcessPoolExecutor(max_workers=workers) as executor:
                rows = _run_tasks(tasks, executor, bar)
    finally:
        bar.close()
    unknown = next((row[_UNKNOWN_SUPPORT] for row in rows if _UNKNOWN_SUPPORT in row), None)
    if unknown is not None:
        raise ValueError(f"support {support!r}: the scene's runs have supports "
                         + ", ".join(unknown))
    table = {name: _column([run.get(name) for run in runs]) for name in names}
    for key in ("status", "error", "n_steps", "final_reaction", "max_reaction",
                "wall_time"):
        table[key] = np.array([row[key] for row in rows])
    table["support"] = np.array([support] * len(rows))
    return table
