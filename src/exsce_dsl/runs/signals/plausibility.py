"""Whether a pose series could be a robot's motion, before it makes a distance or a speed.

A pose topic can hold something no robot did: two localisation estimates published on one
topic by one connection (a root ``/location`` alternating at 27 Hz between two tracks metres
apart reads as kilometres of path and metres per second of speed), or a pose that teleports.
:func:`check_poses` measures every step between consecutive poses against physics:

- a step is **implausible** when it is longer than ``bound × its time + NOISE``: the speed
  ``bound`` is the spec's own speed limit (the largest ``safe below`` limit in m/s of its own
  metrics) × :data:`SPEC_FACTOR`, else :data:`DEFAULT_BOUND`; when the robot's own velocity is recorded,
  the bound is at most :data:`VELOCITY_FACTOR` × the largest speed it reports (never below
  :data:`VELOCITY_FLOOR`); :data:`NOISE` allows for a localiser's corrections and the jitter of
  the recorder's clock (two messages logged a fraction of a millisecond apart);
- the series **alternates between two tracks** when at least :data:`MIN_RETURNS` times an
  implausible step is followed by another that returns to where the first started;
- else each implausible step is a **teleport**.

A series with any implausible step is refused whole (never thinned): no value is computed from
it, and :meth:`Implausible.describe` says why, with the counts and the worst instance.  Pure
numpy: the caller gives times, positions and the velocity it has.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

DEFAULT_BOUND = 10.0
"""m/s: the speed no ground robot of the method reaches, when the spec says no speed limit."""
SPEC_FACTOR = 3.0
"""The spec's speed limit × this: the fastest speed a robot that breaks its limit may reach."""
VELOCITY_FACTOR = 3.0
"""The robot's own largest reported speed × this: the fastest a pose may imply."""
VELOCITY_FLOOR = 1.0
"""m/s: the least bound a reported velocity gives (a robot whose twist stays 0 still moves)."""
NOISE = 0.5
"""Metres a step may exceed the bound by: a localiser's correction, the recorder's clock jitter."""
MIN_RETURNS = 3
"""Back-and-forth steps from which a series alternates between two tracks (fewer: teleports)."""


@dataclass(frozen=True)
class Velocity:
    """The robot's own velocity signal: where it was read and the largest speed it reports."""

    topic: str
    peak: float


@dataclass(frozen=True)
class ImplausibleStep:
    """One implausible step: when (seconds from the series' first pose), how long, in what time."""

    at: float
    length: float
    seconds: float


@dataclass(frozen=True)
class Implausible:
    """Why a pose series is no robot's motion (see the module's docstring)."""

    topic: str
    bound: float
    """The speed its steps were measured against (m/s)."""
    steps: int
    """Steps longer than ``bound × time + NOISE``."""
    poses: int
    returns: int
    """Implausible steps followed by one back to where they started."""
    worst: ImplausibleStep
    velocity: Velocity | None = None

    @property
    def alternates(self) -> bool:
        return self.returns >= MIN_RETURNS

    def describe(self) -> str:
        """``/location alternates between two tracks up to 3.8 m apart; 2,636 steps imply more
        than 1 m/s while /velocity never exceeds 0.31 m/s``."""
        worst = self.worst
        if self.alternates:
            said = f"{self.topic} alternates between two tracks up to {worst.length:.1f} m apart"
        else:
            said = (
                f"{self.topic} teleports {worst.length:.1f} m in {worst.seconds:.3f} s, "
                f"{worst.at:.1f} s after its first pose"
            )
        verb = "implies" if self.steps == 1 else "imply"
        said += f"; {self.steps:,} of {self.poses - 1:,} steps {verb} more than {self.bound:.3g} m/s"
        if self.velocity is not None:
            said += f" while {self.velocity.topic} never exceeds {self.velocity.peak:.2f} m/s"
        return said


def speed_bound(limit: float | None) -> float:
    """The speed a pose is measured against: the spec's speed limit × :data:`SPEC_FACTOR`, or
    :data:`DEFAULT_BOUND` when the spec has none."""
    return DEFAULT_BOUND if limit is None or not limit > 0 else limit * SPEC_FACTOR


def velocity_peak(topic: str, axes: Sequence[np.ndarray]) -> Velocity | None:
    """The largest speed of a velocity signal's linear ``axes`` (None: no finite value)."""
    if not axes or not len(axes[0]):
        return None
    norm = np.sqrt(sum(np.square(np.asarray(a, dtype=np.float64)) for a in axes))
    finite = norm[np.isfinite(norm)]
    return Velocity(topic, float(finite.max())) if len(finite) else None


def check_poses(
    topic: str,
    t: np.ndarray,
    positions: Sequence[np.ndarray],
    bound: float,
    velocity: Velocity | None = None,
) -> Implausible | None:
    """The finding of the pose series at times ``t`` (seconds) and ``positions`` (one array per
    axis, metres), or None when every step is plausible; ``bound``: :func:`speed_bound`'s;
    ``velocity``: the robot's own, when recorded (not estimated from these poses)."""
    if velocity is not None:
        bound = min(bound, max(VELOCITY_FACTOR * velocity.peak, VELOCITY_FLOOR))
    times = np.asarray(t, dtype=np.float64)
    if len(times) < 2:
        return None
    p = np.stack([np.asarray(a, dtype=np.float64) for a in positions], axis=1)
    length = np.linalg.norm(np.diff(p, axis=0), axis=1)
    seconds = np.diff(times)
    with np.errstate(invalid="ignore"):  # a NaN position makes no step either way
        jump = length > bound * np.maximum(seconds, 0.0) + NOISE
    if not jump.any():
        return None
    back = np.linalg.norm(p[2:] - p[:-2], axis=1)
    with np.errstate(invalid="ignore"):
        returned = jump[:-1] & jump[1:] & (back <= bound * np.maximum(times[2:] - times[:-2], 0.0) + NOISE)
    k = int(np.nanargmax(np.where(jump, length, -np.inf)))
    worst = ImplausibleStep(float(times[k] - times[0]), float(length[k]), float(seconds[k]))
    return Implausible(topic, bound, int(jump.sum()), len(times), int(returned.sum()), worst, velocity)
