"""Path segments from the robot's pose arriving at its planned waypoints, in plan order.

For a robot whose bag holds no goals at all, only its pose track.  The rules:

1. **Departure.**  The robot's first tracked pose is where it started.  It moved when it first
   went farther than the position tolerance from there (in 3-D where arrival compares heights);
   the first segment starts at the last sample before that at which it was still at its first
   pose (within `STILL_POSITION` and `STILL_HEADING`, a stationary localisation's noise): the
   moment it set off, not the start of the recording (a bag often begins well before the
   mission).  If it set off at once, that is the track's first sample.  A robot that never
   moved: every segment NOT_STARTED, with a warning.
2. **Arrival.**  The k-th segment ends at the first sample, at or after segment k-1's end (the first
   one: its start), where the robot is within the `Tolerance` of waypoint k (in 3-D when the
   waypoint gives a height or the robot's type says ``motion 3d``: see `track.near`); it starts when
   segment k-1 ended, so the time spent at a waypoint counts to the next segment, as the
   dispatcher's next goal starts only once the previous one is done.  Order matters: passing
   through a later waypoint before an earlier one counts for nothing; passing through the
   current one on the way elsewhere is arriving at it.  A reached waypoint's status is
   SUCCEEDED, so that its goal pose starts the next segment and it counts as visited.
3. **Not reached.**  The first waypoint never reached, and every later one, are NOT_REACHED (no
   start, no end), with a warning.
4. **No track**, or no plan: no segments, with a warning.
5. **Start poses** as `segmentation` says: all reached segments SUCCEEDED, so each starts at the
   previous waypoint; the first at the declared start pose, or at the robot's first tracked pose
   (with a warning) if that is farther than the tolerance from it.

The search is vectorised over the samples with numpy: one pass over the track per waypoint.
"""

from __future__ import annotations

import numpy as np

from exsce_dsl.model import Scenario
from exsce_dsl.model.conventions import Tolerance
from exsce_dsl.runs.segments.track import (
    DEFAULT_TOLERANCE,
    SUCCEEDED,
    Segmentation,
    Track,
    WaypointResult,
    angle_between,
    at,
    build_segmentation,
    near,
    planned_waypoints,
)
from exsce_dsl.wording import counted

STILL_POSITION = 0.01
"""Metres: a robot whose position changes less than this has not moved (localisation noise)."""
STILL_HEADING = 0.01
"""Radians: likewise for its heading (a robot turning on the spot has set off)."""


def arrival_segments(
    scenario: Scenario, robot: str, track: Track, tolerance: Tolerance = DEFAULT_TOLERANCE
) -> Segmentation:
    """The path segments of ``robot`` from its pose ``track`` reaching its planned waypoints."""
    plan = planned_waypoints(scenario, robot)
    if not plan:
        return Segmentation((), (f"robot {robot} has no planned waypoints in scenario {scenario.id}",))
    if not len(track):
        return Segmentation((), (f"robot {robot} has an empty pose track: no segments by arrival",))
    warnings: list[str] = []
    x0, y0, yaw0 = float(track.x[0]), float(track.y[0]), float(track.yaw[0])
    from_start = np.hypot(track.x - x0, track.y - y0)
    if track.z is not None and (track.three_d or any(p.pose.position.z != 0 for p in plan)):
        from_start = np.hypot(from_start, track.z - track.z[0])  # a climb is a departure too
    away = np.flatnonzero(from_start > tolerance.position)
    if not away.size:
        warnings.append(f"robot {robot} never moved: it stayed within {tolerance.position} m of {at(x0, y0)}")
        outcomes = [WaypointResult(None, None, "NOT_STARTED")] * len(plan)
        return build_segmentation(scenario, robot, plan, outcomes, track, tolerance, warnings)
    departure = int(away[0])
    still = (from_start[:departure] <= STILL_POSITION) & (
        angle_between(track.yaw[:departure], yaw0) <= STILL_HEADING
    )
    index = int(np.flatnonzero(still)[-1])  # the first sample is at the first pose
    outcomes = []
    for k, planned in enumerate(plan):
        heights = track.z[index:] if track.z is not None else None
        close = near(
            tolerance,
            planned.pose,
            track.x[index:],
            track.y[index:],
            track.yaw[index:],
            heights,
            track.three_d,
        )
        arrival = int(np.argmax(close))
        if not close[arrival]:
            later = len(plan) - k - 1
            warnings.append(
                f"robot {robot} never reached {planned.label} after {track.times[index]:.3f}"
                + (f"; it and the {counted(later, 'waypoint')} after it are NOT_REACHED" if later else "")
            )
            outcomes += [WaypointResult(None, None, "NOT_REACHED")] * (len(plan) - k)
            break
        reached = WaypointResult(float(track.times[index]), float(track.times[index + arrival]), SUCCEEDED)
        outcomes.append(reached)
        index += arrival
    return build_segmentation(scenario, robot, plan, outcomes, track, tolerance, warnings)
