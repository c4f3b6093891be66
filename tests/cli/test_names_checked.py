"""Names checked against the bag and the store (issue 33, item 3), with the real exscec.

The stumbles, from a new user with real recordings: a topic misspelt in the spec (``/ground_truth``
for the bag's ``/groundtruth``) gave only per-metric warnings, with no did-you-mean and no list of
the bag's topics; nothing could make such a run an error before it was stored; and
``exscec query run_metric -p metric=distance_travelld`` answered an empty table and nothing else.

The bag is the executor's Nav2 run with its ``/odom`` recorded a second time as ``/groundtruth``
(a simulator's ground truth odometry), written with rosbags; the references are rosbags' own
reading of it.
"""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import numpy as np
import pytest
from rosbags.highlevel import AnyReader
from rosbags.rosbag1 import Reader, Writer

from exsce_dsl import api as exsce
from exsce_dsl.errors import UnknownNameWarning
from exsce_dsl.lang import load_spec
from exsce_dsl.sim.run import simulate

from tests.support.cli import exscec_here
from tests.support.paths import EXAMPLES

BUILDING = EXAMPLES / "brsu_building_c"
ODOMETRY = "nav_msgs/msg/Odometry"
EXECUTING, SUCCEEDED = 2, 4  # action_msgs/msg/GoalStatus


def spec(topic: str, scenario: str = "gt_drive") -> str:
    """A Nav2 robot at the root whose pose and a metric of its own read ``topic``."""
    return f"""\
import "{BUILDING}/environment.exsce"
import "{BUILDING}/tasks/deliveries.exsce"

robot type rover {{
  base pmb2
  torso no
  convention nav2
  pose on "{topic}" nav_msgs/msg/Odometry
}}

metric gt_path for each robot {{
  "path length along the simulator's ground truth"
  unit m
  reads g: nav_msgs/msg/Odometry on "{topic}"
  value path_length(g.pose.pose.position.x, g.pose.pose.position.y)
}}

scenario {scenario} in brsu_building_c_with_doors {{
  robots {{
    bot: rover namespace "" starts at classroom_c025-w001
  }}
  mission {scenario}_mission sequential {{
    bot does delivery_a
  }}
}}
"""


@pytest.fixture(scope="module")
def bag(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The executor's Nav2 run (ROS 1) with ``/groundtruth``: its ``/odom`` messages again."""
    folder = tmp_path_factory.mktemp("names")
    (folder / "plain.exsce").write_text(spec("/odom", "plain"))
    (run,) = simulate(load_spec(folder / "plain.exsce").scenario(), folder / "sim", fmt="ros1", seed=3,
                      convention="nav2")  # fmt: skip
    target = folder / "gt_run.bag"
    with Reader(run.bag) as reader, Writer(target) as writer:
        out = {
            c.id: writer.add_connection(c.topic, c.msgtype, msgdef=c.msgdef.data, md5sum=c.digest,
                                        callerid=c.ext.callerid)  # type: ignore[union-attr]
            for c in reader.connections
        }  # fmt: skip
        (odom,) = [c for c in reader.connections if c.topic == "/odom"]
        truth = writer.add_connection("/groundtruth", odom.msgtype, msgdef=odom.msgdef.data, md5sum=odom.digest,
                                      callerid="/gazebo")  # fmt: skip
        for c, t, raw in reader.messages():
            writer.write(out[c.id], t, raw)
            if c.topic == "/odom":
                writer.write(truth, t, raw)
    return target


def odometry_topics(bag: Path) -> list[str]:
    with AnyReader([bag]) as reader:
        return sorted(c.topic for c in reader.connections if c.msgtype == ODOMETRY)


def ground_truth_path(bag: Path) -> float:
    """The path along /groundtruth from the first goal EXECUTING to the last SUCCEEDED (log times)."""
    with AnyReader([bag]) as reader:
        conns = {c.topic: c for c in reader.connections}

        def read(topic: str) -> list[tuple[float, object]]:
            c = conns[topic]
            return [(t / 1e9, reader.deserialize(raw, c.msgtype)) for _, t, raw in reader.messages([c])]

        statuses = read("/navigate_to_pose/_action/status")
        started = min(t for t, m in statuses if any(s.status == EXECUTING for s in m.status_list))  # type: ignore[attr-defined]
        ended = max(t for t, m in statuses if any(s.status == SUCCEEDED for s in m.status_list))  # type: ignore[attr-defined]
        xy = np.array(
            [[m.pose.pose.position.x, m.pose.pose.position.y] for t, m in read("/groundtruth")  # type: ignore[attr-defined]
             if started <= t <= ended]
        )  # fmt: skip
    return float(np.sum(np.hypot(*np.diff(xy, axis=0).T)))


def runs_in(store: str) -> list[dict[str, dict[str, str]]]:
    listed = exscec_here("runs", "-f", "json", "--store", store)
    assert listed.returncode == 0, listed.stderr
    rows: list[dict[str, dict[str, str]]] = json.loads(listed.stdout)["results"]["bindings"]
    return rows


def test_a_misspelt_topic_warns_with_did_you_mean_and_the_bags_topics_of_its_type(
    bag: Path, tmp_path: Path
) -> None:
    (tmp_path / "gt.exsce").write_text(spec("/ground_truth"))
    store = str(tmp_path / "store")
    done = exscec_here("ingest", str(bag), "--scenario", str(tmp_path / "gt.exsce"), "--store", store)
    assert done.returncode == 0, done.stderr
    said = [line for line in done.stderr.splitlines() if "did you mean" in line]
    assert len(said) == 1, done.stderr  # once for the bag and the topic, not once per reader
    (line,) = said
    assert line.startswith(f"warning: {bag}: topic /ground_truth, read for the pose of 'bot', metric gt_path,")
    assert "did you mean /groundtruth?" in line
    topics = odometry_topics(bag)
    assert topics == ["/groundtruth", "/odom"]
    assert f"the bag's {ODOMETRY} topics: {', '.join(topics)}" in line
    # what needs no pose and no ground truth is still stored: task_duration
    (row,) = runs_in(store)
    run = row["run"]["value"]
    table = exscec_here("query", "run_metric", "-p", f"run={run}", "-p", "metric=task_duration", "-p", "robot=bot",
                        "-f", "csv", "--store", store)  # fmt: skip
    assert table.returncode == 0 and float(table.stdout.splitlines()[1].split(",")[0]) > 0, table.stdout


def test_strict_ingest_refuses_a_missing_metric_and_stores_nothing(bag: Path, tmp_path: Path) -> None:
    (tmp_path / "gt.exsce").write_text(spec("/ground_truth"))
    store = str(tmp_path / "store")
    done = exscec_here("ingest", str(bag), "--scenario", str(tmp_path / "gt.exsce"), "--store", store,
                       "--strict")  # fmt: skip
    assert done.returncode == 2, done.stderr
    assert f"error: {bag}: 1 metric value would be missing (gt_path of 'bot')" in done.stderr, done.stderr
    assert "(gt_path of 'bot'), and --strict stores no run with a missing metric:\n  " in done.stderr
    assert "did you mean /groundtruth?" in done.stderr
    assert "0 ingested, 0 skipped, 1 failed" in done.stderr
    assert runs_in(store) == []
    # spelt as the bag spells it, the same bag ingests with --strict, with rosbags' path length
    (tmp_path / "fixed.exsce").write_text(spec("/groundtruth"))
    done = exscec_here("ingest", str(bag), "--scenario", str(tmp_path / "fixed.exsce"), "--store",
                       store, "--strict")  # fmt: skip
    assert done.returncode == 0 and "did you mean" not in done.stderr, done.stderr
    (row,) = runs_in(store)
    table = exscec_here("query", "run_metric", "-p", f"run={row['run']['value']}", "-p", "metric=gt_path", "-p",
                        "robot=bot", "-f", "csv", "--store", store)  # fmt: skip
    assert float(table.stdout.splitlines()[1].split(",")[0]) == pytest.approx(ground_truth_path(bag), rel=1e-9)


def test_strict_is_the_apis_too(bag: Path, tmp_path: Path) -> None:
    (tmp_path / "gt.exsce").write_text(spec("/ground_truth"))
    with exsce.open_store(str(tmp_path / "store")) as store:
        (result,) = exsce.ingest(store, exsce.load(tmp_path / "gt.exsce"), [bag], strict=True)
        assert result.failed and "gt_path of 'bot'" in result.message and "/groundtruth" in result.message
        assert exsce.query(store, "runs").empty
        (lenient,) = exsce.ingest(store, exsce.load(tmp_path / "gt.exsce"), [bag])
        assert not lenient.failed
        assert len(exsce.query(store, "runs")) == 1


@pytest.fixture(scope="module")
def stored(bag: Path, tmp_path_factory: pytest.TempPathFactory) -> tuple[str, str]:
    """A store holding the bag's run of ``gt_drive`` (spelt right): the store and the run."""
    folder = tmp_path_factory.mktemp("store")
    (folder / "gt.exsce").write_text(spec("/groundtruth"))
    store = str(folder / "store")
    done = exscec_here("ingest", str(bag), "--scenario", str(folder / "gt.exsce"), "--store", store)
    assert done.returncode == 0, done.stderr
    (row,) = runs_in(store)
    return store, row["run"]["value"]


RIGHT = {"metric": "distance_travelled", "robot": "bot"}


@pytest.mark.parametrize(
    ("query", "wrong", "said"),
    [
        ("run_metric", {"metric": "distance_travelld"},
         "warning: the store holds no metric 'distance_travelld'; did you mean 'distance_travelled'?"),
        ("run_metric", {"robot": "bott"}, "warning: the store holds no robot 'bott'; did you mean 'bot'?"),
        ("runs", {"scenario": "gt_driv"}, "warning: the store holds no scenario 'gt_driv'; did you mean 'gt_drive'?"),
    ],
)  # fmt: skip
def test_a_misspelt_metric_parameter_warns_with_did_you_mean(
    stored: tuple[str, str], query: str, wrong: dict[str, str], said: str
) -> None:
    """The answer is empty as before (exit 0), and stderr says why; spelt right, a row and no warning."""
    store, run = stored
    right = {"run": run, **RIGHT} if query == "run_metric" else {"scenario": "gt_drive"}

    def asked(params: dict[str, str]) -> list[str]:
        return [a for k, v in params.items() for a in ("-p", f"{k}={v}")]

    done = exscec_here("query", query, *asked({**right, **wrong}), "-f", "csv", "--store", store)
    assert done.returncode == 0, done.stderr
    assert done.stdout.count("\n") == 1, done.stdout  # the header: no row
    assert done.stderr.strip() == said, done.stderr
    done = exscec_here("query", query, *asked(right), "-f", "csv", "--store", store)
    assert done.returncode == 0 and done.stderr == "", done.stderr
    assert done.stdout.count("\n") == 2, done.stdout  # the header and one row


def test_a_misspelt_parameter_warns_through_the_api(stored: tuple[str, str]) -> None:
    store_path, run = stored
    with exsce.open_store(store_path) as store:
        with pytest.warns(UnknownNameWarning, match=r"no metric 'distance_travelld'; did you mean 'distance_travelled'\?"):
            table = exsce.query(store, "run_metric", run=run, metric="distance_travelld", robot="bot")
        assert table.empty
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            assert len(exsce.query(store, "run_metric", run=run, metric="distance_travelled", robot="bot")) == 1


def test_a_misspelt_metric_parameter_warns_on_virtuoso_too(bag: Path, tmp_path: Path) -> None:
    """The store's names come from SPARQL the store evaluates: Virtuoso 7 answers the same."""
    from tests.support.store_servers import virtuoso_server

    (tmp_path / "gt.exsce").write_text(spec("/groundtruth"))
    with virtuoso_server(tmp_path / "virtuoso") as server:
        store = f"virtuoso+{server.url}"
        done = exscec_here("ingest", str(bag), "--scenario", str(tmp_path / "gt.exsce"), "--store",
                           store)  # fmt: skip
        assert done.returncode == 0, done.stderr
        (row,) = runs_in(store)
        done = exscec_here("query", "run_metric", "-p", f"run={row['run']['value']}", "-p", "metric=distance_travelld",
                           "-p", "robot=bott", "-f", "csv", "--store", store)  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert done.stderr.splitlines() == [
        "warning: the store holds no metric 'distance_travelld'; did you mean 'distance_travelled'?",
        "warning: the store holds no robot 'bott'; did you mean 'bot'?",
    ]
