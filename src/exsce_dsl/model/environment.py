"""Environments: their models, areas of named poses, and obstacles."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field

from exsce_dsl.errors import SourceLocation
from exsce_dsl.model.geometry import Pose


@dataclass(frozen=True)
class RosResource:
    """Where a ROS tool finds a file: a package and a path inside it."""

    package: str
    path: str | None = None


@dataclass(frozen=True)
class MapModel:
    """The occupancy grid. ``file`` is the map_server YAML on this machine."""

    name: str
    source: RosResource | None = None
    file: str | None = None
    location: SourceLocation | None = field(default=None, compare=False, repr=False)


@dataclass(frozen=True)
class WorldModel:
    """The simulator's world model (e.g. a Gazebo world)."""

    name: str
    source: RosResource | None = None
    location: SourceLocation | None = field(default=None, compare=False, repr=False)


@dataclass(frozen=True)
class Area:
    """A region of the environment (a room) holding named poses."""

    id: str
    poses: tuple[Pose, ...] = ()
    location: SourceLocation | None = field(default=None, compare=False, repr=False)


@dataclass(frozen=True)
class Obstacle:
    id: str
    pose: Pose
    model: str | None = None
    size: tuple[float, ...] | None = None
    location: SourceLocation | None = field(default=None, compare=False, repr=False)
    size_written: tuple[str, ...] = field(default=(), compare=False, repr=False)
    """The size as the author wrote it (``50 cm``), for the formatter."""


@dataclass(frozen=True)
class Environment:
    id: str
    map: MapModel | None = None
    world: WorldModel | None = None
    areas: tuple[Area, ...] = ()
    obstacles: tuple[Obstacle, ...] = ()
    location: SourceLocation | None = field(default=None, compare=False, repr=False)

    def poses(self) -> Iterator[Pose]:
        for area in self.areas:
            yield from area.poses

    def pose(self, pose_id: str) -> Pose | None:
        return next((p for p in self.poses() if p.id == pose_id), None)
