"""Driving a path: rotate to the path, drive it with a trapezoidal speed
profile (bounded speed and acceleration), rotate to the goal's heading.

Everything is sampled on one clock (``RATE`` Hz) as numpy arrays.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

RATE = 50.0
DT = 1.0 / RATE


@dataclass(frozen=True)
class Limits:
    max_speed: float = 0.6  # m/s
    max_accel: float = 0.5  # m/s²
    max_turn_rate: float = 1.0  # rad/s


@dataclass(frozen=True)
class SampledMotion:
    """Samples every DT seconds from ``t0``: position, heading, speed, turn rate."""

    x: np.ndarray
    y: np.ndarray
    yaw: np.ndarray
    v: np.ndarray
    w: np.ndarray

    def __len__(self) -> int:
        return len(self.x)

    @staticmethod
    def hold(x: float, y: float, yaw: float, samples: int) -> SampledMotion:
        z = np.zeros(samples)
        return SampledMotion(z + x, z + y, z + yaw, z.copy(), z.copy())

    @staticmethod
    def concat(parts: list[SampledMotion]) -> SampledMotion:
        return SampledMotion(
            *(np.concatenate([getattr(p, f) for p in parts]) for f in ("x", "y", "yaw", "v", "w"))
        )


def _turn(x: float, y: float, yaw0: float, yaw1: float, limits: Limits) -> SampledMotion:
    delta = math.atan2(math.sin(yaw1 - yaw0), math.cos(yaw1 - yaw0))
    n = int(math.ceil(abs(delta) / (limits.max_turn_rate * DT)))
    if n == 0:
        return SampledMotion.hold(x, y, yaw0, 0)
    yaw = yaw0 + delta * np.arange(1, n + 1) / n
    w = np.full(n, delta / (n * DT))
    z = np.zeros(n)
    return SampledMotion(z + x, z + y, yaw, z, w)


def _speed_profile(length: float, limits: Limits) -> np.ndarray:
    """Arc length travelled at each sample of a trapezoidal (or triangular) profile."""
    a, vmax = limits.max_accel, limits.max_speed
    t_acc = vmax / a
    if a * t_acc**2 >= length:  # triangular: never reaches vmax
        t_acc = math.sqrt(length / a)
        vmax = a * t_acc
        t_flat = 0.0
    else:
        t_flat = (length - a * t_acc**2) / vmax
    total = 2 * t_acc + t_flat
    t = np.arange(1, int(math.ceil(total / DT)) + 1) * DT
    t = np.minimum(t, total)
    s = np.where(
        t < t_acc,
        0.5 * a * t**2,
        np.where(
            t < t_acc + t_flat,
            0.5 * a * t_acc**2 + vmax * (t - t_acc),
            length - 0.5 * a * np.maximum(total - t, 0.0) ** 2,
        ),
    )
    profile: np.ndarray = np.minimum(s, length)
    return profile


def drive(path: list[tuple[float, float]], yaw0: float, goal_yaw: float, limits: Limits) -> SampledMotion:
    """From ``path[0]`` heading ``yaw0`` along ``path`` to ``path[-1]``, ending at ``goal_yaw``."""
    pts = np.asarray(path, dtype=np.float64)
    seg = np.diff(pts, axis=0)
    seg_len = np.hypot(seg[:, 0], seg[:, 1])
    keep = seg_len > 1e-9
    pts = np.vstack([pts[:1], pts[1:][keep]])
    seg, seg_len = seg[keep], seg_len[keep]
    x0, y0 = float(pts[0, 0]), float(pts[0, 1])
    if len(seg_len) == 0:
        return _turn(x0, y0, yaw0, goal_yaw, limits)
    headings = np.unwrap(np.arctan2(seg[:, 1], seg[:, 0]))
    first = _turn(x0, y0, yaw0, float(headings[0]), limits)
    cum = np.concatenate([[0.0], np.cumsum(seg_len)])
    s = _speed_profile(float(cum[-1]), limits)
    idx = np.clip(np.searchsorted(cum, s, side="right") - 1, 0, len(seg_len) - 1)
    frac = (s - cum[idx]) / seg_len[idx]
    x = pts[idx, 0] + frac * seg[:, 0][idx]
    y = pts[idx, 1] + frac * seg[:, 1][idx]
    # heading follows the path, blended over ±0.4 m around corners (no instant turns)
    blend = 0.4
    yaw = np.interp(
        s,
        np.concatenate(
            [[0.0], np.repeat(cum[1:-1], 2) + np.tile([-blend, blend], len(cum) - 2), [cum[-1]]]
        ).clip(0, cum[-1]),
        np.concatenate(
            [[headings[0]], np.repeat(headings, 2)[1:-1] if len(headings) > 1 else [], [headings[-1]]]
        ),
    )
    prev_s = np.concatenate([[0.0], s[:-1]])
    v = (s - prev_s) / DT
    prev_yaw = np.concatenate([[float(headings[0])], yaw[:-1]])
    w = (yaw - prev_yaw) / DT
    moving = SampledMotion(x, y, yaw, v, w)
    last = _turn(float(x[-1]), float(y[-1]), float(yaw[-1]), goal_yaw, limits)
    return SampledMotion.concat([first, moving, last])
