"""A robot's pose from TF: interpolation, composition along the tree, validity and the errors people see.

Expected values come from an independent path: 4×4 homogeneous matrices built per sample in a Python
loop (rotation interpolated as R0·exp(u·log(R0ᵀR1)) with Rodrigues' formula, not slerp), closed-form
motions, and hand-computed cases.

Speed (not a test; measured by hand on the shared 2-core machine, numpy 2.4): ``pose_at`` for 60,000
times over a 3-edge chain (odom → base_link 50 Hz, map → odom 10 Hz, a static laser) takes ~30 ms,
and ~45 ms with three dynamic edges (EdgeSeries of 60,000 rows: ~15 ms to build).
"""

from __future__ import annotations

import bisect
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from exsce_dsl.errors import ExsceError, TfError
from exsce_dsl.runs.signals.tf_poses import (
    EdgeSeries,
    FrameTree,
    Poses,
    default_times,
    pose_at,
    yaw_from_quaternion,
)

# --- the independent path: plain matrices, one sample at a time -------------------------------------


def quat_about(axis: tuple[float, float, float], angle: float) -> list[float]:
    norm = math.sqrt(sum(a * a for a in axis))
    s = math.sin(angle / 2) / norm
    return [axis[0] * s, axis[1] * s, axis[2] * s, math.cos(angle / 2)]


def yaw_quat(yaw: float) -> list[float]:
    return quat_about((0.0, 0.0, 1.0), yaw)


def rotation_matrix(q: list[float] | np.ndarray) -> np.ndarray:
    """The rotation of a quaternion x, y, z, w (any norm), written out."""
    x, y, z, w = (float(v) for v in q)
    s = 2.0 / (x * x + y * y + z * z + w * w)
    return np.array(
        [
            [1 - s * (y * y + z * z), s * (x * y - z * w), s * (x * z + y * w)],
            [s * (x * y + z * w), 1 - s * (x * x + z * z), s * (y * z - x * w)],
            [s * (x * z - y * w), s * (y * z + x * w), 1 - s * (x * x + y * y)],
        ]
    )


def homogeneous(rotation: np.ndarray, translation: list[float] | np.ndarray) -> np.ndarray:
    m = np.eye(4)
    m[:3, :3] = rotation
    m[:3, 3] = translation
    return m


def rodrigues(axis: np.ndarray, angle: float) -> np.ndarray:
    k = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    return np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * (k @ k)


def rotation_between(r0: np.ndarray, r1: np.ndarray, u: float) -> np.ndarray:
    """R0·exp(u·log(R0ᵀR1)): the rotation a fraction u of the way from r0 to r1 (the shorter way)."""
    relative = r0.T @ r1
    angle = math.acos(max(-1.0, min(1.0, (np.trace(relative) - 1) / 2)))
    if angle < 1e-12:
        return r0
    axis = np.array(
        [relative[2, 1] - relative[1, 2], relative[0, 2] - relative[2, 0], relative[1, 0] - relative[0, 1]]
    ) / (2 * math.sin(angle))
    return r0 @ rodrigues(axis, u * angle)


def matrix_yaw(m: np.ndarray) -> float:
    return math.atan2(m[1, 0], m[0, 0])


class Samples:
    """One edge's raw data as the reference sees it: sorted by time, looked up one time at a time."""

    def __init__(
        self, times: list[float], translations: list[list[float]], quats: list[list[float]], static: bool
    ):
        rows = sorted(zip(times, translations, quats, strict=True), key=lambda r: r[0])
        self.times = [r[0] for r in rows]
        self.translations = [r[1] for r in rows]
        self.rotations = [rotation_matrix(r[2]) for r in rows]
        self.static = static

    def matrix(self, k: int) -> np.ndarray:
        return homogeneous(self.rotations[k], self.translations[k])

    def at(self, t: float, max_extrapolation: float = 0.5, max_gap: float = 1.0) -> np.ndarray | None:
        if self.static:
            return self.matrix(len(self.times) - 1)
        first, last = self.times[0], self.times[-1]
        if t < first:
            return self.matrix(0) if first - t <= max_extrapolation else None
        if t >= last:
            return self.matrix(len(self.times) - 1) if t - last <= max_extrapolation else None
        k = bisect.bisect_right(self.times, t) - 1
        t0, t1 = self.times[k], self.times[k + 1]
        if t == t0:
            return self.matrix(k)
        if t1 - t0 > max_gap:
            return None
        u = (t - t0) / (t1 - t0)
        p = [a + u * (b - a) for a, b in zip(self.translations[k], self.translations[k + 1], strict=True)]
        return homogeneous(rotation_between(self.rotations[k], self.rotations[k + 1], u), p)


def reference_pose(
    edges: dict[str, tuple[str, Samples]], fixed: str, body: str, t: float, **limits: float
) -> np.ndarray | None:
    """``body`` in ``fixed`` at ``t``: climb both to their lowest common ancestor, multiply matrices down
    from it to each, and take inv(ancestor→fixed) · (ancestor→body). ``edges``: child → (parent, data)."""

    def ancestry(frame: str) -> list[str]:
        path = [frame]
        while path[-1] in edges:
            path.append(edges[path[-1]][0])
        return path

    from_fixed, from_body = ancestry(fixed), ancestry(body)
    common = next(f for f in from_fixed if f in from_body)

    def down_to(frame: str, path: list[str]) -> np.ndarray | None:
        m = np.eye(4)
        for child in reversed(path[: path.index(common)]):
            edge = edges[child][1].at(t, **limits)
            if edge is None:
                return None
            m = m @ edge
        return m

    to_fixed, to_body = down_to(fixed, from_fixed), down_to(body, from_body)
    if to_fixed is None or to_body is None:
        return None
    return np.linalg.inv(to_fixed) @ to_body


def assert_poses_match(poses: Poses, expected: list[np.ndarray | None], atol: float = 1e-9) -> None:
    assert poses.valid.tolist() == [m is not None for m in expected]
    for i, m in enumerate(expected):
        if m is None:
            assert np.isnan(poses.position[i]).all() and np.isnan(poses.quaternion[i]).all()
            assert math.isnan(poses.yaw[i])
            continue
        np.testing.assert_allclose(poses.position[i], m[:3, 3], atol=atol, rtol=0)
        np.testing.assert_allclose(rotation_matrix(poses.quaternion[i]), m[:3, :3], atol=atol, rtol=0)
        assert abs(math.remainder(poses.yaw[i] - matrix_yaw(m), math.tau)) < 1e-7
        assert abs(np.linalg.norm(poses.quaternion[i]) - 1) < 1e-12


def edge(
    parent: str,
    child: str,
    times: list[float] | np.ndarray,
    translations: list[list[float]] | np.ndarray,
    quats: list[list[float]] | np.ndarray,
    static: bool = False,
) -> EdgeSeries:
    return EdgeSeries(
        parent,
        child,
        np.asarray(times, float),
        np.asarray(translations, float),
        np.asarray(quats, float),
        static=static,
    )


def one_edge(times: list[float], translations: list[list[float]], quats: list[list[float]]) -> FrameTree:
    return FrameTree([edge("odom", "base_link", times, translations, quats)])


# --- interpolation, by hand -------------------------------------------------------------------------


def test_translation_halfway_is_the_mean() -> None:
    tree = one_edge([10.0, 11.0], [[1, 2, 3], [3, -2, 7]], [[0, 0, 0, 1]] * 2)
    poses = pose_at(tree, "odom", "base_link", [10.0, 10.25, 10.5, 11.0])
    np.testing.assert_allclose(poses.position, [[1, 2, 3], [1.5, 1, 4], [2, 0, 5], [3, -2, 7]], atol=1e-12)
    assert poses.valid.all()


def test_a_yaw_from_170_to_minus_170_degrees_passes_through_180_not_0() -> None:
    tree = one_edge([0.0, 1.0], [[0, 0, 0]] * 2, [yaw_quat(math.radians(170)), yaw_quat(math.radians(-170))])
    yaw = np.degrees(pose_at(tree, "odom", "base_link", [0.0, 0.25, 0.5, 0.75, 1.0]).yaw)
    assert yaw[0] == pytest.approx(170)
    assert yaw[1] == pytest.approx(175)
    assert abs(yaw[2]) == pytest.approx(180)
    assert yaw[3] == pytest.approx(-175)
    assert yaw[4] == pytest.approx(-170)


@pytest.mark.parametrize("axis", [(0.0, 0.0, 1.0), (1.0, 0.0, 0.0), (1.0, 1.0, 1.0)])
def test_slerp_of_a_quarter_turn_at_half_time_is_an_eighth_turn(axis: tuple[float, float, float]) -> None:
    tree = one_edge([0.0, 1.0], [[0, 0, 0]] * 2, [[0, 0, 0, 1], quat_about(axis, math.pi / 2)])
    poses = pose_at(tree, "odom", "base_link", [0.5, 0.25])
    np.testing.assert_allclose(poses.quaternion[0], quat_about(axis, math.pi / 4), atol=1e-12)
    np.testing.assert_allclose(poses.quaternion[1], quat_about(axis, math.pi / 8), atol=1e-12)
    if axis == (0.0, 0.0, 1.0):
        assert math.degrees(poses.yaw[0]) == pytest.approx(45)


def test_sign_flipped_quaternions_in_the_data_interpolate_the_short_way() -> None:
    # every other quaternion is stored as -q (the same rotation): the yaw steps 10° a second
    quats = [
        [-c for c in yaw_quat(math.radians(10 * k))] if k % 2 else yaw_quat(math.radians(10 * k))
        for k in range(4)
    ]
    tree = one_edge([0.0, 1.0, 2.0, 3.0], [[0, 0, 0]] * 4, quats)
    yaw = np.degrees(pose_at(tree, "odom", "base_link", [0.5, 1.5, 2.5, 2.75]).yaw)
    np.testing.assert_allclose(yaw, [5, 15, 25, 27.5], atol=1e-9)


def test_nearly_equal_quaternions_blend_without_dividing_by_zero() -> None:
    tiny = 1e-9
    tree = one_edge([0.0, 1.0], [[0, 0, 0]] * 2, [yaw_quat(0.3), yaw_quat(0.3 + tiny)])
    poses = pose_at(tree, "odom", "base_link", [0.0, 0.5, 1.0])
    assert np.isfinite(poses.quaternion).all()
    np.testing.assert_allclose(poses.yaw, [0.3, 0.3 + tiny / 2, 0.3 + tiny], atol=1e-15)


def test_identical_quaternions_interpolate_to_themselves() -> None:
    q = quat_about((0.2, -0.4, 1.0), 2.0)
    tree = one_edge([0.0, 1.0, 2.0], [[0, 0, 0]] * 3, [q, q, [-c for c in q]])
    poses = pose_at(tree, "odom", "base_link", [0.3, 1.7])
    np.testing.assert_allclose(poses.quaternion, [q, q], atol=1e-15)


def test_yaw_is_read_from_a_rolled_and_pitched_quaternion() -> None:
    roll, pitch, yaw = 0.3, -0.7, 2.5
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    q = [
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
        cr * cp * cy + sr * sp * sy,
    ]
    assert yaw_from_quaternion(np.array([q, [-c for c in q]])) == pytest.approx([yaw, yaw])
    assert matrix_yaw(homogeneous(rotation_matrix(q), [0, 0, 0])) == pytest.approx(yaw)


# --- a robot's chain: map → odom → base_link → laser --------------------------------------------------

TILT = (0.1, -0.05, 1.0)  # map → odom turns about a slightly tilted axis, to exercise the full 3-D maths


def odom_base_link(t: float) -> tuple[list[float], list[float]]:
    """Wheel odometry: drives along x and drifts in y, turning at 0.2 rad/s (past π after 16 s)."""
    return [0.3 * t, 0.05 * t, 0.0], yaw_quat(0.2 * t)


def map_odom(t: float) -> tuple[list[float], list[float]]:
    """AMCL's correction, moving slowly as the odometry drifts."""
    return [1.0 + 0.01 * t, -0.5 + 0.002 * t, 0.001 * t], quat_about(TILT, 0.3 - 0.005 * t)


LASER = ([0.2, 0.0, 0.15], [1.0, 0.0, 0.0, 0.0])  # mounted upside down: 180° about x


def robot_tree(odom_times: np.ndarray, map_times: np.ndarray) -> FrameTree:
    odom = [odom_base_link(t) for t in odom_times]
    amcl = [map_odom(t) for t in map_times]
    return FrameTree(
        [
            edge("odom", "base_link", odom_times, [p for p, _ in odom], [q for _, q in odom]),
            edge("map", "odom", map_times, [p for p, _ in amcl], [q for _, q in amcl]),
            edge("base_link", "laser", [0.0], [LASER[0]], [LASER[1]], static=True),
        ]
    )


def closed_form(
    t: float, odom_span: tuple[float, float], map_span: tuple[float, float], frame: str = "laser"
) -> np.ndarray:
    """The exact pose of the laser (or base_link) in map: each motion is linear in time (a fixed axis, a
    linear angle), so interpolating its samples gives it back exactly; outside its samples a stream
    holds its end."""
    p1, q1 = map_odom(min(max(t, map_span[0]), map_span[1]))
    p2, q2 = odom_base_link(min(max(t, odom_span[0]), odom_span[1]))
    m = homogeneous(rotation_matrix(q1), p1) @ homogeneous(rotation_matrix(q2), p2)
    return m @ homogeneous(rotation_matrix(LASER[1]), LASER[0]) if frame == "laser" else m


def test_the_laser_in_map_composes_odometry_the_slower_correction_and_the_static_mount() -> None:
    odom_times = 0.004 + 0.02 * np.arange(1000)  # 50 Hz, 0.004 … 19.984
    map_times = 0.037 + 0.1 * np.arange(200)  # 10 Hz, stamps not aligned with odometry's
    tree = robot_tree(odom_times, map_times)
    times = np.concatenate([default_times(tree, "map", "laser"), np.linspace(0.5, 19.5, 777)])
    poses = pose_at(tree, "map", "laser", times)
    spans = (odom_times[0], odom_times[-1]), (map_times[0], map_times[-1])
    assert_poses_match(poses, [closed_form(t, *spans) for t in times])
    np.testing.assert_array_equal(poses.times, times)


def test_the_chain_from_map_to_laser_goes_down_three_edges() -> None:
    tree = robot_tree(np.arange(3.0), np.arange(3.0))
    chain = tree.chain("map", "laser")
    assert chain.up == ()
    assert [e.name for e in chain.down] == ["map → odom", "odom → base_link", "base_link → laser"]
    assert tree.parent_of("laser") == "base_link" and tree.parent_of("map") is None
    assert tree.outline() == "map → odom → base_link → laser"


def test_natural_times_are_the_fastest_edge_s_stamps_where_every_edge_has_data() -> None:
    odom_times = 0.02 * np.arange(500)  # 0 … 9.98 s at 50 Hz
    map_times = 2.0 + 0.1 * np.arange(51)  # 2 … 7 s at 10 Hz: AMCL starts late and stops early
    tree = robot_tree(odom_times, map_times)
    times = default_times(tree, "map", "base_link")
    inside = (odom_times >= 1.5) & (odom_times <= 7.5)
    np.testing.assert_array_equal(times, odom_times[inside])
    assert pose_at(tree, "map", "base_link", times).valid.all()
    np.testing.assert_array_equal(
        default_times(tree, "map", "base_link", max_extrapolation=0.0),
        odom_times[(odom_times >= 2.0) & (odom_times <= 7.0)],
    )


def test_natural_times_need_a_dynamic_edge_and_overlapping_data() -> None:
    tree = robot_tree(np.arange(0.0, 5.0, 0.02), np.arange(10.0, 12.0, 0.1))
    with pytest.raises(TfError, match=r"never overlap.*map → odom 10\.000–11\.900 s"):
        default_times(tree, "map", "base_link")
    with pytest.raises(TfError, match="every transform between 'base_link' and 'laser' is static"):
        default_times(tree, "base_link", "laser")


def test_the_static_mount_holds_at_every_time() -> None:
    tree = robot_tree(np.arange(3.0), np.arange(3.0))
    poses = pose_at(tree, "base_link", "laser", [-1000.0, 0.0, 1e9])
    assert poses.valid.all()
    np.testing.assert_allclose(poses.position, [LASER[0]] * 3)
    np.testing.assert_allclose(np.abs(poses.quaternion), [LASER[1]] * 3)


def test_a_frame_in_itself_is_the_identity() -> None:
    tree = robot_tree(np.arange(3.0), np.arange(3.0))
    poses = pose_at(tree, "odom", "odom", [0.0, 99.0])
    np.testing.assert_array_equal(poses.position, np.zeros((2, 3)))
    np.testing.assert_array_equal(poses.quaternion, [[0, 0, 0, 1]] * 2)


def test_the_output_quaternion_is_sign_continuous_over_a_full_turn() -> None:
    times = np.arange(0.0, 40.0, 0.02)  # 0.2 rad/s for 40 s: 8 rad, more than a turn
    tree = robot_tree(times, times)
    q = pose_at(tree, "odom", "base_link", times + 0.01).quaternion[:-1]
    assert q[0, 3] >= 0
    assert (np.einsum("ij,ij->i", q[1:], q[:-1]) > 0).all()


# --- validity: holding near the ends, gaps, bad times ------------------------------------------------


def test_a_stream_s_ends_are_held_only_within_max_extrapolation() -> None:
    odom_times = 0.02 * np.arange(501)  # 0 … 10 s
    map_times = 2.0 + 0.5 * np.arange(13)  # 2 … 8 s
    tree = robot_tree(odom_times, map_times)
    times = [1.4, 1.5, 1.6, 2.0, 5.0, 8.0, 8.4, 8.5, 8.6]
    poses = pose_at(tree, "map", "base_link", times)
    spans = (odom_times[0], odom_times[-1]), (map_times[0], map_times[-1])
    assert_poses_match(poses, [None, *(closed_form(t, *spans, frame="base_link") for t in times[1:-1]), None])
    # held, not extrapolated: before AMCL's first message its first correction applies
    held = pose_at(tree, "map", "odom", [1.6, 2.0, 8.0, 8.4]).position
    np.testing.assert_array_equal(held[0], held[1])
    np.testing.assert_array_equal(held[2], held[3])
    strict = pose_at(tree, "map", "base_link", times, max_extrapolation=0.0)
    assert strict.valid.tolist() == [False, False, False, True, True, True, False, False, False]


def test_a_dropped_stream_is_not_interpolated_across() -> None:
    stamps = [0.0, 0.5, 1.0, 3.5, 4.0, 4.8]  # 2.5 s without odometry, then 0.8 s
    tree = one_edge(stamps, [[t, 0, 0] for t in stamps], [yaw_quat(0.1 * t) for t in stamps])
    times = [0.75, 1.0, 1.01, 2.0, 3.49, 3.5, 3.75, 4.4]
    poses = pose_at(tree, "odom", "base_link", times)
    assert poses.valid.tolist() == [True, True, False, False, False, True, True, True]
    np.testing.assert_allclose(poses.position[poses.valid, 0], [0.75, 1.0, 3.5, 3.75, 4.4])
    tighter = pose_at(tree, "odom", "base_link", times, max_gap=0.6)
    assert tighter.valid.tolist() == [True, True, False, False, False, True, True, False]


def test_non_finite_times_are_invalid() -> None:
    tree = one_edge([0.0, 1.0], [[0, 0, 0], [1, 0, 0]], [[0, 0, 0, 1]] * 2)
    poses = pose_at(tree, "odom", "base_link", [math.nan, 0.5, math.inf, -math.inf])
    assert poses.valid.tolist() == [False, True, False, False]


def test_an_edge_without_data_makes_every_pose_invalid() -> None:
    tree = FrameTree([EdgeSeries("odom", "base_link", np.zeros(0), np.zeros((0, 3)), np.zeros((0, 4)))])
    assert not pose_at(tree, "odom", "base_link", [0.0, 1.0]).valid.any()
    with pytest.raises(TfError, match="no usable transforms odom → base_link"):
        default_times(tree, "odom", "base_link")


def test_limits_must_make_sense() -> None:
    tree = one_edge([0.0], [[0, 0, 0]], [[0, 0, 0, 1]])
    with pytest.raises(TfError, match="max_extrapolation"):
        pose_at(tree, "odom", "base_link", [0.0], max_extrapolation=-1)
    with pytest.raises(TfError, match="max_gap"):
        pose_at(tree, "odom", "base_link", [0.0], max_gap=0)
    with pytest.raises(TfError, match="1-D"):
        pose_at(tree, "odom", "base_link", [[0.0]])


# --- cleaning the data -------------------------------------------------------------------------------


def test_an_edge_series_sorts_drops_bad_rows_and_normalises() -> None:
    series = EdgeSeries(
        "/odom",
        "/base_link",
        np.array([2.0, 0.0, np.nan, 1.0, 3.0, 1.0, 4.0]),
        np.array([[2, 0, 0], [0, 0, 0], [9, 9, 9], [1, 0, 0], [np.inf, 0, 0], [1.5, 0, 0], [4, 0, 0]], float),
        np.array(
            [
                [0, 0, 0, 2],
                [0, 0, 0, 1],
                [0, 0, 0, 1],
                [0, 0, 0, -3],
                [0, 0, 0, 1],
                [0, 0, 0, -1],
                [0, 0, 0, 0],
            ],
            float,
        ),
    )
    assert (series.parent, series.child) == ("odom", "base_link")  # tf2 drops the leading slash
    np.testing.assert_array_equal(series.times, [0.0, 1.0, 2.0])  # NaN, inf and zero-quaternion rows gone
    np.testing.assert_array_equal(series.translation[:, 0], [0.0, 1.5, 2.0])  # of equal stamps, the last
    np.testing.assert_array_equal(series.rotation, [[0, 0, 0, 1]] * 3)  # unit, sign-continuous
    assert not series.times.flags.writeable


def test_an_edge_series_with_mismatched_columns_is_an_error() -> None:
    with pytest.raises(TfError, match=r"odom → base_link: expected times \(n,\)"):
        EdgeSeries("odom", "base_link", np.zeros(3), np.zeros((3, 3)), np.zeros((2, 4)))
    with pytest.raises(TfError, match="to itself"):
        EdgeSeries("odom", "/odom", np.zeros(1), np.zeros((1, 3)), np.array([[0, 0, 0, 1.0]]))


# --- frames that are not where the user thinks ---------------------------------------------------------


def _static(parent: str, child: str) -> EdgeSeries:
    return edge(parent, child, [0.0], [[0, 0, 0]], [[0, 0, 0, 1]], static=True)


def test_a_frame_with_two_parents_is_an_error_naming_both() -> None:
    with pytest.raises(TfError) as caught:
        FrameTree([_static("map", "odom"), _static("odom", "base_link"), _static("map", "base_link")])
    assert isinstance(caught.value, ExsceError)
    assert "frame 'base_link' has two parents, 'odom' and 'map'" in str(caught.value)


def test_all_tree_problems_are_reported_together() -> None:
    with pytest.raises(TfError) as caught:
        FrameTree(
            [
                _static("odom", "base_link"),
                edge("odom", "base_link", [0.0], [[0, 0, 0]], [[0, 0, 0, 1]]),
                _static("a", "b"),
                _static("b", "c"),
                _static("c", "a"),
                _static("map", "laser"),
                _static("base_link", "laser"),
            ]
        )
    message = str(caught.value)
    assert "the transform odom → base_link is given twice (dynamic and static)" in message
    assert "the frames a → b → c → a form a cycle" in message
    assert "frame 'laser' has two parents, 'map' and 'base_link'" in message


def test_a_misspelt_frame_is_reported_with_a_suggestion_and_the_frames_there_are() -> None:
    tree = robot_tree(np.arange(3.0), np.arange(3.0))
    with pytest.raises(TfError) as caught:
        pose_at(tree, "map", "base_footprint", [0.0])
    assert str(caught.value) == (
        "error: no frame 'base_footprint' in the TF data; did you mean 'base_link'? "
        "The TF data has frames base_link, laser, map, odom, connected as: map → odom → base_link → laser"
    )
    with pytest.raises(TfError, match=r"no frame 'world' in the TF data\. The TF data has frames"):
        tree.chain("world", "base_link")


def test_frames_in_separate_trees_are_not_connected() -> None:
    tree = FrameTree([_static("map", "odom"), _static("odom", "base_link"), _static("camera_rig", "camera")])
    with pytest.raises(TfError) as caught:
        tree.chain("map", "camera")
    assert str(caught.value) == (
        "error: frames 'map' and 'camera' are not connected in TF: 'map' is in the tree of 'map' and "
        "'camera' in the tree of 'camera_rig'. The TF data has frames base_link, camera, camera_rig, map, "
        "odom, connected as (separate trees): camera_rig → camera; map → odom → base_link"
    )


# --- chains that climb before they descend -------------------------------------------------------------


def test_a_sensor_in_another_sensor_climbs_to_their_common_parent() -> None:
    times = 0.1 * np.arange(30)
    laser = Samples(
        list(times),
        [[0.2, 0.01 * k, 0.1] for k in range(30)],
        [quat_about((0, 1, 1), 0.05 * k) for k in range(30)],
        False,
    )
    camera = Samples([0.0], [[0.1, -0.05, 0.4]], [quat_about((1, 0, 0), -1.2)], True)
    tree = FrameTree(
        [
            edge(
                "base_link",
                "laser",
                laser.times,
                laser.translations,
                [quat_about((0, 1, 1), 0.05 * k) for k in range(30)],
            ),
            edge(
                "base_link", "camera", [0.0], camera.translations, [quat_about((1, 0, 0), -1.2)], static=True
            ),
        ]
    )
    chain = tree.chain("camera", "laser")
    assert [e.name for e in chain.up] == ["base_link → camera"]
    assert [e.name for e in chain.down] == ["base_link → laser"]
    queries = [0.05, 1.234, 2.9, 3.3, 3.5]
    poses = pose_at(tree, "camera", "laser", queries)
    edges = {"laser": ("base_link", laser), "camera": ("base_link", camera)}
    expected = [reference_pose(edges, "camera", "laser", t) for t in queries]
    assert expected[-1] is None
    assert_poses_match(poses, expected)


def test_one_robot_seen_from_another_climbs_to_map() -> None:
    times = list(0.05 * np.arange(100))
    edges: dict[str, tuple[str, Samples]] = {}
    series = []
    for robot, sign in (("r1", 1.0), ("r2", -1.0)):
        for parent, child, make in (
            ("map", f"{robot}/odom", lambda t, s=sign: ([s * 0.01 * t, 1.0, 0.0], yaw_quat(s * 0.02 * t))),
            (
                f"{robot}/odom",
                f"{robot}/base_link",
                lambda t, s=sign: ([0.4 * t, s * 0.1 * t, 0.0], yaw_quat(s * 0.3 * t)),
            ),
        ):
            values = [make(t) for t in times]
            edges[child] = (parent, Samples(times, [p for p, _ in values], [q for _, q in values], False))
            series.append(edge(parent, child, times, [p for p, _ in values], [q for _, q in values]))
    tree = FrameTree(series)
    assert len(tree.chain("r1/base_link", "r2/base_link").up) == 2
    queries = list(np.linspace(-0.4, 5.3, 57))
    assert_poses_match(
        pose_at(tree, "r1/base_link", "r2/base_link", queries),
        [reference_pose(edges, "r1/base_link", "r2/base_link", t) for t in queries],
    )


def test_the_map_seen_from_the_robot_is_the_inverse_pose() -> None:
    tree = robot_tree(0.02 * np.arange(100), 0.1 * np.arange(20))
    times = np.linspace(0, 1.9, 40)
    forward, backward = pose_at(tree, "map", "laser", times), pose_at(tree, "laser", "map", times)
    for i in range(len(times)):
        m = homogeneous(rotation_matrix(forward.quaternion[i]), forward.position[i])
        inverse = homogeneous(rotation_matrix(backward.quaternion[i]), backward.position[i])
        np.testing.assert_allclose(m @ inverse, np.eye(4), atol=1e-12)


# --- the property: any tree, any frames, any times: the module agrees with the matrix loop -----------

# r → a → b and r → c → d: every pair of frames, whether one is the other's ancestor or not
TREE_SHAPE = {"a": "r", "b": "a", "c": "r", "d": "c"}


def _quat_product(a: list[float], b: list[float]) -> list[float]:
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return [
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    ]


@st.composite
def tf_data(draw: st.DrawFn) -> tuple[list[EdgeSeries], dict[str, tuple[str, Samples]], list[float]]:
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    series, samples = [], {}
    for child, parent in TREE_SHAPE.items():
        static = draw(st.booleans())
        n = draw(st.integers(1, 2 if static else 8))
        times = np.sort(rng.uniform(0.0, 10.0, n))
        q = list(rng.normal(size=4))
        quats = []
        for _ in range(n):  # each step turns at most 2.5 rad, so the short way is well defined
            q = _quat_product(q, quat_about(tuple(rng.normal(size=3)), rng.uniform(0, 2.5)))
            scale = rng.choice([-1.0, 1.0]) * rng.uniform(0.5, 2.0)  # q and -q, and not normalised
            quats.append([scale * c for c in q])
        translations = rng.uniform(-5, 5, (n, 3)).tolist()
        samples[child] = (parent, Samples(list(times), translations, quats, static))
        order = rng.permutation(n)  # the module must sort them itself
        series.append(
            edge(
                parent, child, times[order], np.asarray(translations)[order], np.asarray(quats)[order], static
            )
        )
    stamps = sorted({float(t) for _, s in samples.values() for t in s.times})
    queries = list(rng.uniform(-1.0, 11.0, draw(st.integers(1, 25))))
    queries += draw(st.lists(st.sampled_from(stamps), max_size=5))
    return series, samples, queries


@settings(max_examples=150, deadline=None)
@given(
    tf_data(),
    st.sampled_from("rabcd"),
    st.sampled_from("rabcd"),
    st.sampled_from([0.0, 0.3, 0.5]),
    st.sampled_from([0.5, 1.0, 3.0]),
)
def test_poses_agree_with_matrices_multiplied_sample_by_sample(
    data: tuple[list[EdgeSeries], dict[str, tuple[str, Samples]], list[float]],
    fixed: str,
    body: str,
    max_extrapolation: float,
    max_gap: float,
) -> None:
    series, samples, queries = data
    poses = pose_at(
        FrameTree(series), fixed, body, queries, max_extrapolation=max_extrapolation, max_gap=max_gap
    )
    expected = [
        reference_pose(samples, fixed, body, t, max_extrapolation=max_extrapolation, max_gap=max_gap)
        for t in queries
    ]
    assert_poses_match(poses, expected, atol=1e-8)
