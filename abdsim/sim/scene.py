"""Scene: the geometries to simulate and the settings to simulate them with."""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np

from abdsim.geometry.simplicial_complex import SimplicialComplex
from abdsim.sim.settings import SceneSettings


@dataclass(frozen=True)
class BodyHandle:
    """The bodies one ``Scene.add`` call created: every instance of one geometry.

    Bodies are numbered geometry by geometry, instance by instance: instance ``i`` of this
    geometry is body ``start + i``.
    """

    geometry: int  #: index in ``Scene.geometries``
    start: int  #: first body index
    stop: int  #: one past the last body index
    sc: SimplicialComplex = field(repr=False, compare=False)

    @property
    def bodies(self) -> range:
        """Body indices of this geometry's instances."""
        return range(self.start, self.stop)

    def body(self, instance: int = 0) -> int:
        """Body index of one instance."""
        if not 0 <= instance < len(self):
            raise IndexError(f"instance {instance} out of range [0, {len(self)})")
        return self.start + instance

    def __len__(self) -> int:
        return self.stop - self.start


class Scene:
    """Geometries (each instance an affine body) plus the simulation settings.

    Args:
        dt: time step (s).
        gravity: gravitational acceleration (m/s²), z-up by default.
        integrator: ``"bdf1"`` or ``"bdf2"``.
        settings: a full ``SceneSettings`` to start from (copied).
        **kwargs: any other ``SceneSettings`` field (``newton_tol_translation=...``).

    Raises:
        ValueError: for a setting out of range; TypeError for an unknown setting.
    """

    def __init__(
        self,
        dt: float | None = None,
        gravity: tuple[float, float, float] | np.ndarray | None = None,
        integrator: str | None = None,
        *,
        settings: SceneSettings | None = None,
        **kwargs: Any,
    ) -> None:
        base = replace(settings) if settings is not None else SceneSettings()
        unknown = set(kwargs) - set(SceneSettings.field_names())
        if unknown:
            raise TypeError(
                f"unknown scene setting(s) {sorted(unknown)}; known: {SceneSettings.field_names()}"
            )
        given = {"dt": dt, "gravity": gravity, "integrator": integrator}
        kwargs.update({k: v for k, v in given.items() if v is not None})
        if "gravity" in kwargs:
            kwargs["gravity"] = tuple(float(x) for x in np.asarray(kwargs["gravity"]).reshape(-1))
        self.settings: SceneSettings = replace(base, **kwargs)
        self.settings.validate()
        self._geometries: list[SimplicialComplex] = []
        self._handles: list[BodyHandle] = []

    @property
    def dt(self) -> float:
        return self.settings.dt

    @property
    def gravity(self) -> np.ndarray:
        return np.asarray(self.settings.gravity, dtype=np.float64)

    @property
    def geometries(self) -> list[SimplicialComplex]:
        """Added geometries, in order (a copy of the list; the geometries themselves)."""
        return list(self._geometries)

    @property
    def handles(self) -> list[BodyHandle]:
        """One handle per added geometry, in order."""
        return list(self._handles)

    @property
    def num_bodies(self) -> int:
        return self._handles[-1].stop if self._handles else 0

    def add(self, sc: SimplicialComplex) -> BodyHandle:
        """Add every instance of ``sc`` as a body; returns their handle.

        ``sc`` must carry a constitution (``AffineBodyConstitution(...).apply_to(sc, kappa)``).
        Its attributes are read when a ``World`` is built, so they can still be edited
        (velocities, flags, transforms), but not its instance count.

        Raises:
            ValueError: no constitution, no instances, or ``sc`` already added.
        """
        if not isinstance(sc, SimplicialComplex):
            raise TypeError(f"Scene.add expects a SimplicialComplex, got {type(sc).__name__}")
        if "constitution_uid" not in sc.meta:
            raise ValueError(
                "geometry has no constitution: apply one first, e.g. "
                "abdsim.AffineBodyConstitution('OrthoPotential').apply_to(sc, kappa=1e8)"
            )
        if any(g is sc for g in self._geometries):
            raise ValueError("this SimplicialComplex was already added to the scene")
        if sc.instance_count < 1:
            raise ValueError("geometry has no instances")
        start = self.num_bodies
        handle = BodyHandle(len(self._geometries), start, start + sc.instance_count, sc)
        self._geometries.append(sc)
        self._handles.append(handle)
        return handle

    def __repr__(self) -> str:
        return (
            f"<Scene geometries={len(self._geometries)} bodies={self.num_bodies} "
            f"dt={self.dt} integrator={self.settings.integrator}>"
        )
