# SPDX-License-Identifier: MIT
"""Thin wrappers over the f2py extension ``_yarnfort`` (the flat Fortran facade).

Every facade routine returns an integer status and a message; a non-zero status becomes a
:class:`YarnfortError`. No physics here: the laws are evaluated by the Fortran library.

Where the extension is found
----------------------------
The extension is built by meson with ``-Dpython=true`` into ``<build>/python/`` and is
not copied into the source tree. It is loaded on first use (so that ``import yarnfort``
works without it, for the result readers) from the first of:

1. ``$YARNFORT_NATIVE``: the extension file, or a folder holding it;
2. the package folder ``yarnfort/`` (an installed or copied ``_yarnfort.<abi>.so``);
3. ``<top>/build/python/`` (the build made by ``tools/bootstrap``), else the most
   recently built ``<top>/build*/python/_yarnfort.<abi>.so`` of this checkout.

Only files with an extension suffix of the running interpreter are considered.
"""
from __future__ import annotations

import functools
import importlib.machinery
import importlib.util
import os
import sys
from pathlib import Path
from types import ModuleType
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike

__all__ = ["YarnfortError", "SceneRun", "force_law", "critical_tension", "run_scene",
           "native_path"]

#: Environment variable naming the extension file (or its folder).
NATIVE_ENV = "YARNFORT_NATIVE"
#: Name of the f2py extension module.
NATIVE_NAME = "_yarnfort"

_PACKAGE = Path(__file__).resolve().parent
_TOP = _PACKAGE.parents[1]

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
}


class SceneRun(NamedTuple):
    """Outcome of :func:`run_scene`: the output folder and the converged steps written."""

    folder: Path
    n_steps: int


class YarnfortError(RuntimeError):
    """An error reported by the Fortran library; the message names what was wrong.

    Attributes
    ----------
    status : int
        The facade's status: 1 for a bad law parameter or a failed solve, 2 for a bad
        scene input or an unusable output folder (the program's exit codes).
    run : SceneRun or None
        For a failed :func:`run_scene` solve: the output folder and the converged steps
        written before the failure (they are kept).
    """

    def __init__(self, message: str, status: int = 1, run: SceneRun | None = None) -> None:
        super().__init__(message)
        self.status = status
        self.run = run


def _candidates(folder: Path) -> list[Path]:
    names = [NATIVE_NAME + suffix for suffix in importlib.machinery.EXTENSION_SUFFIXES]
    return [folder / name for name in names if (folder / name).is_file()]


def native_path() -> Path:
    """Path of the extension module that :func:`force_law` and friends load.

    Raises
    ------
    ImportError
        If no built extension is found (see the module notes for where it is looked for).
    """
    override = os.environ.get(NATIVE_ENV)
    if override:
        path = Path(override)
        found = _candidates(path) if path.is_dir() else [path] if path.is_file() else []
        if not found:
            raise ImportError(f"{NATIVE_ENV}={override!r}: no {NATIVE_NAME} extension there")
        return found[0]
    found = _candidates(_PACKAGE) or _candidates(_TOP / "build" / "python")
    if found:
        return found[0]
    built = [path for folder in _TOP.glob("build*/python") for path in _candidates(folder)]
    if not built:
        raise ImportError(
            f"the {NATIVE_NAME} extension is not built: in {_TOP} run 'meson configure build"
            f" -Dpython=true && meson compile -C build' (or set {NATIVE_ENV})")
    return max(built, key=lambda path: path.stat().st_mtime)


@functools.cache
def _facade() -> ModuleType:
    """The facade module inside the extension, loaded once."""
    path = native_path()
    name = f"{__package__}.{NATIVE_NAME}" if __package__ else NATIVE_NAME
    spec = importlib.util.spec_from_file_location(name, path)
    if spec is None or spec.loader is None:
        raise ImportError(f"cannot load the {NATIVE_NAME} extension from {path}")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    sys.modules[name] = module
    return module.yarnfort_facade


def _check(status: int, message: bytes, run: SceneRun | None = None) -> None:
    if status != 0:
        text = message.decode("utf-8", errors="replace").strip()
        raise YarnfortError(text or f"yarnfort failed with status {status}", int(status), run)


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
        ``area`` S1 in m**2) or ``'table'`` (``table_file``: CSV of strain, force in N).
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
    _check(status, message)
    return _shaped((force, dforce, energy), lam.shape)


def critical_tension(law: str, tension_min: ArrayLike, angle: ArrayLike, **params: float
                     ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Critical tension T_crit(T_min, alpha) of a friction law of the library.

    Parameters
    ----------
    law : str
        ``'coulomb'`` (``friction_coefficient`` mu), ``'adhesion'`` (mu and ``adhesion``
        beta in N/rad) or ``'decaying_adhesion'`` (mu, beta, ``decay_start`` w_d and
        ``decay_end`` s_d in N).
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
    values = list(map(float, _parameters("friction", law, FRICTION_LAW_PARAMETERS, params)))
    mu, beta, w_d, s_d = (values + [np.nan] * 4)[:4]
    tension, alpha = np.broadcast_arrays(np.asarray(tension_min, dtype=float),
                                         np.asarray(angle, dtype=float))
    critical, d_dtension, d_dangle, status, message = _facade().friction_critical_tension(
        law, mu, beta, w_d, s_d, _flat(tension), _flat(alpha))
    _check(status, message)
    return _shaped((critical, d_dtension, d_dangle), tension.shape)


def run_scene(path: str | os.PathLike) -> SceneRun:
    """Run the scene in a namelist file, as ``yarnfort < path`` does but silently.

    Writes ``curve.csv``, the VTK states and ``input.nml`` to the scene's ``&output``
    folder (a relative folder is taken from the working directory; relative file names
    inside the input from the folder of ``path``).

    Returns
    -------
    SceneRun
        The output folder (absolute) and the number of converged steps written (rows of
        ``curve.csv``, the initial state included).

    Raises
    ------
    YarnfortError
        For bad input (status 2) or a failed solve (status 1; the converged steps written
        so far are kept and described by the error's ``run``).
    """
    status, message, n_steps, folder = _facade().run_scene_file(os.fsencode(path))
    run = SceneRun(Path.cwd() / os.fsdecode(folder.strip()), int(n_steps))
    _check(status, message, run if n_steps > 0 else None)
    return run
