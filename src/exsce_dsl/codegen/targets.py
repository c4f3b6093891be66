"""The generators exsce offers, by target name (``exscec generate TARGET``, ``textx generate --target``).

Each target turns a checked specification (and one of its scenarios) into
files below an output folder.  Modules are imported when a target runs, so
listing the targets stays cheap.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from exsce_dsl.model import Specification

Generate = Callable[[Specification, "str | None", Path, bool], list[Path]]
"""(specification, scenario id or None for the root file's only one, output folder, overwrite) → files."""


@dataclass(frozen=True)
class GenerationTarget:
    name: str
    description: str
    module: str
    function: str

    def generate(
        self, spec: Specification, scenario_id: str | None, out_dir: Path, overwrite: bool = False
    ) -> list[Path]:
        func: Generate = getattr(importlib.import_module(self.module), self.function)
        return func(spec, scenario_id, out_dir, overwrite)


TARGETS: dict[str, GenerationTarget] = {
    t.name: t
    for t in (
        GenerationTarget(
            "monitors",
            "vectorised numpy monitor classes (RobotMetrics, MissionMetrics) for the spec's metrics",
            "exsce_dsl.codegen.monitors",
            "generate_monitors",
        ),
        GenerationTarget(
            "dispatcher-config",
            "the waypoint files the method's dispatcher reads: the mission, and each robot's task files",
            "exsce_dsl.codegen.dispatcher",
            "generate_dispatcher_config",
        ),
        GenerationTarget(
            "ros1-monitor",
            "a ROS 1 (catkin, rospy) package of a runtime monitor node: the scenario's metrics live, "
            "its oracles' verdicts as JSON on /exsce/verdicts",
            "exsce_dsl.codegen.ros_monitor",
            "generate_ros1_monitor",
        ),
        GenerationTarget(
            "ros2-monitor",
            "a ROS 2 (ament_python, rclpy) package of a runtime monitor node: the scenario's metrics live, "
            "its oracles' verdicts as JSON on /exsce/verdicts",
            "exsce_dsl.codegen.ros_monitor",
            "generate_ros2_monitor",
        ),
    )
}
