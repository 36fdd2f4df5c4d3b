"""No pass-through: the reported motion between two steps never carries a body through another.

Head-on pairs (boxes and spheres, 1-100 m/s each, dt 0.005-0.1): Newton's iterates are each
CCD-bounded, but before substepping the straight line from one reported state to the next
crossed (bodies slid round each other within a step) once a step moved them about their own
size. Checked independently with ipctk's CCD (is_step_collision_free) on every step's
straight-line motion.
"""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

import abdsim

ipctk = pytest.importorskip("ipctk")

GAP = 0.1  # between the surfaces at the start (m)


def _solid(
    mesh: trimesh.Trimesh, x: float, y: float, vx: float, rotvec
) -> abdsim.SimplicialComplex:
    sc = abdsim.geometry.from_trimesh(mesh)
    abdsim.AffineBodyConstitution().apply_to(sc, 1e8)
    T = np.eye(4)
    angle = float(np.linalg.norm(rotvec))
    if angle > 0:
        T[:3, :3] = trimesh.transformations.rotation_matrix(angle, rotvec)[:3, :3]
    T[:2, 3] = (x, y)
    sc.transforms = T
    V = np.zeros((4, 4))
    V[0, 3] = vx
    sc.instances["velocity"] = V
    return sc


class _Chords:
    """ipctk's CCD along the straight line between two reported states of the bodies."""

    def __init__(self, world: abdsim.World, handles):
        self.world, self.handles = world, handles
        rest = [h.sc.positions for h in handles]
        offsets = np.cumsum([0] + [len(r) for r in rest])
        faces = np.vstack([h.sc.triangles + o for h, o in zip(handles, offsets, strict=False)])
        self.mesh = ipctk.CollisionMesh(np.vstack(rest), ipctk.edges(faces), faces)

    def vertices(self) -> np.ndarray:
        return np.vstack([self.world.vertices(h)[0] for h in self.handles])

    def free(self, V0: np.ndarray, V1: np.ndarray) -> bool:
        # Tight Inclusion without its conservative rescaling (0.8 by default, which flags
        # lines that merely end close, e.g. in resting contact): a crossing, to 1e-6.
        ccd = ipctk.TightInclusionCCD(
            tolerance=1e-6, max_iterations=10_000_000, conservative_rescaling=1.0
        )
        return ipctk.is_step_collision_free(self.mesh, V0, V1, narrow_phase_ccd=ccd)


@pytest.mark.parametrize("dt", [0.005, 0.05, 0.1])
@pytest.mark.parametrize("speed", [1.0, 5.0, 20.0, 100.0])
@pytest.mark.parametrize("shape", ["box", "sphere"])
@pytest.mark.parametrize("pose", ["aligned", "glancing"])
def test_head_on_bodies_never_pass_through(pose, shape, speed, dt):
    size = 0.2
    mesh = (
        trimesh.creation.box(extents=(size, size, size))
        if shape == "box"
        else trimesh.creation.icosphere(subdivisions=1, radius=size / 2)
    )
    x = (size + GAP) / 2
    # glancing: slightly off-centre and turned, as real head-on impacts are (they may then
    # deflect and slide past each other, but never through)
    y, rot = (0.0, (0.0, 0.0, 1.0)) if pose == "aligned" else (0.02, (0.3, 0.2, 0.1))
    turn = 0.0 if pose == "aligned" else 1.0
    scene = abdsim.Scene(dt=dt, gravity=(0.0, 0.0, 0.0))
    handles = [
        scene.add(_solid(mesh, -x, -y, speed, turn * np.asarray(rot))),
        scene.add(_solid(mesh, x, y, -speed, -turn * np.asarray(rot))),
    ]
    world = abdsim.World(scene)
    chords = _Chords(world, handles)
    steps = int(np.ceil(GAP / (2 * speed * dt))) + 3  # the meeting step, then a few more
    V0 = chords.vertices()
    for _ in range(steps):
        world.step()
        V1 = chords.vertices()
        assert chords.free(V0, V1), f"step {world.step_count}: a body passed through the other"
        if pose == "aligned":
            assert world.q[0, 0] < world.q[1, 0], "the bodies swapped sides"
        V0 = V1
    # they met and pushed each other: body 0 lost a good part of its velocity towards +x
    dv = np.linalg.norm(world.q_dot[0, :3] - [speed, 0.0, 0.0])
    assert dv > 0.25 * speed


def test_a_fast_ball_is_stopped_by_a_free_plate():
    """A ball at 50-100 m/s used to pass a free 1 m plate at dt = 0.05 with its velocity
    unchanged; now the two move on together (inelastic): momentum m v = (m + M) v'."""
    for speed in (50.0, 100.0):
        scene = abdsim.Scene(dt=0.05, gravity=(0.0, 0.0, 0.0))
        plate = abdsim.geometry.box((1.0, 1.0, 0.02))
        abdsim.AffineBodyConstitution().apply_to(plate, 1e8)
        scene.add(plate)
        ball = _solid(
            trimesh.creation.icosphere(subdivisions=2, radius=0.1), 0.0, 0.0, 0.0, (0, 0, 1)
        )
        T = ball.transforms[0]
        T[2, 3] = 1.0
        ball.transforms = T
        V = np.zeros((4, 4))
        V[2, 3] = -speed
        ball.instances["velocity"] = V
        scene.add(ball)
        world = abdsim.World(scene)
        world.step(4)
        assert world.q[1, 2] > world.q[0, 2], "the ball went through the plate"
        m, M = float(ball.meta["mass"]), float(plate.meta["mass"])
        v_common = -speed * m / (m + M)
        assert world.q_dot[1, 2] == pytest.approx(v_common, rel=0.05)
        assert world.q_dot[0, 2] == pytest.approx(v_common, rel=0.05)
