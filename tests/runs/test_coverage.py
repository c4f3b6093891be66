"""What a run's recording does not cover, found at ingest: executor bags of scenario_c, cut short,
with a topic silent, thinned or with ``/clock`` reset (:mod:`tests.support.bag_surgery`), each giving the
shortfall it should, and a clean bag giving none.

Every expected bound is computed here from the surgery's parameters and the bag as rosbags reads
it (log times; the executor stamps its headers with them), never from exsce's reading.
"""

from __future__ import annotations

import datetime as dt
import json
from pathlib import Path

import numpy as np
import pytest
from rosbags.highlevel import AnyReader

from exsce_dsl.lang import load_spec
from exsce_dsl.model import Scenario
from exsce_dsl.model.coverage import CoverageGap, Shortfall
from exsce_dsl.model.runs import RunStatus
from exsce_dsl.runs.analyse import analyse_bag
from exsce_dsl.runs.coverage import GAP_FLOOR
from exsce_dsl.sim.run import simulate

from tests.support.bag_factory import Topic, typestore_for
from tests.support.bag_surgery import bag_span, cut, drop, reset_clock, rewrite, thin

SPEC = Path(__file__).resolve().parents[2] / "examples" / "brsu_building_c" / "scenario_c.exsce"
SCAN_METRICS = ("distance_to_obstacles", "violation_duration")
"""What reads a robot's scan in scenario_c (the standard library's metrics): the minimum range,
and its violation duration below 0.1 m."""
ACTIVE = 1


@pytest.fixture(scope="module")
def scenario() -> Scenario:
    return load_spec(SPEC).scenario("scenario_c")


@pytest.fixture(scope="module")
def clean(scenario: Scenario, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """An executor bag of scenario_c (MCAP, the method's topics)."""
    (run,) = simulate(scenario, tmp_path_factory.mktemp("clean"), fmt="mcap", seed=4)
    return run.bag


def _log_times(bag: Path, topic: str) -> np.ndarray:
    """``topic``'s log times in seconds, as rosbags reads them."""
    with AnyReader([bag]) as reader:
        connections = [c for c in reader.connections if c.topic == topic]
        return (
            np.array(sorted(t for _, t, _ in reader.messages(connections=connections)), dtype=np.int64) * 1e-9
        )


def _date(seconds: float) -> dt.datetime:
    return dt.datetime.fromtimestamp(seconds, tz=dt.timezone.utc)


def _close(found: dt.datetime | None, seconds: float) -> bool:
    return found is not None and abs(found.timestamp() - seconds) < 1e-3


def _kinds(gaps: tuple[CoverageGap, ...]) -> set[tuple[Shortfall, str | None, str | None, tuple[str, ...]]]:
    return {(g.kind, g.robot, g.topic, g.metrics) for g in gaps}


def test_a_clean_executor_bag_has_no_gaps(scenario: Scenario, clean: Path) -> None:
    analysed = analyse_bag(clean, scenario)
    assert analysed.run.coverage == ()
    assert not [p for p in analysed.problems if p.startswith("coverage")]
    assert analysed.run.status is RunStatus.COMPLETED


@pytest.mark.parametrize("convention", ["nav2", "move_base"])
def test_clean_bags_of_the_stacks_conventions_have_no_gaps(
    scenario: Scenario, convention: str, tmp_path: Path
) -> None:
    """TF at 100 Hz, a latched tf_static (one message), AMCL at 2 Hz: none of it is a gap."""
    (run,) = simulate(scenario, tmp_path, fmt="mcap", seed=4, convention=convention)
    assert analyse_bag(run.bag, scenario).run.coverage == ()


def test_topic_rates_are_messages_per_second_over_each_topics_span(scenario: Scenario, clean: Path) -> None:
    rates = {r.topic: r for r in analyse_bag(clean, scenario).run.topic_rates}
    expected_topics = {f"/{r}/{t}" for r in ("tiago1", "tiago2") for t in ("scan", "nav_vel", "robot_pose")}
    assert expected_topics <= rates.keys()
    for topic in expected_topics | {"/tiago1/distance_travelled"}:
        times = _log_times(clean, topic)
        rate = rates[topic]
        assert rate.messages == len(times), topic
        assert rate.rate == pytest.approx((len(times) - 1) / (times[-1] - times[0]), rel=1e-6), topic
        assert rate.robot == topic.split("/")[1]
    assert rates["/tiago1/scan"].metrics == SCAN_METRICS
    assert rates["/tiago1/scan"].rate == pytest.approx(10.0, rel=1e-6)  # the executor's laser


def _active_at(bag: Path, robot: str, when: float) -> float:
    """When the waypoint that ``robot``'s dispatcher had ACTIVE at log time ``when`` became ACTIVE
    (seconds), from the feedback as rosbags deserialises it."""
    topic = f"/{robot}/waypoint_dispatcher/feedback"
    with AnyReader([bag]) as reader:
        connections = [c for c in reader.connections if c.topic == topic]
        updates = [
            (t * 1e-9, [(s.goal_id.id, s.status) for s in reader.deserialize(raw, c.msgtype).feedback.goal_status.status_list])
            for c, t, raw in reader.messages(connections=connections)
        ]  # fmt: skip
    last = [u for u in updates if u[0] <= when][-1]
    waypoint = next(w for w, status in last[1] if status == ACTIVE)
    return next(t for t, statuses in updates if (waypoint, ACTIVE) in statuses)


def test_a_recording_cut_at_60_percent_is_cut_short_for_both_robots(
    scenario: Scenario, clean: Path, tmp_path: Path
) -> None:
    span = bag_span(clean)
    cut_at = span.start * 1e-9 + 0.6 * span.seconds
    bag = cut(clean, tmp_path / "cut", "mcap", 0.6)
    end = bag_span(bag).end * 1e-9
    analysed = analyse_bag(bag, scenario)
    gaps = analysed.run.coverage
    assert _kinds(gaps) == {(Shortfall.CUT_SHORT, r, None, ()) for r in ("tiago1", "tiago2")}
    for gap in gaps:
        assert gap.robot is not None
        assert _close(gap.start, _active_at(clean, gap.robot, cut_at)), gap
        assert _close(gap.end, end), gap
        assert gap.concerns("max_velocity", gap.robot) and gap.concerns("distance_between_robots", None)
    # one warning per kind: the longest, with how many and whose (issue 47, item 8)
    (said,) = [p for p in analysed.problems if p.startswith("coverage: cut short: ")]
    assert said.endswith("; the longest of 2 of this kind in this run: robot 'tiago1' 1, robot 'tiago2' 1"), (
        said
    )


def test_a_silent_scan_is_a_gap_of_the_metrics_that_read_it(
    scenario: Scenario, clean: Path, tmp_path: Path
) -> None:
    bag = drop(clean, tmp_path / "dropped", "mcap", "/tiago1/scan", 30.0, 40.0)
    times = _log_times(clean, "/tiago1/scan")
    first = bag_span(clean).start * 1e-9
    before = times[times <= first + 30.0][-1]
    after = times[times >= first + 40.0][0]
    (gap,) = analyse_bag(bag, scenario).run.coverage
    assert (gap.kind, gap.robot, gap.topic, gap.metrics) == (
        Shortfall.GAP,
        "tiago1",
        "/tiago1/scan",
        SCAN_METRICS,
    )
    assert _close(gap.start, before) and _close(gap.end, after)
    assert gap.concerns("distance_to_obstacles", "tiago1") and not gap.concerns("max_velocity", "tiago1")
    assert not gap.concerns("distance_to_obstacles", "tiago2")


def test_a_silent_scan_is_an_annotation_of_the_scan_values_over_the_silence_only(
    scenario: Scenario, clean: Path, tmp_path: Path
) -> None:
    """Regression (issue 49, the walk): the values' windows go onto the wall clock in the metrics
    step and the coverage step adds the findings after; the gap still reaches exactly the values
    that read the scan of its robot over a window that holds it."""
    bag = drop(clean, tmp_path / "dropped", "mcap", "/tiago1/scan", 30.0, 40.0)
    times = _log_times(clean, "/tiago1/scan")
    first = bag_span(clean).start * 1e-9
    before, after = times[times <= first + 30.0][-1], times[times >= first + 40.0][0]
    run = analyse_bag(bag, scenario).run
    (gap,) = run.coverage
    named: dict[tuple[str, str | None, str | None, bool], set[bool]] = {}
    for value in run.metrics:
        if value.accounting is not None:
            over = value.accounting.start <= after and value.accounting.end >= before
            key = (value.metric, value.safety_metric, value.robot, over)
            named.setdefault(key, set()).add(gap.reason in value.accounting.annotations)
    assert named[("distance_to_obstacles", None, "tiago1", True)] == {True}
    assert named[("violation_duration", "distance_to_obstacles", "tiago1", True)] == {True}
    assert named[("distance_to_obstacles", None, "tiago1", False)] == {False}  # segments elsewhere
    assert named[("distance_to_obstacles", None, "tiago2", True)] == {False}
    assert named[("max_velocity", None, "tiago1", True)] == {False}


def test_a_short_silence_is_no_gap(scenario: Scenario, clean: Path, tmp_path: Path) -> None:
    """Four scans lost (0.4 s at 10 Hz) are under the threshold: max(0.5 s, 10 periods = 1 s)."""
    bag = drop(clean, tmp_path / "hiccup", "mcap", "/tiago1/scan", 30.05, 30.45)
    assert len(_log_times(clean, "/tiago1/scan")) - len(_log_times(bag, "/tiago1/scan")) == 4
    assert analyse_bag(bag, scenario).run.coverage == ()
    assert GAP_FLOOR == 0.5


def test_velocity_that_stops_before_the_robots_window_ends_is_no_data(
    scenario: Scenario, clean: Path, tmp_path: Path
) -> None:
    """tiago2's velocity is lost from 90 s to the end; its window ends with its last goal."""
    span = bag_span(clean)
    bag = drop(clean, tmp_path / "no-velocity", "mcap", "/tiago2/nav_vel", 90.0, span.seconds + 1.0)
    times = _log_times(clean, "/tiago2/nav_vel")
    last = times[times <= span.start * 1e-9 + 90.0][-1]
    window_end = _log_times(clean, "/tiago2/waypoint_dispatcher/result")[-1]  # its last goal's end
    (gap,) = analyse_bag(bag, scenario).run.coverage
    assert (gap.kind, gap.robot, gap.topic) == (Shortfall.NO_DATA, "tiago2", "/tiago2/nav_vel")
    assert "max_velocity" in gap.metrics and "distance_to_obstacles" not in gap.metrics
    assert _close(gap.start, last) and _close(gap.end, window_end)


def test_a_thinned_scan_without_a_declared_rate_is_no_gap(
    scenario: Scenario, clean: Path, tmp_path: Path
) -> None:
    """Every 5th scan kept (2 Hz): its median period grows with it, so no silence is a gap; only a
    declared rate says it is low (tests/lang/builders/test_declared_rates)."""
    bag = thin(clean, tmp_path / "thin", "mcap", "/tiago1/scan", 5)
    analysed = analyse_bag(bag, scenario)
    assert analysed.run.coverage == ()
    times = _log_times(bag, "/tiago1/scan")
    rate = next(r for r in analysed.run.topic_rates if r.topic == "/tiago1/scan")
    assert rate.rate == pytest.approx((len(times) - 1) / (times[-1] - times[0]), rel=1e-6)
    assert rate.rate == pytest.approx(2.0, rel=1e-3)


def test_a_clock_reset_is_a_jump_to_the_end_of_the_run(
    scenario: Scenario, clean: Path, tmp_path: Path
) -> None:
    span = bag_span(clean)
    bag = reset_clock(clean, tmp_path / "reset", "mcap", at=50.0, back=30.0, hz=50.0)
    ticks = _log_times(bag, "/clock")
    jump = ticks[ticks >= span.start * 1e-9 + 50.0][0]
    analysed = analyse_bag(bag, scenario)
    (gap,) = analysed.run.coverage
    assert (gap.kind, gap.robot, gap.topic, gap.metrics) == (Shortfall.CLOCK_JUMP, None, "/clock", ())
    assert _close(gap.start, jump) and _close(gap.end, bag_span(bag).end * 1e-9)
    assert gap.concerns("max_velocity", "tiago1")
    assert any("/clock went back" in p for p in analysed.problems)


def test_a_cancelled_mission_in_the_bags_own_prov_is_cut_short(
    scenario: Scenario, clean: Path, tmp_path: Path
) -> None:
    """The run-time PROV the dispatcher publishes on /exsce/prov (no .prov.json beside the bag)."""
    span = bag_span(clean)
    store = typestore_for("mcap")
    document = {"bundle": {"run:b": {"activity": {"run:run_x": {"exsce:mission_status": "cancelled"}}}}}
    message = store.types["std_msgs/msg/String"](data=json.dumps(document))
    prov = Topic("/exsce/prov", "std_msgs/msg/String", [(span.start, message)])
    bag = rewrite(clean, tmp_path / "cancelled", "mcap", lambda name, messages, first, last: messages, [prov])
    assert not list(tmp_path.glob("*.prov.json"))
    analysed = analyse_bag(bag, scenario)
    assert analysed.run.status is RunStatus.CANCELLED
    (gap,) = analysed.run.coverage
    assert (gap.kind, gap.robot, gap.metrics) == (Shortfall.CUT_SHORT, None, ())
    assert "cancelled" in gap.reason and _close(gap.end, span.end * 1e-9)


def test_velocity_that_starts_after_the_robots_first_goal_is_no_data(
    scenario: Scenario, clean: Path, tmp_path: Path
) -> None:
    """tiago1's velocity is lost for its first 20 s; its window starts with its first goal."""
    bag = drop(clean, tmp_path / "late-velocity", "mcap", "/tiago1/nav_vel", -1.0, 20.0)
    times = _log_times(clean, "/tiago1/nav_vel")
    first = times[times >= bag_span(clean).start * 1e-9 + 20.0][0]
    goal_start = _active_at(clean, "tiago1", _log_times(clean, "/tiago1/waypoint_dispatcher/feedback")[1])
    (gap,) = analyse_bag(bag, scenario).run.coverage
    assert (gap.kind, gap.robot, gap.topic) == (Shortfall.NO_DATA, "tiago1", "/tiago1/nav_vel")
    assert _close(gap.start, goal_start) and _close(gap.end, first)


def test_times_in_bursts_at_a_coarse_clocks_ticks_are_no_gaps_but_a_long_silence_is() -> None:
    """A recorder on simulated time logs with the last /clock it heard: with a clock ticking every
    0.5 s, a 20 Hz topic comes as 10 messages per tick (exsce's stand-in, Stage).  One tick of
    silence is the clock's, not lost data; the threshold is 3 ticks (1.5 s), and 4 s is a gap."""
    from exsce_dsl.runs.coverage import GAP_TICKS, gap_threshold

    ticks = np.arange(0.0, 60.0, 0.5)
    bursts = np.repeat(ticks, 10)
    mean_period = 60.0 / len(bursts)  # about 0.05 s: ten of them are 0.5 s, the floor
    assert gap_threshold(bursts) == pytest.approx(max(GAP_FLOOR, 10 * mean_period, GAP_TICKS * 0.5))
    assert gap_threshold(bursts) == pytest.approx(1.5)
    holed = bursts[(bursts < 20.0) | (bursts >= 24.0)]
    assert np.diff(holed).max() == pytest.approx(4.5) and np.diff(holed).max() > gap_threshold(holed)
    steady = np.arange(0.0, 60.0, 0.05)  # the same topic on a fine clock: ten periods, the floor
    assert gap_threshold(steady) == pytest.approx(max(GAP_FLOOR, 10 * 0.05))
