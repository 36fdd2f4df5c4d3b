"""A URDF robot as the dynamic articulation ``abdsim validate`` compares, optionally with a
deliberately wrong model (to see the checks fail), and an independent measure of how well
its joints hold: the source's joint anchors and axes carried by both bodies' motion.

The robot is ``load_urdf`` + ``build_articulated_scene`` (exact joints). Each body's frame
is Pinocchio's joint frame ``oMi[j]`` (``LoadResult.source_map``: joint id → body), so a
body origin is the joint origin Pinocchio reports.
"""

from __future__ import annotations

import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np


def default_configuration(model, offset: float = 0.3) -> np.ndarray:
    """A non-singular pose away from equilibria (the joints issue's): Pinocchio's neutral
    configuration, or the middle of a joint's range where it has finite position limits,
    plus ``offset``·sin(k + 1) (at most a tenth of its range) on its k-th 1-dof coordinate
    (neutral is often an unstable
    equilibrium, e.g. the upright double pendulum), kept 5 % of the range inside the limits.
    Mid-range because a joint released near a limit reaches it within a fraction of a second
    (the Panda's elbow and wrist from neutral), and past a limit MuJoCo's soft limit and
    abdsim's barrier are different models (Pinocchio has none)."""
    import pinocchio as pin

    q = pin.neutral(model)
    lo, hi = model.lowerPositionLimit, model.upperPositionLimit
    finite = np.isfinite(lo) & np.isfinite(hi) & (hi > lo)
    one_dof = [model.idx_qs[j] for j in range(1, model.njoints) if model.nqs[j] == 1]
    limited = [i for i in one_dof if finite[i]]
    q[limited] = 0.5 * (lo[limited] + hi[limited])
    # the offset is at most a tenth of a joint's range (the Panda's fingers span 4 cm)
    amplitude = np.full(len(q), float(offset))
    amplitude[limited] = np.minimum(offset, 0.1 * (hi[limited] - lo[limited]))
    q[one_dof] += amplitude[one_dof] * np.sin(np.arange(len(one_dof)) + 1.0)
    margin = 0.05 * (hi - lo)
    q[finite] = np.clip(q[finite], (lo + margin)[finite], (hi - margin)[finite])
    return q


def perturb_masses(result, factors: dict[str, float]) -> None:
    """Scale the mass and inertia of the bodies holding the named links (abdsim only)."""
    import abdsim

    for link, factor in factors.items():
        try:
            body = result.bodies[result.index(link)]
        except KeyError as err:
            raise ValueError(f"perturb mass: {err.args[0]}") from None
        rb = abdsim.to_rigid_body(body.geometry)
        f = float(factor)
        abdsim.assign_rigid_body(body.geometry, rb.mass * f, rb.mass_center, rb.inertia * f)


def _across(axis: np.ndarray) -> np.ndarray:
    """A unit vector perpendicular to ``axis``."""
    across = np.cross(axis, [1.0, 0.0, 0.0])
    if np.linalg.norm(across) < 0.5:
        across = np.cross(axis, [0.0, 1.0, 0.0])
    return across / np.linalg.norm(across)


def perturb_joints(result, anchors: dict[str, float], axes: dict[str, float]):
    """A copy of ``result`` whose named joints sit ``anchors[name]`` metres off their source
    anchor (across the axis) or whose axes are tilted by ``axes[name]`` radians: a wrong
    joint in abdsim only."""
    by_name = {j.name: j for j in result.joints}
    unknown = sorted((set(anchors) | set(axes)) - set(by_name))
    if unknown:
        raise ValueError(f"perturb joint: no joint {unknown}; joints: {sorted(by_name)}")
    joints = []
    for j in result.joints:
        axis = j.axis if j.axis is not None else np.array([0.0, 0.0, 1.0])
        if j.name in anchors:
            j = replace(j, anchor=j.anchor + anchors[j.name] * _across(axis))
        if j.name in axes:
            a = axes[j.name]
            j = replace(j, axis=np.cos(a) * axis + np.sin(a) * _across(axis))
        joints.append(j)
    return replace(result, joints=joints, _scene=None)


def load_result(path: Path, q: np.ndarray | None, *, floating: bool, kappa: float):
    """(LoadResult, configuration) of the URDF robot at ``q`` (default:
    ``default_configuration``); the loader's notes are in ``result.notes``."""
    import pinocchio as pin

    from abdsim.bridges import load_urdf

    if q is None:
        root = pin.JointModelFreeFlyer() if floating else None
        model = (
            pin.buildModelFromUrdf(str(path), root) if root else pin.buildModelFromUrdf(str(path))
        )
        q = default_configuration(model)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = load_urdf(path, q=q, floating_base=floating, kappa=kappa)
    return result, np.asarray(q, dtype=float)


def lift(result, dz: float):
    """``result`` moved up by ``dz`` (bodies, joint anchors and ``q``, a floating robot's
    base height): the same robot as loaded ``dz`` higher, without loading it again."""
    for body in result.bodies:
        T = body.transform
        T[2, 3] += dz
        body.geometry.transforms = T[None]
    q = result.q.copy()
    q[2] += dz
    joints = [replace(j, anchor=j.anchor + np.array([0.0, 0.0, dz])) for j in result.joints]
    return replace(result, joints=joints, q=q, _scene=None)


def articulate(
    result,
    perturb_mass: dict[str, float] | None = None,
    perturb_anchor: dict[str, float] | None = None,
    perturb_axis: dict[str, float] | None = None,
    **settings,
):
    """``build_articulated_scene(result, **settings)`` of the robot, with the wrong models
    asked for (abdsim only; ``perturb_mass`` edits ``result``'s bodies in place)."""
    from abdsim.bridges import build_articulated_scene

    if perturb_mass:
        perturb_masses(result, perturb_mass)
    if perturb_anchor or perturb_axis:
        result = perturb_joints(result, perturb_anchor or {}, perturb_axis or {})
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # notes found while building are in result.notes
        return build_articulated_scene(result, **settings)


def load_robot(
    path: Path,
    q: np.ndarray | None,
    *,
    floating: bool,
    kappa: float,
    perturb_mass: dict[str, float] | None = None,
    perturb_anchor: dict[str, float] | None = None,
    perturb_axis: dict[str, float] | None = None,
    **settings,
):
    """(LoadResult, Scene, configuration): ``load_result`` then ``articulate``; the result is
    the source's (the joint perturbations are in the scene only)."""
    result, q = load_result(path, q, floating=floating, kappa=kappa)
    scene = articulate(result, perturb_mass, perturb_anchor, perturb_axis, **settings)
    return result, scene, q


class JointFrames:
    """The source's joint anchors and axes in both joined bodies' rest coordinates.

    ``violation(T)`` is, for body transforms ``T`` (n, 4, 4, affine), the largest distance
    between the anchor as the parent carries it and as the child carries it (across the
    parent's axis, for a slide), and the largest angle between the two carried axes: a
    measure independent of abdsim's joint code (it uses only the source's joint placement
    and the bodies' motion).
    """

    def __init__(self, result) -> None:
        T0 = result.transforms()
        self.rows = []
        for j in result.joints:
            if j.type not in ("revolute", "prismatic"):
                continue
            axis = j.axis if j.axis is not None else np.array([0.0, 0.0, 1.0])
            local = []
            for b in (j.parent, j.child):
                if b is None:
                    local.append((None, j.anchor, axis))
                    continue
                A_inv = np.linalg.inv(T0[b][:3, :3])
                local.append((b, A_inv @ (j.anchor - T0[b][:3, 3]), A_inv @ axis))
            self.rows.append((j.name, j.type == "prismatic", local))

    def violation(self, T: np.ndarray) -> tuple[float, float]:
        """(largest anchor separation [m], largest axis angle [rad]) at transforms ``T``."""
        dist, angle = 0.0, 0.0
        for _, sliding, local in self.rows:
            points, axes = [], []
            for b, x_bar, a_bar in local:
                if b is None:
                    points.append(x_bar)
                    axes.append(a_bar)
                else:
                    points.append(T[b][:3, :3] @ x_bar + T[b][:3, 3])
                    axes.append(T[b][:3, :3] @ a_bar)
            a, c = (x / np.linalg.norm(x) for x in axes)
            gap = points[0] - points[1]
            if sliding:  # a slide moves the anchors apart along the axis, and only along it
                gap = gap - np.dot(gap, a) * a
            dist = max(dist, float(np.linalg.norm(gap)))
            angle = max(angle, float(np.arctan2(np.linalg.norm(np.cross(a, c)), np.dot(a, c))))
        return dist, angle
