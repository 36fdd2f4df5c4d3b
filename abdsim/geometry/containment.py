"""Is a point inside a closed surface? (generalised winding number)

Used to refuse bodies nested inside another body's closed solid: surfaces that do not
intersect can still be one inside the other, which contact (a barrier between surfaces) can
neither see nor undo.
"""

from __future__ import annotations

import numpy as np


def winding_numbers(points: np.ndarray, vertices: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """Winding number of a closed, outward-oriented triangle surface around each point.

    ~1 inside, ~0 outside (exact for points off the surface), from the signed solid angle of
    every triangle (Van Oosterom & Strackee): Ω = 2 atan2(a·(b×c), |a||b||c| + (a·b)|c| +
    (b·c)|a| + (c·a)|b|) with a, b, c the corners relative to the point.

    Args:
        points: (k, 3).
        vertices: (nv, 3) surface vertices (world positions).
        triangles: (nf, 3) outward-oriented faces.

    Returns:
        (k,) winding numbers.
    """
    p = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    corners = np.asarray(vertices, dtype=np.float64)[np.asarray(triangles)]  # (nf, 3, 3)
    out = np.empty(len(p))
    for i, x in enumerate(p):  # one point per candidate body: a short loop
        r = corners - x
        a, b, c = r[:, 0], r[:, 1], r[:, 2]
        la, lb, lc = (np.linalg.norm(v, axis=1) for v in (a, b, c))
        numerator = np.einsum("ij,ij->i", a, np.cross(b, c))
        denominator = (
            la * lb * lc
            + np.einsum("ij,ij->i", a, b) * lc
            + np.einsum("ij,ij->i", b, c) * la
            + np.einsum("ij,ij->i", c, a) * lb
        )
        out[i] = 2.0 * np.arctan2(numerator, denominator).sum() / (4.0 * np.pi)
    return out


def nested_pairs(
    boxes: np.ndarray,
    solids: dict[int, tuple[np.ndarray, np.ndarray]],
    probes: np.ndarray,
    may_collide,
) -> list[tuple[int, int]]:
    """Pairs (inner, outer): body ``inner`` lies inside the closed solid of body ``outer``.

    Assumes no two surfaces intersect (checked before), so one vertex of the inner body
    decides: it is inside iff the whole body is.

    Args:
        boxes: (n, 2, 3) world bounding boxes (min, max) of every body.
        solids: body -> (world vertices, triangles) of every body that is a closed solid.
        probes: (n, 3) one world vertex of every body.
        may_collide: (a, b) -> whether contact acts between bodies a and b.
    """
    found = []
    for outer, (v, f) in solids.items():
        lo, hi = boxes[outer]
        inside_box = np.all((boxes[:, 0] >= lo) & (boxes[:, 1] <= hi), axis=1)
        candidates = [
            b for b in np.flatnonzero(inside_box) if b != outer and may_collide(int(b), outer)
        ]
        if not candidates:
            continue
        w = winding_numbers(probes[candidates], v, f)
        found += [(int(b), outer) for b, wn in zip(candidates, w, strict=True) if wn > 0.5]
    return found
