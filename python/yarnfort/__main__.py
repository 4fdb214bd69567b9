# SPDX-License-Identifier: MIT
"""Command line:

- ``python -m yarnfort plot <output folder> [--channel NAME] [--step N] [--support NAME]
  [--out FILE]`` writes a PNG (:func:`plot_folder`): force against displacement of what
  drives the run, the network at the peak coloured by tension, the history of rings and
  obstacles;
- ``python -m yarnfort plot-states <output folder> [-o FILE] [--strains 0 0.5 1] ...``
  writes a PNG of the deformed states nearest to the given strains, coloured by tension
  on one scale (:func:`yarnfort.plots.plot_states`);
- ``python -m yarnfort plot-membrane <output folder> [-o FILE]`` writes a PNG of a
  periodic-cell run's membrane forces against its strain (:func:`yarnfort.plots.plot_membrane`);
- ``python -m yarnfort examples DIR [--force]`` writes the example scenes with their
  tables and models into ``DIR/inputs/`` (run one there: ``cd DIR && yarnfort <
  inputs/vnet.nml``);
- ``python -m yarnfort export-fabric RUN... --component C... --format abaqus|lsdyna|csv
  --thickness 0.6mm --units N,mm -o FILE`` writes the effective loading and unloading
  curves of periodic-cell runs for a macro model (:func:`yarnfort.export_fabric`);
- ``python -m yarnfort reference`` prints the input reference (``inputs/REFERENCE.md``:
  every group and variable, checks, output files).

Exit codes: 0 success, 2 bad arguments, a missing or unreadable output folder, an
unknown support set, or strains the run does not reach.
"""
from __future__ import annotations

import argparse
import sys
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from .namelist import read_scene
from .results import Curve, incomplete_reason, read_curve, read_states

# matplotlib (through .plots) is imported only once a plot is to be made, so that
# --help and argument errors answer quickly.

#: Exit code for bad arguments or unusable inputs (as the Fortran program).
EXIT_BAD_INPUT = 2
#: File name of the default plot inside the output folder.
DEFAULT_PLOT = "plot.png"
#: File name of the default state plot inside the output folder.
DEFAULT_STATES_PLOT = "states.png"
#: File written by ``plot-membrane`` into the run's folder unless told otherwise.
DEFAULT_MEMBRANE_PLOT = "membrane.png"


class CommandError(Exception):
    """A problem reported as a message on stderr and exit code 2."""


def _moving_supports(folder: Path) -> list[str]:
    """Support sets with a non-zero prescribed displacement in the effective input."""
    scene_file = folder / "input.nml"
    if not scene_file.is_file():
        return []
    try:
        scene = read_scene(scene_file)
    except Exception:  # an unreadable input.nml only loses the hint
        return []
    found = scene.get("support", [])
    groups = list(found) if isinstance(found, list) else [found]
    return [str(group["name"]) for group in groups
            if "name" in group and np.any(np.asarray(group.get("displacement", 0.0)) != 0)]


def choose_support(curve: Curve, folder: Path, name: str | None = None) -> str:
    """The support set to plot.

    Parameters
    ----------
    curve : Curve
        The run's curve.
    folder : Path
        Its output folder (its input.nml tells which supports move).
    name : str, optional
        The support asked for; it must exist.

    Returns
    -------
    str
        ``name`` if given, else the first support set that moves, else the first with a
        non-zero reaction, else the first.

    Raises
    ------
    CommandError
        If the curve has no supports or ``name`` is not one of them.
    """
    from .plots import supports

    known = supports(curve)
    if not known:
        raise CommandError(f"{folder / 'curve.csv'} has no support reaction columns")
    if name is not None:
        if name not in known:
            raise CommandError(f"unknown support {name!r}; the supports are: "
                               + ", ".join(known))
        return name
    for moving in _moving_supports(folder):
        if moving in known:
            return moving
    for support in known:
        if np.any(curve.reaction(support) != 0):
            return support
    return known[0]


def _dominant_component(curve: Curve, support: str) -> str:
    reaction = np.abs(curve.reaction(support))
    return "xyz"[int(np.argmax(reaction.max(axis=0)))] if reaction.size else "y"


def _dominant_projection(position: np.ndarray) -> str:
    extent = np.ptp(position, axis=0)
    keep = sorted(np.argsort(extent)[1:])
    return "xyz"[keep[0]] + "xyz"[keep[1]]


def plot_folder(folder: Path, support: str | None = None, out: Path | None = None, *,
                channel: str | None = None, step: int | None = None) -> Path:
    """Write the summary plot of an output folder (:func:`summary_figure`).

    Parameters
    ----------
    folder, support, channel, step
        As in :func:`summary_figure`.
    out : Path, optional
        PNG to write (default ``<folder>/plot.png``).

    Returns
    -------
    Path
        The PNG written.

    Raises
    ------
    CommandError
        As :func:`summary_figure`.
    """
    from .plots import save_figure

    figure = summary_figure(folder, support, channel=channel, step=step)
    return save_figure(figure, out if out is not None else folder / DEFAULT_PLOT)


def summary_figure(folder: Path, support: str | None = None, *, channel: str | None = None,
                   step: int | None = None) -> Any:
    """The summary plot of an output folder.

    Panels: the force against the displacement of what drives the run (a moving support
    or a load; a fabric: force per unit width against strain; a periodic cell without
    force_per_width, e.g. sheared: its membrane force against the strain it changes
    most, n12 against gamma12), force positive in tension; the network at the step of the largest force (or ``step``), coloured by
    tension; for a scene with rings or obstacles, their history (ring position, obstacle
    reaction) against the load. Lengths in mm, as ``plot-states``.

    Parameters
    ----------
    folder : Path
        A run's output folder (holds curve.csv and input.nml).
    support : str, optional
        Support set whose force is drawn (default: the driver's own).
    channel : str, optional
        The load channel whose driver gives the abscissa (default: the channel that
        changes in the most steps).
    step : int, optional
        The step of the network panel (default: the saved step of the largest force).

    Returns
    -------
    matplotlib.figure.Figure
        Its first Axes is the force-displacement panel (the step shown marked by the
        line of gid ``'shown_step'``), the second the network; then the history panels.

    Raises
    ------
    CommandError
        For a missing folder or curve, a curve without rows, an unknown support,
        channel or step.
    """
    curve = read_run_curve(folder)
    from matplotlib.figure import Figure

    from .plots import (DEFAULT_UNIT, LENGTH_UNITS, choose_driver, driver_response, load_drivers,
                        membrane_pair, peak_step, plot_fabric_hysteresis, plot_history,
                        plot_hysteresis, plot_load_displacement, plot_membrane_curve,
                        plot_network)

    states = read_states(folder)
    scene = _scene(folder)
    if support is not None:
        choose_support(curve, folder, support)  # a clear error for an unknown name
    drivers = load_drivers(curve, scene)
    try:
        driver = choose_driver(curve, drivers, channel)
    except ValueError as error:
        raise CommandError(str(error)) from None
    fabric = support is None and channel is None and "force_per_width" in curve.names
    # A periodic cell without force_per_width (sheared, say) has its membrane curve,
    # where a reaction of its anchor would be rounding noise.
    pair = (membrane_pair(curve) if support is None and channel is None and not fabric
            and driver is None else None)
    history = 0
    if driver is not None and not fabric and scene is not None:
        history = int(bool(scene.get("ring"))) + int(any(
            f"{o.get('name')}_rx" in curve.names for o in _groups(scene, "obstacle")))
    panels = 2 + history
    figure = Figure(figsize=(5.2 * panels, 4.6), layout="constrained")
    axes = list(figure.subplots(1, panels))
    left, right = axes[0], axes[1]
    if fabric:
        plot_fabric_hysteresis(curve, ax=left)
        left.set_title("effective curve of the fabric")
        force = curve["force_per_width"]
        abscissa = curve["strain"]
    elif pair is not None:
        plot_membrane_curve(curve, ax=left)
        left.set_title("membrane curve of the cell")
        abscissa, force = curve[pair[0]], curve[pair[1]]
    elif driver is not None:
        plot_load_displacement(curve, driver, ax=left, support=support)
        left.set_title(f"load-displacement ({driver.channel})")
        displacement, force = driver_response(curve, driver, support)
        abscissa = displacement / LENGTH_UNITS[DEFAULT_UNIT]
        if history:
            plot_history(curve, states, driver, scene, axes[2:])
    else:
        # Nothing moves or pushes (a prestressed net): a reaction against the factors.
        name = choose_support(curve, folder, support)
        component = _dominant_component(curve, name)
        channels = curve.channels
        moving = [c for c in channels if np.ptp(curve[c]) > 0]
        x = (moving or channels or ["time"])[0]
        plot_hysteresis(curve, name, component=component, x=x, ax=left)
        left.set_title(f"reaction of '{name}'")
        force = curve.reaction(name)[:, "xyz".index(component)]
        abscissa = curve[x]
    saved = [state.step for state in states if state.step is not None]
    if states and saved:
        if step is None:
            shown = peak_step(curve, force, saved)
        elif step in saved:
            shown = step
        else:
            raise CommandError(f"no saved state of step {step}; saved steps: "
                               + _ranges(saved))
        state = next(s for s in states if s.step == shown)
        plot_network(state, ax=right, projection=_dominant_projection(state.position),
                     unit=DEFAULT_UNIT)
        row = int(np.flatnonzero(curve["step"] == shown)[0])
        left.plot(abscissa[row], force[row], "o", color="black", markersize=6,
                  label=f"step {shown} (right)", gid="shown_step")
        left.legend()
        title = ("largest force" if step is None else "chosen step") + f": step {shown}"
        peak = peak_step(curve, force, [int(s) for s in curve["step"]])
        if step is None and peak != shown:  # vtk_every > 1: the peak may have no state
            title = (f"largest force of the saved states: step {shown}\n(the peak, step"
                     f" {peak}, has no saved state)")
        right.set_title(title)
    else:
        right.set_axis_off()
        right.text(0.5, 0.5, "no states written", ha="center", va="center")
    return figure


def read_run_curve(folder: Path) -> Curve:
    """The curve of output folder `folder`, with at least one row.

    Raises
    ------
    CommandError
        For a missing folder or curve, or a curve without rows.
    """
    if not folder.is_dir():
        raise CommandError(f"no output folder {str(folder)!r}")
    if not (folder / "curve.csv").is_file():
        raise CommandError(f"{str(folder)!r} holds no curve.csv: not a yarnfort output"
                           " folder")
    curve = read_curve(folder)
    if len(curve) == 0:
        raise CommandError(f"{folder / 'curve.csv'} has no rows (only its header): the run"
                           " wrote no converged step, nothing to plot")
    if reason := incomplete_reason(folder, curve):
        warnings.warn(f"{folder}: {reason}", RuntimeWarning, stacklevel=2)
    return curve


def _scene(folder: Path) -> Any:
    """The run's effective input, or None if unreadable (only hints are lost)."""
    try:
        return read_scene(folder / "input.nml")
    except Exception:
        return None


def _groups(scene: Any, name: str) -> list[Any]:
    found = scene.get(name, []) if scene is not None else []
    return list(found) if isinstance(found, list) else [found]


def _ranges(steps: list[int]) -> str:
    """'0-12, 15' for a list of steps."""
    ordered = sorted(set(steps))
    parts = []
    start = previous = ordered[0]
    for step in ordered[1:] + [None]:
        if step is not None and step == previous + 1:
            previous = step
            continue
        parts.append(str(start) if start == previous else f"{start}-{previous}")
        if step is not None:
            start = previous = step
    return ", ".join(parts)


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="python -m yarnfort",
        description="yarnfort tools: plot a run's output folder, export a fabric's curves,"
                    " write the example scenes, print the input reference.")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    plot = commands.add_parser(
        "plot", help="write a PNG: force-displacement loop, network at the peak, history",
        description="Write a PNG with the force against the displacement (mm) of what"
        " drives the run (a moving support or a load; a fabric: force per width against"
        " strain; a sheared periodic cell: n12 against gamma12), force positive in tension; the network at the step of the largest force"
        " coloured by tension; and for rings and obstacles their history against the"
        " load.")
    plot.add_argument("folder", type=Path, help="output folder of a run (holds curve.csv)")
    plot.add_argument("--support", metavar="NAME",
                      help="support set whose force is drawn (default: the one that moves,"
                      " or the load)")
    plot.add_argument("--channel", metavar="NAME",
                      help="load channel whose support or load gives the displacement axis"
                      " (default: the channel that changes in the most steps)")
    plot.add_argument("--step", type=int, metavar="N",
                      help="step of the network panel (default: the saved step of the"
                      " largest force)")
    plot.add_argument("--out", type=Path, metavar="FILE",
                      help=f"PNG to write (default: <folder>/{DEFAULT_PLOT})")
    states = commands.add_parser(
        "plot-states", help="write a PNG: deformed states at given strains",
        description="Write a PNG of the saved states nearest to the given strains on the"
        " first loading, the yarns coloured by tension on one scale.")
    states.add_argument("folder", type=Path, help="output folder of a run (curve.csv and"
                        " VTK states)")
    states.add_argument("-o", "--out", type=Path, metavar="FILE",
                        help=f"PNG to write (default: <folder>/{DEFAULT_STATES_PLOT})")
    states.add_argument("--strains", type=float, nargs="+", default=[0.0, 0.5, 1.0],
                        metavar="S", help="values of the --by column (default 0 0.5 1)")
    states.add_argument("--by", default="strain", metavar="COLUMN",
                        help="curve.csv column the strains are values of (default strain;"
                        " p_disp for a scene that is no fabric)")
    states.add_argument("--of-peak", action="store_true",
                        help="strains are fractions of the peak (largest magnitude) on the first"
                        " loading")
    states.add_argument("--images", type=int, nargs="+", default=[1, 1], metavar="N",
                        help="periodic images per period of a periodic cell (e.g. 3 3)")
    states.add_argument("--projection", nargs="+", default=["xy"], metavar="VIEW",
                        help="views, one row each: xy, xz, yz or 3d (default xy)")
    states.add_argument("--depth-scale", type=float, default=1.0, metavar="F",
                        help="draw z this many times stretched (default 1)")
    states.add_argument("--title", help="figure title")
    membrane = commands.add_parser(
        "plot-membrane", help="write a PNG: membrane forces of a periodic-cell run",
        description="Write a PNG of a periodic-cell run's membrane forces: n11, n22 and"
        " e22 against e11, one panel each (forces from zero: a held force is a flat"
        " line); a shear run: n12 (with n22 tan(gamma12)), n11 and e22 against gamma12.")
    membrane.add_argument("folder", type=Path, help="output folder of a periodic-cell run"
                          " (holds curve.csv)")
    membrane.add_argument("-o", "--out", type=Path, metavar="FILE",
                          help=f"PNG to write (default: <folder>/{DEFAULT_MEMBRANE_PLOT})")
    examples = commands.add_parser(
        "examples", help="write the example scenes and their tables into a folder",
        description="Write the example scenes (inputs/*.nml), their tables (inputs/data/)"
        " and TexGen models into FOLDER/inputs/; run one there with"
        " `cd FOLDER && yarnfort < inputs/vnet.nml`.")
    examples.add_argument("folder", type=Path, help="folder to write into (made if missing)")
    examples.add_argument("--force", action="store_true",
                          help="overwrite example files that exist there")
    export = commands.add_parser(
        "export-fabric", help="write a fabric's effective curves for Abaqus, LS-DYNA or CSV",
        description="Write the effective loading and unloading curves of periodic-cell"
        " runs: an Abaqus/Explicit *FABRIC material block (*UNIAXIAL, *LOADING DATA,"
        " *UNLOADING DATA), LS-DYNA *DEFINE_CURVE_TITLE blocks, or a CSV. Loading: the"
        " primary loading of each run; unloading: one curve per peak the run releases"
        " from. Stress = membrane force per width / thickness, in the units asked for."
        " Layouts and sources: docs/fabric_export.md.")
    export.add_argument("runs", type=Path, nargs="+", metavar="RUN",
                        help="output folders of periodic-cell runs")
    export.add_argument("--component", nargs="+", required=True, metavar="C",
                        choices=["1", "2", "12"],
                        help="the component each RUN gives, in order (1, 2 or 12 for shear);"
                        " one RUN with several components reads its e11/n11, e22/n22"
                        " and gamma12 columns (12: against n12 cos(gamma12) - n22"
                        " sin(gamma12), the shear in the yarns' frame)")
    export.add_argument("--format", default="abaqus", choices=["abaqus", "lsdyna", "csv"],
                        help="file format (default abaqus)")
    export.add_argument("--thickness", metavar="LENGTH",
                        help="fabric thickness with its unit, e.g. 0.6mm (required for"
                        " abaqus and lsdyna: their curves are stress against strain)")
    export.add_argument("--units", default="N,mm", metavar="FORCE,LENGTH",
                        help="force and length units of the macro model (default N,mm:"
                        " stress in MPa)")
    export.add_argument("-o", "--out", type=Path, required=True, metavar="FILE",
                        help="file to write (refused if it exists, unless --force)")
    export.add_argument("--force", action="store_true", help="overwrite an existing FILE")
    export.add_argument("--uniaxial", action="store_true",
                        help="components 1 and 2 from strain and force_per_width (the"
                        " cell's x direction) even where curve.csv has e11/n11, e22/n22:"
                        " a cell turned by 90 degrees given as component 2")
    export.add_argument("--no-unloading", action="store_true",
                        help="write the loading curves only")
    export.add_argument("--name", default="YARNFORT_FABRIC",
                        help="Abaqus material name (default YARNFORT_FABRIC)")
    export.add_argument("--first-curve-id", type=int, default=1, metavar="LCID",
                        help="LS-DYNA id of the first curve (default 1)")
    commands.add_parser(
        "reference", help="print the input reference (inputs/REFERENCE.md)",
        description="Print the input reference: every namelist group and variable with"
        " default, unit and range, the checks, the output files (Markdown).")
    return parser


def plot_states_command(args: argparse.Namespace) -> Path:
    """Write the state plot that ``plot-states`` asks for; the PNG written."""
    from .plots import plot_states, save_figure

    figure = plot_states(args.folder, tuple(args.strains), by=args.by, of_peak=args.of_peak,
                         images=tuple(args.images), projections=tuple(args.projection),
                         depth_scale=args.depth_scale, title=args.title)
    return save_figure(figure, args.out if args.out is not None
                       else args.folder / DEFAULT_STATES_PLOT)


def plot_membrane_command(args: argparse.Namespace) -> Path:
    """Write the membrane plot that ``plot-membrane`` asks for; the PNG written."""
    from .plots import plot_membrane, save_figure

    curve = read_run_curve(args.folder)
    scene = _scene(args.folder)
    title = str(scene.get("control", {}).get("title", "")) if scene is not None else ""
    figure = plot_membrane(curve, title)
    return save_figure(figure, args.out if args.out is not None
                       else args.folder / DEFAULT_MEMBRANE_PLOT, dpi=110)


def export_fabric_command(args: argparse.Namespace) -> Path:
    """Write the file that ``export-fabric`` asks for; the path written."""
    from .fabric_export import export_fabric

    runs, components = list(args.runs), list(args.component)
    if len(runs) == 1 and len(components) > 1:
        runs = runs * len(components)
    elif len(runs) != len(components):
        raise CommandError(f"{len(runs)} runs and {len(components)} components: give one"
                           " --component per RUN, in order (or several for one RUN with"
                           " membrane columns)")
    return export_fabric(list(zip(components, runs)), args.out, format=args.format,
                         thickness=args.thickness, units=args.units,
                         unloading=not args.no_unloading, uniaxial=args.uniaxial,
                         name=args.name,
                         first_curve_id=args.first_curve_id, overwrite=args.force)


def main(argv: list[str] | None = None) -> int:
    """Run the command line.

    Parameters
    ----------
    argv : list of str, optional
        The arguments (default ``sys.argv[1:]``).

    Returns
    -------
    int
        The exit code: 0 success, 2 bad arguments or unusable inputs.
    """
    args = _parser().parse_args(argv)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", RuntimeWarning)
        code = _command(args)
    # After the command's own lines, as the program's last lines (an incomplete run).
    for warning in caught:
        if issubclass(warning.category, RuntimeWarning):
            print(f"yarnfort {args.command}: warning: {warning.message}", file=sys.stderr)
        else:
            warnings.showwarning(warning.message, warning.category, warning.filename,
                                 warning.lineno)
    return code


def _command(args: argparse.Namespace) -> int:
    """Run the command `args` asks for; its exit code."""
    try:
        if args.command == "reference":
            from .resources import reference_text

            sys.stdout.write(reference_text())
            return 0
        if args.command == "examples":
            from .resources import write_examples

            written = write_examples(args.folder, overwrite=args.force)
            print(f"yarnfort: wrote {len(written)} example files into"
                  f" {args.folder / 'inputs'}; run one with: cd {args.folder} &&"
                  " yarnfort < inputs/vnet.nml")
            return 0
        if args.command == "export-fabric":
            path = export_fabric_command(args)
            print(f"yarnfort: wrote {path}")
            return 0
        if args.command == "plot":
            path = plot_folder(args.folder, args.support, args.out, channel=args.channel,
                               step=args.step)
        elif args.command == "plot-membrane":
            path = plot_membrane_command(args)
        else:
            path = plot_states_command(args)
        print(f"yarnfort: wrote {path}")
    except (CommandError, OSError, ValueError, KeyError) as error:
        if isinstance(error, KeyError):
            error = error.args[0] if error.args else error
        print(f"yarnfort {args.command}: error: {error}", file=sys.stderr)
        return EXIT_BAD_INPUT
    return 0


if __name__ == "__main__":
    sys.exit(main())
