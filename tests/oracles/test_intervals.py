"""Student's t quantile and the prediction interval, against scipy (not used at run time)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from exsce_dsl.errors import ExsceError
from exsce_dsl.oracles.intervals import prediction_half_width, regularized_beta, t_cdf, t_quantile

DEGREES = (1, 2, 3, 4, 5, 9, 19, 29, 99, 1000, 0.5, 2.5)
PROBABILITIES = (0.75, 0.9, 0.95, 0.975, 0.99, 0.995, 0.9995, 0.99999, 0.25, 0.025, 0.005)


@pytest.mark.parametrize("df", DEGREES)
def test_the_t_quantile_is_scipys(df: float) -> None:
    for p in PROBABILITIES:
        assert t_quantile(p, df) == pytest.approx(stats.t.ppf(p, df), rel=1e-10), p


@pytest.mark.parametrize("df", DEGREES)
def test_the_t_cdf_is_scipys(df: float) -> None:
    for t in (-30.0, -2.5, -0.3, 0.0, 0.7, 1.96, 4.0, 63.0):
        assert t_cdf(t, df) == pytest.approx(stats.t.cdf(t, df), rel=1e-11, abs=1e-14), t


def test_the_regularized_beta_is_scipys() -> None:
    for a, b in ((0.5, 0.5), (2.0, 0.5), (10.0, 3.0), (0.25, 40.0)):
        for x in (0.0, 1e-6, 0.1, 0.5, 0.9, 0.999, 1.0):
            assert regularized_beta(a, b, x) == pytest.approx(stats.beta.cdf(x, a, b), rel=1e-11, abs=1e-15)


def test_the_half_width_is_t_times_s_times_root_one_plus_one_over_n() -> None:
    values = [97.1, 98.4, 96.9, 99.0, 97.7, 98.2]
    n = len(values)
    for confidence in (0.8, 0.95, 0.99):
        expected = stats.t.ppf((1 + confidence) / 2, n - 1) * np.std(values, ddof=1) * np.sqrt(1 + 1 / n)
        assert prediction_half_width(values, confidence) == pytest.approx(expected, rel=1e-10)
    assert prediction_half_width([4.0, 4.0, 4.0], 0.99) == 0.0


def test_a_band_needs_two_values_and_a_confidence_above_a_half() -> None:
    with pytest.raises(ExsceError, match="at least 2 baseline values, not 1"):
        prediction_half_width([1.0], 0.95)
    for bad in (0.5, 1.0, 0.3, 95.0):
        with pytest.raises(ExsceError, match="between 50 % and 100 % \\(exclusive\\)"):
            prediction_half_width([1.0, 2.0], bad)
    with pytest.raises(ValueError):
        t_quantile(1.0, 3)
