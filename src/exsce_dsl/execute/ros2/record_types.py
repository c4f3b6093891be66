"""What the ROS 2 recorder writes of a topic besides its messages: the type's definition and hash,
the QoS it subscribes with and the QoS its publishers offer.

A type is described from exsce's typestore (rosbags' ROS 2 Jazzy store with the navigation
stacks' types, :func:`exsce_dsl.messages.navigation.register_navigation_types`), and the
description is checked against the type hash (RIHS01) the publishers advertise on the graph.
When the store lacks the type, or its hash is not the advertised one (another distro's
definition), the type is described from the ``.msg`` files installed with its package
(``share/<pkg>/msg/<Name>.msg`` under ``$AMENT_PREFIX_PATH`` and the Python environment), and
that description must hash as advertised too.  A type described by neither is an error naming it:
a bag never carries a definition that does not decode its messages.

The QoS is rosbag2's adaptive one: reliable if every publisher offers reliable, else best effort;
transient local if every publisher offers it (latched topics: ``tf_static``, exsce's PROV), so
that what was published before the recorder joined is recorded too; a deep history.
"""

from __future__ import annotations

import functools
import importlib
import os
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from rosbags.interfaces import Qos, QosDurability, QosHistory, QosLiveliness, QosReliability, QosTime
from rosbags.typesys import Stores, get_types_from_msg, get_typestore
from rosbags.typesys.store import Typestore

from exsce_dsl.errors import RosGraphError
from exsce_dsl.messages.catalogue import ARRAY, NAME, SEQUENCE
from exsce_dsl.messages.navigation import register_navigation_types, ros2_message_definition

DEPTH = 1000
"""The recorder's history depth: deep enough that no message waits out of it at the usual rates."""
UNKNOWN_HASHES = frozenset({"", "RIHS01_" + "0" * 64})
"""What a publisher advertises when its middleware does not say its type's hash."""


@functools.lru_cache(maxsize=1)
def recorder_typestore() -> Typestore:
    """ROS 2 Jazzy's standard types with the navigation stacks' (``nav2_msgs``' feedback...)."""
    store = get_typestore(Stores.ROS2_JAZZY)
    register_navigation_types(store)
    return store


def describe_type(msgtype: str, advertised: Sequence[str]) -> tuple[str, str, str]:
    """``(definition, rihs01, where from)`` of ``msgtype`` as a rosbag2 bag carries them;
    ``advertised``: the hashes its publishers advertise.  :class:`RosGraphError` when neither
    the typestore nor the installed ``.msg`` files describe it with the advertised hash."""
    hashes = {h for h in advertised if h not in UNKNOWN_HASHES}
    if len(hashes) > 1:
        raise RosGraphError(f"the publishers of {msgtype} advertise different type hashes: {sorted(hashes)}")
    store = recorder_typestore()
    tried: list[str] = []
    if msgtype in store.fielddefs:
        rihs01 = store.hash_rihs01(msgtype)
        if not hashes or rihs01 in hashes:
            return _definition(store, msgtype), rihs01, "exsce's typestore (ROS 2 Jazzy)"
        tried.append(f"exsce's typestore has {rihs01}")
    installed = installed_typestore(msgtype)
    if installed is not None:
        rihs01 = installed.hash_rihs01(msgtype)
        if not hashes or rihs01 in hashes:
            return _definition(installed, msgtype), rihs01, "its installed .msg files"
        tried.append(f"its installed .msg files give {rihs01}")
    else:
        tried.append("no installed .msg files of it were found")
    wanted = f"advertised hash {next(iter(hashes))}" if hashes else "no advertised hash"
    raise RosGraphError(f"cannot describe the message type {msgtype} ({wanted}): {'; '.join(tried)}")


def _definition(store: Typestore, msgtype: str) -> str:
    if "/action/" in msgtype:  # rosbags' generator writes no definition of pkg/action/ types
        return ros2_message_definition(store, msgtype)
    text: str = store.generate_msgdef(msgtype, ros_version=2)[0]
    return text


def share_folders() -> list[Path]:
    """Where installed ROS 2 packages keep their interface files: ``$AMENT_PREFIX_PATH``'s
    prefixes (a sourced distro, a workspace), then this Python environment's (PyPI's wheels)."""
    prefixes = [p for p in os.environ.get("AMENT_PREFIX_PATH", "").split(os.pathsep) if p]
    return [Path(p) / "share" for p in dict.fromkeys([*prefixes, sys.prefix])]


def installed_typestore(msgtype: str) -> Typestore | None:
    """A typestore of ``msgtype`` and every type it needs, read from installed ``.msg`` files;
    None when one of them has none (an action's types have no ``.msg`` file of their own)."""
    types: dict[str, Any] = {}
    pending = [msgtype]
    while pending:
        name = pending.pop()
        if name in types:
            continue
        package, kind, short = name.split("/")
        files = (share / package / kind / f"{short}.msg" for share in share_folders())
        found = next((f for f in files if f.is_file()), None)
        if found is None:
            return None
        parsed = get_types_from_msg(found.read_text(encoding="utf-8"), name)
        types.update(parsed)
        pending += [n for n in _needed(parsed[name][1]) if n not in types]
    store = get_typestore(Stores.EMPTY)
    store.register(types)
    return store


def _needed(fields: list[tuple[str, Any]]) -> list[str]:
    """The message types the fields of a parsed definition name (in arrays and sequences too)."""
    found = []
    for _, desc in fields:
        while int(desc[0]) in (ARRAY, SEQUENCE):  # (element, length)
            desc = desc[1][0]
        if int(desc[0]) == NAME:
            found.append(str(desc[1]))
    return found


def message_class(msgtype: str) -> Any:
    """The Python class of ``pkg/kind/Name`` (``pkg.kind`` module); an action's own message types
    (``nav2_msgs/action/NavigateToPose_FeedbackMessage``) are its ``Impl``'s.  None if not installed."""
    package, kind, name = msgtype.split("/")
    try:
        module = importlib.import_module(f"{package}.{kind}")
    except ImportError:
        return None
    found = getattr(module, name, None)
    if found is None and "_" in name:
        action, part = name.rsplit("_", 1)
        owner = getattr(module, action, None)
        impl = getattr(owner, "Impl", None)
        found = getattr(impl, part, None) or getattr(owner, part, None)
    return found


def _time(nanoseconds: int) -> QosTime:
    sec, nsec = divmod(int(nanoseconds), 1_000_000_000)
    return QosTime(sec, nsec)


def offered_qos(profile: Any) -> Qos:
    """A publisher's offered QoS (rclpy's ``QoSProfile``) as rosbags writes it into metadata.yaml."""
    return Qos(
        history=QosHistory(int(profile.history)),
        depth=int(profile.depth),
        reliability=QosReliability(int(profile.reliability)),
        durability=QosDurability(int(profile.durability)),
        deadline=_time(profile.deadline.nanoseconds),
        lifespan=_time(profile.lifespan.nanoseconds),
        liveliness=QosLiveliness(int(profile.liveliness)),
        liveliness_lease_duration=_time(profile.liveliness_lease_duration.nanoseconds),
        avoid_ros_namespace_conventions=bool(profile.avoid_ros_namespace_conventions),
    )


def adapted_qos(offered: Sequence[Qos]) -> tuple[bool, bool]:
    """``(reliable, transient_local)`` the recorder asks for, given what the publishers offer."""
    reliable = bool(offered) and all(q.reliability == QosReliability.RELIABLE for q in offered)
    latched = bool(offered) and all(q.durability == QosDurability.TRANSIENT_LOCAL for q in offered)
    return reliable, latched
