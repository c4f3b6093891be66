"""Why a message definition a bag carries does not parse, in words (the file checks raise
:class:`~exsce_dsl.errors.FileProblem` with it)."""

from __future__ import annotations

from rosbags.typesys import TypesysError, get_types_from_idl, get_types_from_msg

from exsce_dsl.runs.bags.mcap_index import IDL_SEPARATOR


def unparsed(msgtype: str, definition: str, topics: list[str], encoding: str) -> str | None:
    """Why the message definition (``msg`` or ``idl``) a bag carries for ``msgtype`` does not
    parse; None if it does (or if there is none: the reader then takes the type from a typestore)."""
    if not definition.strip():
        return None
    name = msgtype if "/msg/" in msgtype else msgtype.replace("/", "/msg/", 1)
    try:
        if encoding == "msg":
            get_types_from_msg(definition, name)
        elif definition.startswith(f"{IDL_SEPARATOR}IDL: "):  # several IDL files, each under its name
            for part in definition.split(IDL_SEPARATOR)[1:]:
                get_types_from_idl(part.split("\n", 1)[1])
        else:
            get_types_from_idl(definition)
    except (TypesysError, IndexError, ValueError) as exc:
        return (
            f"the message definition of {name} ({_topics(topics)}) that the bag carries does not parse"
            f"{_where(str(exc))}: the bag was written with a broken definition"
        )
    return None


def _topics(topics: list[str]) -> str:
    if not topics:
        return "no topic"
    return f"topic {topics[0]}" if len(topics) == 1 else f"topics {', '.join(topics)}"


def _where(error: str) -> str:
    """`` near '...'``: the text rosbags' parser stopped at (its error gives the offset, then the rest)."""
    lines = error.splitlines()
    for k, line in enumerate(lines[:-1]):
        rest = lines[k + 1].strip()
        if line.strip().isdigit() and rest:
            return f" near '{rest[:60]}'"
    return ""
