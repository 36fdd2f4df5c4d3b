"""Shared helpers for the contact tests: the compiled module and finite differences."""

import numpy as np
import pytest

from abdsim._native import _core


class FiniteDifferences:
    """Central differences, for checking analytic gradients and Hessians."""

    @staticmethod
    def gradient(f, x, h=1e-6):
        x = np.asarray(x, dtype=float)
        g = np.zeros_like(x)
        for i in range(x.size):
            e = np.zeros_like(x)
            e[i] = h
            g[i] = (f(x + e) - f(x - e)) / (2 * h)
        return g

    @staticmethod
    def jacobian(g, x, h=1e-6):
        x = np.asarray(x, dtype=float)
        cols = []
        for i in range(x.size):
            e = np.zeros_like(x)
            e[i] = h
            cols.append((np.asarray(g(x + e)) - np.asarray(g(x - e))) / (2 * h))
        return np.stack(cols, axis=-1)


@pytest.fixture(scope="session")
def contact():
    return _core.contact


@pytest.fixture(scope="session")
def fd():
    return FiniteDifferences


@pytest.fixture
def rng():
    return np.random.default_rng(20240601)


class Drops:
    """A box (0.2 x 0.16 x 0.1 m) or a sphere (r = 5 cm), 500 kg/m³, ABD-stiff (κ = 1e8),
    dropped from rest onto the ground (damping and restitution tests)."""

    @staticmethod
    def geometry(shape: str):
        import abdsim

        if shape == "box":
            sc = abdsim.geometry.box((0.2, 0.16, 0.1))
        else:
            sc = abdsim.geometry.sphere(0.05, subdivisions=2)
        abdsim.AffineBodyConstitution("OrthoPotential").apply_to(sc, kappa=1e8, mass_density=500.0)
        return sc

    @staticmethod
    def world(shape: str, drop: float, integrator: str, dt: float, **settings):
        """The body with its lowest point `drop` above the ground: (world, mass, height of
        the lowest point below the centre)."""
        import abdsim

        sc = Drops.geometry(shape)
        half = float(-np.asarray(sc.positions)[:, 2].min())
        T = np.eye(4)
        T[2, 3] = half + drop
        sc.transforms = T[None]
        scene = abdsim.Scene(dt=dt, integrator=integrator, **settings)
        scene.add(sc)
        scene.add_ground()
        return abdsim.World(scene), float(sc.meta["abd_mass"]), half


class Scenes:
    """Small scenes of affine bodies for the contact-term tests."""

    @staticmethod
    def box(extents=(1.0, 1.0, 1.0)):
        import trimesh

        mesh = trimesh.creation.box(extents=extents)
        return np.asarray(mesh.vertices, float), np.asarray(mesh.faces, np.int32)

    @staticmethod
    def q_of(p, A=None):
        A = np.eye(3) if A is None else np.asarray(A, float)
        return np.concatenate([np.asarray(p, float), A[0], A[1], A[2]])

    @staticmethod
    def rotation(rng, angle=None):
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        angle = rng.uniform(0, 2 * np.pi) if angle is None else angle
        K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
        return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K

    @staticmethod
    def term(geometries, body_geometry, q, is_fixed=None, mass=None, dt=0.01, **settings):
        """geometries: list of dicts with V, F (optional), E (optional), r (optional), self."""
        s = _core.contact.ContactSettings()
        for key, value in settings.items():
            setattr(s, key, value)
        empty_f = np.zeros((0, 3), np.int32)
        empty_e = np.zeros((0, 2), np.int32)
        return _core.contact.IpcContactTerm(
            [g["V"] for g in geometries],
            [g.get("F", empty_f) for g in geometries],
            [g.get("E", empty_e) for g in geometries],
            [g.get("r", np.zeros(len(g["V"]))) for g in geometries],
            [g.get("self", 0) for g in geometries],
            list(body_geometry),
            np.asarray(q, float),
            is_fixed=is_fixed,
            mass=mass,
            settings=s,
            dt=dt,
        )


@pytest.fixture(scope="session")
def scenes():
    return Scenes


class WorldContact:
    """Scenes through the public Scene/World API, and an independent intersection check with
    coal's Python bindings (triangle-level BVH collision and distance, world-space meshes)."""

    @staticmethod
    def solid(mesh, n=1, kappa=1e8, density=1e3):
        import abdsim

        sc = abdsim.geometry.from_trimesh(mesh)
        sc.instances.resize(n)
        abdsim.AffineBodyConstitution("OrthoPotential").apply_to(
            sc, kappa=kappa, mass_density=density
        )
        return sc

    @staticmethod
    def box(extents, n=1, **kw):
        import trimesh

        return WorldContact.solid(trimesh.creation.box(extents=extents), n, **kw)

    @staticmethod
    def place(sc, positions, rotations=None):
        T = np.tile(np.eye(4), (len(positions), 1, 1))
        T[:, :3, 3] = positions
        if rotations is not None:
            T[:, :3, :3] = rotations
        sc.transforms = T

    @staticmethod
    def pushing_world(speed, **settings):
        """A scripted 10×20×10 cm block 2 cm behind a 10 cm box on the ground, moving
        along +x at `speed` (m/s): (world, pusher handle, box handle). The box starts 1.5 mm
        up, outside d̂, and lands in the first steps (a box placed inside d̂ gets the barrier
        stiffness that makes its start an equilibrium, softer than the one it lands with)."""
        import abdsim

        scene = abdsim.Scene(dt=0.01, **settings)
        scene.add_ground(0.0)
        pusher = WorldContact.box((0.1, 0.2, 0.1))
        WorldContact.place(pusher, [[-0.12, 0.0, 0.06]])
        hp = scene.add(pusher, kinematic=True)
        box = WorldContact.box((0.1, 0.1, 0.1))
        WorldContact.place(box, [[0.0, 0.0, 0.0515]])
        hb = scene.add(box)
        world = abdsim.World(scene)
        T0 = world.transforms()[hp.start]

        def script(t):
            T = T0.copy()
            T[0, 3] += speed * t
            return T

        world.set_kinematic_schedule(hp.start, script)
        return world, hp, hb

    @staticmethod
    def coal_model(V, F):
        import coal

        m = coal.BVHModelOBBRSS()
        m.beginModel(len(F), len(V))
        m.addVertices(np.ascontiguousarray(V, dtype=float))
        m.addTriangles(np.ascontiguousarray(F, dtype=np.int64))
        m.endModel()
        return coal.CollisionObject(m, coal.Transform3s())

    @staticmethod
    def coal_check(world, skip=()):
        """Every pair of bodies with triangles (except `skip`, pairs of body indices): number of
        intersecting pairs (coal.collide) and the smallest distance (coal.distance); with a
        ground, the lowest vertex height above it. Independent of abdsim's contact code."""
        import coal

        objects, body_ids, low = [], [], np.inf
        ground = world.scene.ground
        for h in world.scene.handles:
            F = np.asarray(h.sc.triangles)
            V = world.vertices(h)
            for k in range(len(h)):
                if ground is not None and not world.is_kinematic(h.start + k):
                    low = min(low, V[k][:, 2].min() - ground.height)
                if len(F):
                    objects.append(WorldContact.coal_model(V[k], F))
                    body_ids.append(h.start + k)
        skip = {tuple(sorted(p)) for p in skip}
        hits, d_min = 0, np.inf
        creq, dreq = coal.CollisionRequest(), coal.DistanceRequest()
        for i in range(len(objects)):
            for j in range(i + 1, len(objects)):
                if (body_ids[i], body_ids[j]) in skip:
                    continue
                cres, dres = coal.CollisionResult(), coal.DistanceResult()
                hits += bool(coal.collide(objects[i], objects[j], creq, cres))
                d_min = min(d_min, coal.distance(objects[i], objects[j], dreq, dres))
        return hits, d_min, low


@pytest.fixture(scope="session")
def wc():
    return WorldContact
