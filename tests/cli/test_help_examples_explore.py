"""The ``--help`` examples of explore: campaigns, simulated and on a live graph: each runs as written, in order, on the state the chapter's
earlier examples made (tests/support/help_examples.py).

The last example is a campaign on a live ROS 1 graph (``--executor ros1 --stand-in``: a roscore
the campaign starts and stops, the dispatcher's actionlib clients, the stand-in's move_base
servers and the real ``rosbag record``), so this is also where the live campaign is checked: the
planted latent deadlock found, shrunk and written as the minimal derivation, as the kinematic
executor's campaign does (tests/explore/test_campaign.py).  Its base runs are the ones the
chapter's first campaign stored, so only the derived scenario's run is played live.  The bags
are read back with rosbags, not with exsce."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from rosbags.highlevel import AnyReader
from rosbags.typesys import Stores, get_typestore

from exsce_dsl.store.open import open_store
from exsce_dsl.store.queries import derivation_of
from exsce_dsl.store.queries.campaigns import campaign_record, campaigns

from tests.support.help_examples import walk

EXSCEC = str(Path(sys.executable).parent / "exscec")
DEADLOCK = "deadlock-start:tiago1:classroom_c025-w002"
"""Revealed by swapping the start poses of tiago1 and tiago2 (see exsce_dsl.sim.faults)."""
PREEMPTED, SUCCEEDED = 2, 3
"""actionlib_msgs/GoalStatus."""


def test_every_help_example_of_the_explore_chapter_runs_as_written(tmp_path: Path) -> None:
    walked = walk("explore", tmp_path)
    [live] = [line for line in walked.ended if "--executor ros1" in line]
    _check_the_live_campaign(walked.ended[live], walked.scratch)


def _check_the_live_campaign(explored: subprocess.CompletedProcess[str], project: Path) -> None:
    """On the live graph the planted deadlock is found in the one trial and shrunk to its one
    step; the derived run's goals show why: tiago1's first stood until the dispatcher's timeout."""
    with open_store(str(project / ".exsce" / "store")) as store:
        [plan] = [p for p in campaigns(store) if p.executor.startswith("ros1")]
        assert plan.executor == f"ros1 --stand-in --fault {DEADLOCK}"
        record = campaign_record(store, plan.id)
        assert record is not None
        (trial,) = record.trials
        assert [name for name, _ in trial.steps] == ["swap_start_poses"]
        assert len(trial.runs) == 1
        # the deadlock's symptom: tiago1's first goal stood until the dispatcher's timeout aborted it
        # (its tasks' time alone no longer shows it: a robot may wait for another, issue 50)
        assert any(r.text == "tiago1 waypoints_visited invariant" for r in trial.violated), trial.violated
        assert record.shrinkings and {s.relation for s in record.shrinkings} == set(trial.violated)
        for shrinking in record.shrinkings:
            assert [name for name, _ in shrinking.minimal_steps] == ["swap_start_poses"]
        minimal = record.shrinkings[0].minimal
        assert minimal == trial.scenario
        derivation = derivation_of(store, minimal)
        assert derivation is not None and [s.transformation for s in derivation.steps] == ["swap_start_poses"]
    campaign = project / "explore" / "live"
    file = campaign / "minimal" / f"{minimal}.exsce"
    assert file.is_file() and f"acceptance for {minimal}" in file.read_text()
    runs = campaign / "runs"
    assert not (runs / "scenario_c").exists()  # the base's three runs were in the store already
    (derived_bag,) = sorted((runs / minimal).glob("*.bag"))
    assert not list(runs.rglob("*.active"))  # every recording closed
    assert derived_bag.with_name(derived_bag.stem + ".prov.json").is_file()
    assert derived_bag.with_name(derived_bag.stem + ".rosparams").is_file()
    # tiago1's first goal stood until the dispatcher's timeout (60 s of simulated time) cancelled it
    first, *rest = _results(derived_bag, "tiago1")
    assert first[0] == PREEMPTED and first[1] >= 59.0
    assert rest and all(status == SUCCEEDED for status, _ in rest)
    assert f"exscec verify explore/live/runs/{minimal}/*.bag --scenario {file.relative_to(project)}" in (
        explored.stdout
    )
    env = {k: v for k, v in os.environ.items() if not k.startswith(("EXSCE_", "ROS_")) or k == "EXSCE_CACHE"}
    again = subprocess.run(
        [EXSCEC, "verify", str(derived_bag), "--scenario", str(file)],
        cwd=project, env=env, capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert again.returncode == 1, again.stdout + again.stderr
    assert "task_duration" in again.stdout


def _results(bag: Path, robot: str) -> list[tuple[int, float]]:
    """The move_base results of ``robot`` in ``bag``: (status, seconds since its goal's stamp)."""
    goals: dict[str, float] = {}
    found = []
    with AnyReader([bag], default_typestore=get_typestore(Stores.ROS1_NOETIC)) as reader:
        wanted = {f"/{robot}/move_base/goal", f"/{robot}/move_base/result"}
        connections = [c for c in reader.connections if c.topic in wanted]
        for connection, _, raw in reader.messages(connections=connections):
            message = reader.deserialize(raw, connection.msgtype)
            if connection.topic.endswith("/goal"):
                goals[message.goal_id.id] = message.header.stamp.sec + message.header.stamp.nanosec * 1e-9
            else:
                stamp = message.header.stamp.sec + message.header.stamp.nanosec * 1e-9
                found.append((message.status.status, stamp - goals[message.status.goal_id.id]))
    return found
