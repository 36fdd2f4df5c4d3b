"""Loads a validation scene into abdsim (through abdsim.bridges) and into the peers' terms.

The bodies compared are the scene's free (dynamic) bodies, in MuJoCo's body order, matched to
abdsim's bodies by name.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from abdsim.validation.abdsim_runner import AffineRigidView, run_abdsim
from abdsim.validation.trajectory import Trajectory


@dataclass
class AbdsimSetup:
    """A loaded scene ready to run in abdsim, with what the comparison needs."""

    loaded: object  # abdsim.bridges.LoadResult
    world: object  # abdsim.World
    names: list[str]
    body_ids: np.ndarray
    mujoco_path: Path
    gravity: np.ndarray
    view: AffineRigidView

    def run(
        self, duration: float, sample_dt: float, progress: bool = True, logger=None
    ) -> Trajectory:
        on_step = logger.log_world if logger is not None else None
        if logger is not None:
            logger.log_world(self.world)
        return run_abdsim(
            self.world,
            self.names,
            self.body_ids,
            self.view,
            self.gravity,
            duration,
            self.world.scene.dt,
            sample_dt,
            progress,
            on_step,
        )

    def make_logger(self, path: Path):
        from abdsim.bridges import McapLogger

        return McapLogger(
            path, self.world, namespace="/abdsim", metadata={"scene": str(self.loaded.source)}
        )

    def log_reference(self, logger, traj: Trajectory, namespace: str) -> None:
        """Log a peer's body poses next to abdsim's (same meshes, other namespace)."""
        T = traj.extra.get("transforms")
        if T is None:
            return
        geoms = [self.loaded.bodies[i].geometry for i in self.body_ids]
        logger.add_bodies(
            self.names,
            meshes=[(g.positions, g.triangles) for g in geoms],
            namespace=namespace,
            kinds=["dynamic"] * len(geoms),
        )
        for k, t in enumerate(traj.time):
            logger.log_state(float(t), T[k], namespace=namespace)

    def rigid_bodies(self) -> list[tuple[float, np.ndarray, np.ndarray]]:
        import abdsim

        out = []
        for i in self.body_ids:
            rb = abdsim.to_rigid_body(self.loaded.bodies[i].geometry)
            out.append((rb.mass, rb.mass_center, rb.inertia))
        return out

    def settings(self) -> dict:
        s = self.world.scene.settings
        keys = (
            "integrator",
            "dt",
            "newton_tol_translation",
            "newton_tol_affine",
            "d_hat",
            "friction",
            "eps_v",
            "contact_stiffness",
        )
        return {f"abdsim_{k}": getattr(s, k) for k in keys if hasattr(s, k)}


def build_abdsim(
    path: Path, kind: str, dt: float, integrator: str, perturb_inertia: dict[str, float]
) -> AbdsimSetup:
    """Load ``path`` into an abdsim World (bodies with the source's exact inertials)."""
    import abdsim
    from abdsim.bridges import load_mjcf
    from abdsim.validation.mujoco_reference import body_names, free_bodies, load_model

    if kind != "mjcf":
        raise ValueError(
            f"{path}: trajectory validation needs free bodies; URDF robots load fixed-base in "
            "MuJoCo and as kinematic links in abdsim, so only MJCF scenes (free joints) can be "
            "validated dynamically for now"
        )
    model = load_model(path)
    mj_names = body_names(model, free_bodies(model))
    if not mj_names:
        raise ValueError(f"{path}: the scene has nothing dynamic (no body with a free joint)")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        loaded = load_mjcf(path, kinematic=True)  # free bodies validated; hinged ones scripted
    ids = []
    for name in mj_names:
        try:
            ids.append(loaded.index(name))
        except KeyError:
            raise ValueError(f"free body {name!r} has no collision geometry in abdsim") from None
    for name, factor in perturb_inertia.items():
        if name not in mj_names:
            raise ValueError(f"--perturb-inertia: no free body {name!r}; bodies: {mj_names}")
        sc = loaded.bodies[loaded.index(name)].geometry
        rb = abdsim.to_rigid_body(sc)
        abdsim.assign_rigid_body(sc, rb.mass, rb.mass_center, rb.inertia * float(factor))
    scene = loaded.build_scene(dt=dt, integrator=integrator)
    world = abdsim.World(scene)
    metas = [loaded.bodies[i].geometry.meta for i in ids]
    view = AffineRigidView(
        np.array([m["abd_mass"] for m in metas]),
        np.array([m["abd_mass_x_bar"] for m in metas]),
        np.array([m["abd_mass_x_bar_x_bar"] for m in metas]),
    )
    return AbdsimSetup(
        loaded, world, mj_names, np.asarray(ids), Path(path), np.asarray(scene.gravity, float), view
    )


def peer_inertias(setup: AbdsimSetup) -> dict[str, list[tuple[float, np.ndarray, np.ndarray]]]:
    """Each peer's (mass, centre in the body frame, inertia about the centre) per body."""
    import mujoco

    from abdsim.validation.mujoco_reference import free_bodies, load_model

    model = load_model(setup.mujoco_path)
    out = []
    for b in free_bodies(model):
        R = np.zeros(9)
        mujoco.mju_quat2Mat(R, model.body_iquat[b])
        R = R.reshape(3, 3)
        out.append(
            (
                float(model.body_mass[b]),
                model.body_ipos[b].copy(),
                R @ np.diag(model.body_inertia[b]) @ R.T,
            )
        )
    return {"MuJoCo": out}
