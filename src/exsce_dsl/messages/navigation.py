"""The navigation stacks' own message types (``nav2_msgs``, ``move_base_msgs``), shipped as
definitions because rosbags' typestores lack them.

The ``.msg`` files are package data, ``definitions/<pkg>/<msg|action>/<Name>.msg`` (a ROS 2 action's
message types are named ``pkg/action/Action_FeedbackMessage``); ``definitions/SOURCES.md`` says
which upstream file each restates, under which licence.
"""

from __future__ import annotations

import functools
from typing import TYPE_CHECKING, Any

from exsce_dsl.messages.catalogue import (
    ARRAY,
    BASE,
    NAME,
    SEQUENCE,
    MessageCatalogue,
    Source,
    parse_definition,
    standard_catalogue,
)
from exsce_dsl.resources import package_file

if TYPE_CHECKING:
    from importlib.resources.abc import Traversable

DEFINITIONS = ("messages", "definitions")
"""Where the definitions are inside the package."""

NEEDED_STANDARD = ("tf2_msgs/msg/TFMessage", "action_msgs/msg/GoalStatusArray")
"""Standard types a navigation stack publishes beside its own that a typestore may lack (rosbags'
ROS 1 store has neither ``tf2_msgs`` nor ROS 2's ``action_msgs``)."""


@functools.lru_cache(maxsize=1)
def navigation_catalogue() -> MessageCatalogue:
    """The packaged definitions of ``nav2_msgs`` and ``move_base_msgs``, each with its file as source."""
    catalogue = MessageCatalogue()
    for package in _folders(package_file(*DEFINITIONS)):
        for kind in _folders(package):
            for file in sorted(kind.iterdir(), key=lambda f: f.name):
                if not file.name.endswith(".msg"):
                    continue
                name = f"{package.name}/{kind.name}/{file.name.removesuffix('.msg')}"
                source = Source(f"exsce's packaged definition {package.name}/{kind.name}/{file.name}")
                found = parse_definition(file.read_text(encoding="utf-8"), name, "msg", source)
                catalogue.add(found.definitions, source)
    return catalogue


def register_navigation_types(typestore: Any) -> None:
    """Add the navigation types to a rosbags ``Typestore``, with every standard type they (and
    TF) need that the store lacks (``action_msgs``, ``unique_identifier_msgs``, ``tf2_msgs`` in
    a ROS 1 store).  Types the store has are kept; a ROS 1 store keeps ROS 2 action types under
    their ROS 1 names (see :func:`stored_name`)."""
    own = navigation_catalogue()
    known = own.layered(standard_catalogue())
    ros1 = is_ros1(typestore)
    types: dict[str, tuple[list[Any], list[tuple[str, Any]]]] = {}
    for root in (*sorted(own.definitions), *NEEDED_STANDARD):
        for name, (constants, fields) in known.needed(root).items():
            if ros1:
                name, fields = _ros1_name(name), [(f, _ros1_desc(d)) for f, d in fields]
            if name not in typestore.fielddefs and name not in types:
                types[name] = (constants, fields)
    typestore.register(types)


def stored_name(typestore: Any, msgtype: str) -> str:
    """The name a typestore keeps ``msgtype`` under: ROS 1 has no ``pkg/action/`` types, so a
    ROS 2 action's ``nav2_msgs/action/NavigateToPose_FeedbackMessage`` is
    ``nav2_msgs/msg/NavigateToPose_FeedbackMessage`` in a ROS 1 store (and bag)."""
    return _ros1_name(msgtype) if is_ros1(typestore) else msgtype


def ros2_message_definition(typestore: Any, msgtype: str) -> str:
    """The ``ros2msg`` text of ``msgtype`` and of every type it needs (``MSG:`` sections, in
    rosbags' order), as a ROS 2 bag carries it; unlike rosbags' generator it writes action
    types (``nav2_msgs/action/NavigateToPose_Feedback``), which rosbag2 itself leaves without one."""
    texts: dict[str, str] = {}
    main = _definition_text(typestore, msgtype, texts)
    return main + "".join(f"{'=' * 80}\nMSG: {_short(name)}\n{text}" for name, text in texts.items())


def _definition_text(typestore: Any, msgtype: str, texts: dict[str, str]) -> str:
    """The lines of one type; the types it needs go into ``texts``, each once, depth first."""
    lines = [f"{typ} {constant}={value}" for constant, typ, value in typestore.fielddefs[msgtype][0]]
    for field, desc in typestore.fielddefs[msgtype][1]:
        if field != "structure_needs_at_least_one_member":
            lines.append(f"{_written(typestore, desc, texts)} {field}")
    return "\n".join([*lines, ""])


def _written(typestore: Any, desc: Any, texts: dict[str, str]) -> str:
    """A field's type as a ``.msg`` file writes it."""
    kind, detail = int(desc[0]), desc[1]
    if kind == BASE:
        return f"string<={detail[1]}" if detail[0] == "string" and detail[1] else str(detail[0])
    if kind == NAME:
        if detail not in texts:
            texts[detail] = ""
            texts[detail] = _definition_text(typestore, detail, texts)
        return _short(detail)
    element, length = detail
    count = "" if length == 0 else str(length) if kind == ARRAY else f"<={length}"
    return f"{_written(typestore, element, texts)}[{count}]"


def _short(msgtype: str) -> str:
    """``pkg/msg/Name`` is written ``pkg/Name``; ``pkg/action/Name`` keeps its ``action``."""
    package, kind, name = msgtype.split("/")
    return f"{package}/{name}" if kind == "msg" else msgtype


def is_ros1(typestore: Any) -> bool:
    """Whether a typestore holds ROS 1's definitions (its ``std_msgs/Header`` has a ``seq``)."""
    return any(name == "seq" for name, _ in typestore.fielddefs["std_msgs/msg/Header"][1])


def _ros1_name(msgtype: str) -> str:
    package, kind, name = msgtype.split("/")
    return f"{package}/msg/{name}" if kind == "action" else msgtype


def _ros1_desc(desc: Any) -> Any:
    kind, detail = int(desc[0]), desc[1]
    if kind == NAME:
        return (desc[0], _ros1_name(detail))
    if kind in (ARRAY, SEQUENCE):
        return (desc[0], (_ros1_desc(detail[0]), detail[1]))
    return desc


def _folders(parent: Traversable) -> list[Traversable]:
    return sorted((f for f in parent.iterdir() if f.is_dir()), key=lambda f: f.name)
