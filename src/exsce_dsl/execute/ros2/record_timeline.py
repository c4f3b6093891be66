"""Where a recorded message goes on simulated time: when it was published, not when it was taken.

A recorder on ``/clock`` (``use_sim_time``) that stamps each message with the time it took it
puts a gap into the recording wherever the recorder itself fell behind: after a stall of 0.1 s of
wall time, what was published meanwhile is taken at once, and at a speed-up of 5 a 20 Hz topic
shows half a second without a message, which makes a run inconclusive for a stall of the
recorder, not of the robot.  So on simulated time each message is placed by its DDS source
timestamp (when its publisher sent it, on this machine's clock) on the timeline of ``/clock``
itself: it gets the simulated time of the last ``/clock`` message sent no later than it.  A
message is written once a ``/clock`` sent after it has arrived (its time is then known), in the
order the messages were sent.  On the wall clock (no ``/clock``) the recorder keeps rosbag2's
time of receipt.
"""

from __future__ import annotations

import bisect
import heapq
import struct
from collections.abc import Iterator

CLOCK = "/clock"


def clock_nanoseconds(data: bytes) -> int:
    """The time a serialized ``rosgraph_msgs/msg/Clock`` carries (CDR: a 4-byte encapsulation
    header, whose second byte says little-endian, then ``int32 sec``, ``uint32 nanosec``)."""
    layout = "<iI" if data[1] == 1 else ">iI"
    sec, nanosec = struct.unpack(layout, data[4:12])
    return int(sec) * 1_000_000_000 + int(nanosec)


class SimTimeline:
    """``/clock``'s messages by when they were sent, and the messages waiting for their time."""

    def __init__(self) -> None:
        self.sent: list[int] = []
        """Source timestamps of the ``/clock`` messages taken, in order."""
        self.times: list[int] = []
        """The simulated time each of them carries."""
        self._waiting: list[tuple[int, int, str, bytes]] = []
        self._count = 0

    def add(self, topic: str, data: bytes, sent: int) -> None:
        """A message taken, sent at ``sent`` (its source timestamp, ns)."""
        heapq.heappush(self._waiting, (sent, self._count, topic, data))
        self._count += 1
        if topic == CLOCK:
            at = bisect.bisect_right(self.sent, sent)
            self.sent.insert(at, sent)
            self.times.insert(at, clock_nanoseconds(data))

    @property
    def waiting(self) -> int:
        return len(self._waiting)

    def ready(self, final: bool = False) -> Iterator[tuple[str, bytes, int | None]]:
        """The messages whose time is known (sent no later than the last ``/clock`` taken; with
        ``final``, every one: the last ``/clock`` is the best there is), in the order they were
        sent, with their simulated time (None: sent before the first ``/clock``)."""
        limit = self.sent[-1] if self.sent else None
        while self._waiting and (final or (limit is not None and self._waiting[0][0] <= limit)):
            sent, _, topic, data = heapq.heappop(self._waiting)
            at = bisect.bisect_right(self.sent, sent) - 1
            yield topic, data, self.times[at] if at >= 0 else None

    @property
    def first(self) -> int | None:
        """The simulated time of the first ``/clock`` (where what was latched before it goes)."""
        return self.times[0] if self.times else None
