"""What each metric value of a run used, as run PROV (written beside the value in its metric's bundle).

On the value ``R:<value>`` (``exsce:output_metric``):

* ``exsce:window_from`` and ``exsce:window_to``: its window, seconds after the run's start
  (``xsd:double``); on a run with dates, ``exsce:window_start`` and ``exsce:window_end`` too
  (``xsd:dateTime``, the recorder's wall clock); ``exsce:window_reason``: why the window is that
  one; ``exsce:annotations``: the coverage findings that touch the value, one per line.

And one entity ``R:<value>-samples_N`` (``exsce:sample_count``) per source it read samples of,
derived from the source's topics: ``exsce:counted_for`` (the value), ``exsce:topic_name`` (the
topics, ``, ``-separated), ``exsce:samples_used``, ``exsce:samples_in_window`` (``xsd:int``) and
``exsce:fewer_because`` where it used fewer (or something else is worth saying).
"""

from __future__ import annotations

import datetime as dt

from prov.constants import PROV_TYPE
from prov.identifier import Namespace, QualifiedName

from exsce_dsl.model.runs import Accounting, Run
from exsce_dsl.prov import identifiers as ids
from exsce_dsl.prov.records import Attributes, BundleWriter, DocumentWriter

TOPIC_SEPARATOR = ", "
"""Between the topics of one source in ``exsce:topic_name``."""


def accounting_facts(w: BundleWriter, run: Run, accounting: Accounting) -> Attributes:
    """The attributes of a value that say its window, why, and the findings that touch it."""
    t = w.term
    start = run.start.timestamp()
    facts: Attributes = {
        t(ids.WINDOW_FROM): float(accounting.start - start),
        t(ids.WINDOW_TO): float(accounting.end - start),
        t(ids.WINDOW_REASON): accounting.reason,
    }
    if run.dated:
        facts[t(ids.WINDOW_START)] = dt.datetime.fromtimestamp(accounting.start, tz=dt.timezone.utc)
        facts[t(ids.WINDOW_END)] = dt.datetime.fromtimestamp(accounting.end, tz=dt.timezone.utc)
    if accounting.annotations:
        facts[t(ids.ANNOTATIONS)] = "\n".join(accounting.annotations)
    return facts


def write_sample_counts(
    writer: DocumentWriter,
    w: BundleWriter,
    parts: Namespace,
    value: tuple[QualifiedName, str],
    accounting: Accounting,
    held: set[str],
) -> None:
    """One ``exsce:sample_count`` per source of the value ``value`` (its id and local name)."""
    t, topic_ns = w.term, w.fixed(ids.TOPIC)
    for index, count in enumerate(accounting.sources, start=1):
        count_id = parts[ids.sample_count_name(value[1], index)]
        writer.claim(count_id, f"the samples of source {index} of {value[1]}")
        facts: Attributes = {
            PROV_TYPE: t(ids.SAMPLE_COUNT_TYPE),
            t(ids.COUNTED_FOR): value[0],
            t(ids.TOPIC_NAME): TOPIC_SEPARATOR.join(count.topics),
            t(ids.SAMPLES_USED): int(count.used),
            t(ids.SAMPLES_IN_WINDOW): int(count.in_window),
        }
        if count.why:
            facts[t(ids.FEWER_BECAUSE)] = count.why
        w.entity(count_id, facts)
        for topic in count.topics:
            if topic in held:
                w.derivation(count_id, topic_ns[ids.topic_local_name(topic)], {})
