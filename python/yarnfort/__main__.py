# SPDX-License-Identifier: MIT
"""Command line:

- ``python -m yarnfort plot <output folder> [--support NAME] [--out FILE]`` writes a PNG
  with the force–displacement (hysteresis) plot of one support set (for a generated
  fabric: force per unit width against strain) and the final deformed network coloured
  by tension;
- ``python -m yarnfort plot-states <output folder> [-o FILE] [--strains 0 0.5 1] ...``
  writes a PNG of the deformed states nearest to the given strains, coloured by tension
  on one scale (:func:`yarnfort.plots.plot_states`).

Exit codes: 0 success, 2 bad arguments, a missing or unreadable output folder, an
unknown support set, or strains the run does not reach.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from .namelist import read_scene
from .results import Curve, read_curve, read_states

# matplotlib (through .plots) is imported only once a plot is to be made, so that
# --help and argument errors answer quickly.

#: Exit code for bad arguments or unusable inputs (as the Fortran program).
EXIT_BAD_INPUT = 2
#: File name of the default plot inside the output folder.
DEFAULT_PLOT = "plot.png"
#: File name of the default state plot inside the output folder.
DEFAULT_STATES_PLOT = "states.png"


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


def plot_folder(folder: Path, support: str | None = None, out: Path | None = None) -> Path:
    """Write the summary plot of an output folder.

    Parameters
    ----------
    folder : Path
        A run's output folder (holds curve.csv).
    support : str, optional
        Support set to plot (default: the first that moves).
    out : Path, optional
        PNG to write (default ``<folder>/plot.png``).

    Returns
    -------
    Path
        The PNG written.

    Raises
    ------
    CommandError
        For a missing folder or curve, a curve without rows or an unknown support.
    """
    if not folder.is_dir():
        raise CommandError(f"no output folder {str(folder)!r}")
    if not (folder / "curve.csv").is_file():
        raise CommandError(f"{str(folder)!r} holds no curve.csv: not a yarnfort output"
                           " folder")
    from matplotlib.figure import Figure

    from .plots import plot_fabric_hysteresis, plot_hysteresis, plot_network, save_figure

    curve = read_curve(folder)
    if len(curve) == 0:
        raise CommandError(f"{folder / 'curve.csv'} has no rows (only its header): the run"
                           " wrote no converged step, nothing to plot")
    states = read_states(folder)
    figure = Figure(figsize=(11, 4.5), layout="constrained")
    left, right = figure.subplots(1, 2)
    if support is None and "force_per_width" in curve.names:
        # A generated fabric: its effective curve.
        plot_fabric_hysteresis(curve, ax=left)
        left.set_title("effective curve of the fabric")
    else:
        name = choose_support(curve, folder, support)
        component = _dominant_component(curve, name)
        # The abscissa: p_disp if it moves, else the first load channel that does.
        channels = curve.channels
        moving = [c for c in channels if np.ptp(curve[c]) > 0]
        x = "p_disp" if "p_disp" in moving else (moving or channels or ["time"])[0]
        plot_hysteresis(curve, name, component=component, x=x, ax=left)
        left.set_title(f"reaction of '{name}'")
    if states:
        final = states[-1]
        plot_network(final, ax=right, projection=_dominant_projection(final.position))
        right.set_title(f"final state (step {int(curve['step'][-1])})")
    else:
        right.set_axis_off()
        right.text(0.5, 0.5, "no states written", ha="center", va="center")
    return save_figure(figure, out if out is not None else folder / DEFAULT_PLOT)


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="python -m yarnfort",
        description="yarnfort result tools: plot a run's output folder.")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    plot = commands.add_parser(
        "plot", help="write a PNG: force-displacement loop and final network",
        description="Write a PNG with the force-displacement (hysteresis) plot of a"
        " support set and the final deformed network coloured by tension.")
    plot.add_argument("folder", type=Path, help="output folder of a run (holds curve.csv)")
    plot.add_argument("--support", metavar="NAME",
                      help="support set to plot (default: the first that moves)")
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
    return parser


def plot_states_command(args: argparse.Namespace) -> Path:
    """Write the state plot that ``plot-states`` asks for; the PNG written."""
    from .plots import plot_states, save_figure

    figure = plot_states(args.folder, tuple(args.strains), by=args.by, of_peak=args.of_peak,
                         images=tuple(args.images), projections=tuple(args.projection),
                         depth_scale=args.depth_scale, title=args.title)
    return save_figure(figure, args.out if args.out is not None
                       else args.folder / DEFAULT_STATES_PLOT)


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
    try:
        if args.command == "plot":
            path = plot_folder(args.folder, args.support, args.out)
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
