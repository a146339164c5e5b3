"""The integrator's default settings, as the engine defines them (written once, in Rust).

Every run function's ``rtol``, ``atol``, ``max_step`` and ``max_steps`` keyword defaults to these;
``simulate.solver_settings`` turns the keywords into the mapping the engine validates, and each
run reports the settings it used (``Solution.settings["solver"]``).
"""

from __future__ import annotations

from typing import Any

from thermojitter import _core

DEFAULTS: dict[str, Any] = dict(_core.SOLVER_DEFAULTS)
"""method "rk45", rtol, atol, max_step (s), max_steps."""
RTOL: float = DEFAULTS["rtol"]
ATOL: float = DEFAULTS["atol"]
MAX_STEP: float = DEFAULTS["max_step"]
MAX_STEPS: int = DEFAULTS["max_steps"]
