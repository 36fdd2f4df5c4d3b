"""URDFs with only visual geometry: their ``<visual>`` elements become the surfaces.

MuJoCo's URDF compiler makes geoms of a link's visual elements when the robot gives no
collision geometry; abdsim does the same for a URDF without any ``<collision>`` element (a
note says so), so such robots load instead of being refused as having nothing to simulate.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path


def visual_only(root: ET.Element, urdf: Path) -> tuple[dict[str, int], str] | None:
    """``(visual elements per link, note)`` when the URDF has visuals but no collision."""
    if root.find("link/collision") is not None:
        return None
    counts: dict[str, int] = {}
    for link in root.iter("link"):
        n = len(link.findall("visual"))
        if n:
            counts[link.get("name", "?")] = n
    if not counts:
        return None
    note = (
        f"URDF {urdf.name} has no <collision> element: its <visual> geometry of links "
        f"{sorted(counts)} is used as the collision surfaces (as MuJoCo's URDF compiler does)"
    )
    return counts, note
