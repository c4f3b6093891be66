"""Import and export of the method's oracle files (``oracles/<scenario>.yaml``).

An oracle file has the scenario's ``id`` and a section per scenario whose runs are compared
with: ``baseline`` (``base_scenario`` is the scenario itself) and ``metamorphic`` (the one
it was derived from).  A section holds, for the mission and for each robot, one entry per
metric: its ``topics``, its numbers (``baseline``) and its ``relationship``.  Here a section
is one acceptance :class:`Criterion` and an entry one :class:`Expectation` with fixed
numbers.  The DSL cannot name topics yet, so a file whose topics are not the defaults
(:func:`default_topics`) is refused rather than imported with another meaning.
"""

from __future__ import annotations

import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import yaml

from exsce_dsl.errors import ExportError, ImportFormatError, OracleFileErrors, SourceLocation
from exsce_dsl.lang.builders.standard_metrics import known_metrics, metric_info
from exsce_dsl.lang.format.acceptance import expectation_text
from exsce_dsl.lang.yaml.located import YamlFile, YamlNode, child_node, node_location
from exsce_dsl.model import Document, Import, Scenario, Specification
from exsce_dsl.model.acceptance import (
    Acceptance,
    BasicRelation,
    Criterion,
    Expectation,
    Quantifier,
    Quantity,
    Subject,
    When,
)
from exsce_dsl.model.metrics import SI_UNIT, Dimension, MetricInfo, default_topics
from exsce_dsl.model.names import NUMBER, is_valid_name
from exsce_dsl.suggest import did_you_mean

#: The only relationship package an oracle file may name (the method's relations, in exsce).
RELATIONSHIPS_PACKAGE = "exsce.metamorphic.relationships"

#: The sections of an oracle file, in the order they are written.
SECTIONS = ("baseline", "metamorphic")

Baseline = Mapping[tuple[str, str | None], tuple[float, float]]
"""(metric, robot or None for the mission) → (mean, standard deviation) of stored runs."""

_LIMIT, _VALUE, _CHANGE = ("limit",), ("value", "tolerance"), ("value", "delta", "tolerance")
_NUMBERS = {
    BasicRelation.BELOW_MAX: _LIMIT,
    BasicRelation.ABOVE_MIN: _LIMIT,
    BasicRelation.INVARIANT: _VALUE,
    BasicRelation.INCREASING: _CHANGE,
    BasicRelation.DECREASING: _CHANGE,
}
"""The numbers each relation takes, in the order they are written; the first is required."""


# -- import ---------------------------------------------------------------------------------


def is_oracle_yaml(path: Path) -> bool:
    """Whether ``path`` is an oracle file (it has a ``baseline`` or ``metamorphic`` section)."""
    data = YamlFile.read(path).data
    return isinstance(data, Mapping) and any(section in data for section in SECTIONS)


def import_oracle_yaml(path: Path, scenario: Scenario) -> Acceptance:
    """The acceptance criteria of an oracle file of ``scenario``; every problem found is
    raised at once, each at its ``file:line:col``.  Nothing the file names is imported."""
    return _OracleReader(YamlFile.read(path), scenario).acceptance()


def import_oracles(path: Path, spec: Specification) -> Acceptance:
    """Like :func:`import_oracle_yaml`, for the scenario of ``spec`` that the file's ``id`` names."""
    file = YamlFile.read(path)
    id_node = file.root_node().get("id")
    scenario_id = id_node.ident("scenario")
    declared = {s.id: s for s in spec.scenarios}
    if scenario_id not in declared:
        raise id_node.error(
            f"oracles for scenario '{scenario_id}', which {spec.root} does not declare"
            f"{did_you_mean(scenario_id, declared)}"
        )
    return _OracleReader(file, declared[scenario_id]).acceptance()


def acceptance_document(acceptance: Acceptance, spec_path: Path, out_dir: Path) -> Document:
    """The criteria as a file of their own in ``out_dir``, importing the spec of their scenario."""
    spec_import = Path(os.path.relpath(spec_path.resolve(), out_dir.resolve())).as_posix()
    return Document(f"{acceptance.scenario}_acceptance.exsce", (Import(spec_import),), (acceptance,))


class _OracleReader:
    def __init__(self, file: YamlFile, scenario: Scenario) -> None:
        self.file = file
        self.scenario = scenario
        self.problems: list[ImportFormatError] = []

    def report(self, message: str, location: SourceLocation) -> None:
        self.problems.append(ImportFormatError(message, location))

    def acceptance(self) -> Acceptance:
        root = self.file.root_node()
        criteria: list[Criterion] = []
        try:
            id_node = root.get("id")
            if (file_id := id_node.ident("scenario")) != self.scenario.id:
                self.report(
                    f"these are oracles of scenario '{file_id}', not of '{self.scenario.id}'",
                    id_node.location,
                )
            for key, section in root.items_of_mapping():
                if key in SECTIONS:
                    criterion = self.section(section, {c.title for c in criteria})
                    criteria += [criterion] if criterion is not None else []
                elif key != "id":
                    hint = did_you_mean(key, SECTIONS) or f"; the sections are {' and '.join(SECTIONS)}"
                    self.report(f"unknown section '{key}'{hint}", _key_location(root, key))
            if not criteria and not self.problems:
                self.report(f"no {' or '.join(SECTIONS)} section: no oracles to import", root.location)
        except ImportFormatError as problem:
            self.problems.append(problem)
        if self.problems:
            raise self.problems[0] if len(self.problems) == 1 else OracleFileErrors(self.problems)
        return Acceptance(self.scenario.id, tuple(criteria), root.location)

    def section(self, node: YamlNode, titles: set[str]) -> Criterion | None:
        base = node.get("base_scenario")
        base_id = base.ident("scenario")
        against = None if base_id == self.scenario.id else base_id
        title = "baseline" if against is None else f"against {base_id}"
        if title in titles:
            self.report(f"a second section compares with the runs of '{base_id}'", base.location)
        fleet = {r.id for r in self.scenario.robots}
        expectations: list[Expectation | None] = []
        for key, part in node.items_of_mapping():
            if key == "mission":
                expectations += [self.entry(part, metric, None, against) for metric, _ in _entries(part)]
            elif key == "robots":
                for robot, metrics in _entries(part):
                    if robot not in fleet:
                        self.report(
                            f"robot '{robot}' is not in the fleet of scenario '{self.scenario.id}'"
                            f"{did_you_mean(robot, fleet)}",
                            _key_location(part, robot),
                        )
                        continue
                    expectations += [
                        self.entry(metrics, metric, robot, against) for metric, _ in _entries(metrics)
                    ]
            elif key != "base_scenario":
                self.report(
                    f"unknown key '{key}' in {node.where}{did_you_mean(key, ('mission', 'robots'))}",
                    _key_location(node, key),
                )
        found = tuple(e for e in expectations if e is not None)
        if not expectations:
            self.report(f"{node.where} has no metrics under 'mission' or 'robots'", node.location)
        if not found:
            return None
        return Criterion(title, (), When(mission=self.scenario.mission.id), found, node.location)

    def entry(
        self, parent: YamlNode, metric: str, robot: str | None, against: str | None
    ) -> Expectation | None:
        """The clause of one metric entry; None (with the problems reported) if it has any."""
        known = len(self.problems)
        try:
            info = self.metric(parent, metric, robot)
            node = parent.get(metric)
            relation = self.relation(node.get("relationship"))
            topics = node.opt("topics")
            if topics is not None and info is not None:
                self.check_topics(topics, metric, robot)
            numbers = node.get("baseline")
            quantities = self.numbers(numbers, relation, info) if relation and info else None
        except ImportFormatError as problem:
            self.problems.append(problem)
            return None
        if quantities is None or relation is None or len(self.problems) > known:
            return None
        subject = Subject(Quantifier.MISSION) if robot is None else Subject(Quantifier.ROBOT, robot)
        q = quantities.get
        return Expectation(
            subject,
            metric,
            relation,
            limit=q("limit"),
            value=q("value"),
            delta=q("delta"),
            tolerance=q("tolerance"),
            against=against,
            location=node.location,
        )

    def metric(self, parent: YamlNode, metric: str, robot: str | None) -> MetricInfo | None:
        info = metric_info(metric, self.scenario)
        where = _key_location(parent, metric)
        if info is None:
            hint = (
                f"; '{metric}' is a robot: put it under 'robots'"
                if self.scenario.robot(metric)
                else did_you_mean(metric, known_metrics(self.scenario))
            )
            self.report(f"unknown metric '{metric}'{hint}", where)
        elif robot is None and info.per_robot and not info.also_mission:
            self.report(f"'{metric}' is measured per robot: put it under 'robots: <robot>:'", where)
        elif robot is not None and not info.per_robot:
            self.report(f"'{metric}' is measured for the whole mission: put it under 'mission'", where)
        else:
            return info
        return None

    def relation(self, node: YamlNode) -> BasicRelation | None:
        package = node.opt("package")
        if package is not None and package.text() != RELATIONSHIPS_PACKAGE:
            self.report(
                f"relationship package '{package.value}' is not {RELATIONSHIPS_PACKAGE}: exsce's relations "
                "come from its own registry and the entry points of installed plugins, never from module "
                f"names in data files (nothing named here is imported); write {RELATIONSHIPS_PACKAGE}",
                package.location,
            )
        name_node = node.get("name")
        name = name_node.text()
        try:
            return BasicRelation(name)
        except ValueError:
            names = [r.value for r in BasicRelation]
            hint = did_you_mean(name, names) or f"; the method's relations are {', '.join(names)}"
            self.report(f"unknown relationship '{name}'{hint}", name_node.location)
            return None

    def check_topics(self, node: YamlNode, metric: str, robot: str | None) -> None:
        expected = default_topics(self.scenario, metric, robot)
        whose = f"'{robot}'" if robot else "the mission"
        items = list(node.items_of_list())
        texts = [item.text() for item in items]
        differ = [(item, text) for item, text in zip(items, texts, strict=True) if text not in expected]
        for item, text in differ:
            self.report(
                f"topic '{text}' is not one exsce computes {metric} of {whose} from "
                f"({', '.join(expected)}); the DSL cannot override a metric's topics yet",
                item.location,
            )
        missing = [t for t in expected if t not in texts]
        if missing and not differ:
            self.report(
                f"the topics of {metric} of {whose} lack {', '.join(missing)}; exsce computes it "
                f"from {', '.join(expected)}, and the DSL cannot override a metric's topics yet",
                node.location,
            )

    def numbers(
        self, node: YamlNode, relation: BasicRelation, info: MetricInfo
    ) -> dict[str, Quantity] | None:
        """The relation's numbers as quantities in the metric's SI unit, by field name."""
        keys = _NUMBERS[relation]
        for key, _ in node.items_of_mapping():
            if key not in keys:
                self.report(
                    f"'{key}' does not go with '{relation.value}', which takes {' and '.join(keys)}",
                    _key_location(node, key),
                )
        if node.opt(keys[0]) is None:
            self.report(
                f"'{relation.value}' needs a {keys[0]}: add '{keys[0]}: <number>' to {node.where}",
                node.location,
            )
            return None
        quantities = {}
        for key in keys:
            number = node.opt(key)
            if number is None:
                continue
            quantities[key] = _quantity(number, info)
            if key == "tolerance" and quantities[key].value < 0:
                self.report(f"a tolerance cannot be negative ({number.value})", number.location)
        return quantities


def _entries(node: YamlNode) -> list[tuple[str, YamlNode]]:
    """The keys of a mapping; nothing for an empty one (``mission:`` with no metric)."""
    return [] if node.value is None else list(node.items_of_mapping())


def _quantity(node: YamlNode, info: MetricInfo) -> Quantity:
    value = node.number()
    written = _scalar_text(node)
    return Quantity(value, SI_UNIT[info.dimension] or None, written if NUMBER.fullmatch(written) else "")


def _yaml_node(node: YamlNode) -> yaml.Node | None:
    current = node.file.tree
    for key in node.keys:
        current = child_node(current, key) if current is not None else None
    return current


def _scalar_text(node: YamlNode) -> str:
    """The number as the file writes it (``97.606``), for the DSL text to show the same."""
    tree = _yaml_node(node)
    return str(tree.value) if isinstance(tree, yaml.ScalarNode) else ""


def _key_location(parent: YamlNode, key: str) -> SourceLocation:
    """Where ``key`` itself is written in the mapping ``parent`` (an unknown name is the key)."""
    tree = _yaml_node(parent)
    if isinstance(tree, yaml.MappingNode):
        for key_node, _ in tree.value:
            if getattr(key_node, "value", None) == key:
                return node_location(parent.file.name, key_node.start_mark, key_node.end_mark)
    return parent.location


# -- export ---------------------------------------------------------------------------------


def export_oracle_yaml(acceptance: Acceptance, scenario: Scenario, baseline: Baseline | None = None) -> str:
    """The method's oracle file of ``acceptance`` (see :func:`oracles_to_yaml`)."""
    data = oracles_to_yaml(acceptance, scenario, baseline)
    text = yaml.safe_dump(data, sort_keys=False, allow_unicode=True)
    return f"# Oracles of scenario {scenario.id}, written by exsce\n{text}"


def export_oracle_file(
    acceptance: Acceptance, scenario: Scenario, out_dir: Path, baseline: Baseline | None = None
) -> Path:
    """Write ``oracles/<scenario>.yaml`` under ``out_dir``; return its path."""
    text = export_oracle_yaml(acceptance, scenario, baseline)  # checks the id before it becomes a path
    target = out_dir / "oracles" / f"{scenario.id}.yaml"
    target.parent.mkdir(parents=True, exist_ok=True)
    target.write_text(text, encoding="utf-8")
    return target


def oracles_to_yaml(
    acceptance: Acceptance, scenario: Scenario, baseline: Baseline | None = None
) -> dict[str, Any]:
    """The oracle file's content, keys in the method's order.

    ``each robot`` is every robot of the fleet.  A clause with no fixed value expects the
    mean of stored runs, taken from ``baseline`` with the metric and robot (or None for the
    mission) of the runs the clause compares with; without it, ``ExportError`` names the
    clause.  So do clauses the method's files cannot hold: windowed ones, and two of one
    metric and robot in a section.
    """
    if acceptance.scenario != scenario.id or not is_valid_name(scenario.id):
        raise ExportError(
            f"the acceptance criteria of '{acceptance.scenario}' are not those of scenario '{scenario.id}'",
            acceptance.location,
        )
    fleet = [r.id for r in scenario.robots]
    sections: dict[str, tuple[str, dict[str, Any], dict[str, dict[str, Any]]]] = {}
    written: dict[tuple[str, str, str | None], Expectation] = {}
    for criterion in acceptance.criteria:
        for e in criterion.expectations:
            _check_whole_run(e, criterion, scenario)
            key = "baseline" if e.against is None else "metamorphic"
            base = e.against or scenario.id
            _, mission, robots = sections.setdefault(key, (base, {}, {r: {} for r in fleet}))
            if sections[key][0] != base:
                raise ExportError(
                    f"'{expectation_text(e)}' compares with '{base}', but the method's oracle "
                    f"file has one metamorphic section (for '{sections[key][0]}' here)",
                    e.location,
                )
            for robot in fleet if e.subject.quantifier is Quantifier.EACH_ROBOT else [e.subject.robot]:
                first = written.setdefault((key, e.metric, robot), e)
                if first is not e:
                    raise ExportError(
                        f"'{expectation_text(e)}' and '{expectation_text(first)}' are both "
                        f"about {e.metric} of {robot or 'the mission'}; the method's oracle "
                        "file holds one oracle per metric and robot",
                        e.location,
                    )
                entry = _entry(e, robot, scenario, baseline)
                (mission if robot is None else robots[robot])[e.metric] = entry
    data: dict[str, Any] = {"id": scenario.id}
    for key in SECTIONS:
        if key in sections:
            base, mission, robots = sections[key]
            data[key] = {"base_scenario": base}
            if mission:
                data[key]["mission"] = mission
            if any(robots.values()):
                data[key]["robots"] = {robot: metrics for robot, metrics in robots.items() if metrics}
    return data


def _check_whole_run(e: Expectation, criterion: Criterion, scenario: Scenario) -> None:
    window = e.window.text() if e.window is not None else None
    when = criterion.when
    per_segment = (info := metric_info(e.metric, scenario)) is not None and info.per_segment
    if window is None and when is not None and when.robot is not None and per_segment:
        window = f"during {when.task}, as 'when {when.text()}' says"
    if window is not None:
        raise ExportError(
            f"'{expectation_text(e)}' looks at part of a run ({window}); the method's oracle "
            "files judge whole runs only",
            e.location,
        )


def _entry(
    e: Expectation, robot: str | None, scenario: Scenario, baseline: Baseline | None
) -> dict[str, Any]:
    info = metric_info(e.metric, scenario)
    assert info is not None  # the expectation was checked against the scenario's metrics
    stats = baseline.get((e.metric, robot)) if baseline is not None else None
    numbers = {key: _number(value, info) for key, value in _numbers(e, robot, stats).items()}
    return {
        "topics": list(default_topics(scenario, e.metric, robot)),
        "baseline": numbers,
        "relationship": {"package": RELATIONSHIPS_PACKAGE, "name": e.relation.value},
    }


def _numbers(e: Expectation, robot: str | None, stats: tuple[float, float] | None) -> dict[str, float]:
    """The clause's numbers in SI units.  Without a fixed value, the value is the runs' mean
    and the tolerance ``k std`` of the runs, ``p %`` of the value, as written, or (none
    written) one std for ``invariant`` and none for the others."""
    if e.limit is not None:
        return {"limit": e.limit.value}
    whose = f"{e.metric} of {robot or 'the mission'}"
    if e.confidence is not None:
        # the band comes from every run's value, which the (mean, std) of a baseline does not keep
        raise ExportError(
            f"'{expectation_text(e)}' takes its tolerance from the baseline's runs at a confidence, "
            "which the method's oracle files cannot say: write a tolerance ('within ...') to export it",
            e.location,
        )
    t = e.tolerance
    if stats is None and (e.value is None or (t is not None and t.unit == "std")):
        needs, fix = (
            ("the mean", "a value ('around <value>' or 'from <value>')")
            if e.value is None
            else ("the standard deviation", "a tolerance in the metric's unit")
        )
        raise ExportError(
            f"'{expectation_text(e)}' needs {needs} of stored runs of {whose}, and no baseline "
            f"was given: write {fix}, or build the baseline first",
            e.location,
        )
    mean, std = stats or (0.0, 0.0)
    numbers = {"value": e.value.value if e.value is not None else mean}
    if e.delta is not None:
        numbers["delta"] = e.delta.value
    if t is not None:
        scale = {"std": std, "%": abs(numbers["value"]) / 100.0}.get(t.unit or "", 1.0)
        numbers["tolerance"] = t.value * scale
    elif e.value is None and e.relation is BasicRelation.INVARIANT:
        numbers["tolerance"] = std
    return numbers


def _number(value: float, info: MetricInfo) -> float | int:
    """A count as an integer when it is one (``value: 3``), anything else as a float."""
    return int(value) if info.dimension is Dimension.COUNT and float(value).is_integer() else float(value)
