# SPDX-License-Identifier: MIT
"""The one grammar of parameter addresses, used by the namelist helpers, sweeps and
calibration.

An address names one variable of one namelist group:

- ``'solver.max_step'``: a variable of a group that appears once (``&solver``);
- ``'contact[0].friction_coefficient'``: of the first ``&contact`` group in file
  order (indices from 0; negative ones count from the end, ``'yarn[-1].material'``);
- ``'support[pull].displacement'``: of the group whose ``name`` is ``pull`` (quotes
  around the name are optional: ``support['pull']``; needed for a name of digits, and
  ``support[1]`` is refused when another group than the second is named ``1``);
- ``'fabric.gap_factor[2]'``: one entry of a list variable (indices from 0, negative
  ones from the end), e.g. one knot value of the gap-factor table. The list must be set
  already and have that entry: its length is the scene's to choose.

A variable the scene gives from a later entry (``displacement(2) = -0.3``) is read and
set counted from its first entry, as the program reads it: ``displacement[1]`` is -0.3,
``displacement`` reads ``[None, -0.3]`` (None: unset, the default), and a value set for
the whole variable starts at its first entry.

Group and variable names are case-insensitive; a group name is matched exactly. Setting a
variable that the group does not have yet adds it, and setting a variable of a group the
scene lacks adds the group, when the address has no index (or index 0): that is how a
sweep sets ``solver.max_step`` in a scene without ``&solver``. Every other problem
(malformed address, repeated group without an index, index out of range, no group of
that name, reading a variable that is not set) raises :class:`AddressError`, whose
message names the address and what the scene has.
"""
from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any

import f90nml
import numpy as np

__all__ = ["Address", "AddressError", "parse_address", "check_address", "get_parameter",
           "set_parameter"]

_ADDRESS = re.compile(r"^\s*(\w+)\s*(?:\[\s*([^\]]*?)\s*\])?\s*\.\s*(\w+)\s*"
                      r"(?:\[\s*([+-]?\d+)\s*\])?\s*$")
_INTEGER = re.compile(r"^[+-]?\d+$")


class AddressError(ValueError):
    """A parameter address that is malformed or names nothing in the scene."""


@dataclass(frozen=True)
class Address:
    """A parsed parameter address.

    Attributes
    ----------
    group : str
        Group name, lower case.
    index : int, str or None
        Position (int), ``name`` of the group (str), or None for a group given once.
    variable : str
        Variable name, lower case.
    text : str
        The address as written.
    element : int or None
        Entry of a list variable (from 0), or None for the whole variable.
    """

    group: str
    index: int | str | None
    variable: str
    text: str
    element: int | None = None


def parse_address(address: str) -> Address:
    """Parse ``'group.variable'``, ``'group[i].variable'`` or ``'group[name].variable'``,
    each optionally with an entry of a list variable: ``'fabric.gap_factor[1]'``.

    Parameters
    ----------
    address : str
        The address.

    Returns
    -------
    Address

    Raises
    ------
    AddressError
        If ``address`` does not have one of these forms.
    """
    match = _ADDRESS.match(address) if isinstance(address, str) else None
    if not match:
        raise AddressError(f"bad parameter address {address!r}: expected 'group.variable',"
                           " 'group[i].variable' or 'group[name].variable', optionally"
                           " with a list entry 'variable[k]'")
    group, index, variable, element = match.groups()
    if index is None or index == "":
        where: int | str | None = None
    elif _INTEGER.match(index):
        where = int(index)
    else:
        where = index.strip("'\"")
    return Address(group.lower(), where, variable.lower(), address,
                   None if element is None else int(element))


def check_address(address: str) -> Address:
    """Parse an address and check that its group and variable are input variables (the
    one description of the input): a sweep or fit of a misspelled name is refused before
    it runs, not left to fail in every run.

    Parameters
    ----------
    address : str
        The address.

    Returns
    -------
    Address

    Raises
    ------
    AddressError
        If the address is malformed, or names a group or variable the input does not
        have (the message suggests the name meant).
    """
    import difflib

    from .resources import input_description

    where = parse_address(address)
    groups = {group["name"]: [v["name"] for v in group["variables"]]
              for group in input_description()["groups"]}
    for name, known, what in ((where.group, list(groups), "group"),
                              (where.variable, groups.get(where.group), "variable")):
        if known is not None and name not in known:
            close = difflib.get_close_matches(name, known, n=1)
            owner = "the input" if what == "group" else f"&{where.group}"
            raise AddressError(f"{address!r}: {owner} has no {what} {name!r}"
                               + (f"; did you mean {close[0]!r}?" if close else "")
                               + " (python -m yarnfort reference)")
    return where


def _instances(nml: f90nml.Namelist, group: str) -> list[f90nml.Namelist]:
    found = nml[group]
    return list(found) if isinstance(found, list) else [found]


def _find_group(nml: f90nml.Namelist, address: Address, create: bool) -> f90nml.Namelist:
    """The one group instance that the address selects (created if allowed)."""
    group, index = address.group, address.index
    if group not in nml:
        if create and index in (None, 0):
            nml[group] = f90nml.Namelist()
            return nml[group]
        raise AddressError(f"{address.text!r}: the scene has no &{group} group")
    instances = _instances(nml, group)
    if index is None:
        if len(instances) != 1:
            raise AddressError(f"{address.text!r}: &{group} appears {len(instances)} times;"
                               f" give an index or a name, e.g. '{group}[0].{address.variable}'")
        return instances[0]
    if isinstance(index, int):
        if not -len(instances) <= index < len(instances):
            raise AddressError(f"{address.text!r}: the scene has {len(instances)}"
                               f" &{group} group(s)")
        # A group named '1' is not always the one at position 1: refused, not guessed.
        named = [k for k, instance in enumerate(instances)
                 if str(instance.get("name", "")) == str(index)]
        if named and named != [index % len(instances)]:
            raise AddressError(f"{address.text!r}: ambiguous, a &{group} is named"
                               f" '{index}' (position {named[0]}); write"
                               f" {group}['{index}'].{address.variable} for the name,"
                               f" {group}[{named[0]}].{address.variable} for its position")
        return instances[index]
    for instance in instances:
        if str(instance.get("name", "")) == index:
            return instance
    names = [str(instance["name"]) for instance in instances if "name" in instance]
    raise AddressError(f"{address.text!r}: no &{group} group named {index!r}; names: "
                       + (", ".join(names) or "none"))


def _plain(value: Any) -> Any:
    """numpy scalars and arrays as Python values f90nml writes."""
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    return value


def entries_from_first(instance: f90nml.Namelist, variable: str) -> Any:
    """A variable's value counted from its first entry. f90nml keeps ``x(2) = 5`` as
    ``[5]`` with a start index 2: read as it is, entry 0 would be x(2). Entries before
    the start are None (null when written: the default stays)."""
    value = instance[variable]
    start = (getattr(instance, "start_index", None) or {}).get(variable)
    if not start or all(index is None or index <= 1 for index in start):
        return value
    if len(start) > 1:
        raise AddressError(f"{variable}{tuple(start)}: an array given from that index in"
                           " more than one dimension; give it whole in the scene")
    return [None] * (start[0] - 1) + (list(value) if isinstance(value, list) else [value])


def _store(instance: f90nml.Namelist, variable: str, value: Any) -> None:
    """Set a variable from its first entry (a start index read from the file no longer
    applies: it would shift the new values)."""
    instance[variable] = value
    starts = getattr(instance, "start_index", None)
    if starts:
        starts.pop(variable, None)


def _entry(instance: f90nml.Namelist, where: Address) -> tuple[list, int]:
    """The list that an address with an entry names, and the entry's position in it."""
    if where.variable not in instance:
        raise AddressError(f"{where.text!r}: &{where.group} has no variable"
                           f" {where.variable!r} set (an entry needs the list set)")
    value = entries_from_first(instance, where.variable)
    items = list(value) if isinstance(value, list) else [value]
    if not -len(items) <= where.element < len(items):
        raise AddressError(f"{where.text!r}: &{where.group} {where.variable} has"
                           f" {len(items)} value(s)")
    return items, where.element % len(items)


def get_parameter(nml: f90nml.Namelist, address: str) -> Any:
    """The value of the variable that ``address`` names (see the module notes).

    Parameters
    ----------
    nml : f90nml.Namelist
        The scene (:func:`yarnfort.read_scene`).
    address : str
        The parameter address.

    Returns
    -------
    object
        The value as f90nml holds it (a number, string, bool or list).

    Raises
    ------
    AddressError
        If the address is malformed, names no group, or the variable is not set.
    """
    where = parse_address(address)
    instance = _find_group(nml, where, create=False)
    if where.element is not None:
        items, position = _entry(instance, where)
        return items[position]
    if where.variable not in instance:
        raise AddressError(f"{address!r}: &{where.group} has no variable"
                           f" {where.variable!r} set")
    return entries_from_first(instance, where.variable)


def set_parameter(nml: f90nml.Namelist, address: str, value: Any) -> f90nml.Namelist:
    """Set the variable that ``address`` names, in place (see the module notes).

    A variable the group lacks is added; a group the scene lacks is added for an address
    without an index (or index 0). An entry (``'fabric.gap_factor[1]'``) is set in a list
    that the scene has; the other entries are kept. An integer given for a variable that
    holds a real is stored as a real; numpy values become Python values.

    Parameters
    ----------
    nml : f90nml.Namelist
        The scene (:func:`yarnfort.read_scene`).
    address : str
        The parameter address.
    value : object
        The new value (a number, string, bool, list or numpy array).

    Returns
    -------
    f90nml.Namelist
        ``nml``, so that calls can be chained.

    Raises
    ------
    AddressError
        If the address is malformed or selects no group, or names an entry of a list
        that is not set or is shorter.
    """
    where = parse_address(address)
    value = _plain(value)
    if where.element is not None:
        instance = _find_group(nml, where, create=False)
        items, position = _entry(instance, where)
        items[position] = _like(items[position], value)
        _store(instance, where.variable, items)
        return nml
    instance = _find_group(nml, where, create=True)
    _store(instance, where.variable, _like(instance.get(where.variable), value))
    return nml


def _like(old: Any, value: Any) -> Any:
    """An integer stored where a real was is stored as a real."""
    if isinstance(old, float) and isinstance(value, int) and not isinstance(value, bool):
        return float(value)
    return value
