"""``speed(x, y[, z])`` and ``derivative(v)``: functions of a series over time, noise-aware.

The numpy core takes differences over ``BASELINE`` (0.5 s) around each
message, not between neighbouring messages.  These tests give it positions
whose truth is known (standing still, driving at 0.5 m/s, both with 1 cm of
noise at 50 Hz; sparse messages; a turn) and compare with that truth and with
differences computed here, message by message.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from exsce_dsl.monitor_kit.monitor_core import BASELINE, Signal, derivative, speed

RATE = 50.0
NOISE = 0.01


def _track(seconds: float, velocity: tuple[float, float], seed: int = 0) -> tuple[Signal, Signal]:
    rng = np.random.default_rng(seed)
    t = 1000.0 + np.arange(int(seconds * RATE)) / RATE
    x = 3.0 + velocity[0] * (t - t[0]) + rng.normal(0.0, NOISE, len(t))
    y = -2.0 + velocity[1] * (t - t[0]) + rng.normal(0.0, NOISE, len(t))
    return Signal(t, x), Signal(t, y)


def _neighbour_speeds(x: Signal, y: Signal) -> list[float]:
    """Speed from each message to the next: what noise does to naive differences."""
    return [
        math.hypot(x.v[i + 1] - x.v[i], y.v[i + 1] - y.v[i]) / (x.t[i + 1] - x.t[i])
        for i in range(len(x.t) - 1)
    ]


def test_standing_still_with_centimetre_noise_is_near_zero_where_neighbour_differences_are_not():
    x, y = _track(10.0, (0.0, 0.0))
    assert np.median(_neighbour_speeds(x, y)) > 0.5  # 1 cm of noise every 20 ms
    estimated = speed(x, y)
    assert np.array_equal(estimated.t, x.t)
    assert float(np.nanmax(estimated.v)) < 0.12
    assert float(np.nanmean(estimated.v)) < NOISE * math.sqrt(2) / BASELINE * 1.6


def test_driving_at_half_a_metre_per_second_gives_that_speed():
    x, y = _track(10.0, (0.3, 0.4))
    estimated = speed(x, y)
    assert float(np.nanmean(estimated.v)) == pytest.approx(0.5, abs=0.01)
    assert float(np.nanmax(np.abs(estimated.v - 0.5))) < 0.1


def test_three_coordinates_and_sparse_messages_give_the_difference_between_neighbours():
    t = np.array([0.0, 2.0, 4.0, 5.0])
    x, y, z = (
        Signal(t, np.array([0.0, 2.0, 2.0, 2.0])),
        Signal(t, np.zeros(4)),
        Signal(t, np.array([0, 0, 2.0, 2])),
    )
    estimated = speed(x, y, z)
    # messages further apart than the baseline: the positions a quarter second either side lie
    # on the straight line between neighbours, so each speed is that of its neighbours' step
    # (at t = 2 s the two steps, 1 m/s along x then 1 m/s along z, meet at a right angle)
    half = BASELINE / 2
    assert estimated.v[0] == pytest.approx(1.0)
    assert estimated.v[1] == pytest.approx(math.hypot(half, half) / BASELINE)
    assert estimated.v[2] == pytest.approx(1.0 * half / BASELINE)  # 1 m/s before, standing after
    assert estimated.v[3] == pytest.approx(0.0)


def test_a_single_message_has_no_speed_and_no_derivative():
    one = Signal(np.array([5.0]), np.array([1.0]))
    assert np.isnan(speed(one, one).v).all()
    assert np.isnan(derivative(one).v).all()
    empty = Signal(np.zeros(0), np.zeros(0))
    assert len(speed(empty, empty).v) == 0 and len(derivative(empty).v) == 0


def test_derivative_of_a_ramp_and_of_a_parabola():
    t = np.arange(0.0, 10.0, 0.02)
    ramp = derivative(Signal(t, 3.0 * t - 1.0))
    assert np.allclose(ramp.v, 3.0)
    parabola = derivative(Signal(t, t**2))
    inside = (t >= BASELINE) & (t <= t[-1] - BASELINE)
    # a central difference of t² is exact: (t + h)² - (t - h)² = 4th, over 2h
    assert np.allclose(parabola.v[inside], 2 * t[inside])
    # at the ends the difference is one-sided, over what the series has (t = 0.25 s lies between
    # messages: the chord of t² there is 1e-4 above it)
    assert parabola.v[0] == pytest.approx(((BASELINE / 2) ** 2 + 1e-4) / (BASELINE / 2))


def test_speeds_of_two_series_on_different_times_are_aligned_to_the_first():
    t = np.arange(0.0, 4.0, 0.1)
    x = Signal(t, 0.5 * t)
    y = Signal(t[::2] + 0.05, np.zeros(len(t[::2])))
    estimated = speed(x, y)
    assert estimated.t[0] == pytest.approx(0.1) and estimated.t[-1] == pytest.approx(3.8)  # y: 0.05..3.85 s
    assert np.allclose(estimated.v, 0.5)
