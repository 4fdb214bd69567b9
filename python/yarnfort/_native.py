# SPDX-License-Identifier: MIT
"""Thin wrappers over the f2py extension ``yarnfort._yarnfort`` (the flat Fortran facade).

Every facade routine returns an integer status and a message; a non-zero status becomes a
:class:`YarnfortError`. No physics here: the laws are evaluated by the Fortran library.
The extension is part of the installed package (``pip install .``) and is imported on
first use, so that ``import yarnfort`` stays quick.
"""
from __future__ import annotations

import functools
import importlib
import os
from types import ModuleType
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["YarnfortError", "force_law", "critical_tension", "EXIT_CATEGORIES"]

#: Exit category of each status, as the program's exit codes.
EXIT_CATEGORIES: dict[int, str] = {1: "solve_failed", 2: "bad_input"}

#: Keyword parameters of each force law, in the order of the facade's p1, p2.
FORCE_LAW_PARAMETERS: dict[str, tuple[str, ...]] = {
    "linear": ("stiffness",),
    "neo_hookean": ("modulus", "area"),
    "table": ("table_file",),
}
#: Keyword parameters of each friction law, in the order of the facade's mu, beta, w_d, s_d.
FRICTION_LAW_PARAMETERS: dict[str, tuple[str, ...]] = {
    "coulomb": ("friction_coefficient",),
    "adhesion": ("friction_coefficient", "adhesion"),
    "decaying_adhesion": ("friction_coefficient", "adhesion", "decay_start", "decay_end"),
    "general": ("rate_table",),
}


class YarnfortError(RuntimeError):
    """An error reported by the Fortran library; the message names what was wrong.

    Attributes
    ----------
    status : int
        The program's exit code for it: 1 for a failed solve, 2 for bad input (a law or
        parameter the library refuses included), a bad restart file or an unusable
        output folder.
    category : str
        ``'solve_failed'`` (status 1) or ``'bad_input'`` (status 2).
    result : object or None
        For a failed :func:`yarnfort.run_scene` solve, the :class:`yarnfort.RunResult`
        of the converged steps written before the failure (they are kept).
    """

    def __init__(self, message: str, status: int = 1, result: object | None = None) -> None:
        super().__init__(message)
        self.status = int(status)
        self.category = EXIT_CATEGORIES.get(self.status, "error")
        self.result = result


@functools.cache
def extension() -> ModuleType:
    """The f2py extension module ``yarnfort._yarnfort``, imported once; the first import
    also makes the process-wide settings of the solver libraries (threads, heap).

    Raises
    ------
    ImportError
        If the package was not built with its extension (install it with ``pip install``).
    """
    module = importlib.import_module(f"{__package__}._yarnfort")
    # The solver libraries' threads and heap, set once for the process as the program
    # sets them at its start (the Fortran library's constructors leave them alone).
    module.yarnfort_facade.process_settings()
    return module


def _facade() -> ModuleType:
    """The facade module inside the extension."""
    return extension().yarnfort_facade


def check_status(status: int, message: bytes | str, result: object | None = None) -> None:
    """Raise :class:`YarnfortError` for a non-zero facade status."""
    if status != 0:
        text = message.decode("utf-8", errors="replace") if isinstance(message, bytes) \
            else message
        text = text.strip()
        raise YarnfortError(text or f"yarnfort failed with status {status}", int(status),
                            result)


def _parameters(kind: str, law: str, table: dict[str, tuple[str, ...]],
                params: dict[str, object]) -> list[object]:
    """The law's parameters in facade order; none for an unknown law, which the library
    rejects by name."""
    names = table.get(law)
    if names is None:
        return []
    unexpected = sorted(set(params) - set(names))
    missing = [name for name in names if name not in params]
    if unexpected or missing:
        problem = (f"unexpected {', '.join(unexpected)}" if unexpected
                   else f"missing {', '.join(missing)}")
        raise TypeError(f"{kind} law {law!r} takes {', '.join(names)}: {problem}")
    return [params[name] for name in names]


def _flat(values: np.ndarray) -> np.ndarray:
    """Contiguous 1-D copy for the facade; an empty input becomes one placeholder value
    (f2py rejects empty arrays), so that the law is still built and checked."""
    flat = np.ascontiguousarray(values, dtype=float).ravel()
    return flat if flat.size else np.ones(1)


def _shaped(values: tuple[np.ndarray, ...], shape: tuple[int, ...]
            ) -> tuple[np.ndarray, ...]:
    """Facade outputs in the input's shape (scalars for 0-d input)."""
    size = int(np.prod(shape))
    return tuple(np.reshape(value[:size], shape)[()] for value in values)


def force_law(law: str, stretch: ArrayLike, **params: float | str | os.PathLike
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Evaluate a force law of the library at the given stretches.

    Parameters
    ----------
    law : str
        ``'linear'`` (``stiffness`` = EA in N), ``'neo_hookean'`` (``modulus`` C in Pa,
        ``area`` S1 in m**2) or ``'table'`` (``table_file``: CSV of strain, force, in the
        units its header states, else 1 and N).
    stretch : array_like
        Stretches lambda = l/L0, any shape.
    **params
        The law's parameters, named as above.

    Returns
    -------
    force, dforce, energy : numpy.ndarray
        Tension f (N), df/dlambda (N) and energy per unit reference length (N), shaped
        like ``stretch``.

    Raises
    ------
    YarnfortError
        If the library rejects the law or a parameter (the message names the value).
    """
    values = _parameters("force", law, FORCE_LAW_PARAMETERS, params)
    p1, p2, table_file = np.nan, np.nan, ""
    if law == "table" and values:
        table_file = os.fspath(values[0])
    elif values:
        p1, p2 = (list(map(float, values)) + [np.nan])[:2]
    lam = np.asarray(stretch, dtype=float)
    force, dforce, energy, status, message = _facade().force_law_eval(
        law, p1, p2, os.fsencode(table_file), _flat(lam))
    check_status(status, message)
    return _shaped((force, dforce, energy), lam.shape)


def critical_tension(law: str, tension_min: ArrayLike, angle: ArrayLike, **params: Any
                     ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Critical tension T_crit(T_min, alpha) of a friction law of the library.

    Parameters
    ----------
    law : str
        ``'coulomb'`` (``friction_coefficient`` mu), ``'adhesion'`` (mu and ``adhesion``
        beta in N/rad), ``'decaying_adhesion'`` (mu, beta, ``decay_start`` w_d and
        ``decay_end`` s_d in N) or ``'general'`` (``rate_table``: a CSV file of T in N and
        g in N/rad, as ``&contact rate_table``; relative to the working directory).
    tension_min, angle : array_like
        Low-side tension T_min (N) and bending angle alpha (rad), broadcast together.
    **params
        The law's parameters, named as above.

    Returns
    -------
    critical, d_dtension, d_dangle : numpy.ndarray
        T_crit and its derivatives with respect to T_min and alpha, in the broadcast shape.

    Raises
    ------
    YarnfortError
        If the library rejects the law or a parameter.
    """
    values = _parameters("friction", law, FRICTION_LAW_PARAMETERS, params)
    rate_table = ""
    if law == "general":
        rate_table = os.fspath(values.pop())
    mu, beta, w_d, s_d = (list(map(float, values)) + [np.nan] * 4)[:4]
    tension, alpha = np.broadcast_arrays(np.asarray(tension_min, dtype=float),
                                         np.asarray(angle, dtype=float))
    critical, d_dtension, d_dangle, status, message = _facade().friction_critical_tension(
        law, mu, beta, w_d, s_d, rate_table, _flat(tension), _flat(alpha))
    check_status(status, message)
    return _shaped((critical, d_dtension, d_dangle), tension.shape)
