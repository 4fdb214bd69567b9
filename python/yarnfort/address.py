# SPDX-License-Identifier: MIT
"""The one grammar of parameter addresses, used by the namelist helpers, sweeps and
calibration.

An address names one variable of one namelist group:

- ``'solver.max_step'``: a variable of a group that appears once (``&solver``);
- ``'contact[0].friction_coefficient'``: of the first ``&contact`` group in file
  order (indices from 0; negative ones count from the end, ``'yarn[-1].material'``);
- ``'support[pull].displacement'``: of the group whose ``name`` is ``pull`` (quotes
  around the name are optional: ``support['pull']``).

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

__all__ = ["Address", "AddressError", "parse_address", "get_parameter", "set_parameter"]

_ADDRESS = re.compile(r"^\s*(\w+)\s*(?:\[\s*([^\]]*?)\s*\])?\s*\.\s*(\w+)\s*$")
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
    """

    group: str
    index: int | str | None
    variable: str
    text: str


def parse_address(address: str) -> Address:
    """Parse ``'group.variable'``, ``'group[i].variable'`` or ``'group[name].variable'``.

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
                           " 'group[i].variable' or 'group[name].variable'")
    group, index, variable = match.groups()
    if index is None or index == "":
        where: int | str | None = None
    elif _INTEGER.match(index):
        where = int(index)
    else:
        where = index.strip("'\"")
    return Address(group.lower(), where, variable.lower(), address)


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
    if where.variable not in instance:
        raise AddressError(f"{address!r}: &{where.group} has no variable"
                           f" {where.variable!r} set")
    return instance[where.variable]


def set_parameter(nml: f90nml.Namelist, address: str, value: Any) -> f90nml.Namelist:
    """Set the variable that ``address`` names, in place (see the module notes).

    A variable the group lacks is added; a group the scene lacks is added for an address
    without an index (or index 0). An integer given for a variable that holds a real is
    stored as a real; numpy values become Python values.

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
        If the address is malformed or selects no group.
    """
    where = parse_address(address)
    instance = _find_group(nml, where, create=True)
    value = _plain(value)
    old = instance.get(where.variable)
    if isinstance(old, float) and isinstance(value, int) and not isinstance(value, bool):
        value = float(value)
    instance[where.variable] = value
    return nml
