# SPDX-License-Identifier: MIT
"""yarnfort: textile stretching with capstan friction — Python side.

Readers for the outputs of ``./yarnfort < scene.nml`` (curve CSV, VTK states) and
helpers to run the program. The physics lives in the Fortran library.
"""
from .results import Curve, State, read_curve, read_state, read_states, read_run
from ._native import SceneRun, YarnfortError, critical_tension, force_law, run_scene
from .namelist import get_parameter, read_scene, set_parameter, write_scene

__all__ = ["Curve", "State", "read_curve", "read_state", "read_states", "read_run",
           "SceneRun", "YarnfortError", "critical_tension", "force_law", "run_scene",
           "read_scene", "write_scene", "set_parameter", "get_parameter"]
from .sweep import run_sweep  # noqa: E402
from .calibrate import CalibrationResult, calibrate, plot_fit  # noqa: E402
__all__ += ["run_sweep", "CalibrationResult", "calibrate", "plot_fit"]
