"""The standard library of metrics: the method's metrics, declared in the language itself.

It ships in the package (``lang/stdlib/metrics.exsce``) and is checked like any
user file; a specification's own metrics sit beside it and may not reuse its
names.
"""

from __future__ import annotations

import functools

from exsce_dsl.errors import Diagnostic, Severity, SourceLocation, SpecError
from exsce_dsl.lang.spec_cache import cached_standard_metrics
from exsce_dsl.model.metrics import METRICS, MetricDefinition


@functools.cache
def standard_metrics() -> tuple[MetricDefinition, ...]:
    """The standard library's metrics, in the order it declares them (parsed once per
    installation: see :mod:`exsce_dsl.lang.spec_cache`)."""
    return cached_standard_metrics(_parse_standard_metrics)


def _parse_standard_metrics() -> tuple[MetricDefinition, ...]:
    from exsce_dsl.lang.build.metrics import build_metric
    from exsce_dsl.lang.parser import parse_text
    from exsce_dsl.messages.catalogue import standard_catalogue
    from exsce_dsl.resources import package_file

    source = package_file("lang", "stdlib", "metrics.exsce")
    pf = parse_text(source.read_text(encoding="utf-8"), str(source))
    problems: list[Diagnostic] = []

    def report(message: str, at: SourceLocation | None, severity: Severity = Severity.ERROR) -> None:
        problems.append(Diagnostic(message, at, severity))

    types = standard_catalogue()  # the method's types only, whatever the user defines
    built = [build_metric(pf, tree, report, standard=True, catalogue=types) for tree in pf.tree.declarations]
    if problems:
        raise SpecError(problems)  # a broken installation, not a user's mistake
    return tuple(m for m in built if m is not None)


def reserved_metric_names() -> dict[str, str]:
    """Names a user's metric may not take, with why."""
    return {name: "is one of exsce's built-in metrics" for name in METRICS}
