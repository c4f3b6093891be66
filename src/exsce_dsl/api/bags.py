"""What bags hold, before any specification is written (``exscec bag info``)."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from exsce_dsl.runs import BagInfo, bag_info_of


def describe_bags(bags: Sequence[str | Path]) -> list[BagInfo]:
    """``exscec bag info``: each bag's format, size, time span, topics (type, where the type's
    definition comes from, messages, rate, the clock of its stamps), TF tree, navigation goals and
    the convention ingestion would detect per namespace."""
    return [bag_info_of(Path(b)) for b in bags]
