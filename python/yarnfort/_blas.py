# SPDX-License-Identifier: MIT
"""Which OpenBLAS kernels the program and the extension run with.

Debian's OpenBLAS (0.3.21) picks its kernels from the processor's model number and falls
back to its oldest generic ones (``Prescott``, SSE3) for a model it does not know. Newer
Intel Xeons are such models (measured on an Emerald Rapids machine, family 6 model 207:
``Core: Prescott``), and there every sparse factorisation pays for it: an elastic Newton
iteration of the 1e5-unknown cable net of ``benchmarks/compare.py`` took 275 ms with
Prescott's kernels, 199 ms with Haswell's and 177 ms with SkylakeX's (0.64x; 1e4
unknowns: 0.88x). The choice is made from the processor's instruction sets instead,
for Intel processors only (OpenBLAS knows AMD's): AVX-512 (F, BW, DQ, VL, CD) ->
``SkylakeX``, else AVX2 and FMA -> ``Haswell``, else OpenBLAS decides. OpenBLAS reads
its choice from the environment (``OPENBLAS_CORETYPE``) when it is loaded, so ``import
yarnfort`` puts it there, before the extension or the program (a child process) can load
the library: ``./yarnfort``, the ``yarnfort`` command and the Python API all run the same
kernels. A value the user set is kept.
"""
from __future__ import annotations

import os
from collections.abc import MutableMapping

__all__ = ["choose_openblas_core", "apply_openblas_core"]

#: The variable OpenBLAS reads at load time.
VARIABLE = "OPENBLAS_CORETYPE"

#: OpenBLAS kernel sets and the instruction sets each needs, best first.
CORES: tuple[tuple[str, frozenset[str]], ...] = (
    ("SkylakeX", frozenset({"avx512f", "avx512bw", "avx512dq", "avx512vl", "avx512cd"})),
    ("Haswell", frozenset({"avx2", "fma"})),
)


def choose_openblas_core(cpuinfo: str) -> str | None:
    """The OpenBLAS kernel set for the processor that ``cpuinfo`` (the text of
    ``/proc/cpuinfo``) describes, or None to leave the choice to OpenBLAS.

    Parameters
    ----------
    cpuinfo : str
        The first processor's ``vendor_id`` and ``flags`` lines are read.

    Returns
    -------
    str or None
        ``'SkylakeX'``, ``'Haswell'``, or None for another vendor, fewer instruction
        sets or a text without those lines.
    """
    vendor, flags = None, None
    for line in cpuinfo.splitlines():
        key, _, value = line.partition(":")
        key = key.strip()
        if key == "vendor_id" and vendor is None:
            vendor = value.strip()
        elif key == "flags" and flags is None:
            flags = frozenset(value.split())
    if vendor != "GenuineIntel" or flags is None:
        return None
    return next((core for core, needed in CORES if needed <= flags), None)


def apply_openblas_core(environ: MutableMapping[str, str] | None = None,
                        cpuinfo_path: str = "/proc/cpuinfo") -> str | None:
    """Set ``OPENBLAS_CORETYPE`` in ``environ`` (default: this process's environment)
    to :func:`choose_openblas_core`'s choice, unless it is set already.

    Returns
    -------
    str or None
        The value now in force (the user's, the choice, or None where OpenBLAS decides:
        no choice, or no readable ``cpuinfo_path``).
    """
    environ = os.environ if environ is None else environ
    if environ.get(VARIABLE):
        return environ[VARIABLE]
    try:
        with open(cpuinfo_path, encoding="utf-8", errors="replace") as file:
            core = choose_openblas_core(file.read())
    except OSError:
        return None
    if core is not None:
        environ[VARIABLE] = core
    return core
