"""example_robot(): the bundled example-robot-data URDFs by name."""

from __future__ import annotations

import pytest

from abdsim.bridges import example_robot, example_robots, load_urdf


def test_panda_is_found_and_loads():
    import pinocchio as pin

    path = example_robot("panda")
    assert path.name == "panda.urdf" and path.parent.parent.name == "panda_description"
    model = pin.buildModelFromUrdf(str(path))
    assert model.nq == 9  # 7 arm joints + 2 fingers
    robot = load_urdf(path)
    assert robot.index("panda_hand") >= 0 and len(robot.joints) == model.njoints - 1


def test_listing_and_description_folder_names():
    robots = example_robots()
    assert len(robots) > 20 and all(p.suffix == ".urdf" and p.is_file() for p in robots.values())
    assert example_robot("double_pendulum").parent.parent.name == "double_pendulum_description"


def test_unknown_robot_names_close_ones():
    with pytest.raises(FileNotFoundError, match="no example robot 'pand'; try one of: panda"):
        example_robot("pand")
