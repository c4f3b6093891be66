"""What makes two derived scenarios the same: a canonical fingerprint of the scenario's content.

Two scenarios are equal when they would run the same, whatever the steps named along the way:

- ids are ignored where derivations rename them: the scenario's, its mission's and its
  environment's (``derive`` gives each derivation its own), and the ids of obstacles' poses;
- a task counts by its waypoints (position and orientation, subtask by subtask), not by its id or
  source file: reversing a task's waypoints twice gives the task back under another id, and is
  the base again;
- a robot the base does not have (one a step minted, e.g. ``add_robot``) counts by the order it
  appears in among the minted ones, and its namespace (its id, as ``add_robot`` makes it) likewise;
  a robot the base has keeps its id and namespace;
- robots are a set (their order in the fleet is ignored); for a parallel mission, the allocation
  is each robot's sequence of tasks (how robots' entries interleave is ignored: each robot runs
  its own), for a sequential one it is the whole order;
- source locations, the way numbers were written and the declared metrics are ignored (they are
  not compared by the model either).
"""

from __future__ import annotations

import hashlib
from collections.abc import Collection

from exsce_dsl.model import Pose, Scenario, Task
from exsce_dsl.model.scenario import MissionType

Canonical = tuple[object, ...]


def fingerprint(scenario: Scenario, base_robots: Collection[str]) -> str:
    """A digest of :func:`canonical_scenario`; ``base_robots`` are the ids the base's robots have
    (any other robot id was minted by a step)."""
    return hashlib.sha256(repr(canonical_scenario(scenario, base_robots)).encode()).hexdigest()


def canonical_scenario(scenario: Scenario, base_robots: Collection[str]) -> Canonical:
    minted = [r.id for r in scenario.robots if r.id not in base_robots]
    names = {robot_id: f"<minted robot {n}>" for n, robot_id in enumerate(minted, start=1)}

    def name(robot_id: str) -> str:
        return names.get(robot_id, robot_id)

    tasks = {t.id: _task(t) for t in scenario.tasks}
    robots = sorted(
        (
            name(r.id),
            (r.type.id, r.type.base, r.type.torso, repr(r.signals)),
            name(r.namespace) if r.namespace == r.id else r.namespace,
            None if r.start_pose is None else _pose(r.start_pose),
        )
        for r in scenario.robots
    )
    allocation: Canonical
    if scenario.mission.type is MissionType.SEQUENTIAL:
        allocation = tuple((name(a.robot), tasks[a.task]) for a in scenario.mission.allocation)
    else:
        allocation = tuple(
            sorted(
                (name(r.id), tuple(tasks[t] for t in scenario.mission.tasks_of(r.id)))
                for r in scenario.robots
            )
        )
    env = scenario.environment
    areas = tuple((a.id, tuple((p.id, _pose(p)) for p in a.poses)) for a in env.areas)
    obstacles = tuple((o.id, _pose(o.pose), o.model, o.size) for o in env.obstacles)
    return (
        (repr(env.map), repr(env.world), areas, obstacles),
        tuple(robots),
        scenario.mission.type.value,
        allocation,
    )


def _pose(pose: Pose) -> Canonical:
    p, o = pose.position, pose.orientation
    return (p.x, p.y, p.z, o.roll, o.pitch, o.yaw)


def _task(task: Task) -> Canonical:
    return tuple(tuple(_pose(w) for w in s.waypoints) for s in task.subtasks)
