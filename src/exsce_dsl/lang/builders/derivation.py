"""Build ``derive NAME from BASE { ... }`` blocks: each step becomes an input transformation,
applied to the base scenario in order; a step that cannot apply is reported at its line."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import replace
from typing import Any

from exsce_dsl.errors import ExsceError, SourceLocation
from exsce_dsl.lang.builders.checks import check_environment_map
from exsce_dsl.lang.builders.context import Declared, Report, name_span, report_duplicate
from exsce_dsl.lang.builders.references import UnknownNames
from exsce_dsl.lang.parser import ParsedFile
from exsce_dsl.lang.transformation_syntax import step_of, written_arguments
from exsce_dsl.model import Environment, Scenario, Task
from exsce_dsl.model.derived import DerivedScenario, Step
from exsce_dsl.transform import TRANSFORMATIONS, derive


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
    environment = base.environment
    for step in steps:  # apply one more step at a time, to place an error at its step
        done.append(step)
        try:
            derived = derive(base, [(s.transformation, dict(s.arguments)) for s in done], tree.name, tasks)
        except ExsceError as exc:
            report(exc.message, step.location)
            return None
        for moved in _moved_obstacles(step, environment, derived.scenario.environment):
            for problem in _obstacle_map_problems(derived.scenario.environment, moved, step.location):
                report(problem, step.location)
        environment = derived.scenario.environment
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


def _moved_obstacles(step: Step, before: Environment, after: Environment) -> list[str]:
    """The obstacles ``step`` names that it put elsewhere."""
    record = TRANSFORMATIONS[step.transformation]
    named = [step.argument(p.name) for p in record.parameters if p.type == "obstacle"]
    was = {o.id: o.pose.position for o in before.obstacles}
    now = {o.id: o.pose.position for o in after.obstacles}
    return [o for o in named if o is not None and o in now and was.get(o) != now[o]]


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
