"""Oracle and verdict PROV name the topics their values were computed from (issue 48, item 3).

A Nav2 or move_base robot's oracles said they used ``/nav_vel`` (the method's topic): the oracle
bundle took the method's default topics, whatever the robot published.  Now an oracle names the
sources of the stored values it learnt from, and a verdict those of the judged run's value.

The reference is the bag itself read with rosbags: which topic of each robot holds the Twist,
the odometry, the scans and the transforms.
"""

from __future__ import annotations

from pathlib import Path

import pytest
from rosbags.highlevel import AnyReader

from exsce_dsl.lang import load_spec
from exsce_dsl.oracles.judging import build_baseline, verify_runs
from exsce_dsl.runs.ingest import ingest_bags
from exsce_dsl.sim.run import simulate
from exsce_dsl.store.embedded import EmbeddedStore
from exsce_dsl.store.queries import oracles

from tests.support.map_files import write_map
from tests.support.yard_spec import YARD_SPEC

EXSCE = "https://www.sesame-project.org/scenarios/"
TOPICS = f"{EXSCE}topics/"


def _by_type(bag: Path) -> dict[str, set[str]]:
    """The bag's topics by message type, as rosbags reads its connections."""
    found: dict[str, set[str]] = {}
    with AnyReader([bag]) as reader:
        for connection in reader.connections:
            found.setdefault(connection.msgtype, set()).add(connection.topic)
    return found


def _mine(topics: set[str], robot: str) -> set[str]:
    return {t for t in topics if t.startswith(f"/{robot}/")}


@pytest.fixture(scope="module", params=["nav2", "move_base"])
def judged(request: pytest.FixtureRequest, tmp_path_factory: pytest.TempPathFactory):
    """The yard with robots of a stack's convention: one run ingested as the baseline, one judged."""
    folder = tmp_path_factory.mktemp(request.param)
    write_map(folder, size=200)
    text = YARD_SPEC.replace("  torso yes\n", f"  torso yes\n  convention {request.param}\n")
    (folder / "spec.exsce").write_text(text.replace("at least 4 baseline", "at least 1 baseline"))
    spec = load_spec(folder / "spec.exsce")
    scenario = spec.scenario()
    bags = [run.bag for run in simulate(scenario, folder / "runs", 2, seed=1)]
    store = EmbeddedStore()
    [ingested] = ingest_bags(bags[:1], scenario, store)
    build_baseline(store, spec)
    verification = verify_runs(store, scenario, [bags[1]])
    return store, scenario, bags, verification, ingested.run_id


def test_a_stack_robot_s_oracles_name_its_topics_not_nav_vel(judged) -> None:
    store, scenario, bags, _, _ = judged
    types = _by_type(bags[0])
    held = {t for topics in types.values() for t in topics}
    assert not any(t.endswith(("/nav_vel", "/robot_pose")) for t in held)
    found = {o.name: set(o.topics) for o in oracles(store, scenario.id)}
    assert all(found.values()) and set().union(*found.values()) <= held
    for robot in ("r1", "r2"):
        assert found[f"{robot}-max_velocity"] == _mine(types["geometry_msgs/msg/Twist"], robot)
        assert found[f"{robot}-distance_travelled"] == _mine(types["nav_msgs/msg/Odometry"], robot)
        assert found[f"{robot}-distance_to_obstacles"] == _mine(types["sensor_msgs/msg/LaserScan"], robot)
    # the poses between robots come from each robot's transforms
    assert found["distance_between_robots"] == types["tf2_msgs/msg/TFMessage"]


def test_a_stack_robot_s_verdicts_name_the_judged_value_s_topics(judged) -> None:
    store, _, bags, verification, _ = judged
    types = _by_type(bags[1])
    held = {t for topics in types.values() for t in topics}
    assert len(verification.verdicts) == 11 and all(v.topics for v in verification.verdicts)
    assert all(set(v.topics) <= held for v in verification.verdicts)
    [speed] = [v for v in verification.verdicts if v.oracle == "r1-max_velocity"]
    assert set(speed.topics) == _mine(types["geometry_msgs/msg/Twist"], "r1")
    # and the verdict's PROV says so: derived from the topic entities
    rows = store.select(
        "SELECT ?topic WHERE { GRAPH ?g { ?verdict a <" + EXSCE + "verdict> ; "
        "<http://www.w3.org/ns/prov#wasDerivedFrom> ?topic . "
        'FILTER(CONTAINS(STR(?verdict), "/verdict-r1-max_velocity-")) '
        'FILTER(STRSTARTS(STR(?topic), "' + TOPICS + '")) } }'
    )
    named = {"/" + topic.value.removeprefix(TOPICS) for (topic,) in rows.rows}
    assert named == _mine(types["geometry_msgs/msg/Twist"], "r1")
    assert not any("nav_vel" in t for t in named)


def _parents(bag: Path, topics: set[str]) -> dict[str, str]:
    """Each frame's parent in the bag's transforms on ``topics``, as rosbags reads them."""
    found: dict[str, str] = {}
    with AnyReader([bag]) as reader:
        connections = [c for c in reader.connections if c.topic in topics]
        for connection, _, raw in reader.messages(connections=connections):
            for transform in reader.deserialize(raw, connection.msgtype).transforms:
                found[transform.child_frame_id] = transform.header.frame_id
    return found


def test_a_pose_from_tf_names_the_transforms_it_composed(judged) -> None:
    """A value computed from TF poses names the chain of frames it composed (``map → odom →
    base_link``) on its sample counts (``exsce:tf_chain``), not only ``/tf``."""
    from exsce_dsl.store.queries.accounting import value_accounts

    store, _, bags, _, baseline_run = judged
    [value] = value_accounts(store, baseline_run, "distance_between_robots")
    types = _by_type(bags[0])
    for robot in ("r1", "r2"):
        tf = _mine(types["tf2_msgs/msg/TFMessage"], robot)
        parents, frame, chain = _parents(bags[0], tf), "base_link", ["base_link"]
        while frame in parents:
            frame = parents[frame]
            chain.insert(0, frame)
        assert chain[0] == "map" and len(chain) >= 3
        [count] = [c for c in value.sources if set(c.topics) == tf]
        assert count.tf_chain == " → ".join(chain)
        assert any(line.startswith(f"TF {' → '.join(chain)} on /{robot}/tf") for line in value.samples_text())
