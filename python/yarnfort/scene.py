# SPDX-License-Identifier: MIT
"""Build scenes in Python: an object for each namelist group, numpy arrays in and out.

A :class:`Scene` holds materials, contacts, nodes (or a geometry file, or a generated
fabric), yarns, supports, loads, the load path and the solver, output and control
settings. It writes the namelist that ``yarnfort < scene.nml`` reads
(:meth:`Scene.write`), reads one back (:meth:`Scene.read`: reading a namelist and
writing it again gives the same effective input), and runs in process
(:meth:`Scene.run`, see :func:`yarnfort.run_scene`).

Validation has two layers. Building an object checks what Python can see alone, against
the one description of the input that also makes the library's reader (every group and
variable with its type, shape, range and choices; installed with the package): a
variable its group does not have is an :class:`UnknownVariableError` (a
:class:`SceneError` and a :class:`TypeError`) that suggests the name meant; types, array
shapes, ranges, names and references between groups (a yarn's material must exist, a
support's nodes must be nodes of the scene) are checked. An unset parameter is None,
never a marker value a real input could collide with. :meth:`Scene.check` then hands the
scene to the library's own reader and checker (the program's ``&control check_only``),
which knows every rule of the input reference (``python -m yarnfort reference``;
``inputs/REFERENCE.md`` in the repository); :meth:`Scene.run` does the same before it
solves. Messages name the group and variable.

Node ids are the namelist's: 1..n in the order of ``nodes``. Variables this module does
not name (settings of ``&solver``, ``&output``, ``&control``, a ``&fabric``, or newer
variables of any group) are given as keywords and written as they are; reading a
namelist keeps them in each object's ``extra``. Relative file names (tables, geometry
files, the output folder) are taken from the working directory of the run, as for
``yarnfort < scene.nml``.

Example
-------
A string under a central point load, as in ``inputs/vnet.nml`` but straight at the start
and loaded once, that the load draws into a V (``python -m yarnfort examples DIR`` writes
the example scenes)::

    import numpy as np, yarnfort
    scene = yarnfort.Scene("V-net", output={"folder": "out/vnet_py"})
    scene.add_material("yarn", "linear", stiffness=100.0)
    scene.nodes = np.array([[-1.0, 0, 0], [0, 0, 0], [1, 0, 0]])
    scene.add_yarn("yarn", [1, 2, 3])
    scene.add_support("ends", [1, 3])
    scene.add_load([2], force=[0, -1.0, 0])
    scene.path = yarnfort.LoadPath(time=[0, 1], p_force=[0, 1])
    result = scene.run(progress=True)
"""
from __future__ import annotations

import difflib
import os
import re
import tempfile
from dataclasses import dataclass, field, fields
from pathlib import Path
from typing import Any

import f90nml
import numpy as np
from numpy.typing import ArrayLike

from .address import AddressError, entries_from_first
from .namelist import make_namelist, read_scene
from .resources import input_description

__all__ = ["Scene", "SceneError", "UnknownVariableError", "Material", "Contact", "Yarn",
           "Support", "Load", "LoadPath", "Fabric", "Geometry", "Obstacle", "Ring"]

_NAME = re.compile(r"^[A-Za-z0-9_.\-]+$")
_FIX = re.compile(r"^(?!.*(.).*\1)[xyzXYZ]{1,3}$")


class SceneError(ValueError):
    """A scene that cannot be written as input; the message names group and variable."""


class UnknownVariableError(SceneError, TypeError):
    """A variable that its group does not have (a typo: the message suggests the name
    meant); also a :class:`TypeError`, as an unexpected keyword argument is."""


def _known_variables(group: str) -> dict[str, dict[str, Any]]:
    """The variables of ``&group`` in the one description of the input
    (:func:`yarnfort.resources.input_description`), by name."""
    for entry in input_description()["groups"]:
        if entry["name"] == group:
            return {var["name"]: var for var in entry["variables"]}
    raise KeyError(group)


#: Bounds of the description's ranges: '> 0', '>= 1', '(0, 1)', '[a, b]'.
_BOUND = re.compile(r"^(>=?)\s*(\S+)$")
_INTERVAL = re.compile(r"^([\[(])\s*([^,]+),\s*([^\])]+)([\])])$")


def _in_range(value: float, rule: str | None) -> bool:
    if rule is None or rule == "finite":
        return bool(np.isfinite(value))
    if match := _BOUND.match(rule):
        bound = float(match[2])
        return value >= bound if match[1] == ">=" else value > bound
    if match := _INTERVAL.match(rule):
        low, high = float(match[2]), float(match[3])
        above = value >= low if match[1] == "[" else value > low
        below = value <= high if match[4] == "]" else value < high
        return above and below
    return True  # a rule in words: the library checks it


def _check_value(group: str, var: dict[str, Any], value: Any, where: str) -> None:
    """One variable's type, shape, range and choices as the description gives them."""
    name = var["name"]
    if value is None:
        return
    if isinstance(value, np.ndarray):
        value = value.tolist()
    shape = var["shape"]
    entries = value if isinstance(value, (list, tuple)) else [value]
    if shape is None and isinstance(value, (list, tuple)):
        raise SceneError(f"{where} {name}: expected one value, got {len(entries)}")
    if isinstance(shape, int) and len(entries) > shape:
        raise SceneError(f"{where} {name}: at most {shape} values, got {len(entries)}")
    kind = var["type"]
    for entry in entries:
        if entry is None:
            continue  # an entry left unset (its default)
        if kind == "character":
            if not isinstance(entry, str):
                raise SceneError(f"{where} {name}: expected a string, got {entry!r}")
            # The reader counts bytes: 'ü' is two in UTF-8.
            if len(entry.encode("utf-8")) > var["length"]:
                raise SceneError(f"{where} {name}: {entry!r} is longer than"
                                 f" {var['length']} characters (bytes in UTF-8)")
            # f90nml writes a line break as the two characters '\n': refused, not changed.
            if any(ord(char) < 32 and char != "\t" or ord(char) == 127 for char in entry):
                raise SceneError(f"{where} {name}: {entry!r} holds a line break or other"
                                 " control character, which a namelist string cannot hold")
            choices = var["choices"]
            folded = entry.lower() if var["lower"] else entry
            advice = (var.get("retired") or {}).get(folded)
            if advice:
                raise SceneError(f"{where} {name} = {entry!r} is no longer offered: {advice}")
            if choices and not var["checked_by"] and folded not in choices:
                raise SceneError(f"{where} {name}: {entry!r} is not one of "
                                 + ", ".join(repr(c) for c in choices))
        elif kind == "logical":
            if not isinstance(entry, (bool, np.bool_)):
                raise SceneError(f"{where} {name}: expected True or False, got {entry!r}")
        else:
            if isinstance(entry, (bool, np.bool_)) or not isinstance(
                    entry, (int, float, np.integer, np.floating)):
                raise SceneError(f"{where} {name}: expected a number, got {entry!r}")
            if kind == "integer" and not isinstance(entry, (int, np.integer)):
                raise SceneError(f"{where} {name}: expected an integer, got {entry!r}")
            rule = None if var["checked_by"] else var["range"]
            if not _in_range(float(entry), rule or "finite"):
                unit = f" {var['unit']}" if var["unit"] not in ("", "1") else ""
                raise SceneError(f"{where} {name} = {entry!r}{unit}: must be "
                                 + (rule or "finite"))


def _check_group(group: str, variables: dict[str, Any], where: str) -> None:
    """Every variable of one group against the description: a name the group does not
    have is an :class:`UnknownVariableError` that suggests the name meant; types, shapes,
    ranges and choices are checked as the library's reader does."""
    known = _known_variables(group)
    for key, value in variables.items():
        if key not in known:
            close = difflib.get_close_matches(key, list(known), n=1)
            hint = f"; did you mean {close[0]!r}?" if close else ""
            raise UnknownVariableError(
                f"{where}: &{group} has no variable {key!r}{hint} (it has:"
                f" {', '.join(known)}; python -m yarnfort reference)")
        _check_value(group, known[key], value, where)


def _name(value: Any, where: str) -> str:
    if not isinstance(value, str) or not _NAME.match(value):
        raise SceneError(f"{where}: {value!r} is not a name (one word of letters, digits,"
                         " '_', '-', '.')")
    return value


def _reals(value: ArrayLike, where: str, shape: tuple[int, ...] | None = None
           ) -> np.ndarray:
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise SceneError(f"{where}: expected numbers, got {value!r}") from None
    if shape is not None and array.shape != shape:
        raise SceneError(f"{where}: expected shape {shape}, got {array.shape}")
    if not np.all(np.isfinite(array)):
        raise SceneError(f"{where}: values must be finite")
    return array


def _ids(value: ArrayLike, where: str, minimum: int = 1) -> np.ndarray:
    array = np.atleast_1d(np.asarray(value))
    if array.ndim != 1 or array.size < minimum or not np.issubdtype(array.dtype, np.integer):
        raise SceneError(f"{where}: expected at least {minimum} integer node id(s),"
                         f" got {value!r}")
    return array.astype(np.int64)


def _optional_float(value: Any, where: str) -> float | None:
    if value is None:
        return None
    # float(True) and float('10') would pass as 1.0 and 10.0: a number is asked for.
    if isinstance(value, (bool, np.bool_, str, bytes)):
        raise SceneError(f"{where}: expected a number, got {value!r}")
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise SceneError(f"{where}: expected a number, got {value!r}") from None
    if not np.isfinite(number):
        raise SceneError(f"{where}: expected a finite number, got {value!r}")
    return number


def _variables(obj: Any, skip: tuple[str, ...] = ()) -> dict[str, Any]:
    """The set variables of a group object, in field order, then its extras."""
    out: dict[str, Any] = {}
    for item in fields(obj):
        if item.name == "extra" or item.name in skip:
            continue
        value = getattr(obj, item.name)
        if value is None or (isinstance(value, tuple) and not value):
            continue
        if isinstance(value, np.ndarray):
            value = value.ravel().tolist()
        elif isinstance(value, tuple):
            value = list(value)
        elif isinstance(value, os.PathLike):
            value = os.fspath(value)
        out[item.name] = value
    out.update(obj.extra)
    return out


def _expanded(group: f90nml.Namelist) -> dict[str, Any]:
    """The variables of a read group, each array from its first entry
    (:func:`~yarnfort.address.entries_from_first`); one given from a start index in more
    than one dimension as read."""
    out: dict[str, Any] = {}
    for key in group:
        try:
            out[key] = entries_from_first(group, key)
        except AddressError:
            out[key] = group[key]
    return out


def _split(group: f90nml.Namelist, names: tuple[str, ...]) -> tuple[dict, dict]:
    """Variables of a read group: those a class names, and the rest."""
    variables = _expanded(group)
    known = {key: value for key, value in variables.items() if key in names}
    extra = {key: value for key, value in variables.items() if key not in names}
    return known, extra


#: Array variables whose unset entries take the default 0 (``displacement(2) = -0.3``
#: leaves the first and third at 0), with the length they have.
_ZERO_FILLED: dict[tuple[str, str], int | None] = {
    ("support", "displacement"): 3, ("load", "force"): 3,
    ("path", "p_force"): None, ("path", "p_disp"): None,
}


def _defaults_filled(group: str, variables: dict[str, Any]) -> dict[str, Any]:
    """Variables as read from a namelist, with the entries a namelist may leave unset
    (f90nml gives None, or a shorter list) set to their default 0."""
    out = dict(variables)
    for (name, variable), length in _ZERO_FILLED.items():
        if name != group or variable not in out:
            continue
        values = out[variable]
        values = list(values) if isinstance(values, list) else [values]
        values = [0.0 if value is None else value for value in values]
        if length is not None and len(values) < length:
            values += [0.0] * (length - len(values))
        out[variable] = values
    return out


@dataclass
class Material:
    """A yarn type (``&material``): a force law and its parameters.

    Parameters
    ----------
    name : str
        Unique name, referred to by yarns and contacts.
    law : str
        ``'linear'`` (``stiffness`` EA, N), ``'neo_hookean'`` (``modulus`` C, Pa, and
        ``area`` S1, m**2) or ``'table'`` (``table_file``: CSV of strain, force; in the
        units its header states, else 1 and N; ``extra`` may hold ``strain_unit``,
        ``force_unit``, ``gauge_length``).
    prestress : float, optional
        Initial tension of every element of this type (N).
    extra : dict
        Further ``&material`` variables, written as given.
    """

    name: str
    law: str
    stiffness: float | None = None
    modulus: float | None = None
    area: float | None = None
    table_file: str | os.PathLike | None = None
    prestress: float | None = None
    extra: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        _name(self.name, "&material name")
        if not isinstance(self.law, str):
            raise SceneError(f"&material '{self.name}' law: expected a string")
        for key in ("stiffness", "modulus", "area", "prestress"):
            setattr(self, key, _optional_float(getattr(self, key),
                                               f"&material '{self.name}' {key}"))
        _check_group("material", _variables(self), f"&material '{self.name}'")


@dataclass
class Contact:
    """The friction law between two yarn types, or at an obstacle or ring (``&contact``).

    Parameters
    ----------
    materials : tuple of str
        The two material names; with ``at``, one material name or none (every type).
    law : str
        ``'bonded'``, ``'coulomb'``, ``'adhesion'``, ``'decaying_adhesion'`` or
        ``'general'``.
    friction_coefficient, adhesion, decay_start, decay_end : float, optional
        mu, beta (N), w_d and s_d (N), as the law needs.
    at : str, optional
        The name of an :class:`Obstacle` or :class:`Ring` whose law this is.
    extra : dict
        Further ``&contact`` variables.
    rate_table : str or path, optional
        ``'general'``: CSV file of (T in N, g in N/rad), the rate of T' = g(T).
    """

    materials: tuple[str, ...]
    law: str
    friction_coefficient: float | None = None
    adhesion: float | None = None
    decay_start: float | None = None
    decay_end: float | None = None
    at: str | None = None
    extra: dict[str, Any] = field(default_factory=dict)
    rate_table: str | os.PathLike | None = None

    def __post_init__(self) -> None:
        if self.at == "":
            self.at = None               # a pair law, as an echoed input has it
        pair = [self.materials] if isinstance(self.materials, str) else list(self.materials)
        pair = [name for name in pair if name not in ("", None)] if self.at else pair
        if self.at is not None:
            _name(self.at, "&contact at")
            if len(pair) > 1:
                raise SceneError(f"&contact at '{self.at}' materials: expected one name or "
                                 f"none, got {self.materials!r}")
        elif len(pair) != 2:
            raise SceneError(f"&contact materials: expected two names, got {self.materials!r}")
        self.materials = tuple(_name(name, "&contact materials") for name in pair)
        for key in ("friction_coefficient", "adhesion", "decay_start", "decay_end"):
            setattr(self, key, _optional_float(getattr(self, key), f"&contact {key}"))
        _check_group("contact", _variables(self), "&contact")


@dataclass
class Yarn:
    """A yarn (``&yarn``): a material and the node ids it passes, in order.

    Parameters
    ----------
    material : str
        Material name.
    nodes : array_like of int
        Node ids (from 1), at least two.
    elements_per_segment : int, optional
        Elements between two listed nodes.
    length0 : array_like, optional
        Reference length of every element (m), in order along the yarn: (len(nodes) - 1)
        * elements_per_segment values.
    stretch : array_like, optional
        Initial stretch of every element instead (L0 = length / stretch).
    extra : dict
        Further ``&yarn`` variables.
    """

    material: str
    nodes: ArrayLike
    elements_per_segment: int | None = None
    extra: dict[str, Any] = field(default_factory=dict)
    length0: ArrayLike | None = None
    stretch: ArrayLike | None = None

    def __post_init__(self) -> None:
        _name(self.material, "&yarn material")
        self.nodes = _ids(self.nodes, f"&yarn ({self.material}) nodes", minimum=2)
        if self.length0 is not None and self.stretch is not None:
            raise SceneError(f"&yarn ({self.material}): length0 and stretch are both given")
        for key in ("length0", "stretch"):
            value = getattr(self, key)
            if value is None:
                continue
            array = np.atleast_1d(_reals(value, f"&yarn ({self.material}) {key}"))
            per_segment = 1 if self.elements_per_segment is None else int(self.elements_per_segment)
            expected = (len(self.nodes) - 1) * per_segment
            if array.ndim != 1 or array.size != expected:
                raise SceneError(f"&yarn ({self.material}) {key}: {array.size} values for "
                                 f"{expected} elements")
            if not np.all(array > 0.0):
                raise SceneError(f"&yarn ({self.material}) {key}: every value must be > 0")
            setattr(self, key, array)
        _check_group("yarn", _variables(self), f"&yarn ({self.material})")


@dataclass
class Support:
    """A named support set (``&support``): prescribed components of some nodes.

    Parameters
    ----------
    name : str
        Unique name; its reaction is reported as ``<name>_rx, _ry, _rz``.
    nodes : array_like of int
        Node ids.
    fix : str
        Prescribed components, e.g. ``'xyz'`` or ``'y'``.
    displacement : array_like of 3 floats, optional
        Displacement at factor 1 of its load channel (m).
    extra : dict
        Further ``&support`` variables.
    channel : str, optional
        The load channel that scales the displacement (default ``'p_disp'``).
    """

    name: str
    nodes: ArrayLike
    fix: str | None = None
    displacement: ArrayLike | None = None
    extra: dict[str, Any] = field(default_factory=dict)
    channel: str | None = None

    def __post_init__(self) -> None:
        _name(self.name, "&support name")
        self.nodes = _ids(self.nodes, f"&support '{self.name}' nodes")
        if self.fix is not None and (not isinstance(self.fix, str) or not _FIX.match(self.fix)):
            raise SceneError(f"&support '{self.name}' fix: {self.fix!r} is not one or more"
                             " of x, y, z")
        if self.displacement is not None:
            self.displacement = _reals(self.displacement,
                                       f"&support '{self.name}' displacement", (3,))
        if self.channel == "":
            self.channel = None          # the default channel, as an echoed input has it
        if self.channel is not None:
            _name(self.channel, f"&support '{self.name}' channel")
        _check_group("support", _variables(self), f"&support '{self.name}'")


@dataclass
class Obstacle:
    """Fixed obstacles (``&obstacle``): nodes held in place that yarns slide through.

    Parameters
    ----------
    name : str
        Unique name (``Contact(at=name)`` gives its law; its reaction is reported as
        ``<name>_rx, _ry, _rz``).
    nodes : array_like of int
        Node ids; each must be passed through, not ended at, by its yarns.
    extra : dict
        Further ``&obstacle`` variables.
    """

    name: str
    nodes: ArrayLike
    extra: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        _name(self.name, "&obstacle name")
        self.nodes = _ids(self.nodes, f"&obstacle '{self.name}' nodes")
        _check_group("obstacle", _variables(self), f"&obstacle '{self.name}'")


@dataclass
class Ring:
    """Free rings (``&ring``): nodes of free position that yarns slide through.

    Parameters
    ----------
    name : str
        Unique name (``Contact(at=name)`` gives its law).
    nodes : array_like of int
        Node ids; each must be passed through, not ended at, by its yarns.
    extra : dict
        Further ``&ring`` variables.
    """

    name: str
    nodes: ArrayLike
    extra: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        _name(self.name, "&ring name")
        self.nodes = _ids(self.nodes, f"&ring '{self.name}' nodes")
        _check_group("ring", _variables(self), f"&ring '{self.name}'")


@dataclass
class Load:
    """Nodal forces (``&load``).

    Parameters
    ----------
    nodes : array_like of int
        Node ids.
    force : array_like of 3 floats
        Force on each node at factor 1 of its load channel (N).
    extra : dict
        Further ``&load`` variables.
    channel : str, optional
        The load channel that scales the force (default ``'p_force'``).
    """

    nodes: ArrayLike
    force: ArrayLike
    extra: dict[str, Any] = field(default_factory=dict)
    channel: str | None = None

    def __post_init__(self) -> None:
        self.nodes = _ids(self.nodes, "&load nodes")
        self.force = _reals(self.force, "&load force", (3,))
        if self.channel == "":
            self.channel = None
        if self.channel is not None:
            _name(self.channel, "&load channel")
        _check_group("load", _variables(self), "&load")


@dataclass
class LoadPath:
    """The load path (``&path``): knots of the load channels' factors.

    Parameters
    ----------
    time : array_like
        Pseudo-times of the knots (at least two).
    p_force, p_disp : array_like, optional
        Factors at the knots of the two default channels (default zeros).
    extra : dict
        Further ``&path`` variables.
    channels : sequence of str, optional
        Names of independent load channels instead (``&path channels``, at most 8).
    factors : array_like, optional
        With ``channels``: shape (n_knots, n_channels), one row per knot (written row by
        row, as ``&path factors`` reads them).
    """

    time: ArrayLike
    p_force: ArrayLike | None = None
    p_disp: ArrayLike | None = None
    extra: dict[str, Any] = field(default_factory=dict)
    channels: list[str] | None = None
    factors: ArrayLike | None = None

    def __post_init__(self) -> None:
        self.time = np.atleast_1d(_reals(self.time, "&path time"))
        if self.time.ndim != 1 or self.time.size < 2:
            raise SceneError(f"&path time: expected a list of at least two knots, got shape"
                             f" {self.time.shape}")
        for key in ("p_force", "p_disp"):
            value = getattr(self, key)
            if value is not None:
                array = np.atleast_1d(_reals(value, f"&path {key}"))
                if array.shape != self.time.shape:
                    raise SceneError(f"&path {key}: shape {array.shape} for"
                                     f" {self.time.size} knots (one value per knot)")
                setattr(self, key, array)
        if self.channels is not None:
            names = [self.channels] if isinstance(self.channels, str) else list(self.channels)
            # Empty entries are unset (an echoed input lists all 8 entries).
            names = [name for name in names if name not in (None, "")]
            self.channels = [_name(name, "&path channels") for name in names] or None
        if self.channels is not None:
            if len(set(self.channels)) != len(self.channels):
                raise SceneError(f"&path channels: a name is given twice: {self.channels}")
            # Zeros are the default (an echoed input writes them), as the library reads it.
            if any(value is not None and np.any(value != 0.0)
                   for value in (self.p_force, self.p_disp)):
                raise SceneError("&path: p_force or p_disp together with channels (give "
                                 "every factor in factors)")
            self.p_force = self.p_disp = None
            if self.factors is None:
                raise SceneError("&path channels: factors (n_knots x n_channels) missing")
            array = np.asarray(_reals(self.factors, "&path factors"), dtype=float)
            shape = (self.time.size, len(self.channels))
            if array.size != shape[0] * shape[1]:
                raise SceneError(f"&path factors: {array.size} values for {shape[0]} knots "
                                 f"x {shape[1]} channels")
            self.factors = array.reshape(shape)
        elif self.factors is not None:
            raise SceneError("&path factors: given without channels")
        _check_group("path", _variables(self), "&path")


@dataclass
class Geometry:
    """A geometry file (``&geometry``) with the nodes and yarns.

    Parameters
    ----------
    file : str or path
        The file (format in the input reference, ``python -m yarnfort reference``);
        relative to the run's working
        directory.
    extra : dict
        Further ``&geometry`` variables.
    """

    file: str | os.PathLike
    extra: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        _check_group("geometry", _variables(self), "&geometry")


@dataclass
class Fabric:
    """A generated fabric (``&fabric``): a knit or a weave instead of nodes and yarns.

    Parameters
    ----------
    kind : str
        ``'knit'``, ``'plain'`` or ``'twill'``.
    extra : dict
        The other ``&fabric`` variables (``cells``, ``spacing``, ``boundary``,
        ``strain``, ``knit_material``, ``gap``, ...; see ``python -m yarnfort reference``), also
        given as keywords: ``Fabric('knit', cells=[2, 2], spacing=[1e-3, 1e-3])``.
    """

    kind: str
    extra: dict[str, Any] = field(default_factory=dict)

    def __init__(self, kind: str, extra: dict[str, Any] | None = None, **variables: Any
                 ) -> None:
        if not isinstance(kind, str):
            raise SceneError(f"&fabric kind: expected a string, got {kind!r}")
        self.kind = kind
        self.extra = {**(extra or {}), **variables}
        _check_group("fabric", {"kind": kind, **self.extra}, "&fabric")


#: Group name -> (class, repeated) for the groups with their own class.
_GROUPS: dict[str, tuple[type, bool]] = {
    "material": (Material, True), "contact": (Contact, True), "yarn": (Yarn, True),
    "support": (Support, True), "load": (Load, True), "path": (LoadPath, False),
    "geometry": (Geometry, False), "fabric": (Fabric, False),
    "obstacle": (Obstacle, True), "ring": (Ring, True),
}
#: Repeated group -> the Scene attribute that holds its list.
_LISTS = {"material": "materials", "contact": "contacts", "yarn": "yarns",
          "support": "supports", "load": "loads", "obstacle": "obstacles", "ring": "rings"}
#: Settings groups held as plain keyword dicts.
_SETTINGS = ("control", "solver", "output")


class Scene:
    """A scene: everything ``yarnfort < scene.nml`` reads, as Python objects.

    Parameters
    ----------
    title : str, optional
        ``&control title``.
    solver, output, control : dict, optional
        Settings of ``&solver``, ``&output`` and ``&control`` by variable name (e.g.
        ``solver={'preset': 'balanced'}``, ``output={'folder': 'out/run1'}``).

    Attributes
    ----------
    materials, contacts, yarns, supports, loads, obstacles, rings : list
        The repeated groups, in order.
    nodes : numpy.ndarray or None
        Node positions, shape (n, 3), m (``&nodes``).
    geometry : Geometry or None
    fabric : Fabric or None
    path : LoadPath or None
    solver, output, control : dict
    """

    def __init__(self, title: str | None = None, *, solver: dict | None = None,
                 output: dict | None = None, control: dict | None = None) -> None:
        self.materials: list[Material] = []
        self.contacts: list[Contact] = []
        self.yarns: list[Yarn] = []
        self.supports: list[Support] = []
        self.loads: list[Load] = []
        self.obstacles: list[Obstacle] = []
        self.rings: list[Ring] = []
        self._nodes: np.ndarray | None = None
        self.nodes_extra: dict[str, Any] = {}
        self.geometry: Geometry | None = None
        self.fabric: Fabric | None = None
        self.path: LoadPath | None = None
        self.solver: dict[str, Any] = dict(solver or {})
        self.output: dict[str, Any] = dict(output or {})
        self.control: dict[str, Any] = dict(control or {})
        if title is not None:
            self.control["title"] = title
        self._check_settings()

    def _check_settings(self) -> None:
        """The settings dicts (and the extras of &nodes) against the description: they
        can change after construction, so :meth:`validate` checks them again."""
        for group in _SETTINGS:
            settings = getattr(self, group)
            for key, value in settings.items():  # output={'folder': Path(...)}: a name
                if isinstance(value, os.PathLike):
                    settings[key] = os.fspath(value)
            _check_group(group, settings, f"Scene {group}")
        _check_group("nodes", self.nodes_extra, "&nodes")

    def __repr__(self) -> str:
        source = ("fabric" if self.fabric is not None else "geometry"
                  if self.geometry is not None else
                  f"{len(self._nodes)} nodes" if self._nodes is not None else "no nodes")
        title = self.control.get("title")
        return (f"Scene({title!r}: {len(self.materials)} materials, {len(self.contacts)}"
                f" contacts, {source}, {len(self.yarns)} yarns, {len(self.supports)}"
                f" supports, {len(self.loads)} loads)")

    # -- building -------------------------------------------------------------------
    @property
    def nodes(self) -> np.ndarray | None:
        """Node positions, shape (n, 3) (m); set from an (n, 3) array or a flat list of
        x1, y1, z1, x2, ... (as ``&nodes xyz``)."""
        return self._nodes

    @nodes.setter
    def nodes(self, value: ArrayLike | None) -> None:
        if value is None:
            self._nodes = None
            return
        array = _reals(value, "&nodes xyz")
        # (n, 3) rows, or the namelist's flat x1, y1, z1, x2, ...: nothing else is
        # reshaped (a (3, 2) array is no set of points).
        if array.ndim == 2 and array.shape[1] != 3 or array.ndim > 2:
            raise SceneError(f"&nodes xyz: expected shape (n, 3) (one row x, y, z per"
                             f" node), got {array.shape}")
        if array.size == 0 or array.size % 3:
            raise SceneError(f"&nodes xyz: {array.size} numbers are not (x, y, z) triplets")
        self._nodes = array.reshape(-1, 3)

    def add_material(self, name: str, law: str, **parameters: Any) -> Material:
        """Add a :class:`Material`.

        Parameters
        ----------
        name : str
            Unique material name.
        law : str
            ``'linear'``, ``'neo_hookean'`` or ``'table'``.
        **parameters
            The law's parameters (``stiffness``; ``modulus``, ``area``; ``table_file``),
            ``prestress`` and any further ``&material`` variable.

        Returns
        -------
        Material
            The material added.

        Raises
        ------
        SceneError
            For a repeated name or a bad value.
        """
        if any(m.name == name for m in self.materials):
            raise SceneError(f"&material name: {name!r} is given twice")
        known = {f.name for f in fields(Material)} - {"name", "law", "extra"}
        material = Material(name, law, **{k: v for k, v in parameters.items() if k in known},
                            extra={k: v for k, v in parameters.items() if k not in known})
        self.materials.append(material)
        return material

    def add_contact(self, materials: tuple[str, str], law: str, **parameters: Any
                    ) -> Contact:
        """Add a :class:`Contact` between two materials.

        Parameters
        ----------
        materials : tuple of str
            The two material names (added before).
        law : str
            ``'bonded'``, ``'coulomb'``, ``'adhesion'``, ``'decaying_adhesion'`` or
            ``'general'``.
        **parameters
            ``friction_coefficient``, ``adhesion``, ``decay_start``, ``decay_end``,
            ``rate_table`` and any further ``&contact`` variable.

        Returns
        -------
        Contact
            The contact added.
        """
        known = {f.name for f in fields(Contact)} - {"materials", "law", "extra"}
        contact = Contact(tuple(materials), law,
                          **{k: v for k, v in parameters.items() if k in known},
                          extra={k: v for k, v in parameters.items() if k not in known})
        self._check_materials(contact.materials, "&contact materials")
        self.contacts.append(contact)
        return contact

    def add_obstacle(self, name: str, nodes: ArrayLike, **variables: Any) -> Obstacle:
        """Add an :class:`Obstacle`: nodes held in place that the yarns slide through.

        Parameters
        ----------
        name : str
            Unique among obstacles and rings; its law is a contact
            ``add_contact((), law, at=name, ...)`` (or with one material).
        nodes : array_like of int
            Node ids.
        **variables
            Any further ``&obstacle`` variable.

        Returns
        -------
        Obstacle
            The obstacle added.
        """
        return self._add_contact_nodes(Obstacle(name, nodes, variables), self.obstacles)

    def add_ring(self, name: str, nodes: ArrayLike, **variables: Any) -> Ring:
        """Add a :class:`Ring`: free nodes that the yarns slide through.

        Parameters
        ----------
        name : str
            Unique among obstacles and rings; its law is a contact
            ``add_contact((), law, at=name, ...)``; its force a :meth:`add_load`.
        nodes : array_like of int
            Node ids.
        **variables
            Any further ``&ring`` variable.

        Returns
        -------
        Ring
            The ring added.
        """
        return self._add_contact_nodes(Ring(name, nodes, variables), self.rings)

    def _add_contact_nodes(self, item: Any, items: list) -> Any:
        names = [o.name for o in self.obstacles] + [r.name for r in self.rings]
        if item.name in names:
            raise SceneError(f"&{type(item).__name__.lower()} name: {item.name!r} is given "
                             "twice (obstacle and ring names are one set)")
        self._check_nodes(item.nodes, f"&{type(item).__name__.lower()} '{item.name}' nodes")
        items.append(item)
        return item

    def add_yarn(self, material: str, nodes: ArrayLike, **variables: Any) -> Yarn:
        """Add a :class:`Yarn`.

        Parameters
        ----------
        material : str
            Material name (added before).
        nodes : array_like of int
            Node ids along the yarn (from 1).
        **variables
            ``elements_per_segment``, ``length0`` or ``stretch`` and any further ``&yarn``
            variable.

        Returns
        -------
        Yarn
            The yarn added.
        """
        yarn = Yarn(material, nodes, variables.pop("elements_per_segment", None),
                    length0=variables.pop("length0", None),
                    stretch=variables.pop("stretch", None), extra=variables)
        self._check_materials([material], "&yarn material")
        self._check_nodes(yarn.nodes, f"&yarn ({material}) nodes")
        self.yarns.append(yarn)
        return yarn

    def add_support(self, name: str, nodes: ArrayLike, fix: str | None = None,
                    displacement: ArrayLike | None = None, **variables: Any) -> Support:
        """Add a named :class:`Support`.

        Parameters
        ----------
        name : str
            Unique support name.
        nodes : array_like of int
            Node ids.
        fix : str, optional
            Prescribed components (default ``'xyz'``).
        displacement : array_like of 3 floats, optional
            Displacement at factor 1 of its channel (m).
        **variables
            ``channel`` and any further ``&support`` variable.

        Returns
        -------
        Support
            The support added.
        """
        if any(s.name == name for s in self.supports):
            raise SceneError(f"&support name: {name!r} is given twice")
        support = Support(name, nodes, fix, displacement,
                          channel=variables.pop("channel", None), extra=variables)
        self._check_nodes(support.nodes, f"&support '{name}' nodes")
        self.supports.append(support)
        return support

    def add_load(self, nodes: ArrayLike, force: ArrayLike, **variables: Any) -> Load:
        """Add a :class:`Load`.

        Parameters
        ----------
        nodes : array_like of int
            Node ids.
        force : array_like of 3 floats
            Force on each node at factor 1 of its channel (N).
        **variables
            ``channel`` and any further ``&load`` variable.

        Returns
        -------
        Load
            The load added.
        """
        load = Load(nodes, force, channel=variables.pop("channel", None), extra=variables)
        self._check_nodes(load.nodes, "&load nodes")
        self.loads.append(load)
        return load

    def _check_materials(self, names: Any, where: str) -> None:
        known = {m.name for m in self.materials}
        for name in names:
            if name not in known:
                raise SceneError(f"{where}: no &material named {name!r} (add it first;"
                                 f" materials: {', '.join(sorted(known)) or 'none'})")

    def _check_nodes(self, ids: np.ndarray, where: str) -> None:
        if self._nodes is None:
            return  # nodes from a geometry file: the library checks them
        bad = ids[(ids < 1) | (ids > len(self._nodes))]
        if bad.size:
            raise SceneError(f"{where}: node id {int(bad[0])} is not in 1..{len(self._nodes)}")

    def validate(self) -> None:
        """Check what Python can see: one source of nodes, a load path, references.

        Raises
        ------
        SceneError
            Naming the first problem. The library's checks (:meth:`check`) cover the rest.
        """
        self._check_settings()
        # Objects can be changed after construction (material.stiffness = -1.0): every
        # variable is checked again against the description.
        for group, attribute in _LISTS.items():
            for item in getattr(self, attribute):
                _check_group(group, _variables(item), f"&{group}")
        for group in ("path", "geometry"):
            if getattr(self, group) is not None:
                _check_group(group, _variables(getattr(self, group)), f"&{group}")
        if self.fabric is not None:
            _check_group("fabric", {"kind": self.fabric.kind, **self.fabric.extra}, "&fabric")
        sources = [name for name, present in (("&nodes", self._nodes is not None),
                   ("&geometry", self.geometry is not None),
                   ("&fabric", self.fabric is not None)) if present]
        if len(sources) > 1:
            raise SceneError(f"give one of &nodes, &geometry and &fabric, not {' and '.join(sources)}")
        if not self.materials:
            raise SceneError("the scene has no &material")
        if self.path is None:
            raise SceneError("the scene has no &path (set scene.path = LoadPath(...))")
        for contact in self.contacts:
            self._check_materials(contact.materials, "&contact materials")
        for yarn in self.yarns:
            self._check_materials([yarn.material], "&yarn material")
            self._check_nodes(yarn.nodes, f"&yarn ({yarn.material}) nodes")
        for support in self.supports:
            self._check_nodes(support.nodes, f"&support '{support.name}' nodes")
        for load in self.loads:
            self._check_nodes(load.nodes, "&load nodes")
        for item in [*self.obstacles, *self.rings]:
            self._check_nodes(item.nodes, f"&{type(item).__name__.lower()} '{item.name}' nodes")

    # -- namelist ---------------------------------------------------------------------
    def to_namelist(self) -> f90nml.Namelist:
        """The scene as an :class:`f90nml.Namelist` (after :meth:`validate`)."""
        self.validate()
        groups: dict[str, Any] = {}
        if self.control:
            groups["control"] = dict(self.control)
        if self.solver:
            groups["solver"] = dict(self.solver)
        groups["material"] = [_variables(m) for m in self.materials]
        if self.contacts:
            groups["contact"] = [_variables(c) for c in self.contacts]
        if self.fabric is not None:
            groups["fabric"] = {"kind": self.fabric.kind, **self.fabric.extra}
        if self._nodes is not None:
            groups["nodes"] = {"xyz": self._nodes.ravel().tolist(), **self.nodes_extra}
        if self.geometry is not None:
            groups["geometry"] = _variables(self.geometry)
        for name, items in (("yarn", self.yarns), ("support", self.supports),
                            ("load", self.loads), ("obstacle", self.obstacles),
                            ("ring", self.rings)):
            if items:
                groups[name] = [_variables(item) for item in items]
        groups["path"] = _variables(self.path)
        if self.output:
            groups["output"] = dict(self.output)
        return make_namelist(groups)

    def write(self, path: str | os.PathLike) -> Path:
        """Write the scene as a namelist file.

        Parameters
        ----------
        path : str or path
            The file to write (parent folders are created).

        Returns
        -------
        pathlib.Path
            The path written.
        """
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        self.to_namelist().write(str(path), force=True)
        return path

    @classmethod
    def from_namelist(cls, nml: f90nml.Namelist) -> Scene:
        """Build a scene from a namelist (:func:`yarnfort.read_scene`).

        Parameters
        ----------
        nml : f90nml.Namelist
            The namelist.

        Returns
        -------
        Scene

        Raises
        ------
        SceneError
            If a group cannot be represented (e.g. a group this version does not know).
        """
        scene = cls()
        for key, content in nml.items():
            groups = list(content) if isinstance(content, list) else [content]
            if key in _SETTINGS:
                for group in groups:
                    getattr(scene, key).update(_expanded(group))
            elif key == "nodes":
                known, scene.nodes_extra = _split(groups[0], ("xyz",))
                scene.nodes = known.get("xyz")
            elif key == "fabric":
                known, extra = _split(groups[0], ("kind",))
                scene.fabric = Fabric(known.get("kind"), extra)
            elif key in _GROUPS:
                kind, repeated = _GROUPS[key]
                names = tuple(f.name for f in fields(kind) if f.name != "extra")
                objects = []
                for group in groups:
                    known, extra = _split(group, names)
                    if key == "contact" and "at" in known:
                        known.setdefault("materials", ())
                    objects.append(kind(**_defaults_filled(key, known), extra=extra))
                if repeated:
                    getattr(scene, _LISTS[key]).extend(objects)
                else:
                    setattr(scene, key, objects[0])
            else:
                groups_known = [g["name"] for g in input_description()["groups"]]
                close = difflib.get_close_matches(key, groups_known, n=1)
                raise SceneError(f"&{key}: not a yarnfort group"
                                 + (f"; did you mean &{close[0]}?" if close else ""))
        return scene

    @classmethod
    def read(cls, path: str | os.PathLike) -> Scene:
        """Read a scene from a namelist file.

        Parameters
        ----------
        path : str or path
            The namelist file.

        Returns
        -------
        Scene
        """
        return cls.from_namelist(read_scene(path))

    # -- running ------------------------------------------------------------------------
    def check(self) -> None:
        """Hand the scene to the library's reader and checker; nothing is solved.

        Raises
        ------
        SceneError
            From :meth:`validate`.
        YarnfortError
            With the library's message (status 2) for anything it rejects.
        """
        from .runner import run_scene

        nml = self.to_namelist()
        nml.setdefault("control", f90nml.Namelist())["check_only"] = True
        with tempfile.TemporaryDirectory(prefix="yarnfort-check-") as folder:
            path = Path(folder) / "scene.nml"
            nml.write(str(path), force=True)
            run_scene(path)

    def run(self, progress: Any = False) -> Any:
        """Run the scene in process (see :func:`yarnfort.run_scene`).

        Parameters
        ----------
        progress : bool or callable
            ``True`` for a tqdm bar, or a call-back taking a :class:`yarnfort.Step`.

        Returns
        -------
        RunResult
        """
        from .runner import run_scene

        return run_scene(self, progress=progress)
