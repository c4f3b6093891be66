"""The localisation noise is a first-order Gauss–Markov process, filtered by a plain loop: it must
give the very bits scipy.signal.lfilter gives (the reference), and the spread it is meant to have."""

from __future__ import annotations

import math

import numpy as np
from scipy.signal import lfilter

from exsce_dsl.sim.localisation import NOISE_TIME, _wandering
from exsce_dsl.sim.motion import DT


def _by_lfilter(seed: int, sigma: float, samples: int) -> np.ndarray:
    a = math.exp(-DT / NOISE_TIME)
    white = np.random.default_rng(seed).normal(0.0, sigma, samples + 1)
    filtered: np.ndarray = lfilter([math.sqrt(1.0 - a * a)], [1.0, -a], white[1:], zi=[a * white[0]])[0]
    return filtered


def test_the_loop_gives_lfilters_bits() -> None:
    for seed, samples in ((1, 1), (2, 2), (3, 977), (4, 20_000)):
        ours = _wandering(np.random.default_rng(seed), 0.02, samples)
        assert ours.shape == (samples,)
        assert np.array_equal(ours.view(np.int64), _by_lfilter(seed, 0.02, samples).view(np.int64)), seed


def test_the_noise_has_its_spread_and_its_correlation_time() -> None:
    noise = _wandering(np.random.default_rng(5), 0.02, 400_000)
    assert abs(noise.std() - 0.02) < 0.002
    lag = round(NOISE_TIME / DT)  # one correlation time: correlation e⁻¹
    correlation = np.corrcoef(noise[:-lag], noise[lag:])[0, 1]
    assert abs(correlation - math.exp(-1.0)) < 0.05
