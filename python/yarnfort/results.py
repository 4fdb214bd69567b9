# SPDX-License-Identifier: MIT
"""Read a run's output folder: ``curve.csv`` and the ``state_NNNNN.vtu`` files."""
from __future__ import annotations

import base64
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import numpy as np


@dataclass
class Curve:
    """One row per converged step; ``columns`` maps a column name to a numpy array."""

    columns: dict[str, np.ndarray]

    def __getitem__(self, name: str) -> np.ndarray:
        return self.columns[name]

    @property
    def names(self) -> list[str]:
        return list(self.columns)

    def reaction(self, support: str) -> np.ndarray:
        """Reaction force (n_steps, 3) applied by the named support set on the net."""
        return np.column_stack([self.columns[f"{support}_r{k}"] for k in "xyz"])


@dataclass
class State:
    """A converged network state: node positions (n, 3) and per-element fields."""

    position: np.ndarray
    elements: np.ndarray
    tension: np.ndarray
    stretch: np.ndarray
    length0: np.ndarray


def read_curve(path: str | Path) -> Curve:
    """Read ``curve.csv`` (a file, or the output folder holding it)."""
    path = Path(path)
    if path.is_dir():
        path = path / "curve.csv"
    data = np.genfromtxt(path, delimiter=",", names=True, ndmin=1)
    return Curve({name: np.atleast_1d(data[name]) for name in data.dtype.names})


_VTK_TYPES = {"Float64": "<f8", "Int64": "<i8", "Int32": "<i4", "UInt8": "u1"}


def _values(node: ET.Element, appended: str) -> np.ndarray:
    """The values of a DataArray: inline ASCII, or appended base64 (a UInt64 byte
    count, then the bytes, each encoded on its own), as yarnfort writes them."""
    dtype = np.dtype(_VTK_TYPES[node.get("type")])
    if node.get("format") != "appended":
        return np.array((node.text or "").split(), dtype=float).astype(dtype)
    data = appended[int(node.get("offset")):]
    count = int(np.frombuffer(base64.b64decode(data[:12]), "<u8")[0])
    return np.frombuffer(base64.b64decode(data[12:12 + 4 * -(-count // 3)]), dtype)


def _array(piece: ET.Element, name: str, appended: str = "") -> np.ndarray:
    for node in piece.iter("DataArray"):
        if node.get("Name") == name:
            return _values(node, appended)
    raise KeyError(f"no DataArray named {name!r}")


def read_state(path: str | Path) -> State:
    """Read one ``state_NNNNN.vtu`` file written by yarnfort: the yarn elements (the
    links, cells of another ``kind``, are left out)."""
    root = ET.parse(path).getroot()
    block = root.find("AppendedData")
    appended = "" if block is None else (block.text or "").strip()[1:]
    piece = root.find("UnstructuredGrid/Piece")
    points = _values(piece.find("Points/DataArray"), appended).astype(float)
    connectivity = _array(piece, "connectivity", appended).astype(int).reshape(-1, 2)
    try:
        element = _array(piece, "kind", appended) == 0
    except KeyError:
        element = np.ones(len(connectivity), dtype=bool)
    return State(
        position=points.reshape(-1, 3),
        elements=connectivity[element],
        tension=_array(piece, "tension", appended).astype(float)[element],
        stretch=_array(piece, "stretch", appended).astype(float)[element],
        length0=_array(piece, "L0", appended).astype(float)[element],
    )


def read_states(folder: str | Path) -> list[State]:
    """The VTK states of an output folder, in step order, as listed in its states.pvd
    (the files of this run only)."""
    folder = Path(folder)
    collection = folder / "states.pvd"
    if collection.exists():
        root = ET.parse(collection).getroot()
        return [read_state(folder / d.get("file")) for d in root.iter("DataSet")]
    return [read_state(p) for p in sorted(folder.glob("state_*.vtu"),
                                          key=lambda p: int(p.stem[len("state_"):]))]


def read_run(folder: str | Path) -> tuple[Curve, list[State]]:
    """The curve and every written state of an output folder."""
    return read_curve(folder), read_states(folder)
