"""What the store holds of what each metric value of a run used (its window and why, its samples
per source, the findings that touch it), and what ingestion said of the run
(:mod:`exsce_dsl.prov.run_accounting` writes both)."""

from __future__ import annotations

import datetime
from dataclasses import dataclass, replace

from exsce_dsl.model.runs import SourceCount
from exsce_dsl.prov.identifiers import DEFAULT_NAMESPACE
from exsce_dsl.store.base import Store, Term
from exsce_dsl.store.queries.terms import datetime_of, float_of, int_of, run_query, text_of
from exsce_dsl.wording import counted

TOPIC_SEPARATOR = ", "
"""Between the topics of one source in ``exsce:topic_name`` (as the run's PROV writes them)."""


@dataclass(frozen=True)
class ValueAccount:
    """One stored metric value and what it used; ``action`` is the local name of the action that
    generated a segment value (``bot-task_01-subtask_001-w_002``), None for a whole-run value;
    ``window`` is (from, to) in seconds after the run's start, None for a value stored before
    values said what they used."""

    metric: str
    robot: str | None
    safety_metric: str | None
    action: str | None
    value: float
    unit: str | None
    window: tuple[float, float] | None
    dates: tuple[datetime.datetime, datetime.datetime] | None
    reason: str | None
    annotations: tuple[str, ...]
    sources: tuple[SourceCount, ...]

    def window_text(self) -> str:
        """``0.000 s to 395.304 s after the run's start (395.304 s), <date> to <date>``; '' for
        a value stored before values said what they used."""
        if self.window is None:
            return ""
        start, end = self.window
        said = f"{_seconds(start)} to {_seconds(end)} after the run's start ({_seconds(end - start)})"
        if self.dates is not None:
            first, last = (d.isoformat().replace("+00:00", "Z") for d in self.dates)
            said += f", {first} to {last}"
        return said

    def samples_text(self) -> list[str]:
        """One line per source: ``/odom: 3952 of 3952 samples in the window`` (and why fewer);
        a pose from TF names its transforms: ``TF map → odom → base_link on /tf + /tf_static``."""
        return [
            (f"TF {c.tf_chain} on " if c.tf_chain else "")
            + f"{' + '.join(c.topics)}: {c.used} of {counted(c.in_window, 'sample')} in the window"
            + (f" ({c.why})" if c.why else "")
            for c in self.sources
        ]

    def summary(self) -> str:
        """What the value used, in a few lines (the report shows it on hover)."""
        if self.window is None or self.reason is None:
            return "what it used was not recorded (ingest the bag again)"
        lines = [f"window: {self.window_text()}", f"why: {self.reason}"]
        lines += self.samples_text() or ["no samples read (the value comes from the window or the goals)"]
        lines += [f"annotation: {a}" for a in self.annotations]
        return "\n".join(lines)


def _seconds(value: float) -> str:
    """``12.345 s``; never ``-0.000 s`` (a window may open a fraction of a millisecond before the
    run's first log time, where a header stamp is earlier)."""
    return f"{value:.3f} s".replace("-0.000", "0.000")


def value_accounts(
    store: Store, run: str, metric: str | None = None, *, namespace: str = DEFAULT_NAMESPACE
) -> list[ValueAccount]:
    """What each value of ``metric`` (every metric without it) of the stored run ``run`` (a uuid)
    used: whole-run values first, then segments, in the query's order."""
    given: dict[str, str] = {"run": run} if metric is None else {"run": run, "metric": metric}
    found: dict[str, ValueAccount] = {}
    counts: dict[str, list[tuple[int, SourceCount]]] = {}
    for row in run_query(store, "value_accounting", given, namespace):
        entity = text_of(row["entity"]) or ""
        if entity not in found:
            found[entity] = _account(row)
            counts[entity] = []
        topics = text_of(row["topics"])
        if topics is not None:
            index = int((text_of(row["count"]) or "_0").rsplit("_", 1)[1])  # R:<value>-samples_N
            count = SourceCount(
                tuple(topics.split(TOPIC_SEPARATOR)),
                int_of(row["used"]),
                int_of(row["in_window"]),
                text_of(row["why"]),
                text_of(row["tf_chain"]),
            )
            counts[entity].append((index, count))
    return [
        _with_sources(account, counts[entity])
        for entity, account in sorted(
            found.items(), key=lambda e: (e[1].action is not None, e[1].action or "")
        )
    ]


def _account(row: dict[str, Term | None]) -> ValueAccount:
    start, end = float_of(row["from"]), float_of(row["to"])
    first, last = datetime_of(row["start"]), datetime_of(row["end"])
    action = text_of(row["action"])
    annotations = text_of(row["annotations"])
    return ValueAccount(
        text_of(row["metric"]) or "",
        text_of(row["robot"]),
        text_of(row["safety"]),
        action.rsplit("/", 1)[-1] if action else None,
        float_of(row["value"]) or 0.0,
        text_of(row["unit"]),
        (start, end) if start is not None and end is not None else None,
        (first, last) if first is not None and last is not None else None,
        text_of(row["reason"]),
        tuple(annotations.split("\n")) if annotations else (),
        (),
    )


def _with_sources(account: ValueAccount, counts: list[tuple[int, SourceCount]]) -> ValueAccount:
    return replace(account, sources=tuple(c for _, c in sorted(counts, key=lambda c: c[0])))


def run_problems(store: Store, run: str, *, namespace: str = DEFAULT_NAMESPACE) -> list[str]:
    """What ingestion said of the stored run ``run`` (a uuid), in the order it said it."""
    rows = run_query(store, "run_problems", {"run": run}, namespace)
    ordered = sorted(rows, key=lambda r: text_of(r["problem"]) or "")
    return [text for row in ordered if (text := text_of(row["text"])) is not None]
