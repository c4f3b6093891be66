"""The live side of the metric monitors: messages in, metric values and oracle verdicts out.
Long because: it is copied as one file into each node package (buffers, windows, runtime).

This module imports only numpy and the standard library, like ``monitor_core`` (``tests/monitor_kit``
holds them so): ``exscec generate ros1-monitor`` and ``ros2-monitor`` copy it as it is into the node
packages, and the tests run it here on bags, without ROS.  The ROS nodes only subscribe, stamp each
message with its receive time and hand it to :meth:`MonitorRuntime.on_message`; a timer calls
:meth:`MonitorRuntime.tick`.

The metrics come from the generated ``RobotMetrics`` and ``MissionMetrics`` classes over ``core.Topic``s
of what has been received, in windows taken from the waypoint dispatcher's goal statuses as ingestion
takes them (a robot's runs from its first waypoint that became ACTIVE to the last one that reached a
final status, or to *now* while one is active).  Fields are read from message objects along their paths
as exsce writes them (``ranges[-1]``, ``len(status_list)``,
``transforms[child_frame_id == "base_link"].transform.translation.x``) into growing numpy buffers
(capacity doubles: amortised O(1) per message); a path that picks an element keeps a ``#present`` mask,
as ingestion does, so that a message without the element gives no sample.  Arrays (laser ranges) are
reduced a block of messages at a time by the monitors' ``REDUCERS``, as ingestion reduces them, so their
rows are not kept.  An evaluation computes every metric over all data so far (vectorised: ~15 ms for an
hour of scenario_c's two robots, ~700k messages).
"""

from __future__ import annotations

import functools
import importlib
import json
import math
import re
import threading
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from types import ModuleType
from typing import Any

import numpy as np

# actionlib's status codes, as the model's goals module defines them (this module imports nothing)
ACTIVE, SUCCEEDED = 1, 3
FINAL = frozenset({2, 3, 4, 5, 8, 9})
"""PREEMPTED, SUCCEEDED, ABORTED, REJECTED, RECALLED, LOST: a waypoint's goal is over."""
PASSED, FAILED, NOT_YET = "passed", "failed", "not_yet"
BLOCK = 256
"""Messages with arrays held before they are reduced to one value per message."""
PRESENT = "#present"
"""Suffix of the key of a path's mask: which messages have the element it picks."""


def judge(
    relation: str,
    result: float,
    limit: float | None = None,
    value: float | None = None,
    tolerance: float | None = None,
) -> tuple[bool, float]:
    """(passed, margin) by exsce's relations: ``below_max``: result <= limit; ``above_min``:
    result >= limit; ``invariant``: |result - value| <= tolerance (none: 0).  NaN fails."""
    if relation == "below_max" and limit is not None:
        margin = limit - result
    elif relation == "above_min" and limit is not None:
        margin = result - limit
    elif relation == "invariant" and value is not None:
        margin = (tolerance or 0.0) - abs(result - value)
    else:
        raise ValueError(f"cannot judge relation {relation!r} live with limit={limit}, value={value}")
    if math.isnan(result) or math.isnan(margin):
        return False, math.nan
    return margin >= 0, margin


def message_class(path: str) -> Any:
    """The message class of an import path such as ``geometry_msgs.msg.Twist``."""
    module, _, name = path.rpartition(".")
    return getattr(importlib.import_module(module), name)


@dataclass(frozen=True)
class Pick:
    """``[3]`` (``names`` empty: by position) or ``[child_frame_id == "base_link"]`` (the first
    element whose field ``names`` equals ``value``)."""

    names: tuple[str, ...]
    value: Any


@dataclass(frozen=True)
class Attributes:
    """A path into message objects: attribute names and picks, or the length of what they name."""

    steps: tuple[str | Pick, ...]
    length: bool = False

    @property
    def picks(self) -> bool:
        return any(isinstance(step, Pick) for step in self.steps)

    def read(self, msg: Any) -> tuple[Any, bool]:
        """(the value in ``msg``, whether it is there).  A name after an array of messages
        applies to every element; a pick with no element gives (None, False)."""
        node = msg
        for step in self.steps:
            if isinstance(step, str) and isinstance(node, (list, tuple)):
                node = [getattr(x, step) for x in node]
            elif isinstance(step, str):
                node = getattr(node, step)
            elif not step.names:
                try:
                    node = node[step.value]
                except IndexError:
                    return None, False
            else:
                node = next((x for x in node if functools.reduce(getattr, step.names, x) == step.value), None)
                if node is None:
                    return None, False
        if self.length:
            return len(node), True
        return node, True


def attributes(text: str) -> Attributes:
    """The path written ``text`` (``transforms[child_frame_id == "base_link"].transform.x``,
    ``ranges[-1]``, ``len(status_list)``); selected values are JSON (a string or a number)."""
    length = text.startswith("len(") and text.endswith(")")
    if length:
        text = text[4:-1]
    steps: list[str | Pick] = []
    at = 0
    while at < len(text):
        if text[at] == ".":
            at += 1
        if text[at] == "[":
            end = _closing(text, at)
            inside = text[at + 1 : end].strip()
            field, equals, value = inside.partition("==")
            if equals:
                steps.append(Pick(tuple(field.strip().split(".")), json.loads(value.strip())))
            else:
                steps.append(Pick((), int(inside)))
            at = end + 1
            continue
        name = re.match(r"[A-Za-z_][A-Za-z0-9_]*", text[at:])
        if name is None:
            raise ValueError(f"not a field path: {text!r}")
        steps.append(name.group())
        at += name.end()
    return Attributes(tuple(steps), length)


def _closing(text: str, start: int) -> int:
    """Where the ``]`` that closes the ``[`` at ``start`` is (``]`` inside a string is text)."""
    quoted = False
    at = start + 1
    while at < len(text):
        char = text[at]
        if quoted and char == "\\":
            at += 2
            continue
        if char == '"':
            quoted = not quoted
        elif char == "]" and not quoted:
            return at
        at += 1
    raise ValueError(f"no ']' closes the '[' of {text!r}")


@dataclass(frozen=True)
class TopicSpec:
    """What to do with one topic: keep ``fields`` (exsce path → attribute path), or, for the
    dispatcher's ``feedback`` and ``result``, follow the goal statuses of ``robot``."""

    type: str
    role: str = "data"
    robot: str | None = None
    fields: Mapping[str, str] = field(default_factory=dict)
    arrays: tuple[str, ...] = ()
    """The fields that hold arrays (one row per message, rows may differ in length)."""
    signals: tuple[str, ...] = ()
    """The robot's signals (``/r1/~pose``) the monitors read from this topic, by those names."""

    def names(self, topic: str) -> tuple[str, ...]:
        """The names the monitors read this topic by: its own and its signals'."""
        return (topic, *self.signals)


class _Column:
    """A growing float64 array: capacity doubles, so appending is amortised O(1)."""

    def __init__(self) -> None:
        self.data = np.empty(64, dtype=np.float64)
        self.n = 0

    def _reserve(self, need: int) -> None:
        if need > len(self.data):
            grown = np.empty(max(need, 2 * len(self.data)), dtype=np.float64)
            grown[: self.n] = self.data[: self.n]
            self.data = grown

    def append(self, value: float) -> None:
        self._reserve(self.n + 1)
        self.data[self.n] = value
        self.n += 1

    def extend(self, values: np.ndarray) -> None:
        self._reserve(self.n + len(values))
        self.data[self.n : self.n + len(values)] = values
        self.n += len(values)

    def view(self) -> np.ndarray:
        return self.data[: self.n]


def _reductions(
    entries: Mapping[str, list[tuple[str, str, Any]]], names: Sequence[str]
) -> list[tuple[str, str, Any]]:
    """The reductions the monitors ask of a topic under any of its ``names``, each once."""
    return list(dict.fromkeys(r for name in names for r in entries.get(name, [])))


def _padded(rows: Sequence[np.ndarray]) -> np.ndarray:
    """Rows of different lengths as one messages × width array, NaN after each row's end
    (as ingestion pads scans of different sizes: NaN is never a valid value).  At least one
    column: an empty scan has no value, and numpy reduces no empty row."""
    width = max([1, *(len(r) for r in rows)])
    out = np.full((len(rows), width), np.nan)
    for i, row in enumerate(rows):
        out[i, : len(row)] = row
    return out


def _row(value: Any) -> np.ndarray:
    """An array field's value as a row of floats (none for an element that is not there)."""
    if value is None:
        return np.empty(0)
    if isinstance(value, (bytes, bytearray)):  # rospy's uint8[] and char[]
        return np.frombuffer(bytes(value), dtype=np.uint8).astype(np.float64)
    return np.asarray(value, dtype=np.float64).ravel()


class _Buffer:
    """One data topic: receive times, scalar fields, and arrays waiting to be reduced."""

    def __init__(self, spec: TopicSpec, reduce: Any) -> None:
        self.spec = spec
        self.paths = {p: attributes(a) for p, a in spec.fields.items()}
        self.reduce = reduce
        self.t = _Column()
        self.columns: dict[str, _Column] = {p: _Column() for p in spec.fields if p not in spec.arrays}
        self.present: dict[str, _Column] = {p + PRESENT: _Column() for p, a in self.paths.items() if a.picks}
        """Per path that picks elements: 1 where the message has the element, else 0."""
        self.outputs: dict[str, _Column] = {}
        """Per-message values of the monitors' aggregates over arrays (``core.reduced`` reads them)."""
        self.pending: dict[str, list[np.ndarray]] = {p: [] for p in spec.arrays}
        self.reduced = 0
        """Messages whose arrays are reduced (or kept, for a topic without reducers)."""
        self.kept: dict[str, list[np.ndarray]] = {p: [] for p in spec.arrays}

    def add(self, t: float, msg: Any) -> None:
        """Keep the fields of ``msg``; all are read before any is kept, so that a message that
        lacks one (an exception) leaves the columns aligned."""
        values: dict[str, Any] = {}
        present: dict[str, float] = {}
        for path, where in self.paths.items():
            values[path], found = where.read(msg)
            if where.picks:
                present[path + PRESENT] = 1.0 if found else 0.0
        scalars = {path: math.nan if values[path] is None else float(values[path]) for path in self.columns}
        rows = {path: _row(values[path]) for path in self.pending}
        for path, column in self.columns.items():
            column.append(scalars[path])
        for key, column in self.present.items():
            column.append(present[key])
        for path, row in rows.items():
            self.pending[path].append(row)
        self.t.append(t)
        if self.spec.arrays and self.t.n - self.reduced >= BLOCK:
            self.flush()

    def flush(self) -> None:
        """Reduce the arrays of the messages received since the last flush."""
        if not self.spec.arrays or self.reduced == self.t.n:
            return
        if self.reduce is None:
            for p, rows in self.pending.items():
                self.kept[p].extend(rows)
        else:
            block = {p: c.view()[self.reduced :] for p, c in self.columns.items()}
            block.update({p: c.view()[self.reduced :] > 0 for p, c in self.present.items()})
            block.update({p: _padded(rows) for p, rows in self.pending.items()})
            for key, values in self.reduce(block).items():
                if key not in block:
                    self.outputs.setdefault(key, _Column()).extend(values)
        for rows in self.pending.values():
            rows.clear()
        self.reduced = self.t.n

    def topic(self, core: ModuleType, name: str) -> Any:
        self.flush()
        fields = {p: c.view() for p, c in {**self.columns, **self.outputs}.items()}
        fields.update({p: c.view() > 0 for p, c in self.present.items()})
        fields.update({p: _padded(rows) for p, rows in self.kept.items() if self.reduce is None})
        t = self.t.view()
        if len(t) > 1 and bool(np.any(np.diff(t) < 0)):  # a clock that went back: time order
            order = np.argsort(t, kind="stable")
            t, fields = t[order], {p: v[order] for p, v in fields.items()}
        return core.Topic(name, t, fields)


class _Dispatch:
    """One robot's dispatcher goals, split as ingestion splits them: a new goal when the goal
    id or the waypoint list changes, or when all statuses fall back to PENDING."""

    def __init__(self) -> None:
        self.goals: list[tuple[str, tuple[str, ...], list[float | None], list[float | None]]] = []
        self.last: tuple[int, ...] = ()

    def update(self, t: float, goal: str, waypoints: tuple[str, ...], statuses: tuple[int, ...]) -> None:
        current = self.goals[-1] if self.goals else None
        same = current is not None and current[0] == goal and current[1] == waypoints
        restarted = same and all(s == 0 for s in statuses) and any(s != 0 for s in self.last)
        if current is None or not same or restarted:
            current = (goal, waypoints, [None] * len(statuses), [None] * len(statuses))
            self.goals.append(current)
        _, _, starts, ends = current
        for w, status in enumerate(statuses[: len(starts)]):
            if status == ACTIVE and starts[w] is None:
                starts[w] = t
            if status in FINAL and ends[w] is None:
                ends[w] = t
        self.last = statuses

    def window(self, now: float) -> tuple[float, float] | None:
        """First ACTIVE to last final status; to ``now`` while a waypoint is active."""
        spans = [(s, e) for _, _, starts, ends in self.goals for s, e in zip(starts, ends)]
        running = [s for s, e in spans if s is not None and e is None]
        done = [(s, e) for s, e in spans if s is not None and e is not None]
        if running:
            return min(running + [s for s, _ in done]), now
        if done:
            return min(s for s, _ in done), max(e for _, e in done)
        return None


@dataclass(frozen=True)
class CheckResult:
    """One oracle's check so far: the value seen and ``verdict``, passed, failed or not yet."""

    oracle: Mapping[str, Any]
    value: float | None
    verdict: str
    margin: float | None


@dataclass(frozen=True)
class Evaluation:
    """Everything known at ``time``: windows, metric values (None: no value yet), verdicts."""

    time: float
    windows: Mapping[str, tuple[float, float] | None]
    robots: Mapping[str, Mapping[str, float | None]]
    mission: Mapping[str, float | None]
    verdicts: tuple[CheckResult, ...]
    problems: tuple[str, ...] = ()

    def outcome(self) -> tuple[str, ...]:
        return tuple(v.verdict for v in self.verdicts)

    def as_dict(self, scenario: str = "") -> dict[str, Any]:
        counts = {kind: self.outcome().count(kind) for kind in (PASSED, FAILED, NOT_YET)}
        return {
            "scenario": scenario,
            "time": self.time,
            **counts,
            "verdicts": [
                {**v.oracle, "observed": v.value, "verdict": v.verdict, "margin": v.margin}
                for v in self.verdicts
            ],
            "metrics": {"robots": self.robots, "mission": self.mission},
            "windows": {robot: None if w is None else list(w) for robot, w in self.windows.items()},
            "problems": list(self.problems),
        }


class MonitorRuntime:
    """Metrics and verdicts of one run, live.  Thread-safe: ROS 1 calls back from many threads.

    ``monitors``: the generated monitor module; ``robots``: (robot id, namespace) in fleet
    order; ``topics``: topic → :class:`TopicSpec` (or its fields as a dict); ``oracles``: dicts
    with ``robot`` (None: the mission), ``metric``, ``relation`` and ``limit``, ``value``,
    ``tolerance`` as the relation needs; any other key is passed through to the verdicts.
    """

    def __init__(
        self,
        monitors: ModuleType,
        robots: Sequence[tuple[str, str]],
        topics: Mapping[str, TopicSpec | Mapping[str, Any]],
        oracles: Sequence[Mapping[str, Any]],
        scenario: str = "",
    ) -> None:
        self.monitors = monitors
        self.core: ModuleType = monitors.core
        self.robots = [(robot, namespace.strip("/")) for robot, namespace in robots]
        self.scenario = scenario
        self.specs = {n: s if isinstance(s, TopicSpec) else TopicSpec(**s) for n, s in topics.items()}
        self.oracles = [dict(o) for o in oracles]
        entries: dict[str, list[tuple[str, str, Any]]] = {}
        for _, namespace in self.robots:
            for pattern, *reduction in monitors.REDUCERS:
                entries.setdefault(self.core.expand_topic(pattern, namespace), []).append(tuple(reduction))
        self.buffers: dict[str, _Buffer] = {}
        for name, spec in self.specs.items():
            found = _reductions(entries, spec.names(name))
            if spec.role == "data":
                self.buffers[name] = _Buffer(spec, self.core.reducer(found) if found else None)
        self.dispatch = {robot: _Dispatch() for robot, _ in self.robots}
        self.succeeded: dict[str, int] = {}
        self.problems: dict[str, None] = {}  # insertion-ordered set
        self._lock = threading.Lock()
        self._published: tuple[float, Any] | None = None

    def on_message(self, topic: str, t: float, msg: Any) -> None:
        """Take one message received at ``t`` (seconds); a message that lacks a field is dropped
        and reported once among the problems, so a live node never stops on it."""
        spec = self.specs.get(topic)
        if spec is None:
            return
        with self._lock:
            try:
                if spec.role == "data":
                    self.buffers[topic].add(t, msg)
                else:
                    self._status(spec, t, msg)
            except (AttributeError, TypeError, ValueError) as exc:
                self.problems.setdefault(f"{topic}: message dropped: {type(exc).__name__}: {exc}")

    def _status(self, spec: TopicSpec, t: float, msg: Any) -> None:
        payload = msg.feedback if spec.role == "feedback" else msg.result
        status_list = payload.goal_status.status_list
        goal = getattr(getattr(getattr(msg, "status", None), "goal_id", None), "id", "") or ""
        statuses = tuple(int(s.status) for s in status_list)
        robot = spec.robot or ""
        if spec.role == "result":
            self.succeeded[robot] = self.succeeded.get(robot, 0) + statuses.count(SUCCEEDED)
        elif robot in self.dispatch:
            self.dispatch[robot].update(t, str(goal), tuple(str(s.goal_id.id) for s in status_list), statuses)

    def evaluate(self, now: float) -> Evaluation:
        """The metrics over each robot's window and the mission's so far, and each oracle's verdict."""
        with self._lock:
            topics = {
                alias: b.topic(self.core, alias)
                for name, b in self.buffers.items()
                if b.t.n
                for alias in self.specs[name].names(name)
            }
            windows = {robot: self.dispatch[robot].window(now) for robot, _ in self.robots}
            succeeded = dict(self.succeeded)
        problems: dict[str, None] = {}
        robots: dict[str, dict[str, float | None]] = {}
        for robot, namespace in self.robots:
            monitor = self.monitors.RobotMetrics(robot, namespace, topics, succeeded.get(robot))
            robots[robot] = self._values(monitor, windows[robot], problems)
        known = [w for w in windows.values() if w is not None]
        mission_window = (min(w[0] for w in known), max(w[1] for w in known)) if known else None
        mission = self._values(self.monitors.MissionMetrics(self.robots, topics), mission_window, problems)
        verdicts = []
        for oracle in self.oracles:
            whose = oracle.get("robot")
            value = (mission if whose is None else robots.get(whose, {})).get(oracle["metric"])
            if value is None:
                verdicts.append(CheckResult(oracle, None, NOT_YET, None))
                continue
            passed, margin = judge(
                oracle["relation"], value, oracle.get("limit"), oracle.get("value"), oracle.get("tolerance")
            )
            verdicts.append(CheckResult(oracle, value, PASSED if passed else FAILED, margin))
        with self._lock:
            problems = {**dict.fromkeys(self.problems), **problems}
        return Evaluation(now, windows, robots, mission, tuple(verdicts), tuple(problems))

    @staticmethod
    def _values(
        monitor: Any, window: tuple[float, float] | None, problems: dict[str, None]
    ) -> dict[str, float | None]:
        """Each metric of ``monitor`` over ``window``; one that cannot be computed from the data
        so far has no value, and the reason is reported (a live node must not stop on it)."""
        values: dict[str, float | None] = dict.fromkeys(monitor.METRICS)
        if window is None:
            return values
        for name in values:
            try:
                values[name] = getattr(monitor, f"get_{name}")(*window)
            # whatever the data so far do to a metric, it is reported with the verdicts instead
            except Exception as exc:  # noqa: BLE001
                problems.setdefault(f"{name}: not computed: {type(exc).__name__}: {exc}")
        return values

    def tick(self, now: float, period: float = 1.0) -> str | None:
        """The JSON text to publish at ``now``: when a verdict changed or a robot's window closed
        (a run's end may come less than a period before the clock stops), or ``period`` seconds
        after the last one; None otherwise."""
        evaluation = self.evaluate(now)
        closed = sorted(r for r, w in evaluation.windows.items() if w is not None and w[1] < now)
        outcome = (evaluation.outcome(), tuple(closed))  # an open window ends at now: not a change
        last = self._published
        if last is not None and last[1] == outcome and now - last[0] < period and now >= last[0]:
            return None
        self._published = (now, outcome)
        return to_json(evaluation, self.scenario)


def to_json(evaluation: Evaluation, scenario: str = "") -> str:
    """The verdict message: plain JSON (no NaN: a metric without a value is null)."""
    data = evaluation.as_dict(scenario)
    for verdict in data["verdicts"]:
        margin = verdict["margin"]
        if margin is not None and not math.isfinite(margin):
            verdict["margin"] = None
    return json.dumps(data, allow_nan=False, sort_keys=False)
