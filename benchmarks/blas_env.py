# SPDX-License-Identifier: MIT
"""The OpenBLAS kernel choice of the yarnfort program (python/yarnfort/_blas.py), applied
to this process's environment so that the binaries a benchmark starts from build/ (and
OpenSeesPy, which loads the same OpenBLAS) run with the kernels the program runs with."""
from __future__ import annotations

import importlib.util
import pathlib

SOURCE = pathlib.Path(__file__).resolve().parent.parent / 'python' / 'yarnfort' / '_blas.py'


def apply() -> str:
    """Set OPENBLAS_CORETYPE as the program does (a value already set is kept); the
    value in force, for the benchmark's header."""
    spec = importlib.util.spec_from_file_location('yarnfort_blas', SOURCE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.apply_openblas_core() or "unset (OpenBLAS's own detection)"
