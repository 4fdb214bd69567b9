# SPDX-License-Identifier: MIT
"""Lab units of measured curves: strain, force and force per width, to SI.

A measured CSV names its units in the column headers, ``strain (%)``, ``force (cN)``,
``force [N/m]``; :func:`split_header` takes them apart and :func:`strain_factor` and
:func:`force_factor` give the factor that turns a value into SI (strain 1, force N,
force per width N/m). The factors are exact: the gram-force and the pound-force by their
definitions (standard gravity 9.80665 m/s^2, 1 lbf = 0.45359237 kg x 9.80665 m/s^2).
Unit names are case-sensitive where SI makes them so (``mN`` is not ``MN``).
"""
from __future__ import annotations

import re

__all__ = ["STRAIN_UNITS", "FORCE_UNITS", "LENGTH_UNITS", "split_header",
           "strain_factor", "force_factor"]

#: Strain unit -> factor to a strain of 1.
STRAIN_UNITS: dict[str, float] = {"": 1.0, "1": 1.0, "-": 1.0, "%": 1.0e-2,
                                  "permille": 1.0e-3, "‰": 1.0e-3}
#: Force unit -> factor to N.
FORCE_UNITS: dict[str, float] = {"N": 1.0, "kN": 1.0e3, "cN": 1.0e-2, "mN": 1.0e-3,
                                 "gf": 9.80665e-3, "kgf": 9.80665,
                                 "lbf": 4.4482216152605}
#: Length unit -> factor to m (the denominator of a force per width).
LENGTH_UNITS: dict[str, float] = {"m": 1.0, "cm": 1.0e-2, "mm": 1.0e-3, "in": 2.54e-2}

_HEADER = re.compile(r"^\s*([^()\[\]]*?)\s*(?:[(\[]\s*([^()\[\]]*?)\s*[)\]])?\s*$")


def split_header(text: str) -> tuple[str, str | None]:
    """``'strain (%)'`` -> ``('strain', '%')``; ``'force [cN]'`` -> ``('force', 'cN')``;
    ``'force'`` -> ``('force', None)``. The name is lower-cased; the unit kept as written.

    Parameters
    ----------
    text : str
        A column header.

    Returns
    -------
    name : str
    unit : str or None

    Raises
    ------
    ValueError
        For a header with unbalanced or repeated brackets.
    """
    match = _HEADER.match(text)
    if not match:
        raise ValueError(f"column header {text!r}: expected 'name' or 'name (unit)'")
    name, unit = match.groups()
    return name.lower(), unit


def strain_factor(unit: str | None) -> float:
    """Factor from a strain in ``unit`` (``'%'``, ``'permille'``, ``'1'``; None is 1)
    to a strain of 1.

    Parameters
    ----------
    unit : str or None
        The unit.

    Returns
    -------
    float

    Raises
    ------
    ValueError
        For an unknown unit; the message lists the known ones.
    """
    key = "" if unit is None else unit.strip()
    if key.lower() in STRAIN_UNITS:
        return STRAIN_UNITS[key.lower()]
    raise ValueError(f"strain unit {unit!r}: known units are "
                     + ", ".join(repr(u) for u in STRAIN_UNITS if u))


def force_factor(unit: str | None) -> tuple[float, bool]:
    """Factor from a force (``'N'``, ``'cN'``, ``'mN'``, ``'gf'``, ``'kgf'``, ``'lbf'``)
    or a force per width (``'N/m'``, ``'cN/cm'``, ``'N/mm'``, ... : any force unit over
    ``m``, ``cm``, ``mm`` or ``in``) to N or N/m; None is N.

    Parameters
    ----------
    unit : str or None
        The unit.

    Returns
    -------
    factor : float
        To N (a force) or N/m (a force per width).
    per_width : bool
        True for a force per width.

    Raises
    ------
    ValueError
        For an unknown unit; the message lists the known ones.
    """
    key = "N" if unit is None else unit.strip()
    force, _, length = (part.strip() for part in key.partition("/"))
    if force in FORCE_UNITS and (not length or length in LENGTH_UNITS):
        if length:
            return FORCE_UNITS[force] / LENGTH_UNITS[length], True
        return FORCE_UNITS[force], False
    raise ValueError(f"force unit {unit!r}: known units are {', '.join(FORCE_UNITS)}, or one"
                     f" of them per {', '.join(LENGTH_UNITS)} for a force per width (N/m)")
