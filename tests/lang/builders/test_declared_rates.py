"""A robot type declares the rate its signals are published at (``scan on "/{ns}/scan" at 10 Hz``,
``velocity at 20 Hz``): the language's side (the model, located errors, the formatter's round
trip) and ingestion's (a scan recorded at a fifth of its declared rate is a low-rate gap).
"""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest
from rosbags.highlevel import AnyReader

from exsce_dsl.errors import SpecError
from exsce_dsl.lang import comments, display_path, format_spec_document, load_spec
from exsce_dsl.model.conventions import TopicSource
from exsce_dsl.model.coverage import Shortfall
from exsce_dsl.runs.analyse import analyse_bag
from exsce_dsl.sim.run import simulate

from tests.support.bag_surgery import thin

EXAMPLE = Path(__file__).resolve().parents[3] / "examples" / "brsu_building_c"
RATED = """\
robot type rover {
  base diff_drive
  convention nav2
  scan on "/{ns}/scan_filtered" sensor_msgs/msg/LaserScan at 10 Hz
  velocity at 20 Hz
  pose at 12.5 Hz
  distance at 50 Hz
}
"""


def _write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "robots.exsce"
    path.write_text(text)
    return path


def test_rates_on_a_source_and_on_a_signal_are_in_the_model(tmp_path: Path) -> None:
    (rover,) = load_spec(_write(tmp_path, RATED)).robot_types
    signals = rover.signals
    assert signals.scan == (TopicSource("/{ns}/scan_filtered", "sensor_msgs/msg/LaserScan", 10.0),)
    assert signals.rates == (("velocity", 20.0), ("pose", 12.5), ("distance", 50.0))
    assert (signals.rate_of("velocity"), signals.rate_of("pose"), signals.rate_of("scan")) == (
        20.0,
        12.5,
        None,
    )
    assert signals.velocity[0].rate is None  # nav2's own sources, no rate of their own


def test_the_formatter_prints_rates_that_parse_back_to_the_same_model(tmp_path: Path) -> None:
    path = _write(tmp_path, RATED)
    spec = load_spec(path)
    source = display_path(path)
    printed = format_spec_document(spec, source, comments(RATED, source))
    assert "at 10 Hz" in printed and "velocity at 20 Hz" in printed and "pose at 12.5 Hz" in printed
    again = load_spec(path, overlay={source: printed})
    assert [t.signals for t in again.robot_types] == [t.signals for t in spec.robot_types]
    assert format_spec_document(again, source, comments(printed, source)) == printed


@pytest.mark.parametrize(
    "line, column, message",
    [
        ("scan at 0 Hz", 3, "a rate is a frequency above zero, not 0 Hz"),
        ('velocity on "/{ns}/cmd_vel" at -2 Hz', 12, "a rate is a frequency above zero, not -2 Hz"),
        ("scan at 10 Hz\n  scan at 5 Hz", 3, "states the rate of its scan twice"),
    ],
)
def test_a_rate_not_above_zero_is_a_located_error(
    tmp_path: Path, line: str, column: int, message: str
) -> None:
    path = _write(tmp_path, f"robot type r {{\n  base b\n  {line}\n}}\n")
    with pytest.raises(SpecError) as caught:
        load_spec(path)
    row = 4 if "twice" in message else 3
    assert f"robots.exsce:{row}:{column}:" in str(caught.value) and message in str(caught.value), caught.value


def test_a_rate_without_its_unit_is_a_syntax_error(tmp_path: Path) -> None:
    with pytest.raises(SpecError) as caught:
        load_spec(_write(tmp_path, "robot type r {\n  scan at 10\n}\n"))
    assert "robots.exsce:2:" in str(caught.value), caught.value


def test_a_scan_thinned_below_its_declared_rate_is_a_low_rate_gap(tmp_path: Path) -> None:
    """scenario_c with its tiago type declaring ``scan at 10 Hz`` (the executor's laser); the bag
    keeps every 5th scan of tiago1 (2 Hz, under half of 10 Hz); tiago2's scans stay at 10 Hz."""
    folder = tmp_path / "brsu_building_c"
    shutil.copytree(EXAMPLE, folder)
    robots = folder / "robots.exsce"
    text = robots.read_text()
    assert "robot type tiago {\n  base pmb2\n  torso yes\n}" in text
    robots.write_text(text.replace("  torso yes\n}", "  torso yes\n  scan at 10 Hz\n}", 1))
    scenario = load_spec(folder / "scenario_c.exsce").scenario("scenario_c")
    assert {r.signals.rate_of("scan") for r in scenario.robots} == {10.0}
    (run,) = simulate(scenario, tmp_path / "runs", fmt="mcap", seed=4)
    assert analyse_bag(run.bag, scenario).run.coverage == ()  # at its rate: nothing to say
    bag = thin(run.bag, tmp_path / "thin", "mcap", "/tiago1/scan", 5)
    with AnyReader([bag]) as reader:
        connections = [c for c in reader.connections if c.topic == "/tiago1/scan"]
        times = sorted(t * 1e-9 for _, t, _ in reader.messages(connections=connections))
    rate = (len(times) - 1) / (times[-1] - times[0])
    assert rate < 0.5 * 10.0
    (gap,) = analyse_bag(bag, scenario).run.coverage
    assert (gap.kind, gap.robot, gap.topic) == (Shortfall.LOW_RATE, "tiago1", "/tiago1/scan")
    assert gap.metrics == ("distance_to_obstacles", "violation_duration")
    assert gap.start is not None and abs(gap.start.timestamp() - times[0]) < 1e-3
    assert gap.end is not None and abs(gap.end.timestamp() - times[-1]) < 1e-3
    assert f"{rate:.3g} Hz" in gap.reason
