"""Build ``scenario`` declarations: the environment, the robots and the mission's allocation."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

from exsce_dsl.errors import SourceLocation
from exsce_dsl.lang.builders.context import BuildContext, Declared, name_span
from exsce_dsl.lang.builders.references import not_in_fleet
from exsce_dsl.lang.builders.robots import build_robots
from exsce_dsl.lang.builders.tasks import timeout_of
from exsce_dsl.lang.parser import ParsedFile
from exsce_dsl.model import Assignment, Mission, MissionType, Scenario, Task


def build_scenario(ctx: BuildContext, d: Declared) -> Scenario | None:
    """The scenario ``d`` declares (None: it has errors, reported, or uses a task that has)."""
    pf, sc = d.file, d.obj
    ok = True
    env = ctx.environments.get(sc.environment.name)
    if env is None:
        ctx.unknown_name("environment", sc.environment.name, pf.span(sc.environment), ctx.environments)
        ok = False
    robots, fleet, robots_ok = build_robots(ctx, pf, sc, env)
    mission = _mission(ctx, pf, sc, fleet)
    if mission is None or env is None or not ok or not robots_ok:
        return None
    used: dict[str, Task] = {}
    for entry in mission.allocation:
        task = ctx.tasks.get(entry.task)
        if task is None:
            return None  # reported where the task is declared or referenced
        used.setdefault(task.id, task)
    return Scenario(sc.name, env, tuple(robots), mission, tuple(used.values()), d.name_location)


def _mission(
    ctx: BuildContext, pf: ParsedFile, sc: Any, fleet: Mapping[str, SourceLocation]
) -> Mission | None:
    m = sc.mission
    if m is None:
        ctx.error(
            f"scenario '{sc.name}' has no mission; add 'mission <id> parallel {{ ... }}'",
            name_span(pf, sc),
        )
        return None
    allocation: list[Assignment] = []
    ok = True
    for line in m.assignments:
        robot = line.robot.name
        if robot not in fleet:
            ctx.error(not_in_fleet(robot, sc.name, fleet), pf.span(line.robot), code="reference")
            ok = False
        for ref in line.tasks:
            if ref.name not in ctx.declared["Task"]:
                ctx.unknown_name("task", ref.name, pf.span(ref), ctx.declared["Task"])
                ok = False
            allocation.append(Assignment(robot, ref.name, pf.span(ref)))
    if not m.assignments:
        ctx.error(f"mission '{m.name}' allocates no task", name_span(pf, m))
        ok = False
    timeout, written, fine = timeout_of(ctx, pf, m.timeout, f"mission '{m.name}'")
    if not ok or not fine:
        return None
    kind, where = MissionType(m.kind), name_span(pf, m)
    return Mission(m.name, kind, tuple(allocation), where, timeout, written)
