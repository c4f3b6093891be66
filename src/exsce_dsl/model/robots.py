"""Robot types (hardware facts) and the robots of a scenario's fleet."""

from __future__ import annotations

from dataclasses import dataclass, field

from exsce_dsl.errors import SourceLocation
from exsce_dsl.model.conventions import METHOD, Signals
from exsce_dsl.model.geometry import Pose


@dataclass(frozen=True)
class RobotType:
    """Hardware facts that similarity uses (unknown facts are ``None``), and where the robot's
    signals are in its bags (``None``: the method's convention, as the robot type did not say)."""

    id: str
    base: str | None = None
    torso: bool | None = None
    location: SourceLocation | None = field(default=None, compare=False, repr=False)
    declared_signals: Signals | None = None
    motion: str = "planar"
    """``planar`` (ground robots: path lengths in x-y) or ``3d`` (drones: in x-y-z)."""

    @property
    def signals(self) -> Signals:
        return self.declared_signals or METHOD


def root_namespace(namespace: str) -> str:
    """A namespace as written; ``/`` (like ``""``) is the root, where a single robot's topics
    often are (``/odom``, not ``/robot1/odom``), and is kept as ``""``."""
    return "" if namespace.strip("/") == "" else namespace


@dataclass(frozen=True)
class Robot:
    id: str
    type: RobotType
    namespace: str
    """The robot's ROS namespace; ``""``: its topics are at the root."""
    start_pose: Pose | None = None
    location: SourceLocation | None = field(default=None, compare=False, repr=False)
    declared_signals: Signals | None = None
    """Where this robot's signals are, when it says otherwise than its type."""

    @property
    def signals(self) -> Signals:
        return self.declared_signals or self.type.signals

    @property
    def declares_signals(self) -> bool:
        """Whether the robot or its type says where its signals are (else: the method's topics)."""
        return self.declared_signals is not None or self.type.declared_signals is not None

    @property
    def names_convention(self) -> bool:
        """Whether the robot or its type names its convention (else ingestion detects it)."""
        return self.declares_signals and self.signals.named

    @property
    def three_d(self) -> bool:
        """Whether the robot moves in 3-D (its type says ``motion 3d``)."""
        return self.type.motion == "3d"
