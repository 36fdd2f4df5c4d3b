"""An intersection check of a robot World that does not use abdsim's contact code: coal's
triangle BVHs of every body's world surface, distances to the ground half-space and between
the body pairs the scene lets collide (its contact table)."""

from __future__ import annotations

import numpy as np


def _bvh(V: np.ndarray, F: np.ndarray):
    import coal

    m = coal.BVHModelOBBRSS()
    m.beginModel(len(F), len(V))
    m.addVertices(np.ascontiguousarray(V, dtype=np.float64))
    m.addTriangles(np.ascontiguousarray(F, dtype=np.int64))
    m.endModel()
    return coal.CollisionObject(m, coal.Transform3s())


def coal_gaps(world) -> tuple[float, float, int]:
    """(smallest body–ground distance, smallest distance between colliding body pairs,
    number of intersecting pairs, the ground included) of ``world`` now, by coal.

    Pairs the contact table excludes (joined links, bodies kept off the ground) are skipped;
    coal reports 0 or less for a pair that intersects. A scene without ground gives inf.
    """
    import coal

    scene = world.scene
    elements = scene.contact_elements()
    objects = []
    for h in scene.handles:
        F = np.asarray(h.sc.triangles)
        for k, V in enumerate(world.vertices(h)):
            objects.append((h.start + k, _bvh(V, F)))
    ground_gap, hits = np.inf, 0
    if scene.ground is not None:
        plane = coal.CollisionObject(
            coal.Halfspace(np.array([0.0, 0.0, 1.0]), float(scene.ground.height)),
            coal.Transform3s(),
        )
        for i, obj in objects:
            if not scene.contact_table.get(int(elements[i]), "ground")[0]:
                continue  # a body the source keeps off the ground (a link without geometry)
            res = coal.DistanceResult()
            ground_gap = min(ground_gap, coal.distance(obj, plane, coal.DistanceRequest(), res))
            hits += bool(coal.collide(obj, plane, coal.CollisionRequest(), coal.CollisionResult()))
    pair_gap = np.inf
    for a in range(len(objects)):
        for b in range(a + 1, len(objects)):
            (i, oi), (j, oj) = objects[a], objects[b]
            collide, _ = scene.contact_table.get(int(elements[i]), int(elements[j]))
            if not collide:
                continue
            cres, dres = coal.CollisionResult(), coal.DistanceResult()
            hits += bool(coal.collide(oi, oj, coal.CollisionRequest(), cres))
            pair_gap = min(pair_gap, coal.distance(oi, oj, coal.DistanceRequest(), dres))
    return float(ground_gap), float(pair_gap), hits
