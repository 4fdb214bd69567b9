# SPDX-License-Identifier: MIT
"""The files the package carries: the input reference (``inputs/REFERENCE.md``), the
example scenes with their tables and models (``inputs/``), and the description of every
namelist group and variable that the scene classes are made from.

meson installs them from the repository's own files as ``yarnfort/data/...``
(python/meson.build), so a pip-installed package stands alone: ``python -m yarnfort
reference`` prints the reference, ``python -m yarnfort examples DIR`` writes the examples
into ``DIR/inputs/`` (the layout their relative paths expect: ``cd DIR && yarnfort <
inputs/knit.nml``).
"""
from __future__ import annotations

import importlib.resources
import json
import os
from functools import cache
from importlib.resources.abc import Traversable
from pathlib import Path
from typing import Any

__all__ = ["reference_text", "example_files", "write_examples", "input_description"]

#: Where the data sit inside the package.
DATA = "data"
#: The examples' folder inside DATA, named as in the repository.
INPUTS = "inputs"


def _data() -> Traversable:
    return importlib.resources.files("yarnfort").joinpath(DATA)


def _missing(what: str) -> FileNotFoundError:
    return FileNotFoundError(f"{what} is missing from the installation: reinstall the"
                             " package (pip install yarnfort)")


def reference_text() -> str:
    """The input reference, ``inputs/REFERENCE.md``: every group and variable with its
    default, unit and range, the checks, the output files.

    Returns
    -------
    str
        The Markdown text.

    Raises
    ------
    FileNotFoundError
        If the installation lacks it.
    """
    path = _data().joinpath(INPUTS, "REFERENCE.md")
    if not path.is_file():
        raise _missing("inputs/REFERENCE.md")
    return path.read_text(encoding="utf-8")


def _walk(folder: Traversable, prefix: str) -> list[tuple[str, Traversable]]:
    out = []
    for item in sorted(folder.iterdir(), key=lambda entry: entry.name):
        name = f"{prefix}/{item.name}"
        if item.is_dir():
            out += _walk(item, name)
        elif item.name != "REFERENCE.md":
            out.append((name, item))
    return out


def example_files() -> list[str]:
    """The example files, as paths relative to the folder they are written to:
    ``'inputs/vnet.nml'``, ``'inputs/data/knit_yarn.csv'``, ...

    Raises
    ------
    FileNotFoundError
        If the installation lacks them.
    """
    folder = _data().joinpath(INPUTS)
    if not folder.is_dir():
        raise _missing("the example scenes (inputs/)")
    return [name for name, _ in _walk(folder, INPUTS)]


def write_examples(folder: str | os.PathLike, overwrite: bool = False) -> list[Path]:
    """Write the example scenes, their tables and models into ``folder/inputs/``.

    Run one there as in the repository: ``cd folder && yarnfort < inputs/vnet.nml``
    (results in ``folder/out/vnet``).

    Parameters
    ----------
    folder : str or path
        Where to write (made if missing).
    overwrite : bool
        Replace files that exist; otherwise an existing file is an error and nothing is
        written.

    Returns
    -------
    list of pathlib.Path
        The files written.

    Raises
    ------
    FileExistsError
        If a file exists and ``overwrite`` is false (nothing written then).
    FileNotFoundError
        If the installation lacks the examples.
    """
    folder = Path(folder)
    source = _data().joinpath(INPUTS)
    if not source.is_dir():
        raise _missing("the example scenes (inputs/)")
    files = _walk(source, INPUTS)
    targets = [(folder / name, item) for name, item in files]
    existing = [str(target) for target, _ in targets if target.exists()]
    if existing and not overwrite:
        raise FileExistsError(f"{existing[0]} exists ({len(existing)} of the"
                              f" {len(targets)} example files do): choose an empty folder"
                              " or overwrite (--force)")
    for target, item in targets:
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_bytes(item.read_bytes())
    return [target for target, _ in targets]


@cache
def input_description() -> dict[str, Any]:
    """Every namelist group and variable (the one description of the input,
    src/yarnfort/input/variables.py, as JSON made at build time).

    Returns
    -------
    dict
        ``{'groups': [{'name', 'kind', 'doc', 'variables': [{'name', 'type', 'default',
        'shape', 'length', 'unit', 'range', 'choices', 'laws', ...}]}]}``.
    """
    path = _data().joinpath("input_description.json")
    if not path.is_file():
        raise _missing("the input description (input_description.json)")
    return json.loads(path.read_text(encoding="utf-8"))
