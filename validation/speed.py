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
