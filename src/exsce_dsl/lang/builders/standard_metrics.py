"""The standard library of metrics: the method's metrics, declared in the language itself.

It ships in the package (``lang/stdlib/metrics.exsce``) and is checked like any
user file; a specification's own metrics sit beside it and may not reuse its
names.
"""

from __future__ import annotations

import functools

from exsce_dsl.errors import Diagnostic, Remedied, Severity, SourceLocation, SpecError
from exsce_dsl.lang.code_cache import cached_standard_metrics
from exsce_dsl.model.metrics import VIOLATION_DURATION, MetricDefinition, MetricInfo
from exsce_dsl.model.scenario import Scenario


@functools.cache
def standard_metrics() -> tuple[MetricDefinition, ...]:
    """The standard library's metrics, in the order it declares them (parsed once per
    installation: see :mod:`exsce_dsl.lang.spec_cache`)."""
    return cached_standard_metrics(_parse_standard_metrics)


def _parse_standard_metrics() -> tuple[MetricDefinition, ...]:
    from exsce_dsl.lang.builders.metrics import build_metric
    from exsce_dsl.lang.parser import parse_text
    from exsce_dsl.messages.catalogue import standard_catalogue
    from exsce_dsl.resources import package_file

    source = package_file("lang", "stdlib", "metrics.exsce")
    pf = parse_text(source.read_text(encoding="utf-8"), str(source))
    problems: list[Diagnostic] = []

    def report(
        message: str,
        at: SourceLocation | None,
        severity: Severity = Severity.ERROR,
        remedied: Remedied | None = None,
    ) -> None:
        problems.append(Diagnostic(message, at, severity, remedied=remedied))

    types = standard_catalogue()  # the method's types only, whatever the user defines
    built = [build_metric(pf, tree, report, standard=True, catalogue=types) for tree in pf.tree.declarations]
    if problems:
        raise SpecError(problems)  # a broken installation, not a user's mistake
    return tuple(m for m in built if m is not None)


def reserved_metric_names() -> dict[str, str]:
    """Names a user's metric may not take, with why."""
    return {name: "is one of exsce's built-in metrics" for name in builtin_metrics()}


@functools.cache
def builtin_metrics() -> dict[str, MetricInfo]:
    """What each built-in metric is: the standard library's, as it declares them, and
    violation_duration (which follows from the safe ones)."""
    declared = {m.name: m.info() for m in standard_metrics()}
    return declared | {VIOLATION_DURATION.name: VIOLATION_DURATION}


def metric_info(name: str, scenario: Scenario | None = None) -> MetricInfo | None:
    """What ``name`` measures: a metric the scenario's specification declares, else a built-in one."""
    if scenario is not None:
        for definition in scenario.metrics:
            if definition.name == name:
                return definition.info()
    return builtin_metrics().get(name)


def known_metrics(scenario: Scenario | None = None) -> dict[str, MetricInfo]:
    """Every metric a clause may name: the built-in ones and the specification's own."""
    found = dict(builtin_metrics())
    if scenario is not None:
        found.update({d.name: d.info() for d in scenario.metrics})
    return found
