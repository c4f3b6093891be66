"""ROS message fields as a metric sees them: field trees, and paths into them.

A message type's fields form a tree (:data:`Fields`): a leaf is a number, an
array of numbers, text or an array of texts; an inner node is a sub-message; an
array of sub-messages is a :class:`MessageArray`.  Where a type's definition
comes from (the bag, rosbags' typestores, the user's ``.msg`` files) is the
business of :mod:`exsce_dsl.messages`; this module only describes shapes.

A :class:`FieldPath` names what a metric reads of a message: field names, an
element of an array (``status_list[0]``, ``ranges[-1]``), the element of an
array of messages whose field has a value (``transforms[child_frame_id ==
"base_link"]``), or the length of an array (``len(status_list)``).  Its
:attr:`FieldPath.key` is the one text by which the bag reader, the monitors
and the formatter know it.  ROS 1 and ROS 2 names of a type are one
(``geometry_msgs/Twist`` is ``geometry_msgs/msg/Twist``).  A robot's goals
signal, and the waypoint dispatcher's feedback and result read as topics, are
read as windows and successes (``elapsed``, ``succeeded``), not field by field.
"""

from __future__ import annotations

import enum
import json
from dataclasses import dataclass
from typing import Union


class Leaf(enum.Enum):
    NUMBER = "a number"
    ARRAY = "an array of numbers"
    TEXT = "text"
    TEXTS = "an array of texts"


@dataclass(frozen=True)
class MessageArray:
    """An array of sub-messages (``transforms`` of a ``tf2_msgs/msg/TFMessage``)."""

    element: Fields
    length: int | None = None
    """The fixed length of the array, None for a sequence."""


Node = Union[Leaf, MessageArray, "Fields"]
Fields = dict[str, Node]

FEEDBACK = "waypoint_dispatcher/msg/FollowWaypointsActionFeedback"
RESULT = "waypoint_dispatcher/msg/FollowWaypointsActionResult"
DISPATCHER = (FEEDBACK, RESULT)
"""Read whole by the run's segmentation; a metric uses them through ``elapsed`` and ``succeeded``."""
GOALS = "exsce_msgs/msg/RobotGoals"
"""What a robot's goals signal (``reads goals: robot goals``) is taken for: no message of any bag,
and no fields; a metric uses it through ``elapsed`` and ``succeeded``."""
WINDOWS = (*DISPATCHER, GOALS)
"""The types read as windows and successes, never field by field."""


@dataclass(frozen=True)
class Index:
    """``[3]`` or ``[-1]``: one element of an array (counted from the end when negative)."""

    position: int

    def text(self) -> str:
        return f"[{self.position}]"


@dataclass(frozen=True)
class Select:
    """``[child_frame_id == "base_link"]``: the first element of an array of messages whose
    field (a path of names) equals ``value``."""

    field: tuple[str, ...]
    value: str | float

    def text(self) -> str:
        value = json.dumps(self.value) if isinstance(self.value, str) else _number(self.value)
        return f"[{'.'.join(self.field)} == {value}]"


Step = str | Index | Select


@dataclass(frozen=True)
class FieldPath:
    """What a metric reads of one message: ``steps`` from the message's top, or their ``length``."""

    steps: tuple[Step, ...]
    length: bool = False

    @property
    def key(self) -> str:
        """The path's one text: ``pose.pose.position.x``, ``transforms[child_frame_id ==
        "base_link"].transform.translation.x``, ``len(status_list)``."""
        text = ""
        for step in self.steps:
            if isinstance(step, str):
                text += f".{step}" if text else step
            else:
                text += step.text()
        return f"len({text})" if self.length else text

    @property
    def names(self) -> tuple[str, ...]:
        """The field names along the path, without indices and selections."""
        return tuple(s for s in self.steps if isinstance(s, str))

    @property
    def picks(self) -> bool:
        """Whether the path picks elements of arrays, so that a message may have no value."""
        return any(not isinstance(s, str) for s in self.steps)


def path_of(*names: str) -> FieldPath:
    """A path of plain field names: ``path_of("linear", "x")``."""
    return FieldPath(tuple(names))


def canonical_type(name: str) -> str:
    """``pkg/Type`` and ``pkg/msg/Type`` are one type; the ROS 2 spelling is kept."""
    package, _, rest = name.partition("/")
    return name if "/" in rest else f"{package}/msg/{rest}"


OLD_NAMES = {"tf/msg/tfMessage": "tf2_msgs/msg/TFMessage"}
"""Types that ROS renamed without changing a field: the old name (ROS 1's ``tf``, recorded by
``tf::TransformBroadcaster`` before tf2) → the type exsce reads it as.  Each is decoded by its own
definition from the bag; only what it is taken for changes."""


def standard_type(name: str) -> str:
    """:func:`canonical_type`, with an old name of a type (:data:`OLD_NAMES`) as its new one."""
    canonical = canonical_type(name)
    return OLD_NAMES.get(canonical, canonical)


def _number(value: float) -> str:
    return str(int(value)) if float(value).is_integer() else repr(float(value))
