# SPDX-License-Identifier: MIT
"""Units of measured CSV columns, as the program reads them in table files.

The same units and header rules as ``src/yarnfort/units.f90`` (``&material table_file``,
REFERENCE.md *Table files*): a column header states its unit in its last brackets
(``Force (cN)``, ``strain [%]``) or as its last word after a blank or ``/`` when that is
a unit (``Force in cN``); plain names (``strain``) state none. A value v in unit u is
``v * numerator / denominator`` in the scene's unit (strain 1, force N, length m).
``tests/python/test_units.py`` checks that both sides convert alike. Measured curves
(:mod:`yarnfort.calibrate`) may also give a force per width, any force unit over a length
unit (``N/m``, ``cN/cm``, ``lbf/in``).
"""
from __future__ import annotations

import re

import numpy as np

__all__ = ["UNITS", "split_header", "to_scene_unit", "strain_factor", "force_factor"]

#: Standard gravity (m/s**2) and the avoirdupois pound-force (N), exact by definition.
STANDARD_GRAVITY = 9.80665
POUND_FORCE = 4.4482216152605

#: spelling -> (kind, numerator, denominator)
UNITS: dict[str, tuple[str, float, float]] = {
    "1": ("strain", 1.0, 1.0), "-": ("strain", 1.0, 1.0), "%": ("strain", 1.0, 100.0),
    "permille": ("strain", 1.0, 1000.0), "\u2030": ("strain", 1.0, 1000.0),
    "m": ("length", 1.0, 1.0), "cm": ("length", 1.0, 100.0), "mm": ("length", 1.0, 1000.0),
    "um": ("length", 1.0, 1.0e6), "\u00b5m": ("length", 1.0, 1.0e6),
    "N": ("force", 1.0, 1.0), "cN": ("force", 1.0, 100.0), "mN": ("force", 1.0, 1000.0),
    "kN": ("force", 1000.0, 1.0), "gf": ("force", STANDARD_GRAVITY, 1000.0),
    "kgf": ("force", STANDARD_GRAVITY, 1.0), "lbf": ("force", POUND_FORCE, 1.0),
}
#: Widths of a force per width: the length units, and the inch of strip tests (exact).
WIDTH_UNITS: dict[str, float] = {**{name: numerator / denominator
                                    for name, (kind, numerator, denominator) in UNITS.items()
                                    if kind == "length"}, "in": 0.0254}
#: Spellings also read in any case (no SI prefix to confuse them with).
ANY_CASE = ("permille", "gf", "kgf", "lbf")
#: A field ending in (unit) or [unit], perhaps followed by words without brackets.
_BRACKETS = re.compile(r"^(?P<name>.*?)\s*(?:\((?P<round>[^()]*)\)|\[(?P<square>[^\[\]]*)\])"
                       r"[^()\[\]]*$")


def find_unit(text: str) -> str | None:
    """The known spelling of ``text`` (exact, or in any case for ANY_CASE), or None."""
    if text in UNITS:
        return text
    return text.lower() if text.lower() in ANY_CASE else None


def split_header(field: str) -> tuple[str, str | None]:
    """A column header as (name, unit text), the unit None where it states none.

    Parameters
    ----------
    field : str
        The header cell (``'Force (cN)'``, ``'strain [%]'``, ``'Force in cN'``).

    Returns
    -------
    name : str
    unit : str or None
    """
    field = field.strip()
    match = _BRACKETS.match(field)
    if match:
        unit = match["round"] if match["round"] is not None else match["square"]
        return match["name"].strip(), unit.strip()
    cut = max(field.rfind(" "), field.rfind("/"))
    last = field[cut + 1:]
    if find_unit(last) is not None:
        name = field[:max(cut, 0)].strip()
        return re.sub(r"\s+in$", "", name, flags=re.IGNORECASE), last
    return field, None


def to_scene_unit(values: np.ndarray, unit: str, kind: str) -> np.ndarray:
    """``values`` in ``unit`` (a spelling of a unit of ``kind``) in the scene's unit.

    Parameters
    ----------
    values : array_like
        The values as given.
    unit : str
        Their unit.
    kind : {'strain', 'force', 'length'}
        What they are.

    Returns
    -------
    numpy.ndarray

    Raises
    ------
    ValueError
        If ``unit`` is not a known unit of that kind (the message lists them).
    """
    name = find_unit(unit)
    if name is None or UNITS[name][0] != kind:
        known = ", ".join(repr(u) for u, (k, _, _) in UNITS.items() if k == kind)
        raise ValueError(f"{unit!r} is not a known {kind} unit ({known})")
    _, numerator, denominator = UNITS[name]
    return (np.asarray(values, dtype=float) * numerator) / denominator


def strain_factor(unit: str | None) -> float:
    """Factor from a strain in ``unit`` (``'%'``, ``'permille'``, ``'1'``; None is 1) to a
    strain of 1.

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
    return float(to_scene_unit(1.0, "1" if unit is None else unit.strip(), "strain"))


def force_factor(unit: str | None) -> tuple[float, bool]:
    """Factor from a force (``'N'``, ``'cN'``, ``'gf'``, ...) or a force per width (a force
    unit over a width unit: ``'N/m'``, ``'cN/cm'``, ``'lbf/in'``) to N or N/m; None is N.

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
    force, _, width = (part.strip() for part in ("N" if unit is None else unit).partition("/"))
    if width and width not in WIDTH_UNITS:
        raise ValueError(f"force unit {unit!r}: a force per width is a force unit over one of "
                         f"{', '.join(WIDTH_UNITS)}")
    try:
        factor = float(to_scene_unit(1.0, force, "force"))
    except ValueError as error:
        raise ValueError(f"force unit {unit!r}: {error}") from None
    return (factor / WIDTH_UNITS[width], True) if width else (factor, False)
