# SPDX-License-Identifier: MIT
"""The yarnfort program (the Fortran executable) that ships inside the package.

meson installs it as ``yarnfort/bin/yarnfort``; :func:`program_path` finds it through
:mod:`importlib.resources`, which also works for an editable install (there it is the
file in the meson build folder that the install was made with). The ``yarnfort``
console command is :func:`main`: it replaces itself by the program, so standard input,
output, error and the exit code are the program's own.
"""
from __future__ import annotations

import importlib.resources
import os
import sys
from pathlib import Path

__all__ = ["program_path", "main"]

#: Where the program sits inside the package.
PROGRAM = ("bin", "yarnfort")


def program_path() -> Path:
    """Path of the yarnfort program of this installation.

    Returns
    -------
    pathlib.Path
        The executable (``./yarnfort < scene.nml`` runs the same file).

    Raises
    ------
    FileNotFoundError
        If the installation has no program (a broken or partial install).
    """
    path = Path(os.fspath(importlib.resources.files("yarnfort").joinpath(*PROGRAM)))
    if not path.is_file():
        raise FileNotFoundError(f"the yarnfort program is missing from the installation"
                                f" ({path}): reinstall the package (pip install .)")
    return path


def main() -> None:
    """Console command ``yarnfort``: run the program with this command's arguments."""
    try:
        path = program_path()
    except FileNotFoundError as error:
        print(f"yarnfort: error: {error}", file=sys.stderr)
        sys.exit(2)
    sys.stdout.flush()
    sys.stderr.flush()
    os.execv(path, [str(path), *sys.argv[1:]])
