# SPDX-License-Identifier: MIT
"""Write small namelist scenes for the verification tests."""
from __future__ import annotations

import numpy as np


def _value(v) -> str:
    if isinstance(v, bool):
        return ".true." if v else ".false."
    if isinstance(v, str):
        return f"'{v}'"
    if isinstance(v, (list, tuple, np.ndarray)):
        return ", ".join(_value(x) for x in np.ravel(v))
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    return repr(float(v))


def group(group_name: str, **values) -> str:
    body = "\n".join(f"    {k} = {_value(v)}" for k, v in values.items())
    return f"&{group_name}\n{body}\n/\n"


def scene(nodes, yarns, supports=(), loads=(), materials=(), path=None, solver=None,
          output=None) -> str:
    """Namelist text. yarns: list of dicts for &yarn; supports/loads/materials likewise."""
    text = group("control", title="verification scene")
    for m in materials:
        text += group("material", **m)
    text += group("nodes", xyz=np.asarray(nodes, dtype=float))
    for y in yarns:
        text += group("yarn", **y)
    for s in supports:
        text += group("support", **s)
    for ld in loads:
        text += group("load", **ld)
    text += group("path", **(path or dict(time=[0.0, 1.0], p_force=[0.0, 1.0],
                                          p_disp=[0.0, 1.0])))
    if solver:
        text += group("solver", **solver)
    text += group("output", **(output or dict(folder="out")))
    return text
