# SPDX-License-Identifier: MIT
"""yarnfort: textiles as networks of 1D hyperelastic strings with capstan friction.

The Python side of yarnfort: build scenes (:class:`Scene`), run them in process
(:func:`run_scene`) or over parameter grids (:func:`run_sweep`), fit parameters to a
measured curve in its lab units (:func:`calibrate`), and read and plot the results
(:func:`read_run`, :mod:`yarnfort.plots`). The physics lives in the Fortran library.

Names are loaded on first use, so that ``import yarnfort`` stays quick. Importing it sets
``OPENBLAS_CORETYPE`` where it is unset (:mod:`yarnfort._blas`).
"""
from __future__ import annotations

import importlib
from typing import Any

from ._blas import apply_openblas_core
from ._version import __version__

# OpenBLAS chooses its kernels when it is loaded: by the extension in this process, or by
# the program in a child process (the console command, yarnfort.program_path()). Both
# inherit this choice, so every route runs the same kernels (yarnfort._blas).
apply_openblas_core()

#: Public name -> module that defines it.
_EXPORTS: dict[str, str] = {
    "Curve": "results", "State": "results", "ResultError": "results",
    "read_curve": "results", "read_state": "results", "read_states": "results",
    "read_run": "results", "read_reactions": "results", "read_contacts": "results",
    "YarnfortError": "_native", "critical_tension": "_native", "force_law": "_native",
    "run_scene": "runner", "RunResult": "runner", "RunInterrupted": "runner",
    "Step": "runner",
    "read_scene": "namelist", "write_scene": "namelist", "make_namelist": "namelist",
    "set_parameter": "address", "get_parameter": "address", "AddressError": "address",
    "Scene": "scene", "Material": "scene", "Contact": "scene", "Yarn": "scene",
    "Support": "scene", "Load": "scene", "LoadPath": "scene", "Fabric": "scene",
    "Obstacle": "scene", "Ring": "scene",
    "Geometry": "scene", "SceneError": "scene", "UnknownVariableError": "scene",
    "write_examples": "resources", "reference_text": "resources",
    "run_sweep": "sweep",
    "CalibrationResult": "calibrate", "calibrate": "calibrate", "plot_fit": "calibrate",
    "IdentifiabilityWarning": "calibrate",
    "program_path": "_program",
    "export_fabric": "fabric_export", "fabric_curves": "fabric_export",
    "FabricExportError": "fabric_export",
}

__all__ = ["__version__", *_EXPORTS]


def __getattr__(name: str) -> Any:
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'yarnfort' has no attribute {name!r}")
    value = getattr(importlib.import_module(f".{module}", __name__), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(__all__)
