"""Cross-validation of abdsim against MuJoCo and Pinocchio (``abdsim validate``).

Installed as ``abdsim.validation``. Import the heavy parts lazily: ``validate`` runs a scene
in all three simulators and writes a report, ``run_sweep`` runs many in parallel.
"""

from __future__ import annotations

__all__ = ["Tolerances", "ValidationResult", "run_sweep", "validate"]


def __getattr__(name: str):
    if name in ("validate", "ValidationResult"):
        from abdsim.validation import harness

        return getattr(harness, name)
    if name == "run_sweep":
        from abdsim.validation.sweep import run_sweep

        return run_sweep
    if name == "Tolerances":
        from abdsim.validation.tolerances import Tolerances

        return Tolerances
    raise AttributeError(name)
