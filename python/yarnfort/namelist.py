# SPDX-License-Identifier: MIT
"""Read, change and write yarnfort scene namelists with :mod:`f90nml`.

A scene (``inputs/*.nml``, or a run's effective ``input.nml``) is read into an
:class:`f90nml.Namelist`: group name -> variables. A group that appears more than once
(``&material``, ``&yarn``, ``&support``, ``&contact``, ...) becomes a list of groups (an
``f90nml`` Cogroup) in file order; a group that appears once is a single Namelist.
Group and variable names are lower case. Comments are not kept on writing.

Addressing one variable
-----------------------
:func:`set_parameter` and :func:`get_parameter` name a variable as
``'group.variable'`` or ``'group[index].variable'``:

- ``'solver.max_step'``: the variable of a group that appears once (the same as
  ``'solver[0].max_step'``);
- ``'contact[0].friction_coefficient'``: of the first ``&contact`` group; negative
  indices count from the end (``'yarn[-1].material'``);
- ``'support[pull].displacement'``: of the group whose ``name`` variable is ``pull``
  (quotes around the name are optional).

Names are case-insensitive. A whole array is replaced (``displacement = [0, -0.2, 0]``).
"""
from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import f90nml

__all__ = ["read_scene", "write_scene", "set_parameter", "get_parameter"]

_ADDRESS = re.compile(r"^\s*(\w+)\s*(?:\[\s*([^\]]*?)\s*\])?\s*\.\s*(\w+)\s*$")


def read_scene(path: str | Path) -> f90nml.Namelist:
    """Read a scene namelist file.

    Parameters
    ----------
    path : str or Path
        The namelist file (e.g. ``inputs/capstan.nml`` or a run's ``input.nml``).

    Returns
    -------
    f90nml.Namelist
        Group name -> variables; repeated groups are lists of groups.
    """
    return f90nml.read(str(path))


def write_scene(nml: f90nml.Namelist, path: str | Path) -> Path:
    """Write ``nml`` as a namelist file that ``./yarnfort < path`` reads.

    An existing file is overwritten; missing parent folders are created.
    Returns the path written.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    nml.write(str(path), force=True)
    return path


def _parse(address: str) -> tuple[str, str | None, str]:
    match = _ADDRESS.match(address)
    if not match:
        raise ValueError(f"bad parameter address {address!r}: expected 'group.variable'"
                         " or 'group[index].variable'")
    group, index, variable = match.groups()
    return group.lower(), index, variable.lower()


def _group(nml: f90nml.Namelist, group: str, index: str | None) -> f90nml.Namelist:
    """The one group instance that ``group[index]`` selects."""
    if group not in nml:
        raise KeyError(f"the scene has no &{group} group")
    found = nml[group]
    instances = list(found) if isinstance(found, list) else [found]
    if index is None or index == "":
        if len(instances) != 1:
            raise KeyError(f"&{group} appears {len(instances)} times: give an index,"
                           f" e.g. '{group}[0]'")
        return instances[0]
    if re.fullmatch(r"[+-]?\d+", index):
        number = int(index)
        if not -len(instances) <= number < len(instances):
            raise IndexError(f"&{group}[{number}]: the scene has {len(instances)}"
                             f" &{group} group(s)")
        return instances[number]
    name = index.strip("'\"")
    for instance in instances:
        if str(instance.get("name", "")).lower() == name.lower():
            return instance
    names = [str(instance.get("name")) for instance in instances]
    raise KeyError(f"no &{group} group named {name!r}; names: {', '.join(names)}")


def get_parameter(nml: f90nml.Namelist, address: str) -> Any:
    """The value of one variable (see the module notes for ``address``).

    Raises
    ------
    KeyError
        If the group, the named group or the variable is missing.
    """
    group, index, variable = _parse(address)
    instance = _group(nml, group, index)
    if variable not in instance:
        raise KeyError(f"&{group} has no variable {variable!r} set")
    return instance[variable]


def set_parameter(nml: f90nml.Namelist, address: str, value: Any) -> f90nml.Namelist:
    """Set one variable of one group in place (see the module notes for ``address``).

    A variable not yet in the group is added. An integer given for a variable that
    holds reals is stored as a real. Returns ``nml``, so calls can be chained.

    Raises
    ------
    ValueError
        If ``address`` is malformed.
    KeyError, IndexError
        If the group is missing, the index is out of range or no group has that name.
    """
    group, index, variable = _parse(address)
    instance = _group(nml, group, index)
    old = instance.get(variable)
    if isinstance(old, float) and isinstance(value, int) and not isinstance(value, bool):
        value = float(value)
    instance[variable] = value
    return nml
