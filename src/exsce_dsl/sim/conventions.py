"""The conventions the executor writes a robot's topics in, one record each, looked up by name.

The names are those of :mod:`exsce_dsl.model.conventions` (``method``, ``nav2``, ``move_base``):
a bag written in a convention is read back through that convention's :class:`Signals`.  The
executor writes each convention's standard topics; a robot type's overridden sources are for
reading bags, not for writing them.  Adding a convention is adding a record here and its module.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from exsce_dsl.errors import ExsceError
from exsce_dsl.model.conventions import Signals
from exsce_dsl.sim import move_base_topics, nav2_topics
from exsce_dsl.sim.messages import navigation_typestore, typestore
from exsce_dsl.sim.method_topics import method_messages
from exsce_dsl.sim.writing import RobotWriter


@dataclass(frozen=True)
class ConventionWriter:
    """How the executor writes the robots of one convention."""

    name: str
    messages: RobotWriter
    """Every message of one robot."""
    typestore: Callable[[str], Any]
    """The rosbags typestore for a bag format (``ros1``, ``ros2``, ``mcap``)."""
    latched: tuple[str, ...] = ()
    """Topics (under the robot's namespace) recorded as latched."""


WRITERS: dict[str, ConventionWriter] = {
    w.name: w
    for w in (
        ConventionWriter("method", method_messages, typestore),
        ConventionWriter("nav2", nav2_topics.nav2_messages, navigation_typestore, nav2_topics.LATCHED),
        ConventionWriter(
            "move_base", move_base_topics.move_base_messages, navigation_typestore, move_base_topics.LATCHED
        ),
    )
}


def convention_writer(convention: Signals | str) -> ConventionWriter:
    """The writer of a convention, given by name or as a robot type's :class:`Signals`."""
    name = convention.convention if isinstance(convention, Signals) else convention
    if name not in WRITERS:
        raise ExsceError(f"unknown convention '{name}'; the executor writes {', '.join(WRITERS)}")
    return WRITERS[name]
