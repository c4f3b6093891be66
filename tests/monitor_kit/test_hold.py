"""How long each sample holds (``monitor_core.hold``), the weight of violation durations."""

from __future__ import annotations

import numpy as np

from exsce_dsl.monitor_kit.monitor_core import hold


def test_samples_sharing_a_time_do_not_make_every_hold_zero() -> None:
    """Stumble: a topic logged in bursts (three samples at each time) had a median step of 0, so
    every sample held 0 s and 2,915 violations summed to "0 s"."""
    t = np.repeat(np.arange(0.0, 10.0, 0.5), 3)
    held = hold(t)
    # each burst's last sample holds until the next burst; the others hold no time
    assert held.sum() == np.float64(10.0)
    assert np.count_nonzero(held) == 20


def test_a_gap_holds_at_most_two_periods() -> None:
    t = np.array([0.0, 0.1, 0.2, 0.3, 5.0, 5.1])
    assert list(np.round(hold(t), 9)) == [0.1, 0.1, 0.1, 0.2, 0.1, 0.1]


def test_one_time_holds_nothing() -> None:
    assert hold(np.array([3.0, 3.0, 3.0])).tolist() == [0.0, 0.0, 0.0]
