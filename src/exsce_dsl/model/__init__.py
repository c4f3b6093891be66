"""The semantic model: plain, immutable dataclasses, free of textX, rdflib and prov."""

from exsce_dsl.model.acceptance import Acceptance
from exsce_dsl.model.document import Declaration, Document, Import, Specification
from exsce_dsl.model.environment import (
    Area,
    Environment,
    MapModel,
    Obstacle,
    RosResource,
    WorldModel,
)
from exsce_dsl.model.geometry import Orientation, Pose, Position
from exsce_dsl.model.robots import Robot, RobotType
from exsce_dsl.model.scenario import Assignment, Mission, MissionType, Scenario
from exsce_dsl.model.tasks import Subtask, Task

__all__ = [
    "Acceptance",
    "Area",
    "Assignment",
    "Declaration",
    "Document",
    "Environment",
    "Import",
    "MapModel",
    "Mission",
    "MissionType",
    "Obstacle",
    "Orientation",
    "Pose",
    "Position",
    "Robot",
    "RobotType",
    "RosResource",
    "Scenario",
    "Specification",
    "Subtask",
    "Task",
    "WorldModel",
]
