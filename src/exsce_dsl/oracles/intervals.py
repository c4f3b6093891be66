"""Prediction intervals: the band a new run falls in, with a chosen confidence, given n past runs.

``is invariant at 99 %`` asks for the band that one new run of a healthy system falls in 99 times
in 100: with the baseline's n values (mean x̄, sample standard deviation s, n − 1 in its
denominator), and the values normal, that is Student's prediction interval

    x̄ ± t_{(1+c)/2, n−1} · s · √(1 + 1/n)

(the new run varies by s, the mean it is compared with by s/√n).  Student's t quantile is computed
here, with no scipy at run time: the t distribution's CDF from the regularized incomplete beta
function (a continued fraction, Lentz's method), inverted by bisection.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from exsce_dsl.errors import ExsceError

_EPSILON = 1e-15
_TINY = 1e-300


def _beta_fraction(a: float, b: float, x: float) -> float:
    """The continued fraction of the incomplete beta function I_x(a, b) (modified Lentz)."""
    c, d = 1.0, 1.0 - (a + b) * x / (a + 1.0)
    d = 1.0 / (d if abs(d) > _TINY else _TINY)
    fraction = d
    for m in range(1, 1000):
        for numerator in (
            m * (b - m) * x / ((a + 2 * m - 1) * (a + 2 * m)),
            -(a + m) * (a + b + m) * x / ((a + 2 * m) * (a + 2 * m + 1)),
        ):
            d = 1.0 + numerator * d
            d = 1.0 / (d if abs(d) > _TINY else _TINY)
            c = 1.0 + numerator / c
            c = c if abs(c) > _TINY else _TINY
            fraction *= c * d
        if abs(c * d - 1.0) < _EPSILON:
            return fraction
    raise ArithmeticError(f"the incomplete beta fraction did not converge (a={a}, b={b}, x={x})")


def regularized_beta(a: float, b: float, x: float) -> float:
    """I_x(a, b), the regularized incomplete beta function, for a, b > 0 and 0 ≤ x ≤ 1."""
    if x <= 0.0:
        return 0.0
    if x >= 1.0:
        return 1.0
    log_front = math.lgamma(a + b) - math.lgamma(a) - math.lgamma(b) + a * math.log(x) + b * math.log1p(-x)
    # the fraction converges fast for x below the distribution's mean; above it, use the symmetry
    if x < (a + 1.0) / (a + b + 2.0):
        return math.exp(log_front) * _beta_fraction(a, b, x) / a
    return 1.0 - math.exp(log_front) * _beta_fraction(b, a, 1.0 - x) / b


def t_cdf(t: float, df: float) -> float:
    """P(T ≤ t) for Student's t with ``df`` degrees of freedom."""
    tail = 0.5 * regularized_beta(df / 2.0, 0.5, df / (df + t * t))
    return 1.0 - tail if t > 0 else tail


def t_quantile(p: float, df: float) -> float:
    """The t with P(T ≤ t) = p for Student's t with ``df`` degrees of freedom (0 < p < 1)."""
    if not 0.0 < p < 1.0:
        raise ValueError(f"a probability strictly between 0 and 1 is needed, not {p}")
    if df <= 0:
        raise ValueError(f"Student's t needs positive degrees of freedom, not {df}")
    if p < 0.5:
        return -t_quantile(1.0 - p, df)
    low, high = 0.0, 1.0
    while t_cdf(high, df) < p:
        low, high = high, high * 2.0
    for _ in range(200):  # bisection: the CDF is monotone, so this cannot miss
        middle = 0.5 * (low + high)
        if t_cdf(middle, df) < p:
            low = middle
        else:
            high = middle
        if high - low <= 1e-14 * high:
            break
    return 0.5 * (low + high)


def check_confidence(confidence: float) -> None:
    """A confidence is a fraction strictly between 0.5 and 1."""
    if not 0.5 < confidence < 1.0:
        raise ExsceError(
            f"a confidence must be between 50 % and 100 % (exclusive), not {confidence * 100:g} %"
        )


def prediction_half_width(values: Sequence[float], confidence: float) -> float:
    """Half the width of the prediction interval for one new value, given ``values`` (n ≥ 2):
    t_{(1+c)/2, n−1} · s · √(1 + 1/n), s the sample standard deviation (n − 1 denominator)."""
    check_confidence(confidence)
    n = len(values)
    if n < 2:
        raise ExsceError(
            f"a tolerance at {confidence * 100:g} % confidence needs at least 2 baseline values, "
            f"not {n}: it comes from their spread"
        )
    mean = math.fsum(values) / n
    s = math.sqrt(math.fsum((v - mean) ** 2 for v in values) / (n - 1))
    return t_quantile((1.0 + confidence) / 2.0, n - 1) * s * math.sqrt(1.0 + 1.0 / n)
