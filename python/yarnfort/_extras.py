# SPDX-License-Identifier: MIT
"""Imports of the optional dependencies (the extras of pyproject.toml): a missing one is
an ImportError that names the extra to install, not a bare ModuleNotFoundError."""
from __future__ import annotations

import importlib
from types import ModuleType

__all__ = ["import_extra"]


def import_extra(module: str, extra: str, purpose: str) -> ModuleType:
    """Import ``module`` of the extra ``extra``.

    Parameters
    ----------
    module : str
        The module (``'pandas'``, ``'distributed'``).
    extra : str
        The extra of the package that installs it (``'pandas'``, ``'dask'``).
    purpose : str
        What needs it, for the message (``'Curve.to_dataframe'``).

    Raises
    ------
    ImportError
        If it is not installed: the message names ``pip install 'yarnfort[extra]'``.
    """
    try:
        return importlib.import_module(module)
    except ModuleNotFoundError as error:
        # Only the module itself missing; a broken dependency of it keeps its own error.
        if error.name is not None and error.name.split(".")[0] != module.split(".")[0]:
            raise
        raise ImportError(f"{purpose} needs {module}, which is not installed: pip install"
                          f" 'yarnfort[{extra}]'", name=module) from None
