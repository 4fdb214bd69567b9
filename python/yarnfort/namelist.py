# SPDX-License-Identifier: MIT
"""Read, change and write yarnfort scene namelists with :mod:`f90nml`.

A scene (``inputs/*.nml``, or a run's effective ``input.nml``) is read into an
:class:`f90nml.Namelist`: group name -> variables. A group that appears more than once
(``&material``, ``&yarn``, ``&support``, ``&contact``, ...) becomes a list of groups (an
``f90nml`` Cogroup) in file order; a group that appears once is a single Namelist.
Group and variable names are lower case. Comments are not kept on writing.

A scene can also be built from plain Python data with :func:`make_namelist` (a dict of
group name -> dict of variables, or a list of such dicts for a repeated group).
Variables are addressed with the grammar of :mod:`yarnfort.address`
(:func:`get_parameter`, :func:`set_parameter`), shared with sweeps and calibration.
"""
from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import f90nml

from .address import AddressError, get_parameter, set_parameter

__all__ = ["read_scene", "write_scene", "make_namelist", "set_parameter", "get_parameter",
           "AddressError"]


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

    Parameters
    ----------
    nml : f90nml.Namelist
        The scene (:func:`read_scene` or :func:`make_namelist`).
    path : str or Path
        The file to write.

    Returns
    -------
    pathlib.Path
        The path written.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    nml.write(str(path), force=True)
    return path


def make_namelist(groups: Mapping[str, Mapping[str, Any] | Sequence[Mapping[str, Any]]]
                  ) -> f90nml.Namelist:
    """Build a namelist from plain data, repeated groups included.

    ``f90nml.Namelist({'material': [{...}, {...}]})`` cannot be written (f90nml expects
    its own cogroups for a repeated group); this builds them.

    Parameters
    ----------
    groups : mapping
        Group name -> a mapping of variables (a group given once), or a sequence of
        mappings (a repeated group, in order). Group and variable names are lower-cased.

    Returns
    -------
    f90nml.Namelist
        Groups in the order given; within a group, variables in the order given.

    Raises
    ------
    TypeError
        If a group is neither a mapping nor a sequence of mappings.
    """
    nml = f90nml.Namelist()
    for name, content in groups.items():
        key = str(name).lower()
        if isinstance(content, Mapping):
            nml[key] = _group(content)
        elif isinstance(content, Sequence) and not isinstance(content, str) and all(
                isinstance(item, Mapping) for item in content):
            for item in content:
                nml.add_cogroup(key, _group(item))
        else:
            raise TypeError(f"&{key}: expected a mapping of variables or a list of them,"
                            f" not {type(content).__name__}")
    return nml


def _group(variables: Mapping[str, Any]) -> f90nml.Namelist:
    group = f90nml.Namelist()
    for name, value in variables.items():
        group[str(name).lower()] = value
    return group
