"""Build acceptance criteria (``acceptance for <scenario> { ... }``) from their parse trees.

Every name is resolved against the scenario the criteria are for (its robots, its
mission, the tasks it allocates to each robot and their waypoints) and every
quantity is checked against the metric's dimension; each problem is reported at
its ``file:line:col`` and all of them at once.
"""

from __future__ import annotations

import re
from collections.abc import Iterable, Mapping, Sequence
from typing import Any

from exsce_dsl.errors import SourceLocation
from exsce_dsl.lang.builders.context import Report
from exsce_dsl.lang.builders.references import UnknownNames, not_in_fleet
from exsce_dsl.lang.builders.standard_metrics import known_metrics
from exsce_dsl.lang.parser import ParsedFile
from exsce_dsl.model import Scenario
from exsce_dsl.model.acceptance import (
    Acceptance,
    AtStartPose,
    BaselineRuns,
    BasicRelation,
    Criterion,
    Expectation,
    Given,
    Moment,
    Quantifier,
    Quantity,
    Subject,
    When,
    Window,
)
from exsce_dsl.model.metrics import SI_UNIT, UNITS, Dimension, MetricInfo
from exsce_dsl.suggest import did_you_mean

_QUANTITY = re.compile(r"(\S+?)\s*(m/s|cm/s|km/h|rad/s|deg/s|mm|cm|km|ms|min|std|rad|deg|m|s|h|%)?")


def build_all_acceptance(
    files: Sequence[ParsedFile],
    scenarios: Mapping[str, Scenario],
    declared_scenarios: Mapping[str, object],
    report: Report,
    unknown: UnknownNames,
) -> dict[int, Acceptance]:
    """Every acceptance block of ``files`` (one per scenario), by the id of its parse tree node."""
    first: dict[str, SourceLocation] = {}
    built: dict[int, Acceptance] = {}
    for pf in files:
        for decl in pf.tree.declarations:
            if decl.__class__.__name__ != "Acceptance":
                continue
            where, name = pf.span(decl.scenario), decl.scenario.name
            if name in first:
                report(
                    f"scenario '{name}' has acceptance criteria already (at {first[name]}); "
                    "put them in one block",
                    where,
                )
                continue
            first[name] = where
            acceptance = build_acceptance(pf, decl, scenarios, declared_scenarios, report, unknown)
            if acceptance is not None:
                built[id(decl)] = acceptance
    return built


def build_acceptance(
    pf: ParsedFile,
    tree: Any,
    scenarios: Mapping[str, Scenario],
    declared_scenarios: Mapping[str, object],
    report: Report,
    unknown: UnknownNames,
) -> Acceptance | None:
    """The criteria of one ``acceptance`` block, or None when it names no valid scenario."""
    name = tree.scenario.name
    scenario = scenarios.get(name)
    if scenario is None:
        if name not in declared_scenarios:
            where = pf.span(tree.scenario)
            if (message := unknown.message("scenario", name, where, declared_scenarios)) is not None:
                report(message, where)
        return None  # a scenario with errors of its own: those are reported where it is
    builder = _AcceptanceBuilder(pf, scenario, declared_scenarios, report, unknown)
    criteria = tuple(builder.criterion(c) for c in tree.criteria)
    titles: dict[str, SourceLocation] = {}
    for criterion, node in zip(criteria, tree.criteria, strict=True):
        where = pf.span(node)
        if criterion.title in titles:
            report(
                f'two acceptance scenarios are called "{criterion.title}" '
                f"(the first at {titles[criterion.title]})",
                where,
            )
        titles.setdefault(criterion.title, where)
    if not tree.criteria:
        report(
            f"the acceptance criteria of '{name}' have no scenario; add 'scenario \"...\" {{ then ... }}'",
            pf.span(tree.scenario),
        )
    return None if builder.failed else Acceptance(name, criteria, pf.span(tree))


class _AcceptanceBuilder:
    def __init__(
        self,
        pf: ParsedFile,
        scenario: Scenario,
        declared: Mapping[str, object],
        report: Report,
        unknown: UnknownNames,
    ) -> None:
        self.pf = pf
        self.unknown = unknown
        self.scenario = scenario
        self.declared = declared
        self._report = report
        self.failed = False
        self.robots = {r.id: r for r in scenario.robots}

    def error(self, message: str, where: SourceLocation | None) -> None:
        self.failed = True
        self._report(message, where)

    def unknown_name(self, kind: str, name: str, where: SourceLocation, known: Iterable[str]) -> None:
        self.failed = True
        if (message := self.unknown.message(kind, name, where, known)) is not None:
            self._report(message, where)

    def criterion(self, node: Any) -> Criterion:
        givens = tuple(g for g in (self.given(n) for n in node.givens) if g is not None)
        when = self.when(node.when) if node.when is not None else None
        expectations = tuple(e for e in (self.expectation(n, when) for n in node.expectations) if e)
        return Criterion(node.title, givens, when, expectations, self.pf.span(node))

    # -- given / when ------------------------------------------------------------

    def given(self, node: Any) -> Given | None:
        where = self.pf.span(node)
        if node.__class__.__name__ == "BaselineRuns":
            if node.runs < 1:
                self.error("a baseline needs at least 1 run", where)
                return None
            return BaselineRuns(node.runs, where)
        subject = self.subject(node.subject)
        return AtStartPose(subject, where) if subject is not None else None

    def when(self, node: Any) -> When | None:
        where = self.pf.span(node)
        if node.__class__.__name__ == "MissionRuns":
            mission = self.scenario.mission.id
            if node.mission.name != mission:
                self.error(
                    f"the mission of scenario '{self.scenario.id}' is '{mission}', not '{node.mission.name}'",
                    self.pf.span(node.mission),
                )
                return None
            return When(mission=mission, location=where)
        robot = self.robot(node.robot)
        if robot is None or not self.task_of(robot, node.task):
            return None
        return When(robot=robot, task=node.task.name, location=where)

    # -- names -------------------------------------------------------------------

    def robot(self, ref: Any) -> str | None:
        if ref.name not in self.robots:
            self.error(not_in_fleet(ref.name, self.scenario.id, self.robots), self.pf.span(ref))
            return None
        return str(ref.name)

    def task_of(self, robot: str, ref: Any) -> bool:
        tasks = self.scenario.mission.tasks_of(robot)
        if ref.name not in tasks:
            self.error(
                f"mission '{self.scenario.mission.id}' does not give task '{ref.name}' to '{robot}'"
                + (f" (its tasks: {', '.join(tasks)})" if tasks else " (it has no tasks)"),
                self.pf.span(ref),
            )
            return False
        return True

    def subject(self, node: Any) -> Subject | None:
        if node.__class__.__name__ == "EachRobot":
            return Subject(Quantifier.EACH_ROBOT)
        robot = self.robot(node.robot)
        return Subject(Quantifier.ROBOT, robot) if robot is not None else None

    # -- then --------------------------------------------------------------------

    def expectation(self, node: Any, when: When | None) -> Expectation | None:
        where = self.pf.span(node)
        metric_ref = node.metric
        metrics = known_metrics(self.scenario)
        info = metrics.get(metric_ref.name)
        if info is None:
            self.unknown_name("metric", metric_ref.name, self.pf.span(metric_ref), metrics)
            return None
        subject = Subject(Quantifier.MISSION) if node.subject is None else self.subject(node.subject)
        if subject is None:
            return None
        if not self.scope_fits(info, subject, where):
            return None
        if (
            when is not None
            and when.robot is not None
            and node.window is None
            and info.per_segment
            and subject.robot != when.robot
        ):
            self.error(
                f"'when {when.text()}' looks at {when.robot}'s task: a clause on '{info.name}' there "
                f"is about {when.robot} (write '{when.robot} {info.name} ...')",
                where,
            )
            return None
        relation, kind = node.relation, node.relation.__class__.__name__
        against = None
        if getattr(relation, "against", None) is not None and relation.against.scenario is not None:
            against = self.base_scenario(relation.against.scenario)
            if against is None:
                return None
        if kind == "StaysBelow" or kind == "StaysAbove":
            limit = clause_quantity(relation.limit, info, where, self.error)
            if limit is None:
                return None
            rel = BasicRelation.BELOW_MAX if kind == "StaysBelow" else BasicRelation.ABOVE_MIN
            window = self.window(node.window, info)
            if node.window is not None and window is None:
                return None
            return Expectation(subject, info.name, rel, limit=limit, window=window, location=where)
        return self.comparison(node, subject, info, against, where)

    def comparison(
        self, node: Any, subject: Subject, info: MetricInfo, against: str | None, where: SourceLocation
    ) -> Expectation | None:
        """A clause that compares with a value or another scenario: ``is invariant``,
        ``is increasing``, ``is decreasing``."""
        relation, kind = node.relation, node.relation.__class__.__name__
        value = tolerance = delta = None
        if (
            relation.value is not None
            and (value := clause_quantity(relation.value, info, where, self.error)) is None
        ):
            return None
        if relation.tolerance is not None:
            tolerance = clause_quantity(relation.tolerance, info, where, self.error, relative=True)
            if tolerance is None:
                return None
        confidence = None
        if relation.confidence is not None:
            confidence = confidence_of(self.pf, relation, kind, value, self.error)
            if confidence is None:
                return None
        if kind == "Invariant":
            rel = BasicRelation.INVARIANT
        else:
            rel = BasicRelation.INCREASING if relation.direction == "increasing" else BasicRelation.DECREASING
            if (
                relation.delta is not None
                and (delta := clause_quantity(relation.delta, info, where, self.error)) is None
            ):
                return None
            if against is None and value is None:
                self.error(
                    f"'is {relation.direction}' compares with the scenario this one was derived from: "
                    f"add 'of <scenario>', or a value to start from ('from <value>')",
                    where,
                )
                return None
        window = self.window(node.window, info)
        if node.window is not None and window is None:
            return None
        return Expectation(
            subject,
            info.name,
            rel,
            value=value,
            delta=delta,
            tolerance=tolerance,
            against=against,
            window=window,
            location=where,
            confidence=confidence,
        )

    def scope_fits(self, info: MetricInfo, subject: Subject, where: SourceLocation) -> bool:
        if subject.quantifier is Quantifier.MISSION and info.per_robot and not info.also_mission:
            self.error(
                f"'{info.name}' is measured per robot: say of whom ('each robot' or a robot's name)", where
            )
            return False
        if subject.quantifier is not Quantifier.MISSION and not info.per_robot:
            self.error(f"'{info.name}' is measured for the whole mission: drop '{subject.text()}'", where)
            return False
        return True

    def base_scenario(self, ref: Any) -> str | None:
        if ref.name == self.scenario.id:
            self.error(
                f"a scenario is compared with its own runs by 'of baseline', not 'of {ref.name}'",
                self.pf.span(ref),
            )
            return None
        if ref.name not in self.declared:
            self.unknown_name("scenario", ref.name, self.pf.span(ref), self.declared)
            return None
        return str(ref.name)

    def window(self, node: Any, info: MetricInfo) -> Window | None:
        if node is None:
            return None
        where = self.pf.span(node)
        if not info.per_segment:
            per = [m.name for m in known_metrics(self.scenario).values() if m.per_segment]
            self.error(
                f"'{info.name}' has no value per path segment, so it cannot be looked at "
                f"{node.moment} part of a run (only {', '.join(per)} can)",
                where,
            )
            return None
        moment = Moment(node.moment)
        if node.__class__.__name__ == "TaskWindow":
            owners = [r for r in self.robots if node.task.name in self.scenario.mission.tasks_of(r)]
            if not owners:
                self.error(
                    f"mission '{self.scenario.mission.id}' allocates no task '{node.task.name}'",
                    self.pf.span(node.task),
                )
                return None
            return Window(moment, owners[0], task=node.task.name, location=where)
        robot = self.robot(node.robot)
        if robot is None:
            return None
        goals = {
            p.id
            for t in self.scenario.mission.tasks_of(robot)
            for task in (self.scenario.task(t),)
            if task is not None
            for p in task.waypoints()
        }
        if node.pose.name not in goals:
            self.error(
                f"'{robot}' never goes to '{node.pose.name}'{did_you_mean(node.pose.name, goals)}",
                self.pf.span(node.pose),
            )
            return None
        return Window(moment, robot, pose=node.pose.name, location=where)


def confidence_of(
    pf: ParsedFile, relation: Any, kind: str, value: Quantity | None, error: Report
) -> Quantity | None:
    """``at 99 %``: a per cent strictly between 50 and 100, of an invariant around a mean."""
    text = relation.confidence
    where = _confidence_span(pf, relation, text)
    if kind != "Invariant":
        error(
            f"'at {text}' is for 'is invariant': a change is judged against another scenario's "
            "runs moved by a delta, which their spread cannot promise to hold with a confidence; "
            "write a tolerance ('within ...')",
            where,
        )
        return None
    if value is not None:
        error(
            f"'at {text}' is a band around the baseline's mean, from its runs; around a fixed "
            "value write a tolerance ('within ...')",
            where,
        )
        return None
    match = _QUANTITY.fullmatch(text)
    assert match is not None, text  # the grammar lets only such tokens through
    number, unit = match.group(1), match.group(2)
    if unit != "%":
        error(f"a confidence is in per cent ('at 99 %'), not '{text}'", where)
        return None
    if not 50.0 < float(number) < 100.0:
        error(
            f"a confidence must be between 50 % and 100 % (exclusive), not '{text}': "
            "'at 95 %' fails one healthy run in 20, 'at 99 %' one in 100",
            where,
        )
        return None
    return Quantity(float(number), "%", number)


def _confidence_span(pf: ParsedFile, relation: Any, text: str) -> SourceLocation:
    """Where ``at <confidence>`` is written in the relation (the parse tree keeps no position
    for a matched token)."""
    start, end = relation._tx_position, relation._tx_position_end
    found = list(re.finditer(r"\bat\s+" + re.escape(text), pf.text[start:end]))
    if not found:
        return pf.span(relation)
    return pf.lines.span(start + found[-1].start(), start + found[-1].end())


def clause_quantity(
    text: str, info: MetricInfo, where: SourceLocation, error: Report, relative: bool = False
) -> Quantity | None:
    """A quantity of a clause on ``info``, in its unit (``std`` and ``%`` only where ``relative``)."""
    match = _QUANTITY.fullmatch(text)
    assert match is not None, text  # the grammar lets only such tokens through
    number, unit = match.group(1), match.group(2)
    value = float(number)
    if unit in ("std", "%"):
        if not relative:
            error(f"'{text}' is relative: 'std' and '%' are for tolerances ('within 1 std')", where)
            return None
        if value < 0:
            error(f"a tolerance cannot be negative ('{text}')", where)
            return None
        return Quantity(value, unit, number)
    if unit is None:
        return Quantity(value, None, number)
    dimension, factor = UNITS[unit]
    if dimension is not info.dimension:
        wanted = SI_UNIT[info.dimension] or "a plain number"
        what = "a count" if info.dimension is Dimension.COUNT else f"a {info.dimension.value}"
        error(f"'{info.name}' is {what}, in {wanted}; '{text}' is a {dimension.value}", where)
        return None
    if relative and value < 0:
        error(f"a tolerance cannot be negative ('{text}')", where)
        return None
    return Quantity(value * factor, unit, number)
