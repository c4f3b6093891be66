"""The run-time PROV of a mission run: what the dispatcher did, as the method's recorder writes it.

The reference for a plain run is the kinematic executor's own ``.prov.json`` for the same
mission (its timings differ: it accelerates and waits, so times are left out of that comparison);
the runs with failed goals are checked record by record against hand-written expectations on
open floor, where every leg is the straight line at 0.5 m/s.
"""

from __future__ import annotations

import datetime as dt
import math
from collections import Counter
from dataclasses import replace

import pytest
from prov.model import ProvActivity, ProvDocument, ProvEnd, ProvStart
from pyoxigraph import Literal, Quad

from exsce_dsl.execute.dispatcher import dispatch
from exsce_dsl.execute.mission import schedule
from exsce_dsl.execute.navigator import SimulatedClock
from exsce_dsl.execute.outcomes import DEFAULT_POLICY, MissionStatus, Policy
from exsce_dsl.execute.provenance import mission_prov_json, mission_run_record
from exsce_dsl.lang import load_spec
from exsce_dsl.maps.planning import planning_grid
from exsce_dsl.model.runs import ActionStatus, RunStatus
from exsce_dsl.prov.run import compile_run
from exsce_dsl.rdf import to_quads, validate
from exsce_dsl.sim.run import simulate

from tests.support.kinematic_navigator import ABORT_AFTER, KinematicNavigator
from tests.support.paths import EXAMPLES

# environment.exsce, by hand
P = {
    "c025-w001": (44.80387496948242, 37.15502166748047),
    "c025-w002": (43.432926177978516, 38.493873596191406),
    "c022-w001": (52.82560729980469, 32.562904357910156),
    "c022-w002": (54.497589111328125, 31.52023696899414),
    "c018-w001": (48.26420974731445, 24.618297576904297),
    "c018-w002": (46.25560760498047, 21.586545944213867),
}
V = 0.5
START = dt.datetime(2026, 3, 1, 10, 0, tzinfo=dt.timezone.utc)
RUN_ID = "0b7a3c52-1f1e-4c8e-9a51-2d4f7c9e8a10"
BAG = "2026-03-01T10-00-00_scenario_c_run-0b7a3c52.bag"
FIRST = ("tiago1", "classroom_c022-w001")
SUCCEEDED, ABORTED = "SUCCEEDED", "ABORTED"


def leg(a: str, b: str) -> float:
    return math.dist(P[a], P[b]) / V


def at(seconds: float) -> dt.datetime:
    return START + dt.timedelta(seconds=seconds)


@pytest.fixture(scope="module")
def scenario_c():
    return load_spec(EXAMPLES / "brsu_building_c" / "scenario_c.exsce").scenario("scenario_c")


@pytest.fixture(scope="module")
def open_floor(scenario_c):
    scenario = replace(scenario_c, environment=replace(scenario_c.environment, map=None))
    return scenario, planning_grid(scenario)


def _mission(scenario, grid, policy=DEFAULT_POLICY, speeds=None, cancelled=None, timeout=None, **failing):
    clock = SimulatedClock()
    nav = KinematicNavigator(scenario, grid, clock, speeds, **failing)
    when = (lambda: cancelled(clock)) if cancelled else None
    return dispatch(schedule(scenario, speeds, timeout), nav, clock, policy, when)


def _open_run(open_floor, policy=DEFAULT_POLICY, **kwargs):
    scenario, grid = open_floor
    mission = _mission(scenario, grid, policy, {"tiago1": V, "tiago2": V}, **kwargs)
    return mission, mission_prov_json(mission, scenario, RUN_ID, START, BAG)


def _records(text: str) -> dict[str, Counter]:
    """Each bundle's records, times left out: (type, id of an element, attributes)."""
    document = ProvDocument.deserialize(content=text, format="json")
    found = {}
    for bundle in document.bundles:
        rows = Counter()
        for r in bundle.get_records():
            formal = tuple((str(k), str(v)) for k, v in r.formal_attributes if "Time" not in str(k))
            extra = tuple(sorted((str(k), str(v)) for k, v in r.extra_attributes))
            rows[(r.get_type().localpart, str(r.identifier) if r.is_element() else None, formal, extra)] += 1
        found[str(bundle.identifier)] = rows
    return found


def _actions(text: str) -> dict[str, tuple]:
    """Each action by its local name: status, goal outcome, attempts, the pose local names that
    started and ended it, start and end."""
    document = ProvDocument.deserialize(content=text, format="json")
    [bundle] = [b for b in document.bundles if b.identifier.localpart.startswith("run_")]
    starts, ends = _poses(bundle, ProvStart), _poses(bundle, ProvEnd)
    found = {}
    for a in bundle.get_records(ProvActivity):
        facts = {str(k): v for k, v in a.extra_attributes}
        if str(facts.get("prov:type")) != "exsce:action":
            continue
        name = a.identifier.localpart
        found[name] = (
            facts["exsce:status"],
            facts.get("exsce:goal_outcome"),
            facts.get("exsce:attempts", 1),
            starts[name].split("-R")[0].removeprefix("classroom_"),
            ends[name].split("-R")[0].removeprefix("classroom_"),
            a.get_startTime(),
            a.get_endTime(),
        )
    return found


def _poses(bundle, kind) -> dict[str, str]:
    """Activity → the pose that started (ProvStart) or ended (ProvEnd) it, by local names."""
    return {
        r.formal_attributes[0][1].localpart: r.formal_attributes[1][1].localpart
        for r in bundle.get_records(kind)
    }


def _mission_status(text: str) -> str | None:
    document = ProvDocument.deserialize(content=text, format="json")
    [bundle] = [b for b in document.bundles if b.identifier.localpart.startswith("run_")]
    [run] = [a for a in bundle.get_records(ProvActivity) if a.identifier.localpart == f"run_{RUN_ID}"]
    return {str(k): v for k, v in run.extra_attributes}.get("exsce:mission_status")


def _close(found: dict[str, tuple], expected: dict[str, tuple]) -> None:
    assert found.keys() == expected.keys()
    for name, row in expected.items():
        assert found[name][:5] == row[:5], name
        assert abs((found[name][5] - row[5]).total_seconds()) < 1e-3, name
        assert abs((found[name][6] - row[6]).total_seconds()) < 1e-3, name


def test_the_prov_of_a_dispatched_run_has_the_kinematic_executors_records(scenario_c, tmp_path):
    [played] = simulate(scenario_c, tmp_path, runs=1, seed=3)
    reference = (tmp_path / (played.bag.name.removesuffix(".bag") + ".prov.json")).read_text()
    mission = _mission(scenario_c, planning_grid(scenario_c))
    assert mission.status is MissionStatus.COMPLETED
    text = mission_prov_json(mission, scenario_c, played.run_id, played.start, played.bag.name)
    ours, theirs = _records(text), _records(reference)
    # simulate's also names what played the run (the agent <run>:simulator, associated with the
    # run); the dispatcher on a live graph does not know what drives its robots
    played_by = {
        name: Counter({row: n for row, n in rows.items() if ":simulator" in (row[1] or "") + str(row[2])})
        for name, rows in theirs.items()
    }
    [simulated] = [rows for rows in played_by.values() if rows]
    assert sorted(row[0] for row in simulated) == ["Agent", "Association"]
    [agent] = [row for row in simulated if row[0] == "Agent"]
    assert ("exsce:simulator", "kinematic") in agent[3]
    assert ours == {name: rows - played_by[name] for name, rows in theirs.items()}
    # the records that matter, by hand: six actions, four task executions, all succeeded
    [run_bundle] = [rows for name, rows in ours.items() if name.endswith(f"run_{played.run_id}_bundle")]
    actions = [row for row in run_bundle if row[0] == "Activity" and ("prov:type", "exsce:action") in row[3]]
    tasks = [
        row for row in run_bundle if row[0] == "Activity" and ("prov:type", "exsce:task_execution") in row[3]
    ]
    assert len(actions) == 6 and all(("exsce:status", SUCCEEDED) in row[3] for row in actions)
    assert sorted(row[1].rsplit(":", 1)[1] for row in tasks) == [
        "tiago1-task_01", "tiago1-task_02", "tiago2-task_01", "tiago2-task_02",
    ]  # fmt: skip


def test_a_plain_run_by_hand_start_poses_goals_and_times(open_floor):
    mission, text = _open_run(open_floor)
    t1 = leg("c025-w001", "c022-w001")
    t2 = t1 + leg("c022-w001", "c018-w001")
    t3 = t2 + leg("c018-w001", "c025-w001")
    u1 = leg("c025-w002", "c022-w002")
    u2 = u1 + leg("c022-w002", "c018-w002")
    u3 = u2 + leg("c018-w002", "c025-w002")
    _close(
        _actions(text),
        {
            "tiago1-task_01-subtask_001-w_001": (SUCCEEDED, None, 1, "c025-w001", "c022-w001", at(0), at(t1)),
            "tiago1-task_01-subtask_001-w_002": (
                SUCCEEDED,
                None,
                1,
                "c022-w001",
                "c018-w001",
                at(t1),
                at(t2),
            ),
            "tiago1-task_02-subtask_001-w_001": (
                SUCCEEDED,
                None,
                1,
                "c018-w001",
                "c025-w001",
                at(t2),
                at(t3),
            ),
            "tiago2-task_01-subtask_001-w_001": (SUCCEEDED, None, 1, "c025-w002", "c022-w002", at(0), at(u1)),
            "tiago2-task_01-subtask_001-w_002": (
                SUCCEEDED,
                None,
                1,
                "c022-w002",
                "c018-w002",
                at(u1),
                at(u2),
            ),
            "tiago2-task_02-subtask_001-w_001": (
                SUCCEEDED,
                None,
                1,
                "c018-w002",
                "c025-w002",
                at(u2),
                at(u3),
            ),
        },
    )
    assert _mission_status(text) is None
    run = mission_run_record(mission, open_floor[0], RUN_ID, START, BAG)
    assert (run.start, run.end, run.bag.file_name, run.status) == (
        START,
        at(max(t3, u3)),
        BAG,
        RunStatus.COMPLETED,
    )


def test_a_retried_goal_is_one_action_from_its_first_start_with_its_attempts(open_floor):
    _, text = _open_run(open_floor, Policy.RETRY_ONCE, aborts={FIRST: 1})
    t1 = ABORT_AFTER + leg("c025-w001", "c022-w001")
    found = _actions(text)
    _close(
        {"w": found["tiago1-task_01-subtask_001-w_001"]},
        {"w": (SUCCEEDED, None, 2, "c025-w001", "c022-w001", at(0), at(t1))},
    )
    assert found["tiago1-task_01-subtask_001-w_002"][2:5] == (1, "c022-w001", "c018-w001")


def test_rejected_and_timed_out_goals_are_aborted_with_why_and_the_robot_stays_where_it_was(open_floor):
    silent = ("tiago2", "classroom_c022-w002")
    _, text = _open_run(open_floor, rejects=[FIRST], silent=[silent], timeout=45.0)
    t2 = leg("c025-w001", "c018-w001")  # tiago1 goes to its second waypoint from its start pose
    u2 = 45.0 + leg("c025-w002", "c018-w002")  # every leg is shorter than 45 s
    found = _actions(text)
    _close(
        {k: v for k, v in found.items() if k.endswith("task_01-subtask_001-w_001") or "w_002" in k},
        {
            "tiago1-task_01-subtask_001-w_001": (
                ABORTED,
                "rejected",
                1,
                "c025-w001",
                "c022-w001",
                at(0),
                at(0),
            ),
            "tiago1-task_01-subtask_001-w_002": (SUCCEEDED, None, 1, "c025-w001", "c018-w001", at(0), at(t2)),
            "tiago2-task_01-subtask_001-w_001": (
                ABORTED,
                "timed out",
                1,
                "c025-w002",
                "c022-w002",
                at(0),
                at(45),
            ),
            "tiago2-task_01-subtask_001-w_002": (
                SUCCEEDED,
                None,
                1,
                "c025-w002",
                "c018-w002",
                at(45),
                at(u2),
            ),
        },
    )
    assert len(found) == 6 and _mission_status(text) is None


def test_an_aborted_goal_has_no_outcome_and_a_stopped_run_holds_only_the_goals_sent(open_floor):
    mission, text = _open_run(open_floor, Policy.STOP_MISSION, aborts={FIRST: 1})
    assert mission.status is MissionStatus.STOPPED and mission.not_sent == 4
    _close(
        _actions(text),
        {
            "tiago1-task_01-subtask_001-w_001": (
                ABORTED, None, 1, "c025-w001", "c022-w001", at(0), at(ABORT_AFTER),
            ),
            "tiago2-task_01-subtask_001-w_001": (
                ABORTED, "cancelled", 1, "c025-w002", "c022-w002", at(0), at(ABORT_AFTER),
            ),
        },
    )  # fmt: skip
    assert _mission_status(text) == "stopped"
    run = mission_run_record(mission, open_floor[0], RUN_ID, START, BAG)
    assert [(t.robot, t.allocation) for t in run.tasks] == [("tiago1", 1), ("tiago2", 1)]
    assert run.status is RunStatus.STOPPED and run.end == at(ABORT_AFTER)


def test_a_cancelled_run_is_marked_and_its_active_goals_cancelled(open_floor):
    mission, text = _open_run(open_floor, cancelled=lambda clock: clock.now() >= 5.0)
    assert mission.status is MissionStatus.CANCELLED
    found = _actions(text)
    assert {k: v[:5] for k, v in found.items()} == {
        "tiago1-task_01-subtask_001-w_001": (ABORTED, "cancelled", 1, "c025-w001", "c022-w001"),
        "tiago2-task_01-subtask_001-w_001": (ABORTED, "cancelled", 1, "c025-w002", "c022-w002"),
    }
    assert all(abs((v[6] - at(5.0)).total_seconds()) < 1e-3 for v in found.values())
    assert _mission_status(text) == "cancelled"


def test_incomplete_runs_and_failed_goals_conform_to_the_run_shapes_and_a_wrong_status_does_not(open_floor):
    scenario = open_floor[0]
    mission, _ = _open_run(open_floor, Policy.RETRY_ONCE, rejects=[FIRST], cancelled=lambda c: c.now() >= 5.0)
    run = mission_run_record(mission, scenario, RUN_ID, START, BAG)
    assert run.status is RunStatus.CANCELLED
    assert {a.outcome for a in run.actions()} == {"rejected", "cancelled"}
    assert max(a.attempts for a in run.actions()) == 2
    quads = to_quads(compile_run(run, scenario))
    assert validate(quads, ["runs"]) == []
    status = next(q for q in quads if q.predicate.value.endswith("/mission_status"))
    broken = [q for q in quads if q != status] + [
        Quad(status.subject, status.predicate, Literal("paused"), status.graph_name)
    ]
    assert [v.path for v in validate(broken, ["runs"])] == [status.predicate.value]


def test_the_kinematic_executor_and_the_dispatcher_write_through_the_same_recorder():
    import exsce_dsl.execute.provenance as execute_side
    import exsce_dsl.sim.run as sim_side
    from exsce_dsl.prov import recorder

    assert sim_side.recorded_run is recorder.recorded_run is execute_side.recorded_run
    assert sim_side.recorded_prov_json is recorder.recorded_prov_json is execute_side.recorded_prov_json


def test_an_action_that_succeeded_cannot_say_why_it_failed(open_floor):
    from exsce_dsl.errors import ExsceError
    from exsce_dsl.model.runs import Action, ActionId

    pose = open_floor[0].robots[0].start_pose
    with pytest.raises(ExsceError, match="cannot have status SUCCEEDED"):
        Action(ActionId("tiago1", 1, 1, 1), pose, pose, ActionStatus.SUCCEEDED, outcome="rejected")
