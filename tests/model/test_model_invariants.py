"""The model's own promises, tested where they are made (issue 36, item 5): what a coverage gap
concerns, how stored outcomes read, run file names, and the quaternion of a pose's rotation.

Reference values are worked by hand here (or with numpy's rotation matrices), not taken from the
code under test.
"""

from __future__ import annotations

import datetime as dt
import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from exsce_dsl.errors import ExsceError
from exsce_dsl.model.coverage import CoverageGap, Shortfall
from exsce_dsl.model.geometry import quaternion
from exsce_dsl.model.runs import run_name
from exsce_dsl.model.verdicts import Outcome


@pytest.mark.parametrize(
    ("gap", "metric", "robot", "concerned"),
    [
        (CoverageGap(Shortfall.CUT_SHORT, "cut"), "max_velocity", "tiago1", True),  # every metric, robot
        (CoverageGap(Shortfall.GAP, "scan", "tiago1", metrics=("distance_to_obstacles",)), "max_velocity", "tiago1", False),
        (CoverageGap(Shortfall.GAP, "scan", "tiago1", metrics=("distance_to_obstacles",)), "distance_to_obstacles", "tiago2", False),
        (CoverageGap(Shortfall.GAP, "scan", "tiago1", metrics=("distance_to_obstacles",)), "distance_to_obstacles", "tiago1", True),
        (CoverageGap(Shortfall.GAP, "odom", "tiago1", metrics=("distance_between_robots",)), "distance_between_robots", None, True),  # the mission's clause reads every robot
        (CoverageGap(Shortfall.CLOCK_JUMP, "clock", None), "mission_duration", None, True),
    ],
)  # fmt: skip
def test_a_gap_concerns_the_clauses_of_its_metrics_and_robot(
    gap: CoverageGap, metric: str, robot: str | None, concerned: bool
) -> None:
    assert gap.concerns(metric, robot) is concerned


def test_a_stored_outcome_of_older_stores_reads_as_inconclusive() -> None:
    assert Outcome("unjudged") is Outcome.INCONCLUSIVE is Outcome("inconclusive")
    with pytest.raises(ValueError):
        Outcome("skipped")


def test_a_run_is_named_as_the_method_names_its_files() -> None:
    start = dt.datetime(2023, 6, 13, 17, 48, 7, tzinfo=dt.timezone(dt.timedelta(hours=2)))
    name = run_name(start, "scenario_c", "e30df0b6-1234-5678-9abc-def012345678")
    assert name == "2023-06-13T15-48-07_scenario_c_run-e30df0b6"  # the start in UTC


@pytest.mark.parametrize("scenario", ["../etc", "a b", "", "scenario/c"])
def test_a_scenario_id_that_is_no_name_cannot_name_a_runs_files(scenario: str) -> None:
    start = dt.datetime(2023, 6, 13, tzinfo=dt.timezone.utc)
    with pytest.raises(ExsceError):
        run_name(start, scenario, "e30df0b6-1234-5678-9abc-def012345678")


def _matrix(roll: float, pitch: float, yaw: float) -> np.ndarray:
    """R = Rz(yaw) · Ry(pitch) · Rx(roll): rotations about the fixed x, y, z axes in that order."""
    cr, sr, cp, sp, cy, sy = (f(a) for a in (roll, pitch, yaw) for f in (math.cos, math.sin))
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    return rz @ ry @ rx


angles = st.floats(min_value=-math.pi, max_value=math.pi, allow_nan=False)


@given(angles, angles, angles)
def test_the_quaternion_of_a_pose_rotates_as_its_roll_pitch_and_yaw(
    roll: float, pitch: float, yaw: float
) -> None:
    x, y, z, w = quaternion(roll, pitch, yaw)
    assert math.isclose(x * x + y * y + z * z + w * w, 1.0, rel_tol=1e-12)
    # the rotation matrix of the unit quaternion (x, y, z, w), as any textbook writes it
    from_quaternion = np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )
    assert np.allclose(from_quaternion, _matrix(roll, pitch, yaw), atol=1e-9)


def test_a_yaw_of_a_quarter_turn_is_the_textbooks_quaternion() -> None:
    x, y, z, w = quaternion(0.0, 0.0, math.pi / 2)
    assert (x, y) == (0.0, 0.0)
    assert z == pytest.approx(math.sqrt(0.5)) and w == pytest.approx(math.sqrt(0.5))
