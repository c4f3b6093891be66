"""What a convention's writer is given for one robot, and what it gives back.

A writer turns one robot's part of an :class:`~exsce_dsl.sim.executor.SimulatedExecution` into
messages, ``(topic, type, stamp in ns, message value)``, in any order: the bag writer sorts them.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass
from typing import Any

import numpy as np

from exsce_dsl.maps.planning import PlanningGrid
from exsce_dsl.sim.batches import Batch
from exsce_dsl.sim.executor import SimulatedExecution
from exsce_dsl.sim.laser import Laser

Message = tuple[str, str, int, Any]
"""(topic, message type, stamp in ns, message value built in the run's typestore)."""


@dataclass(frozen=True)
class RobotRun:
    """One robot of one run, as a convention's writer sees it."""

    store: Any
    """The rosbags typestore of the bag's format (ROS 1 or ROS 2 definitions)."""
    robot: str
    namespace: str
    """Without slashes; ``""``: the robot's topics are at the root."""
    execution: SimulatedExecution
    grid: PlanningGrid
    laser: Laser
    rng: np.random.Generator
    start_ns: int
    twist_stamped: bool = False
    """Velocity commands as ``TwistStamped`` (Nav2 from Jazzy on) instead of ``Twist``."""

    def topic(self, name: str) -> str:
        """``/ns/name``; ``/name`` for a robot at the root."""
        return f"/{self.namespace}/{name}" if self.namespace else f"/{name}"


RobotWriter = Callable[[RobotRun], Iterator[Message | Batch]]
"""A convention's writer: every message of one robot, one at a time or in batches of one topic."""
