"""What a value used, counted where it is made (runs/metrics/accounting.py): every sample of its
window, or fewer with the reason, for the ways a monitor reads fewer than its window holds."""

from __future__ import annotations

import numpy as np

from exsce_dsl.monitor_kit import monitor_core as core
from exsce_dsl.runs.metrics.accounting import SampleCounter


def _topic(name: str, t: np.ndarray, values: np.ndarray) -> core.Topic:
    return core.Topic(name, t, {"v": values})


def test_samples_outside_the_span_of_a_combined_topic_are_said() -> None:
    """``a.v - b.v``: values of two topics are combined only where both have data (0..10 s
    against 2..8 s): four samples of ``/a`` in the window are not used, and it says so."""
    a = _topic("/a", np.arange(11.0), np.arange(11.0))
    b = _topic("/b", np.arange(2.0, 9.0), np.zeros(7))
    p = core.prepare("max", core.combine(np.subtract, a.field("v"), b.field("v")))
    counter = SampleCounter({"/a": a, "/b": b})
    counted = counter.accounting([p], ["/a", "/b"], (0.0, 10.0), "the recording")
    by_topic = {c.topics[0]: c for c in counted.sources}
    assert (by_topic["/a"].used, by_topic["/a"].in_window) == (7, 11)
    assert by_topic["/a"].why == (
        "4 samples outside the span where every topic it combines has data "
        "(values of several topics are combined only there)"
    )
    assert (by_topic["/b"].used, by_topic["/b"].in_window, by_topic["/b"].why) == (7, 7, None)


def test_samples_without_a_value_and_a_duration_s_gap_are_said() -> None:
    t = np.array([0.0, 1.0, 2.0, 3.0, 10.0, 11.0])
    speed = _topic("/v", t, np.array([0.1, np.nan, 0.3, 2.0, 2.0, 0.1]))
    top = core.prepare("max", speed.field("v"))
    counter = SampleCounter({"/v": speed})
    (count,) = counter.accounting([top], ["/v"], (0.5, 11.0), "a segment").sources
    assert (count.used, count.in_window) == (4, 5)
    assert count.why == "1 sample without a value (NaN, or no element meeting its condition)"
    over = core.prepare("duration", None, core.combine(np.greater, speed.field("v"), 1.0))
    (held,) = SampleCounter({"/v": speed}).accounting([over], ["/v"], (0.0, 11.0), "the recording").sources
    assert (held.used, held.in_window) == (6, 6)
    assert held.why == "1 sample before a gap held for two median periods, not the whole gap"


def test_a_violation_duration_says_its_samples_hold_at_a_gap() -> None:
    """A violation duration sums how long the metric's samples hold: its accounting says the gap."""
    t = np.array([0.0, 1.0, 2.0, 3.0, 10.0, 11.0])
    speed = _topic("/v", t, np.array([0.1, np.nan, 0.3, 2.0, 2.0, 0.1]))
    top = core.prepare("max", speed.field("v"))
    (count,) = (
        SampleCounter({"/v": speed})
        .accounting([top], ["/v"], (0.0, 11.0), "the recording", held=True)
        .sources
    )
    assert (count.used, count.in_window) == (5, 6)
    assert count.why == (
        "1 sample without a value (NaN, or no element meeting its condition); "
        "1 sample before a gap held for two median periods, not the whole gap"
    )
