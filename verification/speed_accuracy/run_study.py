# SPDX-License-Identifier: MIT
"""Speed against accuracy of the solver settings, on three scenes.

Scenes: the one-pin hysteresis scene of ``tests/verification/test_hysteresis.py``
(adhesion, mu = 0.3, beta = 0.1 N: it has an exact closed form), the knit
(``inputs/knit.nml``) and the belt (``inputs/belt.nml``). Each is run with many
``&solver`` settings (number of load steps through ``max_step = initial_step``,
``residual_tolerance``, ``friction_tolerance``, ``scheme``) and, for the fabrics,
``&fabric elements_per_segment``. Every run is compared with a converged reference of
its scene (README.md, *Errors*) and timed (CPU time of the process, median of repeats).
Prints the table of every run, writes ``results.txt`` and the Pareto plot
``pareto.png`` next to this script. About 2.5 minutes (3.5 under heavy load) on 2 cores.

    .venv/bin/python verification/speed_accuracy/run_study.py   (after ./yarnfort has built
    once; YARNFORT_EXE picks another binary)
"""
from __future__ import annotations

import math
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

import f90nml
import matplotlib
import matplotlib.ticker
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

HERE = Path(__file__).resolve().parent
TOP = HERE.parents[1]
sys.path[:0] = [str(TOP / "tests" / "verification"), str(TOP / "python")]
from test_hysteresis import Case, ClosedForm, hysteresis_scene  # noqa: E402
from yarnfort import read_curve  # noqa: E402
from yarnfort.results import Curve  # noqa: E402
from yarnfort import set_parameter  # noqa: E402

EXECUTABLE = Path(os.environ.get("YARNFORT_EXE", TOP / "build" / "yarnfort"))
#: Runs faster than this (CPU s) are run REPEATS times and timed by the median. The
#: repeats go in rounds over all runs of a scene, in a shuffled order, so that a burst of
#: load on a shared machine spreads over many runs instead of spoiling one.
REPEAT_BELOW = 1.0
REPEATS = 5
SHUFFLE_SEED = 6
#: Reference runs: steps of this size (pseudo-time) and tight tolerances.
REFERENCE_STEP = 0.001
REFERENCE_TOLERANCES = dict(residual_tolerance=1e-12, friction_tolerance=1e-12)
#: The closed form's grid for the hysteresis scene's curve error: points per half cycle.
EXACT_POINTS = 4000
#: Swept values.
MAX_STEPS = (1.0, 0.5, 0.25, 0.1, 0.05, 0.02, 0.01, 0.005)
RESIDUAL_TOLERANCES = (1e-4, 1e-6, 1e-8, 1e-10, 1e-12)
FRICTION_TOLERANCES = (1e-3, 1e-6, 1e-9)
TOLERANCE_STEPS = (0.25, 0.05)
ELEMENTS = (1, 2, 3, 4)
ELEMENT_STEPS = (0.25, 0.05, 0.01)
#: The presets of &solver preset, run by name on every scene (see REFERENCE.md).
PRESETS = ("balanced", "accurate")
#: The &solver variables a preset sets: removed from a scene run with a preset.
PRESET_VARIABLES = ("initial_step", "max_step", "residual_tolerance", "scheme")
#: Errors below this are plotted at this value (log axis).
ERROR_FLOOR = 1e-14


@dataclass(frozen=True)
class Settings:
    """The swept settings of one run (None: the scene's own value)."""

    max_step: float = 0.05
    residual_tolerance: float = 1e-10
    friction_tolerance: float = 1e-9
    scheme: str = "monolithic"
    elements_per_segment: int | None = None
    preset: str | None = None        #: run `&solver preset` instead of the values above

    def values(self) -> dict[str, object]:
        if self.preset is not None:
            return {"solver.preset": self.preset}
        out: dict[str, object] = {
            "solver.max_step": self.max_step, "solver.initial_step": self.max_step,
            "solver.residual_tolerance": self.residual_tolerance,
            "solver.friction_tolerance": self.friction_tolerance,
            "solver.scheme": self.scheme}
        if self.elements_per_segment is not None:
            out["fabric.elements_per_segment"] = self.elements_per_segment
        return out

    def label(self) -> str:
        if self.preset is not None:
            return f"preset '{self.preset}'"
        eps = "" if self.elements_per_segment is None else f" eps={self.elements_per_segment}"
        return (f"{self.scheme[:4]} h={self.max_step:g} rtol={self.residual_tolerance:.0e} "
                f"ftol={self.friction_tolerance:.0e}{eps}")


@dataclass
class Scene:
    """A scene: its namelist text for given settings, and how to read its force."""

    name: str
    text: Callable[[Settings, str], str]      #: (settings, output folder) -> namelist
    cwd: Path                                 #: working directory of the runs
    knots: list[float]                        #: path knots (pseudo-time)
    force: Callable[[Curve], np.ndarray]      #: the compared force at every step
    unit: str
    default_elements: int | None              #: the scene's own elements_per_segment
    reference_elements: int | None


@dataclass
class Run:
    settings: Settings
    time: np.ndarray            #: pseudo-time of every converged step
    force: np.ndarray
    steps: int
    newton: int
    cpus: list[float]           #: CPU time of the process (s) in each repeat
    walls: list[float]          #: wall time of the process (s) in each repeat
    error_curve: float = math.nan
    error_steps: float = math.nan

    @property
    def cpu(self) -> float:
        """CPU time of the run (s): the median of the repeats."""
        return statistics.median(self.cpus)

    @property
    def wall(self) -> float:
        return statistics.median(self.walls)


# ------------------------------------------------------------------------- scenes
def patched(text: str, values: dict[str, object], folder: str) -> str:
    nml = f90nml.reads(text)
    if "solver.preset" in values and "solver" in nml:
        for name in PRESET_VARIABLES:          # else the scene's values override it
            nml["solver"].pop(name, None)
    for address, value in values.items():
        set_parameter(nml, address, value)
    set_parameter(nml, "output.folder", folder)
    set_parameter(nml, "output.progress", False)
    set_parameter(nml, "output.vtk_every", 0)      # timing the solver, not VTK writing
    return str(nml) + "\n"


def fabric_scene(name: str, unit: str, default_elements: int,
                 reference_elements: int) -> Scene:
    path = TOP / "inputs" / f"{name}.nml"
    source = path.read_text()
    knots = [float(t) for t in f90nml.reads(source)["path"]["time"]]
    return Scene(name=name, text=lambda s, folder: patched(source, s.values(), folder),
                 cwd=TOP, knots=knots, force=lambda c: c["force_per_width"], unit=unit,
                 default_elements=default_elements, reference_elements=reference_elements)


#: The hysteresis scene's case: adhesion, so the loop visits every branch of T_crit.
HYSTERESIS = Case(law="adhesion", mu=0.3, beta=0.1)


def hysteresis_text(settings: Settings, folder: str) -> str:
    case = replace(HYSTERESIS, scheme=settings.scheme, max_step=settings.max_step)
    return patched(hysteresis_scene(case), settings.values(), folder)


def hysteresis_force(curve: Curve) -> np.ndarray:
    return curve.reaction("pull") @ HYSTERESIS.directions()[1]


SCENES = [
    Scene(name="hysteresis", text=hysteresis_text, cwd=TOP, knots=[0.0, 1.0, 2.0, 3.0, 4.0],
          force=hysteresis_force, unit="N", default_elements=None, reference_elements=None),
    fabric_scene("knit", "N/m", default_elements=1, reference_elements=3),
    fabric_scene("belt", "N/m", default_elements=1, reference_elements=4),
]


# ------------------------------------------------------------------------ running
def run_once(scene: Scene, settings: Settings) -> tuple[Curve, float, float]:
    """One run in a fresh folder: (curve, CPU s, wall s) of the process."""
    env = dict(os.environ, OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
    with tempfile.TemporaryDirectory() as tmp:
        text = scene.text(settings, str(Path(tmp) / "out"))
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        start = time.perf_counter()
        proc = subprocess.run([str(EXECUTABLE)], input=text, text=True, capture_output=True,
                              cwd=scene.cwd, env=env)
        wall = time.perf_counter() - start
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        if proc.returncode != 0:
            raise RuntimeError(f"{scene.name}, {settings.label()}: yarnfort failed:\n"
                               + proc.stderr[-2000:])
        cpu = (after.ru_utime + after.ru_stime) - (before.ru_utime + before.ru_stime)
        return read_curve(Path(tmp) / "out"), cpu, wall


def run(scene: Scene, settings: Settings) -> Run:
    """Run once (the curve and the first timing); `repeat` adds timings."""
    curve, cpu, wall = run_once(scene, settings)
    return Run(settings, curve["time"].copy(), scene.force(curve).copy(),
               len(curve["step"]) - 1, int(curve["newton_iterations"].sum()), [cpu], [wall])


def repeat(scene: Scene, runs: list[Run]) -> None:
    """Time the short runs again, REPEATS times in all, round after shuffled round."""
    short = [r for r in runs if r.cpu < REPEAT_BELOW]
    rng = np.random.default_rng(SHUFFLE_SEED)
    for _ in range(REPEATS - 1):
        for i in rng.permutation(len(short)):
            _, cpu, wall = run_once(scene, short[i].settings)
            short[i].cpus.append(cpu)
            short[i].walls.append(wall)


# ------------------------------------------------------------------------- errors
def branches(time_: np.ndarray, knots: list[float]) -> list[np.ndarray]:
    """Masks of the steps on each monotone piece of the path (knots belong to both)."""
    slack = 1e-9
    return [(time_ >= a - slack) & (time_ <= b + slack) for a, b in zip(knots, knots[1:])]


def curve_error(run_: Run, ref_time: np.ndarray, ref_force: np.ndarray,
                knots: list[float]) -> float:
    """Max |run's polyline - reference| at the reference's points, per branch."""
    worst = 0.0
    for mr, mx in zip(branches(ref_time, knots), branches(run_.time, knots)):
        line = np.interp(ref_time[mr], run_.time[mx], run_.force[mx])
        worst = max(worst, float(np.max(np.abs(line - ref_force[mr]))))
    return worst


def step_error(run_: Run, ref_time: np.ndarray, ref_force: np.ndarray,
               knots: list[float]) -> float:
    """Max |run - reference| at the run's own steps (reference interpolated, per branch)."""
    worst = 0.0
    for mr, mx in zip(branches(ref_time, knots), branches(run_.time, knots)):
        value = np.interp(run_.time[mx], ref_time[mr], ref_force[mr])
        worst = max(worst, float(np.max(np.abs(run_.force[mx] - value))))
    return worst


def exact_hysteresis(time_: np.ndarray) -> np.ndarray:
    """Closed-form reaction at B at the pseudo-times `time_` (steps landing on knots)."""
    d = np.interp(time_, [0.0, 1.0, 2.0, 3.0, 4.0], HYSTERESIS.knots)
    return ClosedForm(HYSTERESIS).follow(d)[1]


# -------------------------------------------------------------------------- sweep
def sweep(scene: Scene) -> list[Settings]:
    """The settings run on a scene (duplicates removed, order kept)."""
    out = [Settings(max_step=h, scheme=s)
           for s in ("monolithic", "staggered") for h in MAX_STEPS]
    for scheme, h in [("monolithic", h) for h in TOLERANCE_STEPS] + [("staggered", 0.05)]:
        out += [Settings(max_step=h, scheme=scheme, residual_tolerance=r, friction_tolerance=f)
                for r in RESIDUAL_TOLERANCES for f in FRICTION_TOLERANCES]
    if scene.default_elements is not None:
        out += [Settings(max_step=h, elements_per_segment=e)
                for h in ELEMENT_STEPS for e in ELEMENTS if e != scene.default_elements]
    out += [Settings(preset=p) for p in PRESETS]
    return list(dict.fromkeys(out))


#: A run joins the Pareto front only if its curve error is below every faster run's by
#: more than this factor (equal errors up to round-off are ties, not improvements).
PARETO_MARGIN = 1.01


def pareto(runs: list[Run]) -> list[Run]:
    """Runs no other run beats in both time and curve error, fastest first."""
    front, best = [], math.inf
    for r in sorted(runs, key=lambda r: (r.cpu, r.error_curve)):
        if r.error_curve * PARETO_MARGIN < best:
            front.append(r)
            best = r.error_curve
    return front


def study(scene: Scene) -> tuple[list[Run], dict[str, float]]:
    info: dict[str, float] = {}
    reference = run(scene, Settings(max_step=REFERENCE_STEP, **REFERENCE_TOLERANCES,
                                    elements_per_segment=scene.reference_elements))
    if scene.name == "hysteresis":
        # The closed form is exact at any pull: a fine grid is the reference curve, and
        # the reference run is checked against it.
        info["reference run vs closed form"] = float(np.max(np.abs(
            reference.force - exact_hysteresis(reference.time))))
        ref_time = np.linspace(0.0, 4.0, 4 * EXACT_POINTS + 1)
        ref_force = exact_hysteresis(ref_time)
    else:
        ref_time, ref_force = reference.time, reference.force
    scale = float(np.max(np.abs(ref_force)))
    info["force scale"] = scale
    info["reference CPU s"] = reference.cpu
    runs = []
    for settings in sweep(scene):
        r = run(scene, settings)
        r.error_curve = curve_error(r, ref_time, ref_force, scene.knots) / scale
        if scene.name == "hysteresis":
            r.error_steps = float(np.max(np.abs(r.force - exact_hysteresis(r.time)))) / scale
        else:
            r.error_steps = step_error(r, ref_time, ref_force, scene.knots) / scale
        runs.append(r)
        print(f"  {scene.name:10} {settings.label():44} {r.cpu:7.3f} s  "
              f"{r.error_curve:8.1e} {r.error_steps:8.1e}", file=sys.stderr, flush=True)
    print(f"  {scene.name:10} timing repeats", file=sys.stderr, flush=True)
    repeat(scene, runs)
    return runs, info


# ------------------------------------------------------------------------- output
def table(scene: Scene, runs: list[Run]) -> list[str]:
    front = {id(r) for r in pareto(runs)}
    lines = [f"## {scene.name}",
             f"{'settings':46} {'steps':>5} {'newton':>6} {'CPU s':>7} {'wall s':>7} "
             f"{'err curve':>9} {'err steps':>9} pareto"]
    for r in sorted(runs, key=lambda r: r.cpu):
        lines.append(f"{r.settings.label():46} {r.steps:5d} {r.newton:6d} {r.cpu:7.3f} "
                     f"{r.wall:7.3f} {r.error_curve:9.1e} {r.error_steps:9.1e} "
                     f"{'*' if id(r) in front else ''}")
    return lines


def markdown_front(scene: Scene, runs: list[Run]) -> list[str]:
    lines = [f"**{scene.name}** (Pareto front, fastest first)", "",
             "| max_step | scheme | residual_tol | friction_tol | elements | steps | CPU s "
             "| error (curve) | error (steps) |", "|---|---|---|---|---|---|---|---|---|"]
    for r in pareto(runs):
        s = r.settings
        if s.preset is not None:
            cells = [f"preset `{s.preset}`", "", "", "", ""]
        else:
            cells = [f"{s.max_step:g}", s.scheme, f"{s.residual_tolerance:.0e}",
                     f"{s.friction_tolerance:.0e}",
                     str(s.elements_per_segment or scene.default_elements or "-")]
        lines.append("| " + " | ".join(cells + [str(r.steps), f"{r.cpu:.3f}",
                                                f"{r.error_curve:.1e}",
                                                f"{r.error_steps:.1e}"]) + " |")
    return lines


def markdown_presets(results: list[tuple[Scene, list[Run]]]) -> list[str]:
    lines = ["**Presets** (`&solver preset`)", "",
             "| scene | preset | steps | Newton iterations | CPU s | error (curve) "
             "| error (steps) |", "|---|---|---|---|---|---|---|"]
    for scene, runs in results:
        for r in runs:
            if r.settings.preset is not None:
                lines.append(f"| {scene.name} | `{r.settings.preset}` | {r.steps} | "
                             f"{r.newton} | {r.cpu:.3f} | {r.error_curve:.1e} | "
                             f"{r.error_steps:.1e} |")
    return lines


def plot(results: list[tuple[Scene, list[Run]]]) -> None:
    """Top row: curve error against time, Pareto front highlighted. Bottom row: the error
    at the run's own steps (what the tolerances control)."""
    fig, axes = plt.subplots(2, len(results), figsize=(5.2 * len(results), 8.4),
                             sharex="col")
    cmap = plt.get_cmap("viridis")
    steps_log = np.log10(MAX_STEPS)
    colour_of = lambda h: cmap((math.log10(h) - steps_log.min()) / np.ptp(steps_log))
    for col, (scene, runs) in enumerate(results):
        for row, key in enumerate(("error_curve", "error_steps")):
            ax = axes[row, col]
            for r in runs:
                s = r.settings
                err = max(getattr(r, key), ERROR_FLOOR)
                if s.preset is not None:
                    ax.plot(r.cpu, err, "*", ms=13, mfc="none", mec="tab:red", mew=1.3)
                    ax.annotate(s.preset, (r.cpu, err), textcoords="offset points",
                                xytext=(6, 4), fontsize=8, color="tab:red")
                    continue
                if s.elements_per_segment is not None:
                    marker = "s"
                elif s.scheme == "staggered":
                    marker = "^"
                else:
                    marker = "o"
                colour = colour_of(s.max_step)
                ax.plot(r.cpu, err, marker, ms=5, color=colour, alpha=0.8,
                        mfc=colour if s.residual_tolerance >= 1e-10 else "none")
            if row == 0:
                front = pareto(runs)
                x = [r.cpu for r in front]
                y = [max(r.error_curve, ERROR_FLOOR) for r in front]
                ax.step(x, y, where="post", color="k", lw=1.0)
                ax.plot(x, y, "o", ms=10, mfc="none", mec="k", mew=1.0)
                ax.set_title(f"{scene.name}", fontsize=10)
            else:
                ax.set_xlabel("CPU time of the run (s, median of repeats)")
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
            ax.grid(alpha=0.3, which="both")
    axes[0, 0].set_ylabel("curve error: max |F - F_ref| / max |F_ref|\n"
                          "(the run's curve, linear between its steps)")
    axes[1, 0].set_ylabel("step error: the same at the run's own steps\n"
                          "(hysteresis: against the closed form)")
    handles = [plt.Line2D([], [], ls="", marker="o", color="0.4", label="monolithic"),
               plt.Line2D([], [], ls="", marker="^", color="0.4", label="staggered"),
               plt.Line2D([], [], ls="", marker="s", color="0.4",
                          label="elements_per_segment\nvaried (monolithic)"),
               plt.Line2D([], [], ls="", marker="o", mfc="none", color="0.4",
                          label="residual_tolerance\n< 1e-10"),
               plt.Line2D([], [], ls="", marker="*", mfc="none", color="tab:red", ms=11,
                          label="presets"),
               plt.Line2D([], [], color="k", marker="o", mfc="none", ms=9,
                          label="Pareto front")]
    handles += [plt.Line2D([], [], ls="", marker="o", label=f"max_step {h:g}",
                           color=colour_of(h)) for h in MAX_STEPS]
    fig.legend(handles=handles, loc="center right", fontsize=8, frameon=False)
    fig.suptitle("Speed against accuracy: every run of the study (colour: max_step = "
                 "initial_step; errors below 1e-14 drawn at 1e-14)", fontsize=10)
    fig.tight_layout(rect=(0, 0, 0.86, 1))
    fig.savefig(HERE / "pareto.png", dpi=110)


def main() -> None:
    if not EXECUTABLE.is_file():
        sys.exit(f"{EXECUTABLE} is missing: build first (./yarnfort --version)")
    start = time.perf_counter()
    results, lines = [], []
    for scene in SCENES:
        runs, info = study(scene)
        results.append((scene, runs))
        lines += table(scene, runs)
        lines += [f"{k}: {v:.3g}" for k, v in info.items()] + [""]
    for scene, runs in results:
        lines += markdown_front(scene, runs) + [""]
    lines += markdown_presets(results) + [""]
    plot(results)
    lines.append(f"study wall time {time.perf_counter() - start:.0f} s")
    text = "\n".join(lines)
    print(text)
    (HERE / "results.txt").write_text(text + "\n")


if __name__ == "__main__":
    main()
