"""What the builders of one specification share: the declarations read, the parts built so far,
the diagnostics, and the one way a name declared twice is reported."""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass
from typing import Any

from exsce_dsl.errors import Diagnostic, Remedied, Severity, SourceLocation
from exsce_dsl.lang.builders.references import UnknownNames
from exsce_dsl.lang.parser import ParsedFile
from exsce_dsl.model import Acceptance, Environment, Pose, RobotType, RosResource, Scenario, Task
from exsce_dsl.model.derived import DerivedScenario
from exsce_dsl.model.metrics import MetricDefinition

Report = Callable[[str, SourceLocation | None], None]
"""Reports a problem (its message) at a place."""

KIND_WORDS = {
    "RobotType": "robot type",
    "Environment": "environment",
    "Task": "task",
    "Scenario": "scenario",
    "Metric": "metric",
}
"""The declarations a file holds (besides acceptance and derive blocks), as messages name them."""


def report_duplicate(
    what: str,
    name: str,
    first: SourceLocation | None,
    where: SourceLocation,
    report: Report,
    inside: str = "",
) -> bool:
    """Report ``name`` (a ``what``, declared ``inside`` a scope, e.g. `` in environment 'e'``) at
    ``where`` when it was declared before, at ``first``; True when it was (a duplicate)."""
    if first is None:
        return False
    report(f"duplicate {what} '{name}'{inside} (first declared at {first})", where)
    return True


@dataclass
class Declared:
    """A declaration of a file, with where its name is written."""

    obj: Any
    file: ParsedFile
    name_location: SourceLocation


def name_span(pf: ParsedFile, obj: Any) -> SourceLocation:
    """The span of ``obj.name`` inside the text of ``obj``."""
    text, name, end = pf.text, obj.name, obj._tx_position_end
    start = text.find(name, obj._tx_position, end)
    while start >= 0:  # the first whole-word occurrence (`t` in `task t` is not the one in `task`)
        before = text[start - 1] if start else " "
        after = text[start + len(name)] if start + len(name) < len(text) else " "
        if not (before.isalnum() or before in "_-") and not (after.isalnum() or after in "_-"):
            return pf.lines.span(start, start + len(name))
        start = text.find(name, start + 1, end)
    return pf.span(obj)


def ros_resource(source: Any) -> RosResource | None:
    """A parsed ``from PACKAGE[/PATH]``."""
    if source is None:
        return None
    return RosResource(source.package, source.path or None)


class BuildContext:
    """The state of building one specification: each builder reads the parts built before its own."""

    def __init__(self, files: list[ParsedFile], unknown: UnknownNames) -> None:
        self.files = files
        self.unknown = unknown
        self.diagnostics: list[Diagnostic] = []
        self.declared: dict[str, dict[str, Declared]] = {k: {} for k in KIND_WORDS}
        self.robot_types: dict[str, RobotType] = {}
        self.environments: dict[str, Environment] = {}
        self.tasks: dict[str, Task] = {}
        self.scenarios: dict[str, Scenario] = {}
        self.metrics: dict[str, MetricDefinition] = {}
        self.poses: dict[str, list[tuple[str, Pose]]] = {}
        """Pose id -> the environments declaring it, with the pose."""
        self.task_poses: dict[str, Pose | None] = {}
        """Pose ids a task may name: unambiguous ones map to their pose."""
        self.acceptance: dict[int, Acceptance] = {}
        """Built acceptance blocks, by the id of their parse tree node."""
        self.derived: dict[int, DerivedScenario] = {}
        """Built derive blocks, by the id of their parse tree node."""

    def error(self, message: str, location: SourceLocation | None, code: str = "semantic") -> None:
        self.diagnostics.append(Diagnostic(message, location, code=code))

    def warning(self, message: str, location: SourceLocation | None, code: str = "semantic") -> None:
        self.diagnostics.append(Diagnostic(message, location, Severity.WARNING, code=code))

    def metric_problem(
        self,
        message: str,
        location: SourceLocation | None,
        severity: Severity = Severity.ERROR,
        remedied: Remedied | None = None,
    ) -> None:
        self.diagnostics.append(Diagnostic(message, location, severity, code="metric", remedied=remedied))

    def unknown_name(self, kind: str, name: str, at: SourceLocation, known: Iterable[str]) -> None:
        """Report that no file read declares ``name`` (unless a file with a syntax error may)."""
        message = self.unknown.message(kind, name, at, known)
        if message is not None:
            self.error(message, at, code="reference")

    def declare(self, pf: ParsedFile, decl: Any) -> None:
        """Note a top-level declaration of ``pf`` (a later one of the same name is a duplicate)."""
        kind = decl.__class__.__name__
        table = self.declared[kind]
        where = name_span(pf, decl)
        first = table.get(decl.name)
        if report_duplicate(
            KIND_WORDS[kind], decl.name, first.name_location if first else None, where, self.error
        ):
            return
        table[decl.name] = Declared(decl, pf, where)
