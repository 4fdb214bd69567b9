# SPDX-License-Identifier: MIT
"""Read a run's output folder: ``curve.csv``, ``reactions.csv`` and ``contacts.csv``, and
the VTK states (``states.pvd`` and the files it lists).

States are read with :mod:`meshio` when it is installed (any VTK XML encoding: ASCII,
inline or appended binary); without it, a small reader of the ASCII encoding is used.
A state is the yarns' file ``state_NNNNN.vtu`` (node positions, the two-node elements,
the field data ``step``, ``time``, load factors, a fabric's ``strain``, and every point
and cell data array by name: ``tension``, ``stretch`` and ``L0`` are required) and, next
to it, the blocks ``holders_NNNNN.vtu`` (gap-holders), ``links_NNNNN.vtu`` (periodic
links) and ``passages_NNNNN.vtu`` (one point per sliding passage) when the scene has them;
``state_NNNNN.vtm`` lists them by name, and ``states.pvd`` lists the ``.vtm`` files.
"""
from __future__ import annotations

import csv
import errno
import re
import warnings
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["Curve", "State", "ResultError", "read_curve", "read_reactions", "read_contacts",
           "read_state", "read_states", "read_run"]

#: ``kind`` of a link of a :class:`State` (0 would be a yarn element).
GAP_HOLDER = 1
PERIODIC_LINK = 2
#: The blocks of a state besides the yarns': file prefix (replacing ``state_``) -> kind
#: of link (None: the passages).
_PARTS = {"holders_": GAP_HOLDER, "links_": PERIODIC_LINK, "passages_": None}
#: Periodic links along one period agree to this fraction of the longest link.
PERIOD_TOLERANCE = 1e-9

#: Columns of text (not numbers) in the long-format step files.
_TEXT_COLUMNS = {"reactions.csv": ("support",), "contacts.csv": ("mode",)}


class ResultError(ValueError):
    """An output file that cannot be read as yarnfort wrote it; the message names the
    file and, where it applies, the line and column."""


@dataclass
class Curve:
    """One row per converged step of ``curve.csv`` (or, for ``reactions.csv`` and
    ``contacts.csv``, one row per node or passage and step).

    Attributes
    ----------
    columns : dict of str to numpy.ndarray
        Column name -> values (float; str for the text columns ``support`` of
        ``reactions.csv`` and ``mode`` of ``contacts.csv``), in file order.
    path : pathlib.Path or None
        The file read.
    """

    columns: dict[str, np.ndarray]
    path: Path | None = None

    def __getitem__(self, name: str) -> np.ndarray:
        try:
            return self.columns[name]
        except KeyError:
            raise KeyError(f"curve has no column {name!r}; columns: "
                           + ", ".join(self.columns)) from None

    def __len__(self) -> int:
        return len(next(iter(self.columns.values()))) if self.columns else 0

    @property
    def names(self) -> list[str]:
        """Column names, in file order."""
        return list(self.columns)

    @property
    def channels(self) -> list[str]:
        """The load channels' columns of ``curve.csv`` (``['p_force', 'p_disp']``
        without ``&path channels``): those after ``time``, before the first support,
        load or fabric column."""
        out = []
        for name in self.names[2:]:
            if name.endswith(("_rx", "_ry", "_rz", "_ux", "_uy", "_uz")) or name in (
                    "strain", "force_per_width", "direction"):
                break
            out.append(name)
        return out

    def reaction(self, support: str) -> np.ndarray:
        """Reaction force of a named support set on the net.

        Parameters
        ----------
        support : str
            The ``&support`` name.

        Returns
        -------
        numpy.ndarray
            Shape (n_steps, 3), N.

        Raises
        ------
        KeyError
            If the curve has no such support set (the message lists those it has).
        """
        missing = [f"{support}_r{k}" for k in "xyz" if f"{support}_r{k}" not in self.columns]
        if missing:
            known = [name[:-3] for name in self.columns if name.endswith("_rx")]
            raise KeyError(f"curve has no support {support!r}; supports: "
                           + (", ".join(known) or "none"))
        return np.column_stack([self.columns[f"{support}_r{k}"] for k in "xyz"])

    def displacement(self, name: str) -> np.ndarray:
        """Displacement of a named support set (its applied displacement) or of a load
        (``'load_<k>'``, the mean displacement of the nodes of ``&load`` number k).

        Parameters
        ----------
        name : str
            The ``&support`` name, or ``'load_1'``, ``'load_2'``, ...

        Returns
        -------
        numpy.ndarray
            Shape (n_steps, 3), m.

        Raises
        ------
        KeyError
            If the curve has no such set (the message lists those it has).
        """
        missing = [f"{name}_u{k}" for k in "xyz" if f"{name}_u{k}" not in self.columns]
        if missing:
            known = [column[:-3] for column in self.columns if column.endswith("_ux")]
            raise KeyError(f"curve has no displacement of {name!r}; sets: "
                           + (", ".join(known) or "none"))
        return np.column_stack([self.columns[f"{name}_u{k}"] for k in "xyz"])

    def to_array(self) -> np.ndarray:
        """The curve as a numpy structured array (one field per column)."""
        dtype = [(name, values.dtype) for name, values in self.columns.items()]
        table = np.empty(len(self), dtype=dtype)
        for name, values in self.columns.items():
            table[name] = values
        return table

    def to_dataframe(self) -> Any:
        """The curve as a :class:`pandas.DataFrame` (pandas must be installed).

        Raises
        ------
        ImportError
            If pandas is not installed (the message names ``pip install
            'yarnfort[pandas]'``).
        """
        from ._extras import import_extra

        pandas = import_extra("pandas", "pandas", "Curve.to_dataframe")
        return pandas.DataFrame(self.columns)


@dataclass
class State:
    """A converged network state.

    Attributes
    ----------
    position : numpy.ndarray
        Node positions, shape (n_nodes, 3), m.
    elements : numpy.ndarray
        Node indices (from 0) of each two-node element, shape (n_elements, 2).
    tension, stretch, length0 : numpy.ndarray
        Per element: tension (N), stretch l/L0 and reference length L0 (m).
    point_data, cell_data : dict of str to numpy.ndarray
        Every array of the yarns' file, by name (the three above included in
        ``cell_data``).
    links : numpy.ndarray
        Node indices (from 0) of each link, (leader, follower): the gap-holders, then
        the periodic links, shape (n_links, 2); empty for a state without them.
    link_kind : numpy.ndarray
        The kind of each link: :data:`GAP_HOLDER` or :data:`PERIODIC_LINK`.
    link_data : dict of str to numpy.ndarray
        The cell data of the links, by name: ``period`` (the lattice vector each spans,
        m), ``leader``, ``follower`` (1-based), and the gap-holders' ``contact_force``
        (N), ``force`` (N), ``stretch`` and ``L0`` (NaN for a periodic link).
    passages : dict of str to numpy.ndarray
        One value per sliding passage: ``passage``, ``node``, ``yarn`` (1-based),
        ``mode`` (1 stick, 2 forward, 3 backward, 4 locked), ``flow``, ``tension_min``,
        ``tension_max``, ``critical_tension``, ``wrap_angle`` (as in ``contacts.csv``);
        empty for a scene without passages.
    field_data : dict of str to numpy.ndarray
        The file's field data: ``step``, ``time``, the load factors and, for a fabric,
        ``strain`` and ``force_per_width`` (one value each).
    """

    position: np.ndarray
    elements: np.ndarray
    tension: np.ndarray
    stretch: np.ndarray
    length0: np.ndarray
    point_data: dict[str, np.ndarray] = field(default_factory=dict)
    cell_data: dict[str, np.ndarray] = field(default_factory=dict)
    links: np.ndarray = field(default_factory=lambda: np.zeros((0, 2), dtype=int))
    link_kind: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=int))
    link_data: dict[str, np.ndarray] = field(default_factory=dict)
    field_data: dict[str, np.ndarray] = field(default_factory=dict)
    passages: dict[str, np.ndarray] = field(default_factory=dict)

    @property
    def step(self) -> int | None:
        """The load step of this state (field data ``step``), or None if the file has
        no such field."""
        if "step" not in self.field_data:
            return None
        return int(np.ravel(self.field_data["step"])[0])

    def periods(self) -> np.ndarray:
        """The current period vectors of a periodic cell, from its links.

        Each link's cell data ``period`` is the lattice vector it spans (a periodic
        link joins a node to its image one period away; a gap-holder may join a node
        to the image of its partner); files without that array give the vectors of the
        periodic links (image minus node). Vectors along the same period are grouped
        (they agree to :data:`PERIOD_TOLERANCE` of the longest, up to sign); the
        vectors returned are independent, ordered by the axis each mostly runs along
        (x first), each with that component positive.

        Returns
        -------
        numpy.ndarray
            Shape (n_periods, 3), m; (0, 3) for a state without periodic links.

        Raises
        ------
        ResultError
            If a lattice vector is no integer combination of the periods found (not a
            periodic cell as yarnfort writes it).
        """
        if "period" in self.link_data:
            vectors = np.asarray(self.link_data["period"], dtype=float).reshape(-1, 3)
        else:
            pairs = self.links[self.link_kind == PERIODIC_LINK]
            vectors = self.position[pairs[:, 1]] - self.position[pairs[:, 0]]
        lengths = np.linalg.norm(vectors, axis=1)
        vectors = vectors[lengths > 0]
        if len(vectors) == 0:
            return np.zeros((0, 3))
        # One sign per vector: its largest component positive.
        largest = np.argmax(np.abs(vectors), axis=1)
        vectors *= np.sign(vectors[np.arange(len(vectors)), largest])[:, None]
        scale = np.linalg.norm(vectors, axis=1).max()
        groups: list[list[np.ndarray]] = []
        for vector in vectors[np.argsort(np.linalg.norm(vectors, axis=1))]:
            for group in groups:
                if np.linalg.norm(vector - group[0]) <= PERIOD_TOLERANCE * scale:
                    group.append(vector)
                    break
            else:
                groups.append([vector])
        basis: list[np.ndarray] = []
        for group in groups:
            mean = np.mean(group, axis=0)
            if np.linalg.matrix_rank(np.array(basis + [mean]),
                                     tol=PERIOD_TOLERANCE * scale) > len(basis):
                basis.append(mean)
            else:
                # A combination of periods (a corner link): it must be one exactly.
                coefficients, *_ = np.linalg.lstsq(np.array(basis).T, mean, rcond=None)
                if (np.abs(coefficients - np.round(coefficients)).max() > PERIOD_TOLERANCE
                        or np.linalg.norm(np.array(basis).T @ np.round(coefficients)
                                          - mean) > PERIOD_TOLERANCE * scale):
                    raise ResultError("periodic links that are no combination of the"
                                      " cell's periods: not a periodic cell")
        basis.sort(key=lambda vector: int(np.argmax(np.abs(vector))))
        return np.array(basis)


def _curve_file(path: str | Path, name: str = "curve.csv") -> Path:
    path = Path(path)
    return path / name if path.is_dir() else path


def read_reactions(path: str | Path) -> Curve:
    """Read ``reactions.csv`` (``&output node_reactions``): the reaction of every
    constrained node per step.

    Parameters
    ----------
    path : str or Path
        The file or its folder.

    Returns
    -------
    Curve
        Columns ``step``, ``support`` (str), ``node``, ``rx``, ``ry``, ``rz`` (N), one
        row per node of each support set and step.

    Raises
    ------
    ResultError
        As :func:`read_curve`.
    OSError
        If the file cannot be read.
    """
    return _read_csv(_curve_file(path, "reactions.csv"), _TEXT_COLUMNS["reactions.csv"])


def read_contacts(path: str | Path) -> Curve:
    """Read ``contacts.csv`` (``&output contact_state``): the state of every sliding
    passage per step.

    Parameters
    ----------
    path : str or Path
        The file or its folder.

    Returns
    -------
    Curve
        Columns ``step``, ``passage``, ``node``, ``yarn``, ``flow`` (m), ``mode`` (str:
        stick, forward, backward, locked), ``tension_min``, ``tension_max``,
        ``critical_tension`` (N), ``wrap_angle`` (rad), one row per passage and step.

    Raises
    ------
    ResultError
        As :func:`read_curve`.
    OSError
        If the file cannot be read.
    """
    return _read_csv(_curve_file(path, "contacts.csv"), _TEXT_COLUMNS["contacts.csv"])


def read_curve(path: str | Path) -> Curve:
    """Read ``curve.csv`` (a file, or the output folder holding it).

    Parameters
    ----------
    path : str or Path
        The file or its folder.

    Returns
    -------
    Curve
        The integer columns (``step``, ``direction``, counts) as integers, the others as
        floats; a file with only its header gives a curve of 0 rows.

    Raises
    ------
    ResultError
        For an empty file, a row with the wrong number of cells, or a cell that is not
        a number (the message names the file, line and column).
    OSError
        If the file cannot be read.

    Warns
    -----
    RuntimeWarning
        If the last row has no line end (a run killed while writing it): that row is
        left out (as a restart drops it), as in :func:`read_reactions` and
        :func:`read_contacts`.
    """
    return _read_csv(_curve_file(path), ())


#: A cell written as an integer.
_INTEGER = re.compile(r"^\s*[+-]?\d+\s*$")


def _read_csv(path: Path, text_columns: tuple[str, ...]) -> Curve:
    """A step file of the run: a header line, then rows of numbers (text in the named
    `text_columns`, kept as str)."""
    with open(path, newline="") as stream:
        text = stream.read()
    rows = list(csv.reader(text.splitlines()))
    # Every row the program writes ends with a line end; a last row without one was cut
    # short by a kill (its last number may be cut to another valid one): left out.
    if len(rows) > 1 and not text.endswith(("\n", "\r")):
        warnings.warn(f"{path}, line {len(rows)}: the last row has no line end (cut short"
                      " by a killed run); it is left out", RuntimeWarning, stacklevel=3)
        rows = rows[:-1]
    if not rows or not any(cell.strip() for cell in rows[0]):
        raise ResultError(f"{path}: empty file (no header line): not a complete"
                          " yarnfort curve")
    header = [cell.strip() for cell in rows[0]]
    numeric = [name for name in header if name not in text_columns]
    texts: dict[str, list[str]] = {name: [] for name in header if name in text_columns}
    values: list[list[float]] = []
    for number, row in enumerate(rows[1:], start=2):
        if not row:
            continue
        if len(row) != len(header):
            raise ResultError(f"{path}, line {number}: {len(row)} cells, the header has"
                              f" {len(header)} (a cut or foreign row)")
        parsed = []
        for name, cell in zip(header, row):
            if name in texts:
                texts[name].append(cell.strip())
                continue
            try:
                parsed.append(float(cell))
            except ValueError:
                raise ResultError(f"{path}, line {number}, column {name!r}: {cell!r} is not"
                                  " a number") from None
        values.append(parsed)
    table = np.array(values, dtype=float).reshape(len(values), len(numeric))
    columns = {name: table[:, k].copy() for k, name in enumerate(numeric)}
    # A column the program writes as integers (no point, no exponent) is one.
    for k, name in enumerate(numeric):
        cells = [row[header.index(name)] for row in rows[1:] if row]
        if cells and all(_INTEGER.match(cell) for cell in cells):
            columns[name] = table[:, k].astype(np.int64)
    columns.update({name: np.array(cells, dtype=str) for name, cells in texts.items()})
    return Curve({name: columns[name] for name in header}, path)


def _ascii_array(piece: ET.Element, section: str, name: str | None) -> np.ndarray:
    for node in piece.iterfind(f"{section}/DataArray"):
        if name is None or node.get("Name") == name:
            if node.get("format", "ascii") != "ascii":
                raise ResultError(f"array {node.get('Name')!r} is {node.get('format')}:"
                                  " install meshio to read binary VTK files")
            return np.array((node.text or "").split(), dtype=float)
    raise KeyError(name)


def _read_ascii(path: Path) -> tuple[np.ndarray, np.ndarray, dict, dict, dict]:
    grid = ET.parse(path).getroot().find("UnstructuredGrid")
    piece = grid.find("Piece") if grid is not None else None
    if piece is None:
        raise ResultError(f"{path}: not a VTK UnstructuredGrid file")
    field_data = {node.get("Name"): _ascii_array(grid, "FieldData", node.get("Name"))
                  for node in grid.iterfind("FieldData/DataArray")}
    points = _ascii_array(piece, "Points", None).reshape(-1, 3)
    connectivity = _ascii_array(piece, "Cells", "connectivity").astype(int)
    per_cell = 2 if "line" in _ascii_types(piece) else 1
    point_data = {node.get("Name"): _ascii_array(piece, "PointData", node.get("Name"))
                  for node in piece.iterfind("PointData/DataArray")}
    cell_data = {node.get("Name"): _ascii_array(piece, "CellData", node.get("Name"))
                 for node in piece.iterfind("CellData/DataArray")}
    for data, count in ((point_data, len(points)), (cell_data, len(connectivity) // per_cell)):
        for name, values in data.items():
            if count and values.size != count and values.size % count == 0:
                data[name] = values.reshape(count, -1)
    return points, connectivity.reshape(-1, per_cell), point_data, cell_data, field_data


def _ascii_types(piece: ET.Element) -> set[str]:
    """The cell types of a piece: 'line' (VTK 3) or 'vertex' (VTK 1)."""
    types = set(_ascii_array(piece, "Cells", "types").astype(int).tolist())
    return {"line" if t == 3 else "vertex" for t in types}


def _read_meshio(meshio: Any, path: Path, cell_type: str = "line"
                 ) -> tuple[np.ndarray, np.ndarray, dict, dict, dict]:
    mesh = meshio.read(path)
    blocks = [k for k, block in enumerate(mesh.cells) if block.type == cell_type]
    if not blocks and cell_type == "line":
        raise ResultError(f"{path}: no line cells (two-node elements)")
    if not blocks:
        n = 2 if cell_type == "line" else 1
        return (np.asarray(mesh.points, dtype=float).reshape(-1, 3),
                np.zeros((0, n), dtype=int), {}, {}, {})
    elements = np.concatenate([mesh.cells[k].data for k in blocks]).astype(int)
    cell_data = {name: np.concatenate([np.asarray(arrays[k]) for k in blocks])
                 for name, arrays in mesh.cell_data.items()}
    point_data = {name: np.asarray(values) for name, values in mesh.point_data.items()}
    field_data = {name: np.asarray(values) for name, values in mesh.field_data.items()}
    return np.asarray(mesh.points, dtype=float), elements, point_data, cell_data, field_data


def _read_grid(path: Path, cell_type: str = "line"
               ) -> tuple[np.ndarray, np.ndarray, dict, dict, dict]:
    """Points, cells of `cell_type`, point, cell and field data of one .vtu file."""
    # Checked here, not left to meshio, whose ReadError is no OSError.
    if not path.exists():
        raise FileNotFoundError(errno.ENOENT, "no such VTK state file", str(path))
    try:
        import meshio
    except ImportError:
        meshio = None
    unreadable: tuple[type[Exception], ...] = (ET.ParseError, KeyError, ValueError)
    if meshio is not None:
        unreadable += (meshio.ReadError,)
    try:
        return (_read_meshio(meshio, path, cell_type) if meshio is not None
                else _read_ascii(path))
    except unreadable as error:
        if isinstance(error, ResultError):
            raise
        raise ResultError(f"{path}: not a readable yarnfort VTK state ({error})") from None


def _yarns_block(path: Path) -> Path:
    """The yarns' file of a state's multiblock file (``state_NNNNN.vtm``): its block
    named ``yarns`` (or its first block)."""
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError as error:
        raise ResultError(f"{path}: not a readable multiblock file ({error})") from None
    blocks = [d for d in root.iter("DataSet") if d.get("file")]
    if not blocks:
        raise ResultError(f"{path}: lists no block")
    yarns = next((d for d in blocks if d.get("name") == "yarns"), blocks[0])
    return path.with_name(yarns.get("file"))


def read_state(path: str | Path) -> State:
    """Read one VTK state written by yarnfort: the yarns' file (``state_*.vtu``) and the
    blocks next to it (gap-holders, periodic links, passages) that exist.

    Parameters
    ----------
    path : str or Path
        The yarns' ``state_NNNNN.vtu`` file, or the state's multiblock file
        ``state_NNNNN.vtm``.

    Returns
    -------
    State

    Raises
    ------
    FileNotFoundError
        If there is no such file (with either reader).
    ResultError
        If a file is not a state of line cells with ``tension``, ``stretch`` and
        ``L0`` cell data, or a block lacks the arrays yarnfort writes there.
    """
    path = Path(path)
    if path.suffix == ".vtm":
        path = _yarns_block(path)
    points, elements, point_data, cell_data, field_data = _read_grid(path)
    missing = [name for name in ("tension", "stretch", "L0") if name not in cell_data]
    if missing:
        raise ResultError(f"{path}: no cell data {', '.join(missing)}")
    pairs, kinds, tables = [], [], []
    passages: dict[str, np.ndarray] = {}
    for prefix, kind in _PARTS.items():
        part = path.with_name(prefix + path.name[len("state_"):])
        if not path.name.startswith("state_") or not part.exists():
            continue
        _, _, part_points, part_cells, _ = _read_grid(
            part, "line" if kind == GAP_HOLDER else "vertex")
        if kind is None:
            passages = {name: np.asarray(values) for name, values in part_points.items()}
            continue
        if "leader" not in part_cells or "follower" not in part_cells:
            raise ResultError(f"{part}: no cell data leader, follower")
        leader = np.ravel(part_cells["leader"]).astype(int)
        pairs.append(np.column_stack([leader, np.ravel(part_cells["follower"])]) - 1)
        kinds.append(np.full(len(leader), kind))
        tables.append({name: np.asarray(values) for name, values in part_cells.items()})
    links = np.concatenate(pairs).astype(int) if pairs else np.zeros((0, 2), dtype=int)
    link_kind = np.concatenate(kinds) if kinds else np.zeros(0, dtype=int)
    link_data: dict[str, np.ndarray] = {}
    for name in {name for table in tables for name in table}:
        columns = []
        for table, kind in zip(tables, kinds):
            if name in table:
                columns.append(np.asarray(table[name], dtype=float))
            else:
                shape = (len(kind),) + np.shape(next(t[name] for t in tables if name in t))[1:]
                columns.append(np.full(shape, np.nan))
        link_data[name] = np.concatenate(columns)
    return State(position=points, elements=elements,
                 tension=np.ravel(cell_data["tension"]),
                 stretch=np.ravel(cell_data["stretch"]),
                 length0=np.ravel(cell_data["L0"]),
                 point_data=point_data, cell_data=cell_data, links=links,
                 link_kind=link_kind, link_data=link_data, field_data=field_data,
                 passages=passages)


def read_states(folder: str | Path) -> list[State]:
    """The VTK states of an output folder, in step order.

    The states are those listed in the folder's ``states.pvd`` (the files of this run
    only: each state's multiblock file, or in folders of earlier versions the yarns'
    files, part 0, each read with its blocks); without a ``states.pvd``, every
    ``state_*.vtu`` in name order.

    Parameters
    ----------
    folder : str or Path
        The output folder.

    Returns
    -------
    list of State

    Raises
    ------
    FileNotFoundError
        If a state the collection lists is missing.
    ResultError
        If the collection or a state is not readable as yarnfort wrote it.
    """
    folder = Path(folder)
    collection = folder / "states.pvd"
    if collection.exists():
        try:
            root = ET.parse(collection).getroot()
        except ET.ParseError as error:
            raise ResultError(f"{collection}: not a readable collection ({error})") from None
        return [read_state(folder / d.get("file")) for d in root.iter("DataSet")
                if d.get("part", "0") == "0"]
    return [read_state(p) for p in sorted(folder.glob("state_*.vtu"),
                                          key=lambda p: int(p.stem[len("state_"):]))]


def read_run(folder: str | Path) -> Any:
    """An output folder as a :class:`~yarnfort.RunResult`, the type
    :func:`~yarnfort.run_scene` returns: ``.curve``, ``.states``, ``.to_dataframe()``.

    Parameters
    ----------
    folder : str or Path
        The output folder.

    Returns
    -------
    RunResult
        ``outcome`` is ``'read'`` (not run here), or ``'incomplete'`` when the curve
        ends before the end of the load path of the run's ``input.nml`` (a failed step,
        Ctrl-C, ``max_steps``, a killed run or one still going); ``n_steps`` the rows
        of its curve.

    Raises
    ------
    ResultError
        If the folder holds no readable ``curve.csv``.

    Warns
    -----
    RuntimeWarning
        For an incomplete run, naming where its curve ends and where the path does.
    """
    from .runner import RunResult

    folder = Path(folder)
    if not folder.is_dir():
        raise ResultError(f"no output folder {str(folder)!r}")
    curve = read_curve(folder)
    missing = incomplete_reason(folder, curve)
    if missing:
        warnings.warn(f"{folder}: {missing}", RuntimeWarning, stacklevel=2)
    return RunResult(folder.resolve(), len(curve), "incomplete" if missing else "read")


#: A curve ends at the path's end when its last time is within this fraction of the
#: path's largest |time| (steps land on the knots; only round-off is forgiven).
PATH_END_TOLERANCE = 1e-9


def incomplete_reason(folder: Path, curve: Curve) -> str:
    """Why the run of `folder` did not reach the end of its load path ('' if it did, or
    if its input.nml gives no path to judge by)."""
    try:
        import f90nml

        times = np.atleast_1d(np.asarray(f90nml.read(folder / "input.nml")["path"]["time"],
                                         dtype=float))
    except Exception:  # noqa: BLE001 - no echo to judge by: nothing is claimed
        return ""
    times = times[np.isfinite(times)]
    if times.size == 0 or "time" not in curve.columns:
        return ""
    end = float(times[-1])
    if len(curve) and curve["time"][-1] >= end - PATH_END_TOLERANCE * np.abs(times).max():
        return ""
    reached = (f"the curve ends at step {int(curve['step'][-1])}, time"
               f" {float(curve['time'][-1]):g}" if len(curve) else "the curve has no step")
    return (f"incomplete run: {reached}, the load path at {end:g} (a failed step, Ctrl-C,"
            " max_steps, a killed run or one still going; &control restart = .true."
            " goes on)")
