"""The unit every metric's numbers are shown with: ``1.418 m/s``, ``161.2 s``, ``3 waypoints``.

A metric's unit comes from what declares it: exsce's built-in metrics, the
metrics the specifications given to the report declare, and the unit the store
recorded with its values (which wins: it is what the numbers were measured in).
A count has no unit in the store, so it says what it counts instead.
"""

from __future__ import annotations

from collections.abc import Iterable

from exsce_dsl.lang import builtin_metrics
from exsce_dsl.model.metrics import SI_UNIT, Dimension, MetricDefinition
from exsce_dsl.store import MetricReading

COUNTED = {"waypoints_visited": "waypoints"}
"""What a count metric counts, said after its numbers; a count not listed here is a ``(count)``."""

_UNCOUNTED = "(count)"
_PLAIN = "(number)"


def unit_label(metric: str, dimension: Dimension) -> str:
    """What follows a value of ``metric``: its SI unit, what it counts, or ``(number)``."""
    if dimension is Dimension.COUNT:
        return COUNTED.get(metric, _UNCOUNTED)
    return SI_UNIT[dimension] or _PLAIN


def metric_units(
    readings: Iterable[MetricReading], definitions: Iterable[MetricDefinition] = ()
) -> dict[str, str]:
    """Metric name → its unit label, from the built-in metrics, ``definitions`` and the stored ``readings``.

    A metric the store has values of but neither declares nor gives a unit is a count (the
    store records no unit for counts).
    """
    units = {name: unit_label(name, info.dimension) for name, info in builtin_metrics().items()}
    units.update({d.name: unit_label(d.name, d.dimension) for d in definitions})
    for reading in readings:
        if reading.unit:
            units[reading.metric] = reading.unit
        else:
            units.setdefault(reading.metric, COUNTED.get(reading.metric, _UNCOUNTED))
    return units
