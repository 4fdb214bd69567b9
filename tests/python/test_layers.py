# SPDX-License-Identifier: MIT
"""The Fortran library keeps the layering of docs/architecture.md: a folder of
src/yarnfort/ uses only modules of the levels above it (and the few named exceptions), so
data flows one way, from the input through the scene and the solvers to the output."""
from __future__ import annotations

import re
from pathlib import Path

SOURCE = Path(__file__).resolve().parents[2] / "src" / "yarnfort"

#: The level of each folder (top-level files by their name), as docs/architecture.md lists them.
LEVELS = {
    "kinds": 1, "error": 1, "text": 1, "csv": 1, "sort": 1, "units": 1, "version": 1,
    "material": 2, "friction": 2, "network": 2, "linalg": 2,
    "input": 3, "generate": 3,
    "scene": 4, "assembly": 5, "solver": 6, "contact": 7, "output": 8, "driver": 9,
}

#: Uses across levels that the architecture names: folder -> modules it may use besides.
EXCEPTIONS = {
    "input": {"yarnfort_scene_channels", "yarnfort_scene_contact_nodes"},
    "scene": {"yarnfort_contact_passages"},
}

MODULE = re.compile(r"^\s*module\s+(?!procedure\b)(\w+)", re.M | re.I)
USE = re.compile(r"^\s*use\s*(?:,\s*\w+\s*::)?\s*(\w+)", re.M | re.I)


def folder_of(path: Path) -> str:
    relative = path.relative_to(SOURCE)
    return relative.parts[0] if len(relative.parts) > 1 else relative.name.split(".")[0]


def sources():
    return sorted(SOURCE.rglob("*.f90")) + sorted(SOURCE.rglob("*.f90.in"))


def module_folders() -> dict[str, str]:
    folders = {}
    for path in sources():
        for match in MODULE.finditer(path.read_text()):
            folders[match.group(1).lower()] = folder_of(path)
    return folders


def uses_across_folders():
    """(file, its folder, used module, that module's folder) for every use of a module of
    another folder of the library."""
    folders = module_folders()
    for path in sources():
        folder = folder_of(path)
        for match in USE.finditer(path.read_text()):
            module = match.group(1).lower()
            if module in folders and folders[module] != folder:
                yield path.relative_to(SOURCE), folder, module, folders[module]


def test_every_folder_has_a_level():
    missing = set(module_folders().values()) - set(LEVELS)
    assert not missing, f"folders of src/yarnfort/ without a level: {sorted(missing)}"


def test_uses_go_up_the_levels_only():
    wrong = []
    for path, folder, module, used in uses_across_folders():
        allowed = (LEVELS[used] < LEVELS[folder] or LEVELS[used] == LEVELS[folder] == 1
                   or (folder == "generate" and used == "input")
                   or module in EXCEPTIONS.get(folder, set()))
        if not allowed:
            wrong.append(f"{path} ({folder}, level {LEVELS[folder]}) uses {module} "
                         f"({used}, level {LEVELS[used]})")
    assert not wrong, "\n".join(wrong)


def test_output_uses_nothing_from_input():
    wrong = [f"{path} uses {module}" for path, folder, module, used in uses_across_folders()
             if folder == "output" and used == "input"]
    assert not wrong, "\n".join(wrong)


def test_the_check_sees_uses():
    """The scan finds known uses, so an empty list above means something."""
    found = {(folder, used) for _, folder, _, used in uses_across_folders()}
    assert ("output", "solver") in found and ("scene", "input") in found
