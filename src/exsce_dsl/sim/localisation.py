"""Where a robot believes it is: wheel odometry that drifts, a localiser's estimate that does
not, and the correction ``map → odom`` between them (what AMCL publishes).

Everything is on the executor's 50 Hz clock, as planar poses (x, y, heading).

- **Odometry** (``odom → base_link``) starts at zero, where the robot is switched on, and
  integrates the robot's true motion as its wheels measure it: every distance driven is off by a
  scale error, every turn by a turn-rate error, and the heading gains a bias per metre driven
  (all three seeded per robot, of a few per cent and a fraction of a degree per metre).  Its
  error grows with the distance driven, as wheel odometry's does.
- **The estimate** (``map → base_link``, AMCL's pose) is the true pose plus noise that wanders
  slowly (a first-order Gauss–Markov process of standard deviation ``LOCALISATION_NOISE`` m and
  ``LOCALISATION_YAW_NOISE`` rad, correlation time ``NOISE_TIME`` s).
- **The correction** (``map → odom``) is ``estimate ∘ odom⁻¹``, so that ``map → odom →
  base_link`` composed at any sample is the estimate: the true pose within the noise.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from exsce_dsl.sim.motion import DT, SampledMotion

SCALE_ERROR = (0.01, 0.03)
"""Odometry's distance scale error, a fraction (its sign is seeded too)."""
TURN_ERROR = (0.01, 0.03)
"""Odometry's turn scale error, a fraction."""
HEADING_BIAS = (math.radians(0.25), math.radians(0.75))
"""Odometry's heading drift per metre driven (rad/m)."""
LOCALISATION_NOISE = 0.02
LOCALISATION_YAW_NOISE = 0.01
NOISE_TIME = 1.0


@dataclass(frozen=True)
class PlanarPoses:
    """Planar poses, one per sample: the pose of a child frame in a parent frame."""

    x: np.ndarray
    y: np.ndarray
    yaw: np.ndarray

    def compose(self, other: PlanarPoses) -> PlanarPoses:
        """``self ∘ other``: ``other``'s poses (given in ``self``'s child frame) in ``self``'s parent."""
        c, s = np.cos(self.yaw), np.sin(self.yaw)
        return PlanarPoses(
            self.x + c * other.x - s * other.y,
            self.y + s * other.x + c * other.y,
            _wrap(self.yaw + other.yaw),
        )

    def inverse(self) -> PlanarPoses:
        c, s = np.cos(self.yaw), np.sin(self.yaw)
        return PlanarPoses(-(c * self.x + s * self.y), s * self.x - c * self.y, _wrap(-self.yaw))


@dataclass(frozen=True)
class Odometry:
    """Drift of one robot's wheel odometry."""

    scale: float
    turn: float
    heading_bias: float  # rad per metre driven

    @staticmethod
    def seeded(rng: np.random.Generator) -> Odometry:
        scale, turn, bias = (
            float(rng.choice((-1.0, 1.0)) * rng.uniform(*bounds))
            for bounds in (SCALE_ERROR, TURN_ERROR, HEADING_BIAS)
        )
        return Odometry(scale, turn, bias)


@dataclass(frozen=True)
class Localisation:
    """A robot's frames, sample by sample."""

    truth: PlanarPoses
    """``map → base_link`` as the robot really is."""
    odom: PlanarPoses
    """``odom → base_link``, the odometry."""
    estimate: PlanarPoses
    """``map → base_link`` as the localiser has it."""
    correction: PlanarPoses
    """``map → odom``."""
    v: np.ndarray
    """Forward speed as odometry measures it (m/s)."""
    w: np.ndarray
    """Turn rate as odometry measures it (rad/s)."""
    drift: Odometry


def localise(
    trajectory: SampledMotion, rng: np.random.Generator, drift: Odometry | None = None, dt: float = DT
) -> Localisation:
    """The odometry, estimate and correction of a robot that drove ``trajectory`` (seeded, its
    samples ``dt`` apart); ``drift``: its odometry's, else drawn from ``rng`` (a robot driving leg
    after leg keeps one)."""
    drift = Odometry.seeded(rng) if drift is None else drift
    truth = PlanarPoses(trajectory.x, trajectory.y, trajectory.yaw)
    odom = _odometry(truth, drift)
    estimate = PlanarPoses(
        truth.x + _wandering(rng, LOCALISATION_NOISE, len(truth.x), dt),
        truth.y + _wandering(rng, LOCALISATION_NOISE, len(truth.x), dt),
        _wrap(truth.yaw + _wandering(rng, LOCALISATION_YAW_NOISE, len(truth.x), dt)),
    )
    return Localisation(
        truth,
        odom,
        estimate,
        estimate.compose(odom.inverse()),
        trajectory.v * (1.0 + drift.scale),
        trajectory.w * (1.0 + drift.turn) + drift.heading_bias * np.abs(trajectory.v),
        drift,
    )


def _odometry(truth: PlanarPoses, drift: Odometry) -> PlanarPoses:
    """Integrate each step's motion, measured in the body frame with the drift's errors, from zero."""
    dx, dy = np.diff(truth.x), np.diff(truth.y)
    c, s = np.cos(truth.yaw[:-1]), np.sin(truth.yaw[:-1])
    forward, lateral = c * dx + s * dy, -s * dx + c * dy
    turned = _wrap(np.diff(truth.yaw))
    measured_turn = turned * (1.0 + drift.turn) + drift.heading_bias * np.hypot(forward, lateral)
    yaw = np.concatenate([[0.0], np.cumsum(measured_turn)])
    oc, os_ = np.cos(yaw[:-1]), np.sin(yaw[:-1])
    f, lat = forward * (1.0 + drift.scale), lateral * (1.0 + drift.scale)
    x = np.concatenate([[0.0], np.cumsum(oc * f - os_ * lat)])
    y = np.concatenate([[0.0], np.cumsum(os_ * f + oc * lat)])
    return PlanarPoses(x, y, _wrap(yaw))


def _wandering(rng: np.random.Generator, sigma: float, samples: int, dt: float = DT) -> np.ndarray:
    """A first-order Gauss–Markov process: standard deviation ``sigma``, correlation ``NOISE_TIME``
    (samples ``dt`` apart)."""
    a = math.exp(-dt / NOISE_TIME)
    white = rng.normal(0.0, sigma, samples + 1)
    # the first value already has the stationary spread: a·e₀ + √(1−a²)·n₁ with e₀ ~ N(0, σ²)
    # y[n] = √(1−a²)·e[n] + a·y[n−1], as a plain loop: the very bits of scipy.signal.lfilter
    # (tests/sim/test_localisation_noise.py), without the second it takes to import scipy.signal
    gain = math.sqrt(1.0 - a * a)
    wandering = [0.0] * samples
    carried = a * float(white[0])
    for i, e in enumerate(white[1:].tolist()):
        wandering[i] = gain * e + carried
        carried = a * wandering[i]
    return np.array(wandering)


def _wrap(angle: np.ndarray) -> np.ndarray:
    wrapped: np.ndarray = np.arctan2(np.sin(angle), np.cos(angle))
    return wrapped
