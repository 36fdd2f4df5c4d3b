"""World: the C++ stepper built from a Scene, with a NumPy-in / NumPy-out API."""

from __future__ import annotations

import math
import numbers
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from abdsim._native import _core
from abdsim.constitution.rigid_body import _dyadic_of
from abdsim.geometry import validation as check
from abdsim.geometry.containment import nested_pairs
from abdsim.sim import pose as pose_math
from abdsim.sim.contact_forces import ContactForces, rest_centers_of_mass, world_centers
from abdsim.sim.contact_rules import contact_rules
from abdsim.sim.joint_sensor_readings import joint_sensor_values
from abdsim.sim.scene import BodyHandle, Scene
from abdsim.sim.sensor_readings import BodyState, sensor_values
from abdsim.sim.sensors import JOINT_TYPES, SensorSet, VelocityHistory

SolverError = _core.SolverError

#: A kinematic schedule: time at the end of a step (s) -> 4x4 transform of the body then.
Schedule = Callable[[float], np.ndarray]


@dataclass(frozen=True)
class StepDiagnostics:
    """What one time step did.

    Attributes:
        step: index of the step (0 for the first).
        time: simulated time at the end of the step (s).
        newton_iterations: Newton iterations: the coupled iterations (with contact or other
            terms), or the most any body took alone (bodies solved on their own).
        total_body_iterations: the iterations each body took part in, summed over bodies.
        converged: always True for a returned step (a failed step raises SolverError).
        integrator_order: 1 for a BDF1 step (BDF2 takes one at its start, after
            ``set_state`` and where contact begins or ends), 2 for a BDF2 step.
        restitution_impulses: impulses the restitution law applied after the step
            (``SceneSettings.restitution``).
        step_translation: last Newton step, max |Δp| / dt (m/s).
        step_affine: last Newton step, max |ΔA| / dt (1/s).
        residual: max |∇Π| at the start of the last Newton iteration.
        line_search_alphas: accepted line-search step per Newton iteration (fast path: the
            smallest over bodies).
        min_term_max_step: smallest step bound (CCD) an energy term returned; 1 if none.
            Also ``ccd_step_bound``.
        coupled_bodies: bodies that needed the coupled Newton iterations (the others kept
            their own free solution: nothing came near them).
        islands: groups of coupled bodies solved (each with its own line search).
        contact_pairs: active contact pairs at the end of the step: ``point_triangle``,
            ``edge_edge``, ``point_ground``, and lagged ``friction`` pairs (zeros without
            contact).
        min_contact_distance: smallest gap d − ξ (m) among the active pairs (inf if nothing
            is within d̂).
        contact_stiffness: the barrier stiffness κ used (0 without contact).
        driven_bodies: kinematic bodies driven by the stiff spring this step because their
            scripted move would have crossed contact.
        kinematic_lag: the largest distance (m) a vertex of a driven body was left from its
            target (0 when every kinematic body reached it); ``kinematic_lag_body`` is that
            body (-1 if none).
        energies: ``kinetic`` (½|q − q̃|²_M), ``shape`` and each added term (potentials,
            unscaled) and ``total`` (Π), at the end of the step; empty when
            ``SceneSettings.energies`` is off.
        substeps: pieces the step was split into (1: solved whole). A step whose straight-line
            motion from t to t + dt would cross contact (a body passing through another between
            the reported states), that would invert or collapse a body, or that Newton could
            not solve, is redone in halves (only the pieces that fail are halved again, down
            to dt / 1024); the iteration counts then sum over all the work the step cost: the
            kept pieces, the failed whole step, failed pieces and refinement rounds redone.
        substep_reason: why the whole step was split ("" when ``substeps == 1``): Newton's
            failure message, the straight-line motion crossing contact, or a body inverting;
            followed by "the whole step's straight line still crosses ..." when the pieces
            each passed but that line did not clear at pieces of dt / 8 everywhere (the step is
            then accepted).
        discarded_newton_iterations: of ``newton_iterations``, those spent on work the step
            threw away (0 when ``substeps == 1``): the rejected whole step, failed pieces and
            refinement rounds redone finer.
        discarded_time: of ``wall_time``, the seconds that work took.
        joint_violation: largest joint anchor separation (m) at the end of the step (for a
            prismatic joint, its offset across the axis); 0 without joints.
        joint_violation_angle: largest joint axis or frame misalignment (rad).
        linear_solver: ``"block_diagonal"``, ``"direct"`` or ``"pcg"``.
        pcg_iterations: PCG iterations summed over the step's Newton iterations.
        wall_time: seconds spent in the C++ step.
        profile: where a coupled step's time went (seconds, summed over its Newton
            iterations): ``assembly`` (gradient and Hessian), ``linear_solve`` (sparse
            analysis, factorisation and solve, or PCG), ``ccd`` (step bounds),
            ``line_search`` (energies of the trials), ``contact_update`` (the contact set
            at each accepted iterate) and ``broad_phase`` (within the others); and counts:
            ``ccd_cuts`` (island line searches whose first trial the step bound cut),
            ``armijo_halvings`` and ``symbolic_analyses`` (sparse pattern analyses: the
            coupled structure changed). Empty for steps without terms.
    """

    step: int
    time: float
    newton_iterations: int
    total_body_iterations: int
    converged: bool
    step_translation: float
    step_affine: float
    residual: float
    line_search_alphas: tuple[float, ...]
    min_term_max_step: float
    energies: dict[str, float]
    linear_solver: str
    pcg_iterations: int
    wall_time: float
    coupled_bodies: int = 0
    islands: int = 0
    contact_pairs: dict[str, int] = field(default_factory=dict)
    min_contact_distance: float = math.inf
    contact_stiffness: float = 0.0
    driven_bodies: int = 0
    kinematic_lag: float = 0.0
    kinematic_lag_body: int = -1
    integrator_order: int = 1
    restitution_impulses: int = 0
    substeps: int = 1
    substep_reason: str = ""
    discarded_newton_iterations: int = 0
    discarded_time: float = 0.0
    joint_violation: float = 0.0
    joint_violation_angle: float = 0.0
    profile: dict[str, float] = field(default_factory=dict)

    @property
    def ccd_step_bound(self) -> float:
        """The smallest CCD step bound of the step (= ``min_term_max_step``)."""
        return self.min_term_max_step

    @classmethod
    def from_core(cls, d: _core.StepDiagnostics) -> StepDiagnostics:
        return cls(
            step=d.step,
            time=d.time,
            newton_iterations=d.newton_iterations,
            total_body_iterations=d.total_body_iterations,
            converged=d.converged,
            step_translation=d.step_translation,
            step_affine=d.step_affine,
            residual=d.residual,
            line_search_alphas=tuple(d.line_search_alphas),
            min_term_max_step=d.min_term_max_step,
            energies=dict(d.energies),
            linear_solver=d.linear_solver,
            pcg_iterations=d.pcg_iterations,
            wall_time=d.wall_time,
            coupled_bodies=d.coupled_bodies,
            islands=d.islands,
            contact_pairs={
                "point_triangle": d.contact_point_triangle,
                "edge_edge": d.contact_edge_edge,
                "point_ground": d.contact_point_ground,
                "friction": d.contact_friction,
            },
            min_contact_distance=d.min_contact_distance,
            contact_stiffness=d.contact_kappa,
            driven_bodies=d.driven_bodies,
            kinematic_lag=d.kinematic_lag,
            kinematic_lag_body=d.kinematic_lag_body,
            integrator_order=d.integrator_order,
            restitution_impulses=d.restitution_impulses,
            substeps=d.substeps,
            substep_reason=d.substep_reason,
            discarded_newton_iterations=d.discarded_newton_iterations,
            discarded_time=d.discarded_time,
            joint_violation=d.joint_violation,
            joint_violation_angle=d.joint_violation_angle,
            profile={
                "assembly": d.time_assembly,
                "linear_solve": d.time_linear_solve,
                "ccd": d.time_ccd,
                "line_search": d.time_line_search,
                "contact_update": d.time_contact_update,
                "broad_phase": d.time_broad_phase,
                "ccd_cuts": d.line_search_ccd_cuts,
                "armijo_halvings": d.line_search_halvings,
                "symbolic_analyses": d.symbolic_analyses,
            },
        )


def transforms_to_q(T: np.ndarray) -> np.ndarray:
    """(n, 4, 4) transforms [[A, p], [0, 1]] (or their time derivatives) -> (n, 12) q."""
    T = np.asarray(T, dtype=np.float64)
    return np.concatenate([T[:, :3, 3], T[:, :3, :3].reshape(len(T), 9)], axis=1)


def q_to_transforms(q: np.ndarray, homogeneous: bool = True) -> np.ndarray:
    """(n, 12) q -> (n, 4, 4); bottom row [0, 0, 0, 1] (or zeros for a velocity)."""
    q = np.asarray(q, dtype=np.float64)
    T = np.zeros((len(q), 4, 4))
    T[:, :3, 3] = q[:, :3]
    T[:, :3, :3] = q[:, 3:].reshape(-1, 3, 3)
    if homogeneous:
        T[:, 3, 3] = 1.0
    return T


def _as_transforms(T: np.ndarray, n: int, what: str) -> np.ndarray:
    T = np.asarray(T, dtype=np.float64)
    if T.shape == (4, 4) and n == 1:
        T = T[None]
    if T.shape != (n, 4, 4):
        raise ValueError(f"{what} must have shape ({n}, 4, 4), got {T.shape}")
    if not np.isfinite(T).all():
        raise ValueError(f"{what} contain NaN or infinite values")
    return T


def _check_bottom_row(T: np.ndarray, what: str) -> None:
    if np.abs(T[:, 3, :] - [0.0, 0.0, 0.0, 1.0]).max(initial=0.0) > 1e-12:
        raise ValueError(f"{what}: the last row of an affine transform must be [0, 0, 0, 1]")


def _geometry_dim(sc) -> int:
    """3 for solids (tet meshes and closed surfaces), 2 for shells, 1 for rods."""
    is_codim = "is_codim" in sc.meta and int(sc.meta["is_codim"]) == 1
    return int(sc.dim) if is_codim else 3


class World:
    """The simulation of a Scene: state, stepping, kinematic drives, diagnostics.

    The state lives in C++; every accessor returns NumPy arrays (copies). Bodies are numbered
    as in the scene (geometry by geometry, instance by instance).

    Args:
        scene: the scene; each geometry's attributes are read now, and its meta
            ``dof_offset`` / ``dof_count`` are filled.

    With ``contact`` on (the default) and something to collide (two bodies with surfaces,
    a ground, or a self-colliding body), IPC contact is built into the C++ world
    (``core.enable_contact``): the initial configuration is checked, and every step keeps
    every pair of surfaces apart (CCD-bounded Newton steps).

    Raises:
        ValueError: a geometry without constitution, non-finite transforms or velocities,
            a singular mass matrix, a bad setting, an empty scene; with contact, surfaces
            that intersect or are closer than their thickness (naming the two bodies).
    """

    def __init__(self, scene: Scene) -> None:
        if not isinstance(scene, Scene):
            raise TypeError(f"World expects a Scene, got {type(scene).__name__}")
        if scene.num_bodies == 0:
            raise ValueError("the scene has no bodies: add geometries with scene.add(sc)")
        self._scene = scene
        self._handles = scene.handles
        settings = scene.settings.to_core()
        data = _core.SceneData()
        data.dt = float(scene.dt)
        data.gravity = scene.gravity
        for h in self._handles:
            self._add_geometry(data, h)
        self._core = _core.World(data, settings)
        self._core.set_history_limit(int(scene.settings.history_limit))
        self._schedules: dict[int, Schedule] = {}
        for h in self._handles:
            if h.kinematic:
                q0 = self._core.q
                for b in h.bodies:
                    self._core.set_kinematic_target(b, q0[b])
        self._joints = self._build_joints(data, scene)
        self._contact = None
        self._rest_centers: np.ndarray | None = None  # for contact_wrenches, on first use
        self._sensors = SensorSet(scene.sensors.specs)
        self._sensors.check_bodies(self.num_bodies)
        self._velocities = VelocityHistory()  # for the sensors' accelerations
        if scene.settings.contact and self._needs_contact(data, scene):
            self._check_d_hat_scale(scene)
            try:
                self._contact = self._core.enable_contact(self._contact_settings(scene))
            except ValueError as e:
                raise ValueError(f"invalid initial configuration for contact: {e}") from None
            self._check_nesting(self._core.q, "invalid initial configuration for contact")
        for h in self._handles:
            h.sc.meta["dof_offset"] = np.int32(12 * h.start)
            h.sc.meta["dof_count"] = np.int32(12 * len(h))

    def _build_joints(self, data: _core.SceneData, scene: Scene):
        """The scene's joints as one C++ constraint on the world, and their physics and
        actuators as one energy term (None, None without joints)."""
        joints = scene.joints
        self._joint_forces = None
        self._wrenches = None
        if not joints:
            return None
        specs = []
        for j in joints:
            spec = _core.JointSpec()
            spec.kind = getattr(_core.JointKind, j.kind)
            spec.parent, spec.child = j.parent, j.child
            spec.anchor, spec.axis = np.array(j.anchor), np.array(j.axis)
            spec.name = j.name
            specs.append(spec)
        q0 = np.ascontiguousarray(self._core.q).reshape(-1)
        joint_set = _core.JointSet(data, q0, specs)
        self._core.add_constraint(joint_set)
        if any(j.kind in ("revolute", "prismatic") for j in joints):
            actuators = []
            for a in scene.actuators:
                spec = _core.ActuatorSpec()
                spec.joint, spec.kind = a.joint, getattr(_core.ActuatorKind, a.kind)
                spec.kp, spec.kv, spec.gear, spec.bias = a.kp, a.kv, a.gear, a.bias
                if a.ctrl_range is not None:
                    spec.ctrl_limited = True
                    spec.ctrl_lower, spec.ctrl_upper = a.ctrl_range
                if a.force_range is not None:
                    spec.force_limited = True
                    spec.force_lower, spec.force_upper = a.force_range
                actuators.append(spec)
            physics = [j.core_physics() for j in joints]
            self._joint_forces = _core.JointForceTerm(joint_set, data, physics, actuators)
            self._core.add_term(self._joint_forces)
        elif any(j.physics() for j in joints):
            bad = next(j for j in joints if j.physics())
            raise ValueError(f"joint '{bad.name}': joint physics act on 1-dof joints only")
        return joint_set

    def _check_d_hat_scale(self, scene: Scene) -> None:
        """d̂ must be small against every dynamic body with a surface: a barrier that reaches across
        a quarter of a part holds it off everything at a distance of its own size (a 1 cm
        part with d̂ = 1 cm), a silently wrong answer rather than contact."""
        d_hat = float(scene.settings.d_hat)
        for h in self._handles:
            fixed = np.asarray(h.sc.instances["is_fixed"]).astype(bool)
            if len(h.sc.positions) < 2 or h.kinematic or fixed.all():
                continue  # scripted and fixed parts (robot links) are not thrown off
            extent = np.ptp(np.asarray(h.sc.positions, dtype=np.float64), axis=0)
            size = float(np.linalg.norm(extent))
            if size > 0 and d_hat > 0.25 * size:
                raise ValueError(
                    f"d_hat = {d_hat:g} m is not small against body {h.start} (its geometry "
                    f"spans {size:.3g} m): the barrier would hold it off everything at a quarter "
                    f"of its size; use a d_hat of about 1 % of the smallest part "
                    f"(here {0.01 * size:.2g} m)"
                )

    @staticmethod
    def _needs_contact(data: _core.SceneData, scene: Scene) -> bool:
        """Two bodies with surfaces (one of them free), a ground, or self-collision."""
        with_surface, free = 0, 0
        for b in range(data.num_bodies):
            body = data.body(b)
            g = data.geometry(body.geometry)
            if len(g.triangles) == 0 and len(g.edges) == 0:
                continue
            with_surface += 1
            free += not body.is_fixed
            if g.self_collision and not body.is_fixed:
                return True
        if free == 0:
            return False
        return with_surface >= 2 or scene.ground is not None

    @staticmethod
    def _contact_settings(scene: Scene):
        st = scene.settings
        cs = _core.contact.ContactSettings()
        cs.d_hat = float(st.d_hat)
        cs.kappa = float(st.contact_stiffness)
        cs.mu = float(st.friction)
        cs.eps_v = float(st.eps_v)
        cs.damping = float(st.contact_damping)
        cs.restitution = -1.0 if st.restitution is None else float(st.restitution)
        cs.restitution_threshold = float(st.restitution_threshold)
        ground = scene.ground
        cs.ground = ground is not None
        cs.ground_height = float(ground.height) if ground is not None else 0.0
        rules = contact_rules(scene)
        cs.ground_contact_element = rules.ground_id
        cs.body_contact_element = rules.elements.tolist()
        if rules.enabled is not None:
            cs.set_contact_table_matrices(rules.enabled, rules.mu, rules.zeta, rules.restitution)
        return cs

    @staticmethod
    def _add_geometry(data: _core.SceneData, h: BodyHandle) -> None:
        sc = h.sc
        where = f"geometry {h.geometry}"
        if "constitution_uid" not in sc.meta:
            raise ValueError(f"{where} has no constitution")
        if sc.instance_count != len(h):
            raise ValueError(
                f"{where} has {sc.instance_count} instances but had {len(h)} when added; "
                "build a new Scene after changing the instance count"
            )
        # The attributes may have been edited since apply_to: check them again here.
        check.check_mesh_arrays(sc, where)
        T = _as_transforms(sc.transforms, len(h), f"{where}: transforms")
        _check_bottom_row(T, f"{where}: transforms")
        check.check_transforms(T, f"{where}: transform of instance")
        V = _as_transforms(sc.instances["velocity"], len(h), f"{where}: velocity")
        kappa = np.asarray(sc.instances["kappa"], dtype=np.float64)
        if not (np.isfinite(kappa).all() and (kappa > 0).all()):
            raise ValueError(f"{where}: kappa must be positive and finite")
        dm = _dyadic_of(sc)
        n_vertices = len(sc.positions)
        thickness = (
            np.asarray(sc.vertices["thickness"], dtype=np.float64)
            if "thickness" in sc.vertices
            else np.zeros(n_vertices)
        )
        g = data.add_geometry(
            np.ascontiguousarray(sc.positions, dtype=np.float64),
            np.ascontiguousarray(sc.triangles, dtype=np.int32).reshape(-1, 3),
            np.ascontiguousarray(sc.edges, dtype=np.int32).reshape(-1, 2),
            thickness,
            int(sc.meta["self_collision"]) if "self_collision" in sc.meta else 0,
            _geometry_dim(sc),
        )
        flags = {
            key: np.ascontiguousarray(sc.instances[key], dtype=np.int32)
            for key in ("is_fixed", "is_dynamic", "external_kinetic")
        }
        data.add_bodies(
            g,
            transforms_to_q(T),
            transforms_to_q(V),
            dm.abd_mass,
            dm.abd_mass_x_bar,
            dm.abd_mass_x_bar_x_bar,
            kappa,
            float(sc.meta["volume"]),
            int(sc.meta["constitution_uid"]),
            flags["is_fixed"],
            flags["is_dynamic"],
            flags["external_kinetic"],
        )

    # -- stepping -------------------------------------------------------------------------
    def step(self, n: int = 1, progress: bool = False, log: Any = None) -> StepDiagnostics:
        """Advance ``n`` time steps; returns the last step's diagnostics.

        Args:
            n: number of steps (>= 1).
            progress: show a tqdm progress bar.
            log: also write every step to an MCAP log (Foxglove): a path, or an
                ``abdsim.bridges.McapLogger``. The same path on the same World continues one
                file; ``abdsim.bridges.close_logs(world)`` (or exit) finishes it. See
                ``abdsim.bridges.step_and_log``.

        Raises:
            SolverError: a step failed (Newton, line search, singular system); the state is
                that at the start of the failed step.
        """
        if (
            isinstance(n, (bool, np.bool_))
            or not isinstance(n, numbers.Real)
            or not math.isfinite(n)
            or int(n) != n
            or n < 1
        ):
            raise ValueError(f"step count must be a positive integer, got {n!r}")
        n = int(n)
        if log is not None:
            # Imported here: the core never depends on bridges, only this option does.
            from abdsim.bridges.mcap_log import step_and_log

            return step_and_log(self, n, log, progress=progress)
        bar = None
        if progress:
            from tqdm.auto import tqdm

            bar = tqdm(total=n, unit="step")
        try:
            # Without schedules the steps run in C++ in chunks (chunks only feed the bar).
            # Acceleration sensors need the velocity before every step: one step at a time.
            per_step = bool(self._schedules) or self._sensors.needs_acceleration
            chunk = 1 if per_step else (max(1, n // 100) if bar else n)
            done = 0
            while done < n:
                k = min(chunk, n - done)
                if self._schedules:
                    self._apply_schedules()
                if self._sensors.needs_acceleration:
                    self._velocities.before_step(self._core.q_dot)
                self._core.step(k)
                done += k
                if bar is not None:
                    bar.update(k)
        finally:
            if bar is not None:
                bar.close()
        return self.diagnostics

    def _apply_schedules(self) -> None:
        t_end = self._core.next_time
        bodies = np.fromiter(self._schedules, dtype=np.int32, count=len(self._schedules))
        T = np.stack([np.asarray(f(t_end), dtype=np.float64) for f in self._schedules.values()])
        self.set_kinematic_targets(bodies, T)

    # -- state ----------------------------------------------------------------------------
    @property
    def scene(self) -> Scene:
        return self._scene

    @property
    def core(self) -> _core.World:
        """The C++ world (``add_term``, raw q access, ...)."""
        return self._core

    @property
    def num_bodies(self) -> int:
        return self._core.num_bodies

    @property
    def time(self) -> float:
        """Simulated time (s)."""
        return self._core.time

    @property
    def step_count(self) -> int:
        return self._core.step_count

    @property
    def q(self) -> np.ndarray:
        """State (n_bodies, 12): ``[p, a1, a2, a3]`` per body (a_i the rows of A)."""
        return np.asarray(self._core.q)

    @property
    def q_dot(self) -> np.ndarray:
        """Velocity (n_bodies, 12)."""
        return np.asarray(self._core.q_dot)

    def transforms(self) -> np.ndarray:
        """Body transforms [[A, p], [0, 1]], (n_bodies, 4, 4)."""
        return q_to_transforms(self._core.q)

    def velocities(self) -> np.ndarray:
        """Time derivatives of the transforms dT/dt, (n_bodies, 4, 4) (bottom row zero).

        For velocities in robotics' terms (v, ω in the world frame) see :meth:`twist`."""
        return q_to_transforms(self._core.q_dot, homogeneous=False)

    def pose(self, body: int | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Position and quaternion ``[w, x, y, z]`` (MuJoCo's order, w >= 0) of the rotation
        nearest to each body's ``A``: ((n_bodies, 3), (n_bodies, 4)), or one body's
        ((3,), (4,)). See :mod:`abdsim.sim.pose`."""
        p, q = pose_math.poses(self.transforms())
        return (p, q) if body is None else (p[self._body(body)], q[self._body(body)])

    def twist(self, body: int | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Linear velocity of each body's origin and angular velocity ω, both in the world
        frame: ((n_bodies, 3), (n_bodies, 3)), or one body's ((3,), (3,)). MuJoCo's free-joint
        ``qvel`` holds the same ``v`` and ``Rᵀ ω``. See :mod:`abdsim.sim.pose`."""
        v, w = pose_math.twists(self.transforms(), self.velocities())
        return (v, w) if body is None else (v[self._body(body)], w[self._body(body)])

    def _body(self, body: int) -> int:
        n = self.num_bodies
        if isinstance(body, bool) or not isinstance(body, (int, np.integer)) or not 0 <= body < n:
            raise IndexError(f"body must be an integer index in [0, {n}), got {body!r}")
        return int(body)

    def vertices(self, handle: BodyHandle) -> np.ndarray:
        """World positions x = A x̄ + p of a geometry's vertices, (n_instances, nv, 3)."""
        q = self.q[handle.start : handle.stop]
        A = q[:, 3:].reshape(-1, 3, 3)
        return np.einsum("kij,vj->kvi", A, handle.sc.positions) + q[:, None, :3]

    def set_state(
        self, transforms: np.ndarray | None = None, velocities: np.ndarray | None = None
    ) -> None:
        """Replace transforms and/or velocities (n_bodies, 4, 4); None keeps the current one.

        BDF2 restarts with a BDF1 step; joints are projected back onto their constraints at the
        next step (least mass-weighted change).

        Raises:
            ValueError: NaN/inf, wrong shapes, mirror or degenerate transforms; with contact,
                bodies that intersect, are closer than their thickness, reach into the ground
                or lie inside another body's closed solid (the state is then unchanged).
        """
        n = self.num_bodies
        q, q_dot = self.q, self.q_dot
        if transforms is not None:
            T = _as_transforms(transforms, n, "transforms")
            _check_bottom_row(T, "transforms")
            check.check_transforms(T, "set_state: transform of body")
            q = transforms_to_q(T)
            if self._contact is not None:
                try:
                    self._contact.check_initial(q)
                except ValueError as e:
                    raise ValueError(f"set_state: invalid configuration for contact: {e}") from None
                self._check_nesting(q, "set_state: invalid configuration for contact")
        if velocities is not None:
            q_dot = transforms_to_q(_as_transforms(velocities, n, "velocities"))
        self._core.set_state(q, q_dot)
        self._velocities.reset()
        if self._joints is not None:  # hinge angles restart from the new poses (in (−π, π])
            self._joints.reset(np.ascontiguousarray(q).reshape(-1))

    def _check_nesting(self, q: np.ndarray, context: str) -> None:
        """Refuse a body wholly inside another's closed solid (contact cannot see it)."""
        n = self.num_bodies
        A = q[:, 3:].reshape(n, 3, 3)
        boxes = np.empty((n, 2, 3))
        probes = np.empty((n, 3))
        solids = {}
        for h in self._handles:  # per geometry, not per step: building the world only
            x = np.einsum("kij,vj->kvi", A[h.start : h.stop], h.sc.positions)
            x += q[h.start : h.stop, None, :3]
            boxes[h.start : h.stop, 0] = x.min(axis=1)
            boxes[h.start : h.stop, 1] = x.max(axis=1)
            probes[h.start : h.stop] = x[:, 0]
            if _geometry_dim(h.sc) == 3 and len(h.sc.triangles):
                solids.update({b: (x[i], h.sc.triangles) for i, b in enumerate(h.bodies)})
        scripted = self._scripted_bodies()
        elements = self._scene.contact_elements()

        excluded = set(self._scene.contact_exclusions())

        def may_collide(a: int, b: int) -> bool:
            if scripted[a] and scripted[b]:
                return False
            if (min(a, b), max(a, b)) in excluded:
                return False
            return self._scene.contact_table.get(int(elements[a]), int(elements[b]))[0]

        pairs = nested_pairs(boxes, solids, probes, may_collide)
        if pairs:
            inner, outer = pairs[0]
            raise ValueError(
                f"{context}: body {inner} lies inside the closed solid of body {outer} (nested "
                "bodies: contact acts between surfaces and cannot push it out)"
            )

    def _scripted_bodies(self) -> np.ndarray:
        """Per body: fixed or kinematic (contact ignores pairs of two of them)."""
        fixed = np.concatenate(
            [np.asarray(h.sc.instances["is_fixed"]).reshape(-1) != 0 for h in self._handles]
        )
        kinematic = np.array([self._core.is_kinematic(b) for b in range(self.num_bodies)])
        return fixed | kinematic

    def sync(self) -> None:
        """Write the state into each geometry's ``transforms`` and ``instances["velocity"]``."""
        T, V = self.transforms(), self.velocities()
        for h in self._handles:
            h.sc.transforms = T[h.start : h.stop]
            h.sc.instances["velocity"] = V[h.start : h.stop]

    # -- joints ---------------------------------------------------------------------------
    @property
    def joints(self) -> list:
        """The scene's joints (``JointHandle``), in coordinate order."""
        return self._scene.joints

    def joint_positions(self) -> np.ndarray:
        """Joint coordinates (nq,), in joint order, MuJoCo's conventions.

        Revolute: the hinge angle (rad, unwrapped, 0 at load); prismatic: the slide (m, 0 at
        load); ball: a w-first unit quaternion of the child's rotation relative to the
        parent, relative to load; free: the body origin p and the quaternion of its
        rotation; fixed: nothing. Affine bodies read as their nearest rotation.
        """
        if self._joints is None:
            return np.zeros(0)
        return np.asarray(self._joints.positions(np.ascontiguousarray(self._core.q).reshape(-1)))

    def joint_velocities(self) -> np.ndarray:
        """Joint velocities (nv,): hinge and slide rates, a ball's relative angular velocity in
        the child's frame, a free body's (ṗ in the world, ω in the body frame)."""
        if self._joints is None:
            return np.zeros(0)
        q = np.ascontiguousarray(self._core.q).reshape(-1)
        q_dot = np.ascontiguousarray(self._core.q_dot).reshape(-1)
        return np.asarray(self._joints.velocities(q, q_dot))

    @property
    def ctrl(self) -> np.ndarray:
        """Actuator controls (n_actuators,), a writable view: ``world.ctrl[:] = targets``."""
        if self._joint_forces is None:
            return np.zeros(0)
        return self._joint_forces.ctrl

    def set_joint_forces(self, tau: np.ndarray | Sequence[float]) -> None:
        """Generalized joint forces (nv,), like MuJoCo's ``qfrc_applied``; they persist until
        replaced. Only revolute and prismatic joints take non-zero entries."""
        nv = sum(j.nv for j in self.joints)
        tau = np.asarray(tau, dtype=np.float64).reshape(-1)
        if tau.shape != (nv,):
            raise ValueError(f"set_joint_forces: expected {nv} values (nv), got {tau.shape}")
        per_joint, k = np.zeros(len(self.joints)), 0
        for j in self.joints:
            if j.nv == 1:
                per_joint[j.index] = tau[k]
            elif np.any(tau[k : k + j.nv] != 0.0):
                raise ValueError(f"set_joint_forces: joint '{j.name}' ({j.kind}) takes none")
            k += j.nv
        if self._joint_forces is None:
            if np.any(per_joint != 0.0):
                raise ValueError("set_joint_forces: the scene has no 1-dof joint")
            return
        self._joint_forces.set_joint_forces(per_joint)

    def apply_wrench(
        self,
        body: int | BodyHandle,
        force: Sequence[float] | np.ndarray = (0.0, 0.0, 0.0),
        torque: Sequence[float] | np.ndarray = (0.0, 0.0, 0.0),
        point: Sequence[float] | np.ndarray | None = None,
    ) -> None:
        """An external force (N) and torque (N·m) on a body, like MuJoCo's ``xfrc_applied``:
        the force acts at the world ``point`` (the material point there now; None: the
        centre of mass). It persists (replacing the body's previous wrench) until
        ``clear_wrenches``."""
        if isinstance(body, BodyHandle):
            if len(body) != 1:
                raise ValueError("apply_wrench: pass handle.body(i) for a multi-instance handle")
            body = body.start
        body = int(body)
        if not 0 <= body < self.num_bodies:
            raise IndexError(f"body index {body} out of range [0, {self.num_bodies})")
        q = self.q[body]
        A, p = q[3:].reshape(3, 3), q[:3]
        if point is None:
            mc = np.asarray(self._core.scene.body(body).mass_x_bar)
            x_bar = mc / float(self._core.scene.body(body).mass)
        else:
            x_bar = np.linalg.solve(A, np.asarray(point, dtype=np.float64).reshape(3) - p)
        if self._wrenches is None:
            self._wrenches = _core.BodyWrenchTerm(self.num_bodies)
            self._core.add_term(self._wrenches)
        self._wrenches.set_wrench(
            body,
            np.asarray(force, dtype=np.float64).reshape(3),
            np.asarray(torque, dtype=np.float64).reshape(3),
            x_bar,
        )

    def clear_wrenches(self) -> None:
        """Remove every wrench ``apply_wrench`` set."""
        if self._wrenches is not None:
            self._wrenches.clear()

    def joint_violation(self) -> tuple[float, float]:
        """(largest anchor separation in m, largest axis/frame misalignment in rad) now."""
        if self._joints is None:
            return (0.0, 0.0)
        return tuple(self._joints.violation(np.ascontiguousarray(self._core.q).reshape(-1)))

    # -- kinematic (scripted) bodies ------------------------------------------------------
    def set_kinematic_target(self, body: int, transform: np.ndarray) -> None:
        """Drive ``body`` kinematically: its transform at the end of the next step.

        The body is held at the target during the solve (it pushes, nothing pushes it) and
        its velocity follows from the motion. Without a new target it rests where it is.
        With contact, a move that would cross a dynamic body (or bring it through contact) is
        not forced: for that step the body is driven towards the target by a stiff spring
        (``kinematic_drive_stiffness``), pushes what it meets without penetrating it, and
        ``diagnostics.kinematic_lag`` says how far it stayed from the target. Kinematic and
        fixed bodies do not collide with each other.
        """
        T = _as_transforms(transform, 1, "kinematic target")
        _check_bottom_row(T, "kinematic target")
        check.check_transforms(T, "kinematic target")
        self._core.set_kinematic_target(int(body), transforms_to_q(T)[0])

    def set_kinematic_targets(
        self, bodies: Sequence[int] | np.ndarray, transforms: np.ndarray
    ) -> None:
        """Vectorised ``set_kinematic_target``: bodies (k,), transforms (k, 4, 4)."""
        b = np.asarray(bodies, dtype=np.int32).reshape(-1)
        T = _as_transforms(transforms, len(b), "kinematic targets")
        _check_bottom_row(T, "kinematic targets")
        check.check_transforms(T, "kinematic target")
        self._core.set_kinematic_targets(b, transforms_to_q(T))

    def set_kinematic_schedule(self, body: int, schedule: Schedule) -> None:
        """Drive ``body`` by ``schedule(t) -> 4x4``, evaluated at the end of every step."""
        if not callable(schedule):
            raise TypeError("schedule must be callable: t -> (4, 4) transform")
        if not 0 <= int(body) < self.num_bodies:
            raise IndexError(f"body index {body} out of range [0, {self.num_bodies})")
        self._schedules[int(body)] = schedule

    def release_kinematic(self, body: int) -> None:
        """Return a kinematic body to the dynamics (keeping its velocity).

        Raises:
            ValueError: with contact, when the body is in contact with (or overlaps) another
                kinematic or fixed body or the ground, which it now collides with.
        """
        self._core.release_kinematic(int(body))
        self._schedules.pop(int(body), None)

    def is_kinematic(self, body: int) -> bool:
        return bool(self._core.is_kinematic(int(body)))

    # -- energy terms and diagnostics ------------------------------------------------------
    @property
    def contact(self):
        """The C++ contact term (``abdsim._core.contact.IpcContactTerm``), or None."""
        return self._contact

    def min_contact_distance(self, max_distance: float | None = None) -> float:
        """Smallest gap (m) between contact surfaces (and to the ground) at the current state.

        Only pairs closer than ``max_distance`` are looked at (None: d̂, the barrier's reach),
        so the result is ``inf`` when nothing is that close, or without contact. Gaps are
        measured beyond the surfaces' ``thickness``.
        """
        if max_distance is not None and not (max_distance > 0 and math.isfinite(max_distance)):
            raise ValueError(f"max_distance must be positive and finite, got {max_distance!r}")
        return float(
            self._core.min_contact_distance(-1.0 if max_distance is None else max_distance)
        )

    def contacts(self) -> ContactForces:
        """Contact forces of the last step, per contact pair (see ``ContactForces``).

        The barrier forces at the current state and the friction lagged for the last step:
        the forces the last step applied. (After ``set_state``, until the next step, the
        friction part still refers to the last step's motion.) Empty without contact.
        """
        if self._contact is None:
            return ContactForces.empty()
        return ContactForces.from_core(self._contact.contact_forces(self._core.q.reshape(-1)))

    def contact_wrenches(self) -> np.ndarray:
        """Net contact force and torque on each body, (n_bodies, 6) rows ``[f, τ]`` (N, N m).

        The torque is about the body's centre of mass; the forces are those of
        ``contacts()`` (the last step's), summed over every pair the body is in.
        """
        if self._contact is None:
            return np.zeros((self.num_bodies, 6))
        if self._rest_centers is None:
            self._rest_centers = rest_centers_of_mass(self._core.scene, self._handles)
        q = self.q
        centers = world_centers(q, self._rest_centers)
        return np.asarray(self._contact.contact_wrenches(q.reshape(-1), centers))

    # -- sensors (abdsim.sim.sensors) --------------------------------------------------------
    @property
    def sensors(self) -> SensorSet:
        """This World's sensors (the scene's, plus those added with ``add_sensor``)."""
        return self._sensors

    def add_sensor(self, type: str, body: int, *args: Any, **kwargs: Any) -> int:
        """Add a sensor on ``body`` (``SensorSet.add``'s arguments); returns its index."""
        i = self._sensors.add(type, body, *args, **kwargs)
        try:
            self._sensors.check_bodies(self.num_bodies)
        except ValueError:
            self._sensors = SensorSet(self._sensors.specs[:-1])
            raise
        return i

    def add_joint_sensor(self, type: str, target: str | int, **kwargs: Any) -> int:
        """Add a ``jointpos``/``jointvel`` sensor on the joint named ``target`` or an
        ``actuatorfrc`` sensor on actuator ``target`` (``SensorSet.add_joint_sensor``'s
        arguments); ValueError if this World has no such joint or actuator."""
        i = self._sensors.add_joint_sensor(type, target, **kwargs)
        try:  # the new one only: the scene's may wait for joints it was not built with
            new = SensorSet(self._sensors.specs[i:])
            new.check_joints([j.name for j in self.joints], len(self._scene.actuators))
        except ValueError:
            self._sensors = SensorSet(self._sensors.specs[:-1])
            raise
        return i

    @property
    def sensor_adr(self) -> np.ndarray:
        """Index of each sensor's first value in ``sensordata`` (MuJoCo's ``sensor_adr``)."""
        return self._sensors.sensor_adr

    @property
    def sensor_dim(self) -> np.ndarray:
        """Number of values of each sensor (MuJoCo's ``sensor_dim``)."""
        return self._sensors.sensor_dim

    @property
    def sensor_names(self) -> list[str]:
        return self._sensors.names

    @property
    def sensordata(self) -> np.ndarray:
        """Every sensor's values at the current state, in MuJoCo's layout (NaN: unsupported)."""
        specs = self._sensors.specs
        types = {s.type for s in specs}
        q, q_dot = self.q, self.q_dot
        state = BodyState(q=q, q_dot=q_dot, acceleration=None, gravity=self._scene.gravity)
        if types & {"accelerometer", "force", "torque"}:
            st = self._scene.settings
            state.acceleration = self._velocities.acceleration(q_dot, st.dt, st.integrator)
        if types & {"touch", "force", "torque"}:
            state.contacts = self.contacts()
            state.wrenches = self.contact_wrenches()
        if types & {"force", "torque"}:
            if self._rest_centers is None:
                self._rest_centers = rest_centers_of_mass(self._core.scene, self._handles)
            state.rest_centers = self._rest_centers
            bodies = {s.body for s in specs if s.type in ("force", "torque")}
            state.mass_matrices = {b: np.asarray(self._core.mass_matrix(b)) for b in bodies}
        values = sensor_values(specs, state)
        if types & JOINT_TYPES:
            adr = self._sensors.sensor_adr
            joint_values = joint_sensor_values(
                specs,
                self.joints,
                self.joint_positions(),
                self.joint_velocities(),
                self._scene.actuators,
                self.ctrl,
            )
            for i, v in joint_values.items():
                values[adr[i]] = v
        return values

    def add_term(self, term: _core.EnergyTerm) -> None:
        """Add a potential (contact, joints, a ``_core.PythonEnergyTerm`` subclass...) to Π.

        A Python term whose ``__init__`` calls ``super().__init__(bodies=[...])`` involves only
        those bodies: the solver couples just them (the others keep their own per-body
        solve); without ``bodies`` a Python term couples every body into one system.
        """
        self._core.add_term(term)

    @property
    def diagnostics(self) -> StepDiagnostics | None:
        """Diagnostics of the last step (None before the first)."""
        if self._core.step_count == 0:
            return None
        return StepDiagnostics.from_core(self._core.diagnostics)

    @property
    def history(self) -> list[StepDiagnostics]:
        """Diagnostics of the last ``history_limit`` steps, oldest first."""
        return [StepDiagnostics.from_core(d) for d in self._core.history]

    def __repr__(self) -> str:
        return f"<World bodies={self.num_bodies} t={self.time:.6g} steps={self.step_count}>"
