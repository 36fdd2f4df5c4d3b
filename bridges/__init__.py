"""Bridges (installed as ``abdsim.bridges``): URDF / MJCF scenes in, MCAP logs out.

* :func:`load_urdf` (Pinocchio) and :func:`load_mjcf` (MuJoCo) turn robot and scene files
  into affine bodies with the source's exact mass properties; they return a
  :class:`LoadResult` (bodies, names, settings, ``result.scene``).
* By default the loaders give dynamic articulations (``result.scene`` joins the bodies by the
  source's joints; ``result.make_world()`` is a :class:`RobotWorld` with the MJCF actuators
  on ``world.ctrl``); with ``kinematic=True``, :class:`RobotDriver` / :class:`MjcfDriver`
  move the kinematic bodies along a joint trajectory.
* :class:`McapLogger` / :func:`run_and_log` write MCAP logs that open in Foxglove;
  :func:`read_log` reads them back into numpy arrays.

Names are imported lazily, so ``import abdsim.bridges`` stays cheap and loading an MJCF file
never imports Pinocchio (nor a URDF MuJoCo).
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

_EXPORTS = {
    "BodyKind": "_bodies",
    "Ground": "_bodies",
    "JointInfo": "_bodies",
    "LoadedBody": "_bodies",
    "LoaderError": "_bodies",
    "LoadResult": "_bodies",
    "load_urdf": "urdf",
    "load_mjcf": "mjcf",
    "build_articulated_scene": "articulated",
    "RobotWorld": "robot_world",
    "ActuatorInfo": "_mjcf_actuators",
    "KinematicDriver": "drivers",
    "RobotDriver": "drivers",
    "MjcfDriver": "drivers",
    "McapLogger": "mcap_log",
    "run_and_log": "mcap_log",
    "step_and_log": "mcap_log",
    "close_logs": "mcap_log",
    "LogData": "log_reader",
    "read_log": "log_reader",
    "log_info": "log_reader",
    "example_robot": "robots",
    "example_robots": "robots",
}

__all__ = [
    "ActuatorInfo",
    "BodyKind",
    "Ground",
    "JointInfo",
    "KinematicDriver",
    "LoadResult",
    "LoadedBody",
    "LoaderError",
    "LogData",
    "McapLogger",
    "MjcfDriver",
    "RobotDriver",
    "RobotWorld",
    "build_articulated_scene",
    "load_mjcf",
    "load_urdf",
    "log_info",
    "read_log",
    "run_and_log",
    "step_and_log",
    "close_logs",
    "example_robot",
    "example_robots",
]

if TYPE_CHECKING:  # pragma: no cover
    from abdsim.bridges._bodies import (
        BodyKind,
        Ground,
        JointInfo,
        LoadedBody,
        LoaderError,
        LoadResult,
    )
    from abdsim.bridges._mjcf_actuators import ActuatorInfo
    from abdsim.bridges.articulated import build_articulated_scene
    from abdsim.bridges.drivers import KinematicDriver, MjcfDriver, RobotDriver
    from abdsim.bridges.log_reader import LogData, log_info, read_log
    from abdsim.bridges.mcap_log import McapLogger, close_logs, run_and_log, step_and_log
    from abdsim.bridges.mjcf import load_mjcf
    from abdsim.bridges.robot_world import RobotWorld
    from abdsim.bridges.robots import example_robot, example_robots
    from abdsim.bridges.urdf import load_urdf


def __getattr__(name: str) -> Any:
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'abdsim.bridges' has no attribute {name!r}")
    value = getattr(importlib.import_module(f"abdsim.bridges.{module}"), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
