# SPDX-License-Identifier: MIT
"""Run a scene in process, as the program does, with progress and a clean Ctrl-C.

:func:`run_scene` runs a namelist file (or a :class:`yarnfort.Scene`) through the
library in this Python process. It behaves as ``yarnfort < scene.nml`` run from the
current working directory: the same output files, relative file names in the scene
(tables, geometry files, the ``&output`` folder) taken from the working directory,
``&control restart`` and ``max_steps`` honoured, and the same exit categories (a
:class:`~yarnfort.YarnfortError` with ``status`` 2 for bad input, 1 for a failed solve).

Progress: after every converged step, once its files are written, a call-back gets a
:class:`Step`; ``progress=True`` shows a :mod:`tqdm` bar (``tqdm.auto``: a widget in
Jupyter) over the load path's pseudo-time. Ctrl-C (SIGINT) during the run stops it
within a Newton iteration (the solver polls for it): the step being solved is abandoned,
every converged step before it is complete on disk (curve rows, VTK states,
``restart.dat``), and :class:`RunInterrupted` (a :class:`KeyboardInterrupt`) is raised
with the :class:`RunResult` and a message naming the last converged step and its load;
the run can go on with ``&control restart = .true.``. (Run from a thread other than the
main one, Ctrl-C is not caught: Python delivers it to the main thread.)
"""
from __future__ import annotations

import os
import tempfile
import threading
import warnings
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from ._native import check_status, extension
from .results import Curve, State, read_curve, read_states

__all__ = ["run_scene", "RunResult", "RunInterrupted", "Step", "OUTCOMES"]

#: The facade's outcome codes of a run that did not fail.
OUTCOMES: dict[int, str] = {0: "done", 1: "max_steps", 2: "stopped", 3: "interrupted"}


@dataclass(frozen=True)
class Step:
    """A converged step, as reported to a progress call-back.

    Attributes
    ----------
    step : int
        Step number (0: the initial equilibrium).
    time, time_start, time_end : float
        Pseudo-time of the step, and of the load path's first and last knots.
    p_force, p_disp : float
        Load factors at the step: of the channels ``p_force`` and ``p_disp``, or with
        ``&path channels`` of the first two channels (0 for a channel the path lacks).
    iterations : int
        Newton iterations of the step.
    residual : float
        Final scaled residual.
    n_slipping, n_passages : int
        Passages slipping, and in all.
    wall_time : float
        Seconds spent on the step.
    """

    step: int
    time: float
    time_start: float
    time_end: float
    p_force: float
    p_disp: float
    iterations: int
    residual: float
    n_slipping: int
    n_passages: int
    wall_time: float

    @property
    def fraction(self) -> float:
        """Fraction of the load path's pseudo-time done, in [0, 1]."""
        span = self.time_end - self.time_start
        return 1.0 if span <= 0 else min(max((self.time - self.time_start) / span, 0.0), 1.0)


@dataclass
class RunResult:
    """What a run wrote.

    Attributes
    ----------
    folder : pathlib.Path
        The output folder (absolute).
    n_steps : int
        Converged steps written by this run (rows it added to ``curve.csv``; step 0
        included unless it continued a restart).
    outcome : str
        ``'done'`` (the load path's end reached), ``'max_steps'`` (stopped by
        ``&control max_steps``), ``'stopped'`` (stopped by the call-back),
        ``'interrupted'`` (Ctrl-C) or ``'failed'`` (a failed solve; see
        :class:`~yarnfort.YarnfortError`); ``'read'`` for a folder read by
        :func:`~yarnfort.read_run`, ``'incomplete'`` for one whose curve ends before its
        load path does.
    """

    folder: Path
    n_steps: int
    outcome: str

    @property
    def curve(self) -> Curve:
        """The folder's ``curve.csv`` (every row, those of earlier pieces of a
        restarted run included)."""
        return read_curve(self.folder)

    @property
    def states(self) -> list[State]:
        """The folder's VTK states, in step order."""
        return read_states(self.folder)

    def to_dataframe(self) -> Any:
        """The curve as a :class:`pandas.DataFrame` (pandas must be installed)."""
        return self.curve.to_dataframe()


class RunInterrupted(KeyboardInterrupt):
    """Ctrl-C stopped a run at a step boundary (the step being solved is abandoned);
    ``result`` describes what was kept, ``detail`` the library's account of it (the step
    abandoned, the last converged step and its load)."""

    def __init__(self, result: RunResult, detail: str = "") -> None:
        where = f"{detail}; " if detail else ""
        if detail and "nothing is kept" in detail:
            advice = "run the scene again to start over"
        else:
            advice = (f"results so far in {result.folder}; to go on from the last converged"
                      " step, run the same scene with &control restart = .true.")
        super().__init__(f"run interrupted after {result.n_steps} converged steps of this"
                         f" run: {where}{advice}")
        self.result = result
        self.detail = detail


class _TqdmProgress:
    """A tqdm bar over the percentage of the load path done."""

    def __init__(self) -> None:
        from tqdm.auto import tqdm

        self.bar = tqdm(total=100.0, unit="%", desc="yarnfort",
                        bar_format="{l_bar}{bar}| {n:.0f}/{total:.0f}% [{elapsed}{postfix}]")

    def __call__(self, step: Step) -> None:
        self.bar.n = round(100.0 * step.fraction, 3)
        postfix = {"step": step.step, "newton": step.iterations}
        if step.n_passages:
            postfix["slipping"] = f"{step.n_slipping}/{step.n_passages}"
        self.bar.set_postfix(postfix, refresh=True)

    def close(self) -> None:
        self.bar.close()


def run_scene(scene: str | os.PathLike | Any, *,
              progress: bool | Callable[[Step], Any] = False) -> RunResult:
    """Run a scene in this process, as ``yarnfort < scene`` from the working directory.

    Parameters
    ----------
    scene : path or Scene
        A namelist file, or a :class:`yarnfort.Scene` (written to a temporary file
        first).
    progress : bool or callable
        ``True`` shows a tqdm bar; a callable gets a :class:`Step` after every converged
        step (a true return value stops the run there, outcome ``'stopped'``).

    Returns
    -------
    RunResult
        The output folder, the steps written and the outcome.

    Raises
    ------
    YarnfortError
        For bad input or a bad restart file (``status`` 2, nothing written) or a failed
        solve (``status`` 1; the converged steps are kept and ``result`` describes them).
    RunInterrupted
        After Ctrl-C, within a Newton iteration; the converged steps are on disk.
    TypeError
        If ``progress`` is neither a bool nor a callable (before anything runs).
    """
    # Anything else ('yes', 42, None) would run silently: refused, not guessed.
    if not (isinstance(progress, bool) or callable(progress)):
        raise TypeError(f"run_scene: progress must be a bool or a callable taking a Step, "
                        f"not {type(progress).__name__} {progress!r}")
    if hasattr(scene, "to_namelist"):
        with tempfile.TemporaryDirectory(prefix="yarnfort-scene-") as folder:
            path = Path(folder) / "scene.nml"
            scene.write(path)
            return _run_file(path, progress)
    return _run_file(Path(scene), progress)


def _run_file(path: Path, progress: bool | Callable[[Step], Any]) -> RunResult:
    failure: list[BaseException] = []
    bar = _TqdmProgress() if progress is True else None
    report = bar if bar is not None else progress if callable(progress) else None
    stopped_by_callback = False

    def notify(step: int, time: float, time_start: float, time_end: float, p_force: float,
               p_disp: float, iterations: int, residual: float, n_slipping: int,
               n_passages: int, wall_time: float) -> int:
        # Never raises: an exception here would unwind through Fortran.
        nonlocal stopped_by_callback
        if step < 0:
            return 0
        try:
            if report is not None and not failure:
                answer = report(Step(int(step), time, time_start, time_end, p_force, p_disp,
                                     int(iterations), residual, int(n_slipping),
                                     int(n_passages), wall_time))
                if answer and bar is None:
                    stopped_by_callback = True
        except BaseException as error:  # noqa: BLE001 - re-raised after the run
            failure.append(error)
        return 1 if failure or stopped_by_callback else 0

    # The library's SIGINT handler (a flag its solver polls) replaces Python's for the
    # run, on the main thread only: signals are delivered to it.
    catch = threading.current_thread() is threading.main_thread()
    try:
        status, message, n_steps, folder, outcome = extension().run_scene_file(
            os.fsencode(path), notify, int(catch))
    finally:
        if bar is not None:
            bar.close()
    name = OUTCOMES.get(int(outcome), "done")
    folder_text = os.fsdecode(folder.strip()) if isinstance(folder, bytes) else folder.strip()
    result = RunResult(Path.cwd() / folder_text, int(n_steps),
                       "failed" if status != 0 else name)
    check_status(status, message, result if status == 1 else None)
    if failure:
        if isinstance(failure[0], KeyboardInterrupt):
            raise RunInterrupted(result) from failure[0]
        raise failure[0]
    if name == "interrupted":
        detail = message.decode("utf-8", errors="replace") if isinstance(message, bytes) \
            else message
        raise RunInterrupted(result, detail.strip())
    _warn_of_jumps(result)
    return result


def _warn_of_jumps(result: RunResult) -> None:
    """Warn, as the program's last lines do, of steps of this run that ended in a jump
    after a slip instability (``curve.csv`` column ``jumped``)."""
    if result.n_steps <= 0:
        return
    curve = result.curve
    if "jumped" not in curve.names:
        return
    steps = [int(s) for s, j in zip(curve["step"][-result.n_steps:],
                                    curve["jumped"][-result.n_steps:]) if j]
    if steps:
        warnings.warn(f"{len(steps)} step(s) ended in a jump after a slip instability "
                      f"(steps {', '.join(map(str, steps))}; curve.csv column 'jumped'; "
                      "python -m yarnfort reference: Slip instabilities)", RuntimeWarning,
                      stacklevel=3)
