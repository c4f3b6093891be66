"""Whose clock went back: stamps judged per publisher, a reset only when every one goes back.

A topic's stamps come from its publishers' clocks, and TF's from several nodes at once: on a Nav2
robot the controller's ``odom → base_footprint`` stamped at about log time and AMCL's ``map →
odom`` post-dated by its transform tolerance (up to seconds ahead), interleaved on ``/tf``.  Read
as one series, those stamps "go back" dozens of times a second, and no clock did.  So stamps are
judged per publisher (a :class:`StampTrack`): per edge (parent → child) for TF, per connection
for every other stamped series (the readers keep each message's connection where a topic has
several: :attr:`~exsce_dsl.runs.bags.data.Series.publishers`).

A track whose stamps go back by more than the caller's tolerance is a finding about that
publisher (:func:`first_back`), never a reason to leave samples out.  A reset of the clock is
``/clock`` going back (:mod:`~exsce_dsl.runs.signals.timeline` reads that), or every stamped track
recorded at that moment going back together (:func:`resets`): a simulation restarted under a
recorder that did not record ``/clock``.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from exsce_dsl.runs.bags.data import Series
from exsce_dsl.runs.bags.decode import TEXTS

TOGETHER = 1.0
"""Seconds of log time within which publishers going back are one reset (a slow publisher's
next message may come later: each track is also given two of its periods)."""

_PARENT, _CHILD = "transforms.header.frame_id", "transforms.child_frame_id"
_SEC, _NANOSEC = "transforms.header.stamp.sec", "transforms.header.stamp.nanosec"


@dataclass(frozen=True)
class StampTrack:
    """One publisher's stamps: its log times and stamps (seconds), in log-time order."""

    name: str
    """The topic, with the TF edge or the publisher it carries (``/tf (map → odom)``,
    ``/pose (/amcl)``)."""
    log: np.ndarray
    stamps: np.ndarray
    publisher: str = ""
    """The topic's publisher (connection) whose stamps these are; empty: the topic's only one, or
    a TF edge."""

    def period(self) -> float:
        """The median interval between its messages (inf with fewer than two)."""
        return float(np.median(np.diff(self.log))) if len(self.log) > 1 else float("inf")


@dataclass(frozen=True)
class Back:
    """A step back of one track's stamps: at log time ``at``, by ``back`` seconds."""

    track: str
    at: float
    back: float


def header_track(topic: str, log: np.ndarray, stamps: np.ndarray) -> StampTrack:
    """The track of a series with one stamp per message (its header's); unusable stamps left out."""
    known = np.isfinite(stamps) & (stamps > 0)
    return StampTrack(topic, log[known], stamps[known])


def header_tracks(series: Series, stamps: np.ndarray) -> list[StampTrack]:
    """One track per publisher (connection) of a series with one stamp per message: the series'
    own where it has a single publisher."""
    log = np.asarray(series.t, dtype=np.float64)
    if series.publishers is None:
        return [header_track(series.topic, log, stamps)]
    found = []
    for index, publisher in enumerate(series.publisher_names):
        mine = series.publishers == index
        track = header_track(f"{series.topic} ({publisher})", log[mine], stamps[mine])
        found.append(StampTrack(track.name, track.log, track.stamps, publisher))
    return found


def tf_tracks(series: Series) -> list[StampTrack]:
    """One track per TF edge (parent → child) of a TFMessage series: every transform's stamp at
    the log time of its message.  Without the frame names read: one track of every transform."""
    fields = series.fields
    if _SEC not in fields or _NANOSEC not in fields or not len(series):
        return []
    table = np.asarray(fields[_SEC] + fields[_NANOSEC] * 1e-9, dtype=np.float64).reshape(len(series), -1)
    log = np.repeat(np.asarray(series.t, dtype=np.float64), table.shape[1])
    stamps = table.ravel()
    known = np.isfinite(stamps) & (stamps > 0)
    texts = fields.get(TEXTS)
    if _PARENT not in fields or _CHILD not in fields or texts is None or not len(texts):
        return [StampTrack(series.topic, log[known], stamps[known])]
    parents = np.asarray(fields[_PARENT], dtype=np.float64).ravel()
    children = np.asarray(fields[_CHILD], dtype=np.float64).ravel()
    known &= np.isfinite(parents) & np.isfinite(children)
    pairs = parents[known].astype(np.int64) * len(texts) + children[known].astype(np.int64)
    log, stamps = log[known], stamps[known]
    found = []
    for pair in np.unique(pairs).tolist():
        parent, child = divmod(pair, len(texts))
        mine = pairs == pair
        name = f"{series.topic} ({texts[parent]} → {texts[child]})"
        found.append(StampTrack(name, log[mine], stamps[mine]))
    return found


def backs(track: StampTrack, tolerance: float) -> list[Back]:
    """Every step back of the track's stamps by more than ``tolerance`` seconds."""
    steps = np.diff(track.stamps)
    where = np.flatnonzero(steps < -tolerance)
    return [Back(track.name, float(track.log[i + 1]), float(-steps[i])) for i in where.tolist()]


def first_back(tracks: Sequence[StampTrack], tolerance: float) -> Back | None:
    """The earliest step back, by more than ``tolerance``, of any of ``tracks`` (one series')."""
    found = [b for t in tracks for b in backs(t, tolerance)[:1]]
    return min(found, key=lambda b: b.at) if found else None


def resets(tracks: Sequence[StampTrack], tolerance: float) -> list[tuple[Back, tuple[str, ...]]]:
    """Where every stamped track recorded at that moment went back together (a reset), and the
    tracks that did: each at the earliest of their steps back.  A track is recorded at a moment
    when it has messages before and after it; it went back with the others when one of its own
    steps back is within :data:`TOGETHER` (or two of its periods) of that moment."""
    stepped = {t.name: backs(t, tolerance) for t in tracks}
    times = {name: np.array([b.at for b in found]) for name, found in stepped.items()}
    candidates = sorted((b for found in stepped.values() for b in found), key=lambda b: b.at)
    found: list[tuple[Back, tuple[str, ...]]] = []
    for candidate in candidates:
        if found and candidate.at - found[-1][0].at <= TOGETHER:
            continue  # the same reset, seen from another track
        alive = [t for t in tracks if len(t.log) and t.log[0] < candidate.at <= t.log[-1]]
        near = [
            _near(stepped[t.name], times[t.name], candidate.at, max(TOGETHER, 2 * t.period())) for t in alive
        ]
        if alive and all(near):
            first = min((b for steps in near for b in steps), key=lambda b: b.at)
            found.append((first, tuple(sorted(t.name for t in alive))))
    return found


def _near(steps: list[Back], at: np.ndarray, moment: float, within: float) -> list[Back]:
    """The steps (their log times ``at``, sorted) within ``within`` seconds of ``moment``."""
    low = int(np.searchsorted(at, moment - within, side="left"))
    high = int(np.searchsorted(at, moment + within, side="right"))
    return steps[low:high]


def publishers_apart(
    tracks: Sequence[StampTrack], on_timeline: Callable[[np.ndarray], np.ndarray], tolerance: float
) -> dict[str, str]:
    """Of one series' publishers (tracks with a ``publisher``), those whose stamps cannot time
    their messages, and why: stamps that go back by more than ``tolerance``, none usable, or
    further than ``tolerance`` from the other publishers' (a node post-dating its messages).  The
    others' are those of the steady publisher nearest the timeline (``on_timeline``: log times
    onto it), so that a publisher sure of its clock is never judged by a late one."""
    named = [t for t in tracks if t.publisher]
    if len(named) < 2:
        return {}
    found = {t.publisher: f"{t.name} carries no usable stamps" for t in named if not len(t.log)}
    for track in named:
        step = backs(track, tolerance)[:1] if track.publisher not in found else []
        if step:
            back, at = step[0].back, step[0].at
            found[track.publisher] = (
                f"the stamps of {track.name} go back {back:.3f} s at log time {at:.3f} (by more than "
                f"{tolerance:g} s)"
            )
    steady = [t for t in named if t.publisher not in found]
    ahead = {t.publisher: float(np.median(t.stamps - on_timeline(t.log))) for t in steady}
    reference = min(ahead.values(), key=abs, default=0.0)
    for track in steady:
        apart = ahead[track.publisher] - reference
        if abs(apart) > tolerance:
            found[track.publisher] = (
                f"the stamps of {track.name} are {apart:+.3f} s from those of the topic's other "
                f"publishers (post-dated, or of another clock; by more than {tolerance:g} s)"
            )
    return found


def steady_stamps(
    tracks: Sequence[StampTrack], offset: float, tolerance: float
) -> tuple[np.ndarray, np.ndarray] | None:
    """The log times and stamps of a series' publishers that can time their messages, judged
    before there is a timeline (against the series' own median ``offset``, log time minus stamp):
    what a timeline made of stamps is made of.  None: every publisher can (or none)."""
    apart = publishers_apart(tracks, lambda log: log - offset, tolerance)
    kept = [t for t in tracks if t.publisher not in apart]
    if not apart or not kept:
        return None
    return np.concatenate([t.log for t in kept]), np.concatenate([t.stamps for t in kept])
