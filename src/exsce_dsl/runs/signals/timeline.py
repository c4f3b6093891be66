"""One timeline per run: which clock each series of a bag carries, and how it goes onto the run's.

A bag holds two clocks.  Every message has the recorder's **log time** (the wall clock of the
machine that recorded).  Many also carry **stamps** (a header's, a TF transform's) from the clock
of the node that published them: the same wall clock, give or take latency, on a real robot; the
**simulated clock** when the robot ran with ``use_sim_time`` (Gazebo, Isaac: a few hundred
seconds, while log time says 2026).  A series timed by one clock never overlaps a window cut on
the other, so everything is put on one timeline before any window is cut:

- The run's timeline is the robots' own clock: simulated time when ``/clock`` was recorded or the
  stamps are far (:data:`OTHER_CLOCK`) from their log times, else the wall clock.  Durations are
  then the robots' (a simulation running at half speed does not make a task twice as long).
- A series whose messages carry usable stamps of the timeline's clock is timed by them, if they
  are finer than its rate (else, a driver stamping whole seconds at 27 Hz, by its log times, said
  in a note).
- Every other series (no header, such as a Twist or a goal status array; or stamps of another
  clock) is timed by its log times, mapped onto the timeline: through ``/clock`` where it was
  recorded (each ``/clock`` message pairs a log time with a simulated time), else through the
  offset between the stamped series' stamps and their log times, per stretch of
  :data:`STRETCH` seconds (so a real-time factor that is not 1 is followed too).
- A stamped series whose stamps are a constant offset from its log times (a computer whose clock
  is not synchronised) on a wall-clock run is moved by that offset, and a note says so.

What cannot be reconciled is said: a ``/clock`` that goes back (the simulation was reset during
the recording) is a :class:`ClockJump`: the timeline follows ``/clock`` up to the jump and goes
on at its last rate after it (so every series stays in order), and the run's coverage says that
nothing from the jump on is on one timeline.  Stamps are judged per publisher
(:mod:`~exsce_dsl.runs.signals.stamp_tracks`: per edge for TF, whose edges come from several
nodes; per connection for every other topic): of a topic's several publishers, one whose stamps
go back by more than :data:`SAME_CLOCK`, or stand that far apart from the others' (post-dated),
has its messages timed by their log times, with a note; a TF edge or a topic's only publisher
whose stamps go back makes its series timed by log time.  A jump is only every stamped publisher
recorded then going back together (a reset without ``/clock``); stamped series whose offsets to
log time differ by more than :data:`SAME_CLOCK` (publishers on different clocks) are named in a
note.  No sample is ever left out.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace

import numpy as np

from exsce_dsl.errors import MessageTypeError
from exsce_dsl.messages.catalogue import MessageCatalogue, standard_catalogue, standard_ros1_catalogue
from exsce_dsl.messages.user import configured_user_catalogue
from exsce_dsl.model.messages import path_of
from exsce_dsl.runs.bags.data import OBJECTS, BagData, Series, Wanted
from exsce_dsl.runs.bags.decode import TEXTS
from exsce_dsl.runs.signals.clock_words import describe_clocks, log_time_is_dated
from exsce_dsl.runs.signals.stamp_tracks import (
    StampTrack,
    first_back,
    header_tracks,
    publishers_apart,
    resets,
    steady_stamps,
    tf_tracks,
)
from exsce_dsl.wording import counted

CLOCK_TOPIC = "/clock"
CLOCK_TYPE = "rosgraph_msgs/msg/Clock"
OTHER_CLOCK = 300.0
"""Seconds: stamps further than this from their log times are of another clock (simulated time)."""
SAME_CLOCK = 1.0
"""Seconds: publishers of one clock differ by latency, far less than this."""
STRETCH = 10.0
"""Seconds of log time over which one offset from log time to stamps is taken (without /clock)."""
COARSE_SHARE = 0.25
"""Share of a series' steps whose header stamp repeats (log time going on) above which its stamps
are coarser than its rate, and it is timed by log time (DESIGN.md, Time)."""

STAMP_PATHS = (path_of("header", "stamp", "sec"), path_of("header", "stamp", "nanosec"))
TF_STAMP_KEYS = ("transforms.header.stamp.sec", "transforms.header.stamp.nanosec")
_CLOCK_PATHS = (path_of("clock", "sec"), path_of("clock", "nanosec"))

LOG_TIME = "log time"
HEADER_STAMPS = "header stamps"
TRANSFORM_STAMPS = "transform stamps"


@dataclass(frozen=True)
class SourceClock:
    """Which clock one topic's series was timed by, and how far its stamps were from log time."""

    topic: str
    clock: str
    """:data:`LOG_TIME`, :data:`HEADER_STAMPS` or :data:`TRANSFORM_STAMPS`."""
    simulated: bool
    """Whether the times are simulated time (stamps of a simulation, or log times mapped onto it)."""
    offset: float = 0.0
    """Median of log time minus stamp, in seconds (0 for a series timed by log time)."""
    by_log: tuple[str, ...] = ()
    """Of a topic timed by its stamps, the publishers (connections) whose messages are timed by
    their log times instead (their stamps go back, or stand apart from the others')."""

    def describe(self) -> str:
        kind = "simulated" if self.simulated else "wall clock"
        if self.clock == LOG_TIME:
            mapped = ", mapped onto simulated time" if self.simulated else ""
            return f"{self.topic}: log time{mapped}"
        but = f"; log time for {', '.join(self.by_log)}" if self.by_log else ""
        return f"{self.topic}: {self.clock} ({kind}, {self.offset:+.3f} s from log time{but})"


@dataclass(frozen=True)
class ClockJump:
    """A clock that went back: ``topic``'s (``/clock``, or a series' stamps) by ``back`` seconds,
    at ``at`` on the run's timeline."""

    topic: str
    at: float
    back: float
    together: tuple[str, ...] = ()
    """Without ``/clock``: every stamped publisher that went back with ``topic``'s."""

    def describe(self) -> str:
        what = "/clock" if self.topic == CLOCK_TOPIC else f"the stamps of {self.topic}"
        if len(self.together) > 1:
            what = f"the stamps of every stamped source ({', '.join(self.together)})"
        return f"{what} went back {self.back:.3f} s (a simulation reset while recording)"


@dataclass(frozen=True)
class Timeline:
    """The run's timeline and how a log time goes onto it (piecewise linear between knots)."""

    simulated: bool
    clocks: tuple[SourceClock, ...] = ()
    notes: tuple[str, ...] = ()
    by: str = "log time"
    """What maps log time onto the timeline: ``log time`` (nothing to map), ``/clock``, or the
    stamps' offsets."""
    log_knots: np.ndarray = field(default_factory=lambda: np.zeros(0))
    time_knots: np.ndarray = field(default_factory=lambda: np.zeros(0))
    jumps: tuple[ClockJump, ...] = ()
    """Where a clock went back: from there on, the run is not on one timeline."""
    log_start: float = float("inf")
    """The bag's first log time (s): before a year after 1970 it is simulated time, no date
    (inf: not known, a date)."""
    clock_recorded: bool = False
    """Whether the bag recorded ``/clock``."""

    @property
    def dated(self) -> bool:
        """Whether the recorder's log times are dates (not simulated time: no run of 1970)."""
        return log_time_is_dated(self.log_start)

    def from_log(self, times: np.ndarray) -> np.ndarray:
        """Log times (seconds) on the timeline."""
        return _through(np.asarray(times, dtype=np.float64), self.log_knots, self.time_knots)

    def to_wall(self, times: np.ndarray) -> np.ndarray:
        """Times on the timeline as the recorder's wall clock had them (for dates in PROV)."""
        return _through(np.asarray(times, dtype=np.float64), self.time_knots, self.log_knots)

    def describe(self) -> str:
        """The bag's clocks in the words ``exscec bag info`` uses (:func:`describe_clocks`)."""
        return describe_clocks(self.log_start, self.clock_recorded, self.simulated)

    def mapping(self) -> str | None:
        """How log times go onto the timeline, when they are moved at all."""
        return None if self.by == LOG_TIME else f"log times mapped onto the timeline through {self.by}"


def _through(times: np.ndarray, xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
    """``times`` through the piecewise-linear map ``xs → ys``, continued beyond its ends with the
    slope of its first and last pieces (1 where it has a single knot, the identity without any)."""
    if len(xs) == 0:
        return times
    if len(xs) == 1:
        moved: np.ndarray = times + (ys[0] - xs[0])
        return moved
    inside: np.ndarray = np.interp(times, xs, ys)
    before, after = times < xs[0], times > xs[-1]
    first = (ys[1] - ys[0]) / (xs[1] - xs[0]) if xs[1] > xs[0] else 1.0
    last = (ys[-1] - ys[-2]) / (xs[-1] - xs[-2]) if xs[-1] > xs[-2] else 1.0
    inside[before] = ys[0] + (times[before] - xs[0]) * first
    inside[after] = ys[-1] + (times[after] - xs[-1]) * last
    return inside


def with_stamps(
    wanted: Mapping[str, Wanted], types: Mapping[str, str], catalogue: MessageCatalogue
) -> dict[str, Wanted]:
    """``wanted`` with each topic whose type starts with a header also reading its stamp, and
    ``/clock`` when the bag (``types``: topic → type) recorded it."""
    found = dict(wanted)
    for topic, want in wanted.items():
        if want.msgtype == OBJECTS or any(p in want.paths for p in STAMP_PATHS):
            continue
        if _has_header(types.get(topic, want.msgtype), catalogue):
            found[topic] = replace(want, paths=(*want.paths, *STAMP_PATHS))
    if types.get(CLOCK_TOPIC) == CLOCK_TYPE:
        found[CLOCK_TOPIC] = Wanted(CLOCK_TYPE, _CLOCK_PATHS)
    return found


def stamp_catalogue() -> MessageCatalogue:
    """The definitions that say which types start with a header: the user's, then the standard
    ROS 2 and ROS 1 ones (a type only a bag defines is timed by log time)."""
    return configured_user_catalogue().layered(standard_catalogue(), standard_ros1_catalogue())


def _has_header(msgtype: str, catalogue: MessageCatalogue) -> bool:
    try:
        fields = catalogue.fields_of(msgtype)
    except MessageTypeError:
        return False
    return bool(fields) and fields[0][0] == "header"


def _stamps(series: Series) -> np.ndarray | None:
    """A series' header stamps in seconds, or None where it has none worth using (no header,
    every stamp zero: a publisher that leaves its header empty)."""
    keys = [p.key for p in STAMP_PATHS]
    if not all(k in series.fields for k in keys) or not len(series):
        return None
    stamps = series.fields[keys[0]] + series.fields[keys[1]] * 1e-9
    if not np.isfinite(stamps).all() or not (stamps > 0).any():
        return None
    return np.asarray(stamps, dtype=np.float64)


def _tf_stamps(series: Series) -> np.ndarray | None:
    """The first transform's stamp of each TF message (what pairs its log time with its clock)."""
    if not all(k in series.fields for k in TF_STAMP_KEYS) or not len(series):
        return None
    sec, nanosec = (np.asarray(series.fields[k], dtype=np.float64) for k in TF_STAMP_KEYS)
    stamps = (sec + nanosec * 1e-9).reshape(len(series), -1)[:, 0]
    keep = np.isfinite(stamps) & (stamps > 0)
    return np.where(keep, stamps, np.nan) if keep.any() else None


SIMULATED_BEFORE = 1e9
"""Stamps before this (2001-09-09) beside log times after it are a simulation's clock."""


@dataclass(frozen=True)
class _Stamped:
    """A series that carries stamps: its log times, its stamps, and how they relate."""

    topic: str
    kind: str
    log: np.ndarray
    stamps: np.ndarray
    offset: float
    tracks: tuple[StampTrack, ...] = ()
    """Its stamps per publisher (per edge for TF), as they are judged for going back."""

    @property
    def simulated(self) -> bool:
        return float(np.nanmedian(self.stamps)) < SIMULATED_BEFORE <= float(np.median(self.log))

    def coarse(self) -> str:
        """Why the stamps are coarser than the series' rate (empty: they are not): header stamps
        that stay the same while log time goes on, for more than :data:`COARSE_SHARE` of the
        steps (a driver stamping whole seconds at 27 Hz would make every duration a whole
        number of seconds, and hold each message for 0 s)."""
        if self.kind != HEADER_STAMPS:
            return ""
        known = np.isfinite(self.stamps) & (self.stamps > 0)
        stamps, log = self.stamps[known], self.log[known]
        going = np.diff(log) > 0
        if going.sum() < 2:
            return ""
        same = int(np.count_nonzero((np.diff(stamps) == 0) & going))
        if same <= COARSE_SHARE * int(going.sum()):
            return ""
        rate = 1.0 / float(np.median(np.diff(log)[going]))
        distinct = counted(len(np.unique(stamps)), "distinct stamp")
        return (
            f"the stamps of {self.topic} are coarser than its rate ({distinct} for "
            f"{counted(len(stamps), 'message')} at {rate:.1f} Hz): timed by log time"
        )


def decide_timeline(data: BagData) -> Timeline:
    """The run's timeline for the series ``data`` read (with their stamps, :func:`with_stamps`)."""
    stamped = _stamped_series(data)
    clock = data.series.get(CLOCK_TOPIC)
    simulated = [s for s in stamped if s.simulated]
    notes: list[str] = []
    jumps: list[ClockJump] = []
    if clock is not None and len(clock):
        log_knots, time_knots, jump = _clock_knots(clock)
        if jump is not None:
            jumps.append(jump)
            notes.append(f"{jump.describe()} at log time {jump.at:.3f}: the timeline goes on at its pace")
        by = CLOCK_TOPIC
        simulated_run = bool(np.median(time_knots) < SIMULATED_BEFORE <= np.median(log_knots))
    elif simulated:
        log_knots, time_knots = _offset_knots([_steady(s) for s in simulated])
        named = ", ".join(s.topic for s in simulated[:3]) + (" ..." if len(simulated) > 3 else "")
        by = f"the offsets of {named}"
        simulated_run = True
        offsets = [s.offset for s in simulated]
        if max(offsets) - min(offsets) > SAME_CLOCK:
            listed = ", ".join(f"{s.topic} {-s.offset:+.3f} s" for s in simulated)
            notes.append(f"simulated stamps of publishers differ from log time unequally ({listed})")
    else:
        log_knots = time_knots = np.zeros(0)
        by, simulated_run = LOG_TIME, False
    tracks = [t for s in stamped for t in s.tracks]
    for back, together in resets(tracks, SAME_CLOCK):
        jumps.append(ClockJump(back.track, back.at, back.back, together))
    recorded = clock is not None and bool(len(clock))
    timeline = Timeline(simulated_run, (), (), by, log_knots, time_knots, (), data.start, recorded)
    jumps = [replace(j, at=float(timeline.from_log(np.array([j.at]))[0])) for j in jumps]
    clocks = []
    for series in stamped:
        clocks.append(_source_clock(series, timeline, notes))
    stamped_topics = {s.topic for s in stamped}
    for topic in sorted(set(data.series) - stamped_topics - {CLOCK_TOPIC}):
        clocks.append(SourceClock(topic, LOG_TIME, simulated_run))
    for topic in sorted(data.messages):
        clocks.append(SourceClock(topic, LOG_TIME, simulated_run))
    if not timeline.dated and recorded:  # the recorder logged simulated time: so is every source
        clocks = [replace(c, simulated=True) for c in clocks]
    return replace(
        timeline, clocks=tuple(sorted(clocks, key=lambda c: c.topic)), notes=tuple(notes), jumps=tuple(jumps)
    )


def _stamped_series(data: BagData) -> list[_Stamped]:
    found = []
    for topic, series in sorted(data.series.items()):
        if topic == CLOCK_TOPIC:
            continue
        stamps, kind = _stamps(series), HEADER_STAMPS
        if stamps is None:
            stamps, kind = _tf_stamps(series), TRANSFORM_STAMPS
        if stamps is None:
            continue
        known = np.isfinite(stamps) & (stamps > 0)
        offset = float(np.median(series.t[known] - stamps[known]))
        tracks = tf_tracks(series) if kind == TRANSFORM_STAMPS else header_tracks(series, stamps)
        found.append(_Stamped(topic, kind, series.t, stamps, offset, tuple(tracks)))
    return found


def _steady(series: _Stamped) -> _Stamped:
    """``series`` without the stamps of its publishers that cannot time it (a post-dated one
    would pull a timeline made of stamps its way)."""
    found = steady_stamps(series.tracks, series.offset, SAME_CLOCK)
    return series if found is None else replace(series, log=found[0], stamps=found[1])


def _clock_knots(clock: Series) -> tuple[np.ndarray, np.ndarray, ClockJump | None]:
    """``/clock``'s messages as (log time, simulated time) knots, up to where it first goes back
    by more than :data:`SAME_CLOCK` (a reset: the jump, at its log time, is returned too)."""
    keys = [p.key for p in _CLOCK_PATHS]
    values = np.asarray(clock.fields[keys[0]] + clock.fields[keys[1]] * 1e-9, dtype=np.float64)
    log = np.asarray(clock.t, dtype=np.float64)
    back = np.diff(values) < -SAME_CLOCK
    jump = None
    if back.any():
        at = int(np.argmax(back))
        jump = ClockJump(CLOCK_TOPIC, float(log[at + 1]), float(values[at] - values[at + 1]))
        log, values = log[: at + 1], values[: at + 1]
    return log, np.maximum.accumulate(values), jump


def _offset_knots(simulated: list[_Stamped]) -> tuple[np.ndarray, np.ndarray]:
    """Knots from the stamps' offsets to log time: one per :data:`STRETCH` of log time, the median
    offset of every simulated stamp logged in it, up to where they would go back (a reset)."""
    log = np.concatenate([s.log for s in simulated])
    stamps = np.concatenate([s.stamps for s in simulated])
    keep = np.isfinite(stamps) & (stamps > 0)
    log, offset = log[keep], log[keep] - stamps[keep]
    order = np.argsort(log, kind="stable")
    log, offset = log[order], offset[order]
    bins = np.floor((log - log[0]) / STRETCH).astype(np.int64)
    edges = np.flatnonzero(np.diff(bins)) + 1
    starts, ends = np.concatenate([[0], edges]), np.concatenate([edges, [len(log)]])
    log_knots = np.array([np.median(log[a:b]) for a, b in zip(starts, ends, strict=True)])
    offsets = np.array([np.median(offset[a:b]) for a, b in zip(starts, ends, strict=True)])
    time_knots = log_knots - offsets
    back = np.flatnonzero(np.diff(time_knots) < 0)
    if back.size:  # the stamps went back (a reset): the timeline goes on at its pace, in order
        log_knots, time_knots = log_knots[: back[0] + 1], time_knots[: back[0] + 1]
    return log_knots, time_knots


def _source_clock(series: _Stamped, timeline: Timeline, notes: list[str]) -> SourceClock:
    """How ``series`` goes on the timeline: by its stamps when they are of the timeline's clock
    and none of its publishers' go back by more than :data:`SAME_CLOCK`, else by its log times
    (a note says which publisher went back: a reset is decided over every publisher); stamps
    coarser than the series' rate are never used (a note says so).  Of a topic with several
    publishers, one whose stamps go back or stand apart from the others' is timed by its log
    times alone, with a note (:func:`publishers_apart`)."""
    coarse = series.coarse()
    if coarse:
        notes.append(coarse)
        return SourceClock(series.topic, LOG_TIME, timeline.simulated)
    apart = (
        publishers_apart(series.tracks, timeline.from_log, SAME_CLOCK) if series.kind == HEADER_STAMPS else {}
    )
    kept = [t for t in series.tracks if t.publisher not in apart]
    back = first_back(kept, SAME_CLOCK)
    if back is not None or not kept:
        back = back or first_back(series.tracks, SAME_CLOCK)
        went = f"go back {back.back:.3f} s at log time {back.at:.3f}" if back else "stand apart"
        notes.append(
            f"the stamps of {back.track if back else series.topic} {went} "
            f"(by more than {SAME_CLOCK:g} s): {series.topic} timed by log time"
        )
        return SourceClock(series.topic, LOG_TIME, timeline.simulated)
    offset = series.offset
    if apart:
        notes.extend(f"{why}: its messages timed by log time" for why in apart.values())
        offset = float(np.median(np.concatenate([t.log - t.stamps for t in kept])))
    if series.simulated == timeline.simulated:
        if abs(offset) > SAME_CLOCK and not series.simulated:
            notes.append(
                f"the stamps of {series.topic} are {offset:+.3f} s from log time "
                "(a clock not synchronised with the recorder's): moved onto log time"
            )
        return SourceClock(series.topic, series.kind, series.simulated, offset, tuple(apart))
    return SourceClock(series.topic, LOG_TIME, timeline.simulated, offset)


def on_timeline(data: BagData, timeline: Timeline) -> BagData:
    """``data`` with every series and message object timed on ``timeline``."""
    clocks = {c.topic: c for c in timeline.clocks}
    start, end = timeline.from_log(np.array([data.start, data.end], dtype=np.float64)).tolist()
    messages = {}
    for topic, found in data.messages.items():
        times = timeline.from_log(np.array([t for t, _ in found], dtype=np.float64)).tolist()
        messages[topic] = list(zip(times, [m for _, m in found], strict=True))
    return replace(
        data,
        start=start,
        end=end,
        series={
            topic: _series_on(series, clocks.get(topic), timeline)
            for topic, series in data.series.items()
            if topic != CLOCK_TOPIC
        },
        messages=messages,
    )


def _series_on(series: Series, clock: SourceClock | None, timeline: Timeline) -> Series:
    if clock is None or clock.clock == LOG_TIME:
        return _retimed(series, timeline.from_log(series.t))
    if clock.clock == TRANSFORM_STAMPS:
        # a TF pose is timed by each transform's stamp: on the timeline already unless the
        # stamps are a wall clock that is not the recorder's
        if clock.simulated or abs(clock.offset) <= SAME_CLOCK:
            return _retimed(series, timeline.from_log(series.t))
        return _tf_moved(_retimed(series, timeline.from_log(series.t)), clock.offset)
    stamps = _stamps(series)
    assert stamps is not None  # a series is timed by header stamps only where it has them
    times = stamps if clock.simulated or abs(clock.offset) <= SAME_CLOCK else stamps + clock.offset
    if clock.by_log and series.publishers is not None:  # those publishers' messages by their log times
        by_log = [series.publisher_names.index(p) for p in clock.by_log]
        mine = np.isin(series.publishers, by_log)
        times = times.copy()
        times[mine] = timeline.from_log(series.t[mine])
    return _retimed(series, times)


def _retimed(series: Series, times: np.ndarray) -> Series:
    """``series`` at ``times``, its messages sorted by them (stably: ties keep their order)."""
    if len(times) > 1 and (np.diff(times) < 0).any():
        order = np.argsort(times, kind="stable")
        fields = {
            k: (v[order] if k != TEXTS and len(v) == len(times) else v) for k, v in series.fields.items()
        }
        publishers = series.publishers[order] if series.publishers is not None else None
        return replace(series, t=times[order], fields=fields, publishers=publishers)
    return replace(series, t=times)


def _tf_moved(series: Series, offset: float) -> Series:
    """A TF series whose transforms' stamps are moved by ``offset`` seconds onto log time."""
    sec, nanosec = TF_STAMP_KEYS
    fields = dict(series.fields)
    fields[sec] = series.fields[sec] + series.fields[nanosec] * 1e-9 + offset
    fields[nanosec] = np.zeros_like(series.fields[nanosec])
    return replace(series, fields=fields)
