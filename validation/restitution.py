"""Restitution per impact, measured the same way on every simulator's samples.

An impact is where a body's centre-of-mass vertical velocity, falling faster than
``min_speed``, rises between samples by more than gravity could make it (a contact impulse);
the impact lasts while it keeps rising that fast (soft contacts act over several samples).
Its restitution is e = max(v_after, 0) / −v_before: 0 for a body that stops dead, 1 for an
elastic bounce. Tumbling bodies trade vertical for other motion, so e is a description of
the trajectory, compared between simulators, not a material constant.
"""

from __future__ import annotations

import numpy as np


def impacts(
    vz: np.ndarray, sample_dt: float, g: float = 9.81, min_speed: float = 0.1
) -> list[dict]:
    """Impacts of one body from its vertical COM velocity samples ``vz`` (m/s).

    Returns one dict per impact: sample index, v_before, v_after (m/s), restitution.
    """
    vz = np.asarray(vz, dtype=np.float64)
    kick = 0.5 * g * sample_dt  # a rise per sample that gravity alone cannot produce
    out: list[dict] = []
    k = 1
    while k < len(vz):
        if vz[k - 1] < -min_speed and vz[k] - vz[k - 1] > kick:
            start = k - 1
            while k + 1 < len(vz) and vz[k + 1] - vz[k] > kick:
                k += 1
            before, after = float(vz[start]), float(vz[k])
            out.append(
                {
                    "sample": start,
                    "v_before": before,
                    "v_after": after,
                    "restitution": max(after, 0.0) / -before,
                }
            )
        k += 1
    return out


def restitution_table(
    names: list[str], vz: np.ndarray, sample_dt: float, g: float = 9.81, max_impacts: int = 5
) -> dict[str, list[float]]:
    """{body: restitution of its first ``max_impacts`` impacts}; vz is (samples, bodies)."""
    return {
        name: [i["restitution"] for i in impacts(vz[:, b], sample_dt, g)[:max_impacts]]
        for b, name in enumerate(names)
    }
