"""The mission dispatcher: drives a schedule through a navigator, event by event.

Each lane of the schedule sends its first goal; from then on the dispatcher waits for the next
goal to end (or the earliest timeout), records it, and sends that lane its next goal.  It never
sleeps on a wall clock: all waiting is the navigator's ``next_finished``, against the clock the
caller gives, so a simulated clock runs a mission as fast as the navigator can play it.

Cancellation: ``cancelled`` is asked before the first goal is sent (yes: nothing is sent) and
after every wake-up (at least every ``poll`` seconds of the clock); once it says yes, every
active goal is cancelled (recorded as CANCELLED), no more goals are sent, and the run ends as
``cancelled``.  A ROS adapter sets it from SIGINT or SIGTERM.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable
from dataclasses import dataclass

from exsce_dsl.execute.mission import Goal, Schedule
from exsce_dsl.execute.navigator import Clock, Navigator
from exsce_dsl.execute.outcomes import (
    DEFAULT_POLICY,
    GoalOutcome,
    GoalRecord,
    MissionRun,
    MissionStatus,
    Policy,
)

DEFAULT_POLL = 1.0
"""Seconds of the clock between two looks at ``cancelled`` while no goal ends."""


@dataclass(frozen=True)
class _Active:
    lane: int
    goal: Goal
    first_start: float
    """When the goal's first attempt was sent."""
    sent: float
    """When this attempt was sent."""
    attempts: int


def dispatch(
    schedule: Schedule,
    navigator: Navigator,
    clock: Clock,
    policy: Policy = DEFAULT_POLICY,
    cancelled: Callable[[], bool] | None = None,
    poll: float = DEFAULT_POLL,
) -> MissionRun:
    """Run ``schedule`` through ``navigator``; failed goals are handled by ``policy``."""
    return _Dispatch(schedule, navigator, clock, policy, cancelled, poll).run()


class _Dispatch:
    def __init__(
        self,
        schedule: Schedule,
        navigator: Navigator,
        clock: Clock,
        policy: Policy,
        cancelled: Callable[[], bool] | None,
        poll: float,
    ) -> None:
        self.navigator, self.clock, self.policy = navigator, clock, policy
        self.cancelled, self.poll = cancelled, poll
        self.lanes = [deque(lane) for lane in schedule.lanes]
        self.active: dict[int, _Active] = {}
        self.records: list[GoalRecord] = []
        self.numbers = 0
        self.skipped = 0
        self.status = MissionStatus.COMPLETED

    def run(self) -> MissionRun:
        start = self.clock.now()
        if self.cancelled is not None and self.cancelled():
            self.status = MissionStatus.CANCELLED
        for lane in range(len(self.lanes)):
            self._next(lane)
        while self.active and self.status is MissionStatus.COMPLETED:
            if self.cancelled is not None and self.cancelled():
                self._cancel_all()
                self.status = MissionStatus.CANCELLED
                break
            deadline = min(a.sent + a.goal.timeout for a in self.active.values())
            if self.cancelled is not None:
                deadline = min(deadline, self.clock.now() + self.poll)
            finished = self.navigator.next_finished(deadline)
            if finished is None:
                self._time_out(self.clock.now())
            elif finished.goal in self.active:  # else: an end after we cancelled it, or reported twice
                if finished.outcome is GoalOutcome.SUCCEEDED:
                    done = self.active.pop(finished.goal)
                    self._record(done, GoalOutcome.SUCCEEDED, finished.time)
                    self._next(done.lane)
                else:
                    self._failed(finished.goal, finished.outcome, finished.time)
        not_sent = self.skipped + sum(len(lane) for lane in self.lanes)
        return MissionRun(self.status, tuple(self.records), start, self.clock.now(), not_sent)

    def _send(self, lane: int, goal: Goal, first_start: float | None, attempts: int) -> None:
        self.numbers += 1
        now = self.clock.now()
        self.active[self.numbers] = _Active(
            lane, goal, now if first_start is None else first_start, now, attempts
        )
        self.navigator.send(self.numbers, goal.robot, goal.pose)

    def _next(self, lane: int) -> None:
        if self.lanes[lane] and self.status is MissionStatus.COMPLETED:
            self._send(lane, self.lanes[lane].popleft(), None, 1)

    def _record(self, done: _Active, outcome: GoalOutcome, end: float) -> None:
        g = done.goal
        self.records.append(
            GoalRecord(
                g.robot,
                g.task,
                g.task_number,
                g.subtask,
                g.waypoint,
                g.pose,
                done.first_start,
                end,
                outcome,
                done.attempts,
            )
        )

    def _time_out(self, now: float) -> None:
        late = [n for n, a in self.active.items() if a.sent + a.goal.timeout <= now]
        for number in late:
            if number in self.active:  # a stop on an earlier one may have cancelled it already
                self.navigator.cancel(number)
                self._failed(number, GoalOutcome.TIMED_OUT, now)

    def _failed(self, number: int, outcome: GoalOutcome, end: float) -> None:
        """A goal that did not succeed: aborted, rejected, timed out, or cancelled by another
        client of the robot's stack (preempted): ``policy`` says what comes next."""
        done = self.active.pop(number)
        if self.policy is Policy.RETRY_ONCE and done.attempts == 1:
            self._send(done.lane, done.goal, done.first_start, 2)
            return
        self._record(done, outcome, end)
        if self.policy is Policy.STOP_MISSION:
            self._cancel_all()
            self.status = MissionStatus.STOPPED
            return
        if self.policy is Policy.SKIP_TASK:
            lane = self.lanes[done.lane]
            while lane and lane[0].task_key == done.goal.task_key:
                lane.popleft()
                self.skipped += 1
        self._next(done.lane)

    def _cancel_all(self) -> None:
        now = self.clock.now()
        for number, active in sorted(self.active.items()):
            self.navigator.cancel(number)
            self._record(active, GoalOutcome.CANCELLED, now)
        self.active.clear()
