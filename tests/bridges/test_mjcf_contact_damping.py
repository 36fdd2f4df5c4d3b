"""MJCF solref → abdsim's contact damping ratio (SceneSettings.contact_damping), checked
against the values MuJoCo itself compiles (``model.geom_solref``), and the drop both
simulators then agree on: critically damped contact stops a dropped box dead in MuJoCo and
in abdsim."""

from __future__ import annotations

import warnings

import mujoco
import numpy as np
import pytest

from abdsim.bridges import load_mjcf

DROP_XML = """<mujoco>
  <option timestep="{dt}"/>
  <default><geom solref="{solref}"/></default>
  <worldbody>
    <geom name="floor" type="plane" size="2 2 0.1"/>
    <body name="box" pos="0 0 {z}">
      <freejoint/>
      <geom type="box" size="0.1 0.08 0.05" density="500"/>
    </body>
  </worldbody>
</mujoco>
"""


def write(tmp_path, solref: str, dt: float = 1e-3, drop: float = 0.05):
    path = tmp_path / "drop.xml"
    path.write_text(DROP_XML.format(dt=dt, solref=solref, z=0.05 + drop))
    return path


def load(path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load_mjcf(path)


@pytest.mark.parametrize("ratio", [0.3, 1.0, 2.0])
def test_solref_damping_ratio_maps_to_contact_damping(tmp_path, ratio):
    path = write(tmp_path, f"0.02 {ratio}")
    compiled = mujoco.MjModel.from_xml_path(str(path)).geom_solref
    res = load(path)
    assert res.contact_damping == pytest.approx(float(compiled[:, 1].mean()), abs=0)
    assert res.contact_damping == pytest.approx(ratio)
    assert any("contact_damping" in n and "time constant" in n for n in res.notes)
    assert res.build_scene().settings.contact_damping == pytest.approx(ratio)
    # an explicit setting still wins
    assert res.build_scene(contact_damping=0.0).settings.contact_damping == 0.0


def test_direct_solref_is_noted_not_mapped(tmp_path):
    res = load(write(tmp_path, "-10000 -100"))
    assert res.contact_damping is None
    assert any("direct solref" in n for n in res.notes)
    assert res.build_scene().settings.contact_damping == 0.0


def mujoco_rebound(path, seconds: float) -> float:
    """Highest bottom height of MuJoCo's box after it first touched the floor."""
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    z = []
    for _ in range(int(round(seconds / m.opt.timestep))):
        mujoco.mj_step(m, d)
        z.append(d.qpos[2] - 0.05)
    z = np.array(z)
    return float(z[np.argmax(z < 1e-3) :].max())


@pytest.mark.parametrize("integrator", ["bdf1", "bdf2"])
def test_default_solref_drop_stops_dead_in_both(tmp_path, integrator):
    """Default solref (0.02 s, ratio 1): MuJoCo's box dropped 5 cm does not bounce (it stays
    below 1 mm after touching); loaded into abdsim, ζ = 1 keeps it inside d̂ = 1 mm too (BDF2
    undamped bounced to ~4 mm)."""
    path = write(tmp_path, "0.02 1")
    assert mujoco_rebound(path, 0.4) < 1e-3
    res = load(path)
    from abdsim import World

    world = World(res.build_scene(integrator=integrator))
    half = 0.05
    z = []
    for _ in range(400):
        world.step()
        z.append(world.transforms()[0, 2, 3] - half)
    z = np.array(z)
    assert z.min() > 0.0
    assert z[np.argmax(z < 1e-3) :].max() <= 1e-3
