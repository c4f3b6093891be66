"""What an id may look like, the same rule the grammar's ``Name`` uses.

Every id that reaches an IRI, a file path or generated code passes through
here, so the grammar and the importers agree on it.
"""

from __future__ import annotations

import re

#: Words of the language that cannot be ids (also those reserved for
#: acceptance criteria, metrics and derivations).  Keep in step with
#: ``grammar/common.tx``; a test checks that they agree.
KEYWORDS: frozenset[str] = frozenset(
    """import robot type base torso yes no environment map world from package path
    file area pose at facing rpy obstacle size model task subtask visit source scenario
    in robots namespace starts mission parallel sequential does then acceptance feature
    given when and but each stays below above is increasing decreasing invariant within
    std of baseline by before after during derive remove add swap reverse substitute
    replace reassign move metric oracle relation monitor topic for least its reaches
    around""".split()
)

NUMBER = re.compile(r"[-+]?(\d+\.\d*|\.\d+|\d+)([eE][-+]?\d+)?")
"""A number as the language writes it."""

NAME_PATTERN = r"[A-Za-z_][A-Za-z0-9_]*(?:-[A-Za-z0-9_]+)*"
_NAME_RE = re.compile(NAME_PATTERN)


def is_valid_name(text: str) -> bool:
    """True if ``text`` can be written as an id in the DSL."""
    return bool(_NAME_RE.fullmatch(text)) and text not in KEYWORDS


_ROS_NAMESPACE = re.compile(r"(/?[A-Za-z][A-Za-z0-9_]*(/[A-Za-z][A-Za-z0-9_]*)*)?")


def is_ros_namespace(text: str) -> bool:
    """True if ``text`` is a ROS namespace a robot may have (``""``: the root)."""
    return bool(_ROS_NAMESPACE.fullmatch(text))


_NOT_IN_TOPICS = re.compile(r'[\s"\\{}]')
TOPIC_RULE = "any characters but spaces, quotes, backslashes and braces; '{ns}' for the robot's namespace"
"""What :func:`is_topic_pattern` takes, for error messages."""


def is_topic_pattern(text: str) -> bool:
    """True if ``text`` names a topic as a bag may hold it, ``{ns}`` standing for a robot's
    namespace: ROS names (``/tiago1/odom``, relative ``groundtruth``) and the names recorders write
    that ROS 2 would refuse (``ORB-SLAM``, non-ASCII); not one empty or of slashes only, nor one
    with spaces, quotes, backslashes or braces other than ``{ns}`` (which the language's strings
    and the generated monitors could not hold as they are)."""
    rest = text.replace("{ns}", "")
    return bool(text.replace("/", "")) and text.isprintable() and not _NOT_IN_TOPICS.search(rest)


_ROS_TOPIC = re.compile(r"/?[A-Za-z_][A-Za-z0-9_]*(?:/[A-Za-z_][A-Za-z0-9_]*)*")
ROS_TOPIC_RULE = "names of letters, digits and '_', not starting with a digit, separated by '/', no '__'"
"""What :func:`is_ros_topic` takes, for error messages."""


def is_ros_topic(topic: str) -> bool:
    """True if a ROS 1 or ROS 2 node may subscribe to ``topic``: the rule of the ROS monitor
    generators, which ``check`` applies too.  ``{ns}`` stands for a robot's namespace (itself
    checked by :func:`is_ros_namespace`); an empty level left by a robot at the root is no level.
    Stricter than :func:`is_topic_pattern`: a bag may hold names ROS refuses (``ORB-SLAM``)."""
    name = topic.replace("{ns}", "ns")
    while "//" in name:
        name = name.replace("//", "/")
    return bool(_ROS_TOPIC.fullmatch(name)) and "__" not in name
