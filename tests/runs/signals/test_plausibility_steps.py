"""The plausibility check's rules, step by step (``runs/signals/plausibility.py``): the bound, the
allowance for noise and clock jitter, and what tells two tracks from a teleport."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from exsce_dsl.lang import load_spec, standard_metrics
from exsce_dsl.runs.plausible_poses import spec_speed_limit
from exsce_dsl.runs.signals.plausibility import (
    DEFAULT_BOUND,
    Velocity,
    check_poses,
    speed_bound,
)

from tests.support.yard_spec import FAR_YARD

LIMITS = """
metric ramp_speed for each robot {
  unit m/s
  safe below 1.5 m/s
  reads vel: geometry_msgs/msg/Twist on "/{ns}/ramp_vel"
  value max(vel.linear.x)
}
metric slow_turn for each robot {
  unit m/s
  safe below 0.4 m/s
  reads vel: geometry_msgs/msg/Twist on "/{ns}/turn_vel"
  value max(vel.linear.y)
}
scenario rooted in yard {
  robots {
    tb: bot namespace "" starts at start
  }
  mission go_far sequential {
    tb does go
  }
}
"""


def _line(speed: float, hz: float = 10.0, seconds: float = 20.0) -> tuple[np.ndarray, np.ndarray]:
    t = np.arange(int(seconds * hz)) / hz
    return t, speed * t


def test_the_bound_is_the_specs_limit_times_three_else_ten_metres_a_second() -> None:
    assert speed_bound(None) == DEFAULT_BOUND == 10.0
    assert speed_bound(0.5) == pytest.approx(1.5)


def test_the_specs_speed_limit_is_its_own_metrics_largest_in_metres_a_second(tmp_path: Path) -> None:
    """The standard library's ``max_velocity`` (safe below 1 m/s) is the method's, for indoor
    robots: only the spec's own metrics give its limit."""
    spec = tmp_path / "limits.exsce"
    spec.write_text(FAR_YARD + LIMITS)
    metrics = load_spec(spec).scenario().metrics
    assert spec_speed_limit(metrics) == pytest.approx(1.5)
    assert spec_speed_limit([*metrics, *standard_metrics()]) == pytest.approx(1.5)
    assert spec_speed_limit(standard_metrics()) == pytest.approx(1.0)


def test_a_fast_clean_drive_passes_the_default_bound() -> None:
    t, x = _line(6.0)
    assert check_poses("/odom", t, [x, np.zeros_like(x)], speed_bound(None)) is None


def test_a_drive_faster_than_its_own_velocity_allows_is_implausible() -> None:
    """8 m/s where the robot says 0.5: 0.8 m a step, beyond 1.5 m/s × 0.1 s + 0.5 m."""
    t, x = _line(8.0)
    found = check_poses("/odom", t, [x, np.zeros_like(x)], speed_bound(None), Velocity("/vel", 0.5))
    assert found is not None and found.bound == pytest.approx(1.5)
    assert found.steps == len(t) - 1 and not found.alternates
    assert "while /vel never exceeds 0.50 m/s" in found.describe()


def test_messages_logged_together_are_no_teleport() -> None:
    """The recorder logs a burst a fraction of a millisecond apart: 2 cm in 0.1 ms is 200 m/s."""
    t, x = _line(1.0, hz=50.0)
    t[1::2] = t[::2][: len(t[1::2])] + 1e-4
    assert check_poses("/odom", t, [x, np.zeros_like(x)], speed_bound(None)) is None


def test_nan_positions_make_no_step() -> None:
    t, x = _line(1.0)
    x[5] = np.nan
    assert check_poses("/odom", t, [x, np.zeros_like(x)], speed_bound(None)) is None


def test_a_single_outlier_pose_is_a_teleport_not_two_tracks() -> None:
    t, x = _line(1.0)
    y = np.zeros_like(x)
    y[50] = 4.0
    found = check_poses("/odom", t, [x, y], speed_bound(None))
    assert found is not None and found.steps == 2 and found.returns == 1 and not found.alternates
    assert found.describe().startswith("/odom teleports 4.0 m in 0.100 s, 4.9 s after its first pose")
