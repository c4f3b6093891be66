"""The API's tables as a notebook uses them: ``segments`` says each value's unit, where its segment
started and which action it is (by its id, not its IRI); a pivot of ``metrics`` keeps the
mission's values when it is written as the documentation says."""

from __future__ import annotations

import re
from collections.abc import Iterator

import pandas as pd
import pytest

from exsce_dsl import api as exsce
from exsce_dsl.model.scenario import Scenario
from exsce_dsl.store.base import Store

from tests.support.paths import EXAMPLES

UNITS = {
    "distance_travelled": "m",
    "distance_to_obstacles": "m",
    "task_duration": "s",
    "fast_driving_time": "s",
    "max_velocity": "m/s",
}
"""The units of scenario_c's segment metrics, by hand (exsce's built-in metrics, in SI)."""


@pytest.fixture(scope="module")
def stored(tmp_path_factory: pytest.TempPathFactory) -> Iterator[tuple[Scenario, Store]]:
    folder = tmp_path_factory.mktemp("tables")
    scenario = exsce.load(EXAMPLES / "brsu_building_c" / "scenario_c.exsce").scenario("scenario_c")
    runs = exsce.simulate(scenario, folder / "runs", runs=2, seed=5)
    with exsce.open_store("memory:") as store:
        results = exsce.ingest(store, scenario, [run.bag for run in runs])
        assert [str(r.status) for r in results] == ["ingested", "ingested"]
        yield scenario, store


def test_segments_have_a_unit_a_start_pose_and_short_actions(stored: tuple[Scenario, Store]) -> None:
    scenario, store = stored
    legs = exsce.segments(store, "scenario_c")
    assert list(legs.columns) == [
        "run", "scenario", "robot", "action", "start", "start_x", "start_y", "goal", "metric", "value", "unit",
    ]  # fmt: skip
    assert legs.run.nunique() == 2 and not legs.isna().any().any()
    assert legs.action.map(lambda a: re.fullmatch(r"tiago[12]-task_\d\d-subtask_\d{3}-w_\d{3}", a)).all()
    assert dict(zip(legs.metric, legs.unit, strict=True)) == {m: UNITS[m] for m in legs.metric.unique()}
    whole_run = exsce.metrics(store, "scenario_c")
    run_units = dict(zip(whole_run.metric, whole_run.unit, strict=True))
    assert all(run_units[m] == u for m, u in zip(legs.metric, legs.unit, strict=True))
    declared = {p.id: p.position for p in scenario.environment.poses()}
    starts = {r.id: r.start_pose.id for r in scenario.robots}
    for (run, robot), drive in legs.groupby(["run", "robot"]):
        actions = drive.drop_duplicates("action").sort_values("action")
        poses = [re.sub(r"-R[-0-9.]+_P[-0-9.]+_Y[-0-9.]+$", "", p) for p in actions.start]
        goals = [re.sub(r"-R[-0-9.]+_P[-0-9.]+_Y[-0-9.]+$", "", p) for p in actions.goal]
        assert poses[0] == starts[robot], (run, robot)  # the first segment leaves the start pose
        assert poses[1:] == goals[:-1], (run, robot)  # each later one where the one before ended
        for name, x, y in zip(poses, actions.start_x, actions.start_y, strict=True):
            assert (x, y) == pytest.approx((declared[name].x, declared[name].y), abs=1e-6)


def test_a_segment_value_is_the_one_its_action_stored(stored: tuple[Scenario, Store]) -> None:
    _, store = stored
    legs = exsce.segments(store, "scenario_c")
    raw = exsce.sparql(
        store,
        "PREFIX prov: <http://www.w3.org/ns/prov#> "
        "SELECT ?action ?metric ?value WHERE { "
        "GRAPH ?g { ?e prov:wasGeneratedBy ?action ; prov:value ?value ; "
        "<https://www.sesame-project.org/scenarios/runs/metricType> ?metric } "
        "GRAPH ?h { ?action a <https://www.sesame-project.org/scenarios/action> } }",
    )
    # the action's IRI is .../runs/run_<uuid>/<its id>
    expected = {
        (iri.rsplit("/", 2)[-2].removeprefix("run_"), iri.rsplit("/", 1)[-1], metric): float(value)
        for iri, metric, value in zip(raw.action, raw.metric, raw.value, strict=True)
    }
    got = {(r.run, r.action, r.metric): r.value for r in legs.itertuples()}
    assert len(got) == len(legs) == len(expected) == 2 * 6 * len(UNITS)  # 2 runs, 6 segments each
    assert all(expected[key] == pytest.approx(value) for key, value in got.items())


def test_the_documented_pivot_keeps_the_mission_metrics(stored: tuple[Scenario, Store]) -> None:
    _, store = stored
    table = exsce.metrics(store, "scenario_c")
    mission = table[table.robot.isna()]
    assert {"mission_duration", "distance_between_robots"} <= set(mission.metric)
    naive = table.pivot_table(index="run", columns=["robot", "metric"], values="value")
    assert "mission_duration" not in set(naive.columns.get_level_values("metric"))  # what went wrong
    wide = table.fillna({"robot": "mission", "safety": ""}).pivot_table(
        index="run", columns=["robot", "metric", "safety"], values="value"
    )
    assert int(wide.notna().sum().sum()) == len(table)  # every value has its cell: none dropped or averaged
    for row in mission.fillna({"safety": ""}).itertuples():
        assert wide.loc[row.run, ("mission", row.metric, row.safety)] == pytest.approx(row.value)


def test_segments_of_no_run_is_an_empty_table_with_the_columns(stored: tuple[Scenario, Store]) -> None:
    _, store = stored
    empty = exsce.segments(store, runs=[])
    assert isinstance(empty, pd.DataFrame) and empty.empty and "start_x" in empty.columns
