"""Positions, orientations and named poses, in SI units (metres, radians)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from exsce_dsl.errors import SourceLocation


def quaternion(roll: float, pitch: float, yaw: float) -> tuple[float, float, float, float]:
    """The unit quaternion (x, y, z, w) of a rotation by ``roll``, ``pitch`` and ``yaw`` (radians,
    applied about the fixed x, y and z axes in that order: ROS's ``rpy``)."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return (
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
        cr * cp * cy + sr * sp * sy,
    )


@dataclass(frozen=True)
class Position:
    x: float
    y: float
    z: float = 0.0
    unit: str = field(default="m", compare=False)
    """How the author wrote it (m, cm, mm); only the formatter looks at it."""
    written: tuple[str, ...] = field(default=(), compare=False, repr=False)
    """x, y (and z if given) as the author wrote them, units included (``200 cm``, ``7``): the
    formatter prints them as long as they read as these values."""

    def distance_to(self, other: Position) -> float:
        return math.dist((self.x, self.y, self.z), (other.x, other.y, other.z))


@dataclass(frozen=True)
class Orientation:
    roll: float = 0.0
    pitch: float = 0.0
    yaw: float = 0.0
    unit: str = field(default="rad", compare=False)
    """How the author wrote it (rad, deg); only the formatter looks at it."""
    written: tuple[str, ...] = field(default=(), compare=False, repr=False)
    """The yaw (``facing``), or roll, pitch and yaw (``rpy``), as the author wrote them
    (``90 deg``, ``1.5 rad``, ``0.3``): the formatter prints them as long as they read as these values."""

    @property
    def is_planar(self) -> bool:
        return self.roll == 0.0 and self.pitch == 0.0


@dataclass(frozen=True)
class Pose:
    """A named pose of an environment, or a waypoint given by coordinates.

    ``area`` is the id of the area that holds it (``None`` for coordinate
    waypoints, which belong to their task).  A use of a declared pose with
    another heading is a ``Pose`` with the same id and another orientation.
    """

    id: str
    position: Position
    orientation: Orientation = Orientation()
    area: str | None = None
    location: SourceLocation | None = field(default=None, compare=False, repr=False)

    def with_orientation(self, orientation: Orientation) -> Pose:
        return Pose(self.id, self.position, orientation, self.area, self.location)
