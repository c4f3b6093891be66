"""What the signals step reads of a bag the bags step opened: the topics wanted, on one timeline.

Analysis opens a bag once (:func:`~exsce_dsl.runs.bags.reading.open_bag`: its topics from its
index) and detects the robots' conventions from those topics; what the conventions and the
metrics want of it is then read here (with the stamps the timeline needs), the run's timeline
decided from what was read, and every series put on it (:mod:`~exsce_dsl.runs.signals.timeline`).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

from exsce_dsl.runs.bags.data import BagData, Check, Reduce, Wanted
from exsce_dsl.runs.bags.reading import OpenedBag
from exsce_dsl.runs.signals.timeline import (
    Timeline,
    decide_timeline,
    on_timeline,
    stamp_catalogue,
    with_stamps,
)


@dataclass(frozen=True)
class OnTimeline:
    """A bag's wanted topics as recorded (log time), the run's timeline, and the topics on it."""

    recorded: BagData
    timeline: Timeline
    data: BagData


def read_on_timeline(
    bag: OpenedBag, wanted: Mapping[str, Wanted], reduce: Mapping[str, Reduce], check: Check
) -> OnTimeline:
    """Read ``wanted`` of ``bag`` (``reduce`` and ``check`` as
    :func:`~exsce_dsl.runs.bags.reading.read_bag` takes them) and the stamps of its topics that
    have them (:func:`with_stamps`), then put it on the run's timeline."""
    recorded = bag.read(with_stamps(wanted, bag.topics, stamp_catalogue()), reduce, check)
    timeline = decide_timeline(recorded)
    return OnTimeline(recorded, timeline, on_timeline(recorded, timeline))
