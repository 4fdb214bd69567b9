# SPDX-License-Identifier: MIT
"""The two kinds of entries of variables.py: a namelist group and one of its variables."""
from __future__ import annotations

from dataclasses import dataclass, field

#: Character lengths by name (the Fortran parameters of the same names).
LENGTHS = {"name_length": 64, "path_length": 512}
TYPES = ("character", "real", "integer", "logical")


@dataclass
class Var:
    """One namelist variable; the fields are explained in variables.py."""

    name: str
    type: str
    default: object = None
    doc: str = ""
    length: int | str | None = None
    shape: int | str | None = None
    max: str = "max_list"
    unit: str = ""
    range: str | None = None
    choices: list[str] | None = None
    retired: dict[str, str] | None = None
    lower: bool = False
    adjust: bool = True
    selects: bool = False
    laws: list[str] | None = None
    presets: dict[str, object] | None = None
    checked_by: str | None = None
    default_doc: str | None = None
    type_doc: str | None = None

    def __post_init__(self) -> None:
        if self.type not in TYPES:
            raise ValueError(f"{self.name}: unknown type {self.type!r}")
        if (self.type == "character") != (self.length is not None):
            raise ValueError(f"{self.name}: a length is given for character variables only")
        if self.shape == "list" and self.default is not None:
            raise ValueError(f"{self.name}: a list has no default (it is empty)")
        if not self.doc:
            raise ValueError(f"{self.name}: no doc")
        if self.retired and set(self.retired) & set(self.choices or []):
            raise ValueError(f"{self.name}: a retired value is still a choice")

    @property
    def optional(self) -> bool:
        """A real scalar without a default: not set until the input gives it (an
        allocatable in Fortran, None in Python), so that no value means 'not set'."""
        return self.type == "real" and self.shape is None and self.default is None

    @property
    def is_list(self) -> bool:
        return self.shape == "list"

    @property
    def size(self) -> int | None:
        """Number of entries of a fixed-size array, None for scalars and lists."""
        return self.shape if isinstance(self.shape, int) else None

    @property
    def char_length(self) -> int:
        return LENGTHS.get(self.length, self.length)  # type: ignore[arg-type]


@dataclass
class Group:
    """One namelist group: singleton (at most once) or repeatable (once per item)."""

    name: str
    kind: str
    doc: str
    variables: list[Var] = field(default_factory=list)

    def __post_init__(self) -> None:
        if self.kind not in ("singleton", "repeatable"):
            raise ValueError(f"&{self.name}: kind must be singleton or repeatable")
        names = [v.name for v in self.variables]
        if len(set(names)) != len(names):
            raise ValueError(f"&{self.name}: a variable is described twice")
        choices = next((v.choices for v in self.variables if v.name == "preset"), None) or []
        for v in self.variables:
            if v.presets and not set(v.presets) <= set(choices):
                raise ValueError(f"&{self.name} {v.name}: presets {sorted(v.presets)} are not "
                                 "all choices of the group's preset variable")
        selectors = [v for v in self.variables if v.selects]
        for v in self.variables:
            for law in v.laws or []:
                if len(selectors) != 1 or law not in (selectors[0].choices or []):
                    raise ValueError(f"&{self.name} {v.name}: law {law!r} is not a choice "
                                     "of the group's selecting variable")

    @property
    def type_name(self) -> str:
        return f"{self.name}_config_type"
