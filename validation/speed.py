"""The one way abdsim states its speed: "abdsim runs at N× MuJoCo's speed (> 1 is faster)".

N is MuJoCo's wall time over abdsim's for the same steps (equivalently abdsim's steps/s over
MuJoCo's). ``validate`` reports two such numbers: *stepping only* (the time inside
``step()``) and *end to end* (the whole run as a user sees it: stepping plus sampling the
state and, for abdsim, writing the MCAP log).
"""

from __future__ import annotations

import math

#: How every speed number is worded (README, report, benchmarks, command line).
CONVENTION = "N× MuJoCo's speed (> 1 is faster)"


def speed_vs_mujoco(abdsim_steps_per_s: float, mujoco_steps_per_s: float) -> float:
    """N in "abdsim runs at N× MuJoCo's speed": > 1 when abdsim is faster."""
    if not (mujoco_steps_per_s > 0 and math.isfinite(abdsim_steps_per_s)):
        return float("nan")
    return float(abdsim_steps_per_s) / float(mujoco_steps_per_s)


def describe(ratio: float, what: str = "") -> str:
    """``"abdsim runs at 0.70× MuJoCo's speed (> 1 is faster), stepping only"``."""
    suffix = f", {what}" if what else ""
    return f"abdsim runs at {ratio:.2f}× MuJoCo's speed (> 1 is faster){suffix}"


def timing(wall: dict[str, float], steps: int, total: float) -> dict:
    """metrics.json's ``timing`` of runs that step together: each simulator's wall time
    inside its step and steps/s, abdsim's speed against MuJoCo's, the whole run's time."""
    sims = {
        name: {"steps": steps, "wall_time": w, "steps_per_s": steps / max(w, 1e-12)}
        for name, w in wall.items()
    }
    return {
        "simulators": sims,
        "speed_vs_mujoco": speed_vs_mujoco(
            sims["abdsim"]["steps_per_s"], sims["mujoco"]["steps_per_s"]
        ),
        "total_wall_time": total,
    }
