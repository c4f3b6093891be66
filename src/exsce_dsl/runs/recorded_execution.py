"""The execution a bag's run-time PROV records: read from inside the bag first, beside it second.

The dispatcher publishes its run-time PROV on :data:`~exsce_dsl.runs.coverage.PROV_TOPIC`
(``exscec execute`` records it in the bag, updated as goals end: the last message that holds a
run of the scenario wins); ``exscec simulate`` and ``execute`` also write it beside the bag as
``<bag's stem>.prov.json``.  Ingestion keeps what it says with the run
(:attr:`~exsce_dsl.model.runs.Run.execution`), so that the store ties the dispatcher's run to
the ingested one (:mod:`exsce_dsl.prov.run_execution`).
"""

from __future__ import annotations

from collections.abc import Iterable
from pathlib import Path
from typing import Any

from exsce_dsl.model.executions import Execution
from exsce_dsl.prov.run_execution import parse_document, read_execution
from exsce_dsl.runs.coverage import PROV_TOPIC

__all__ = ["prov_file_beside", "recorded_execution"]


def prov_file_beside(bag: Path) -> Path:
    """``<bag's stem>.prov.json`` beside ``bag`` (a ROS 2 bag folder: ``<folder>.prov.json``)."""
    return bag.with_name(bag.stem + ".prov.json") if bag.suffix else bag.with_name(bag.name + ".prov.json")


def recorded_execution(
    bag: Path, scenario: str, published: Iterable[tuple[float, Any]] = ()
) -> Execution | None:
    """The execution of scenario ``scenario`` that the run-time PROV recorded with ``bag`` says:
    the last of the messages the bag holds on :data:`PROV_TOPIC` (``published``: (time,
    std_msgs/String)) that holds one, else the ``.prov.json`` beside the bag; None without
    either (or when they are about another scenario's run)."""
    for _, message in reversed(list(published)):
        found = read_execution(parse_document(str(getattr(message, "data", ""))), PROV_TOPIC, scenario)
        if found is not None:
            return found
    beside = prov_file_beside(bag)
    try:
        text = beside.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError):
        return None
    return read_execution(parse_document(text), beside.name, scenario)
