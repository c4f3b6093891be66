"""Build ``derive NAME from BASE { ... }`` blocks: each step becomes an input transformation,
applied to the base scenario in order; a step that cannot apply is reported at its line."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import replace
from typing import Any

from exsce_dsl.errors import ExsceError, SourceLocation
from exsce_dsl.lang.build.checks import check_environment_map
from exsce_dsl.lang.build.context import Declared, Report, name_span, report_duplicate
from exsce_dsl.lang.build.poses import position_of
from exsce_dsl.lang.build.references import UnknownNames
from exsce_dsl.lang.lexical import quantity_text
from exsce_dsl.lang.parser import ParsedFile
from exsce_dsl.model import Environment, Scenario, Task
from exsce_dsl.model.derived import DerivedScenario, Step
from exsce_dsl.transform.derivation import derive


def _name(ref: Any) -> str | None:
    return None if ref is None else str(ref.name)


def step_of(node: Any) -> tuple[str, dict[str, str | None]]:
    """The transformation a step of the grammar names, with its arguments."""
    kind = node.__class__.__name__
    if kind == "RemoveRobot":
        return "remove_robot", {"robot": _name(node.robot), "reassign": _name(node.heir)}
    if kind == "AddRobot":
        return "add_robot", {
            "robot": node.robot,
            "like": _name(node.like),
            "start": _name(node.start),
            "take_over": _name(node.donor),
        }
    if kind == "ReplaceRobot":
        return "replace_robot", {
            "robot": _name(node.robot),
            "by": node.new,
            "like": _name(node.like),
            "start": _name(node.start),
        }
    if kind in ("SwapTasks", "SwapStartPoses"):
        name = "swap_assignment" if kind == "SwapTasks" else "swap_start_poses"
        return name, {"robot": _name(node.robot), "with": _name(node.other)}
    if kind == "ReverseWaypoints":
        return "reverse_waypoint_order", {"task": _name(node.task), "as": node.new or None}
    if kind == "ReverseTaskOrder":
        return "reverse_task_order", {"robot": _name(node.robot)}
    if kind == "AddTask":
        position = str(node.position) if node.position else None
        return "add_task", {"task": _name(node.task), "robot": _name(node.robot), "position": position}
    if kind == "RemoveTasksOf":
        return "remove_task", {"robot": _name(node.robot)}
    if kind == "RemoveTask":
        return "remove_task", {"task": _name(node.task), "robot": _name(node.robot)}
    if kind == "SubstituteTask":
        return "substitute_task", {"task": _name(node.task), "with": _name(node.other)}
    if kind == "StartAt":
        return "add_start_pose", {"robot": _name(node.robot), "pose": _name(node.pose)}
    if kind == "RemoveStartPose":
        return "remove_start_pose", {"robot": _name(node.robot)}
    if kind == "MoveObstacle":
        p = position_of(node.position)
        metres = [p.x, p.y] + ([p.z] if p.z != 0.0 else [])  # as move_obstacle records it
        return "move_obstacle", {"obstacle": _name(node.obstacle), "to": ",".join(repr(v) for v in metres)}
    assert kind == "Reallocate", kind
    entries = [f"{a.robot.name}:{t.name}" for a in node.assignments for t in a.tasks]
    return "substitute_allocation", {"allocation": ",".join(entries)}


def written_arguments(node: Any) -> tuple[tuple[str, str], ...]:
    """The arguments of a step whose text is not their value's (see :attr:`Step.written`)."""
    if node.__class__.__name__ == "MoveObstacle":
        texts = [node.position.x, node.position.y] + (
            [node.position.z] if node.position.z is not None else []
        )
        return (("to", ", ".join(quantity_text(t) for t in texts)),)
    return ()


def build_derivation(
    pf: ParsedFile,
    tree: Any,
    scenarios: Mapping[str, Scenario],
    declared_scenarios: Mapping[str, object],
    tasks: Mapping[str, Task],
    report: Report,
    unknown: UnknownNames,
) -> DerivedScenario | None:
    base = scenarios.get(tree.base.name)
    if base is None:
        if tree.base.name not in declared_scenarios:
            where = pf.span(tree.base)
            message = unknown.message("scenario", tree.base.name, where, declared_scenarios)
            if message is not None:
                report(message, where)
        return None  # a base with errors of its own: reported where it is
    steps = []
    for node in tree.steps:
        name, arguments = step_of(node)
        given = tuple((k, v) for k, v in arguments.items() if v is not None)
        steps.append(Step(name, given, pf.span(node), written_arguments(node)))
    done: list[Step] = []
    derived = None
    for step in steps:  # apply one more step at a time, to place an error at its step
        done.append(step)
        try:
            derived = derive(base, [(s.transformation, dict(s.arguments)) for s in done], tree.name, tasks)
        except ExsceError as exc:
            report(exc.message, step.location)
            return None
        if step.transformation == "move_obstacle":
            moved = str(step.argument("obstacle"))
            for problem in _obstacle_map_problems(derived.scenario.environment, moved, step.location):
                report(problem, step.location)
    assert derived is not None  # the grammar asks for one step at least
    return DerivedScenario(
        tree.name,
        base.id,
        tuple(steps),
        derived.scenario,
        derived.new_tasks,
        derived.derivation,
        pf.span(tree),
    )


def _obstacle_map_problems(env: Environment, obstacle_id: str, where: SourceLocation | None) -> list[str]:
    """What the map check says of one obstacle of ``env`` (the map's own problems are
    reported where the map is declared)."""
    obstacle = next(o for o in env.obstacles if o.id == obstacle_id)
    alone = replace(env, areas=(), obstacles=(replace(obstacle, location=where),))
    return [d.message for d in check_environment_map(alone) if d.location == where]


def build_derivations(
    files: Sequence[ParsedFile],
    scenarios: dict[str, Scenario],
    declared: dict[str, Declared],
    tasks: Mapping[str, Task],
    report: Report,
    unknown: UnknownNames,
) -> dict[int, DerivedScenario]:
    """Every derive block of ``files``, bases first (one may start from a derived scenario).

    The derived scenarios join ``scenarios`` and their names ``declared``;
    returns them by the id of their parse tree node.
    """
    pending = [(pf, d) for pf in files for d in pf.tree.declarations if d.__class__.__name__ == "Derivation"]
    for pf, decl in list(pending):
        made = Declared(decl, pf, name_span(pf, decl))
        first = declared.get(decl.name)
        if report_duplicate(
            "scenario", decl.name, first.name_location if first else None, made.name_location, report
        ):
            pending.remove((pf, decl))
            continue
        declared[decl.name] = made
    built: dict[int, DerivedScenario] = {}
    while pending:
        waiting = {other.name for _, other in pending}
        ready = [(pf, d) for pf, d in pending if d.base.name in scenarios or d.base.name not in waiting]
        if not ready:
            for pf, decl in pending:
                report(f"scenario '{decl.name}' is derived, through others, from itself", pf.span(decl.base))
            break
        for pf, decl in ready:
            pending.remove((pf, decl))
            derived = build_derivation(pf, decl, scenarios, declared, tasks, report, unknown)
            if derived is not None:
                built[id(decl)] = derived
                scenarios[derived.id] = derived.scenario
    return built
