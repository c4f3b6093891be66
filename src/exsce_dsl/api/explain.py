"""``exscec explain``: what each value of a metric of a stored run used.

For every value of the metric (whole run, and each path segment): the value and its unit, the
bag topics it was read from, its window (start, end, and why that window), the samples of each
source it used of those in the window (and why fewer), and the coverage findings that touch it.
A metric without a value says why, in the words ingestion used for the run's problems.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from exsce_dsl.errors import UnknownValueError
from exsce_dsl.store import Store, ValueAccount, metric_sources, resolve_run, run_problems, value_accounts
from exsce_dsl.suggest import did_you_mean

__all__ = ["Explanation", "explain"]


@dataclass(frozen=True)
class Explanation:
    """What each value of ``metric`` in ``run`` used; ``missing``: why values are missing (the
    run's problems that name the metric)."""

    run: str
    metric: str
    values: tuple[ValueAccount, ...]
    topics: dict[tuple[str | None, str | None, float], tuple[str, ...]]
    """(robot, action, value) → the bag topics the value was computed from."""
    missing: tuple[str, ...] = ()

    def text(self) -> str:
        """The explanation for people, one block per value."""
        lines = [f"{self.metric} of run {self.run}"]
        for value in self.values:
            lines += _value_lines(value, self.topics.get((value.robot, value.action, value.value), ()))
        if self.missing:
            lines.append("  missing:")
            lines += [f"    {p}" for p in self.missing]
        return "\n".join(lines)


def explain(
    store: Store, run: str, metric: str, robot: str | None = None, segment: str | None = None
) -> Explanation:
    """What each value of ``metric`` in the stored run ``run`` (its uuid, a unique prefix of it or
    its IRI) used: of ``robot`` only when given (and the mission's values then left out), of the
    path segment ``segment`` only when given (its action's name or the end of it: ``w_002``).

    Raises :class:`~exsce_dsl.errors.UnknownRunError` for a run the store lacks and
    :class:`~exsce_dsl.errors.UnknownValueError` for a metric, robot or segment the run has no value
    or problem of."""
    uuid = resolve_run(store, run)
    accounts = value_accounts(store, uuid, metric)
    problems = [p for p in run_problems(store, uuid) if re.search(rf"\b{re.escape(metric)}\b", p)]
    if not accounts and not problems:
        known = sorted({a.metric for a in value_accounts(store, uuid)})
        raise UnknownValueError(
            f"run {uuid} has no value of metric '{metric}' (its metrics: {', '.join(known) or 'none'})"
            + did_you_mean(metric, known)
        )
    if robot is not None:
        robots = sorted({a.robot for a in accounts if a.robot is not None})
        accounts = [a for a in accounts if a.robot == robot]
        problems = [p for p in problems if f"'{robot}'" in p or "mission" in p]
        if not accounts and not problems:
            raise UnknownValueError(
                f"run {uuid} has no value of '{metric}' for robot '{robot}' "
                f"(its robots: {', '.join(robots) or 'none: a mission metric'})" + did_you_mean(robot, robots)
            )
    if segment is not None:
        actions = sorted({a.action for a in accounts if a.action is not None})
        accounts = [a for a in accounts if a.action is not None and a.action.endswith(segment)]
        if not accounts:
            raise UnknownValueError(
                f"run {uuid} has no path segment '{segment}' with a value of '{metric}' "
                f"(its segments: {', '.join(actions) or 'none'})" + did_you_mean(segment, actions)
            )
    topics = {(s.robot, s.segment, s.value): s.topics for s in metric_sources(store, uuid, metric)}
    return Explanation(uuid, metric, tuple(accounts), topics, tuple(problems))


def _value_lines(value: ValueAccount, topics: tuple[str, ...]) -> list[str]:
    """One value's block: what it is, then what it used."""
    whose = value.action or (f"robot {value.robot}" if value.robot else "the mission")
    about = f" (violations of {value.safety_metric})" if value.safety_metric else ""
    unit = f" {value.unit}" if value.unit else ""
    lines = [f"  {'segment ' if value.action else ''}{whose}{about}: {value.value:.10g}{unit}"]
    counted_topics = [t for c in value.sources for t in c.topics]
    sources = list(dict.fromkeys([*topics, *counted_topics]))
    lines.append(f"    sources: {', '.join(sources) or 'none recorded'}")
    if value.window is None or value.reason is None:
        lines.append(
            "    window: not recorded (stored before values said what they used; ingest the bag again)"
        )
        return lines
    lines.append(f"    window: {value.window_text()}")
    lines.append(f"      why: {value.reason}")
    samples = value.samples_text()
    if samples:
        lines += ["    samples:", *(f"      {line}" for line in samples)]
    else:
        lines.append(
            "    samples: none read (the value comes from the window or the goals, not from samples)"
        )
    lines.append("    annotations:" + ("" if value.annotations else " none"))
    lines += [f"      {a}" for a in value.annotations]
    return lines
