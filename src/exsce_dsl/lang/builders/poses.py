"""Positions and orientations as written in a parse tree, in metres and radians.

Every builder that reads a pose (environments, tasks, derivation steps that move an obstacle)
and the editor's index use these; they import nothing of the builders.
"""

from __future__ import annotations

from typing import Any

from exsce_dsl.lang.lexical import quantity_parts, read_angle, read_length
from exsce_dsl.model import Orientation, Position


def position_of(pos: Any) -> Position:
    """A parsed `(x, y[, z])` with units, in metres (what the author wrote kept for the formatter)."""
    unit = quantity_parts(pos.x)[1] or "m"
    texts = [pos.x, pos.y] + ([pos.z] if pos.z is not None else [])
    z = read_length(pos.z) if pos.z is not None else 0.0
    return Position(read_length(pos.x), read_length(pos.y), z, unit, tuple(texts))


def orientation_of(orientation: Any) -> Orientation:
    """A parsed ``facing YAW`` or ``(roll, pitch, yaw)`` with units, in radians (none: the identity)."""
    if orientation is None:
        return Orientation()
    unit = quantity_parts(orientation.yaw)[1] or "rad"
    if orientation.__class__.__name__ == "Facing":
        return Orientation(0.0, 0.0, read_angle(orientation.yaw), unit, (orientation.yaw,))
    texts = (orientation.roll, orientation.pitch, orientation.yaw)
    roll, pitch, yaw = (read_angle(t) for t in texts)
    return Orientation(roll, pitch, yaw, unit, texts)
