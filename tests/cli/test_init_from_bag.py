"""Issue 33, "Done when" line 1: from a bag to a report in four commands, as a new user would,
in an empty folder: ``exscec bag info BAG``, ``exscec init --from-bag BAG``, ``exscec ingest BAG
--scenario <bag stem>.exsce``, ``exscec report``; every one exits 0, the report is written, and
the stored run's values are the bag's, as rosbags reads it (tests/support/draft_references.py).

One test per convention, on a bag the test writes (the executor's run of the yard), each in
another format.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
from rosbags.highlevel import AnyReader

from exsce_dsl.lang import load_spec
from exsce_dsl.sim.run import simulate

from tests.support.bag_factory import FORMATS, Topic, typestore_for, write_bag
from tests.support.cli import exscec_here, run_exscec
from tests.support.draft_references import reference
from tests.support.yard_spec import yard_text

ROBOTS = {"root_robot": "", "r2": "r2"}
"""The yard's robots as a drafted specification names them (r1 is at the root), and namespaces."""


def _ok(*args: str) -> str:
    done = exscec_here(*args)
    assert done.returncode == 0, f"exscec {' '.join(args)}:\n{done.stdout}\n{done.stderr}"
    assert "Traceback" not in done.stderr, done.stderr
    return done.stdout


def _yard_bag(folder: Path, convention: str, fmt: str) -> Path:
    spec = folder / "yard.exsce"
    spec.write_text(yard_text("torso no" if convention == "method" else f"convention {convention}"))
    (run,) = simulate(load_spec(spec).scenario(), folder, fmt=fmt, seed=7, convention=convention)
    return run.bag


def _stored(run: str, metric: str, robot: str) -> float:
    table = _ok(
        "query",
        "run_metric",
        "-p",
        f"run={run}",
        "-p",
        f"metric={metric}",
        "-p",
        f"robot={robot}",
        "--format",
        "csv",
    )
    return float(table.splitlines()[1].split(",")[0])


@pytest.mark.parametrize(("convention", "fmt"), [("method", "ros1"), ("nav2", "mcap"), ("move_base", "ros2")])
def test_from_a_bag_to_a_report_in_four_commands(
    in_tmp: Path, tmp_path_factory: pytest.TempPathFactory, convention: str, fmt: str
) -> None:
    bag = _yard_bag(tmp_path_factory.mktemp("recorded"), convention, fmt)
    assert list(in_tmp.iterdir()) == []
    info = _ok("bag", "info", str(bag))
    assert "robots    namespace '/'" in info and "robots    namespace 'r2'" in info
    said = _ok("init", "--from-bag", str(bag))
    spec = Path(f"{bag.stem if bag.is_file() else bag.name}.exsce")
    assert spec.exists() and f"wrote {spec}" in said
    _ok("ingest", str(bag), "--scenario", str(spec))
    _ok("report")
    assert "index.html" in {p.name for p in Path("report").iterdir()}
    (row,) = json.loads(_ok("runs", "--format", "json"))["results"]["bindings"]
    run = row["run"]["value"]
    for robot, ns in ROBOTS.items():
        expected = reference(bag, ns, convention)
        assert _stored(run, "distance_travelled", robot) == pytest.approx(expected.distance, rel=1e-9)
        assert _stored(run, "task_duration", robot) == pytest.approx(expected.duration, abs=0.05)
        assert _stored(run, "waypoints_visited", robot) == len(expected.targets)


def test_init_says_what_is_wrong_with_its_input(
    in_tmp: Path, tmp_path_factory: pytest.TempPathFactory
) -> None:
    missing = run_exscec("init", "--from-bag", "no_such.bag")
    assert missing.returncode == 2 and "no_such.bag: no such bag" in missing.stderr
    bag = _yard_bag(tmp_path_factory.mktemp("recorded"), "nav2", "ros1")
    _ok("init", "--from-bag", str(bag), "-o", "mine.exsce")
    again = run_exscec("init", "--from-bag", str(bag), "-o", "mine.exsce")
    assert again.returncode == 2 and "would overwrite mine.exsce; use --force to replace" in again.stderr
    _ok("init", "--from-bag", str(bag), "-o", "mine.exsce", "--force")
    _ok("check", "mine.exsce")


def _renamed_bag(source: Path, target: Path, namespace: str, keep_root: bool = True) -> Path:
    """``source`` (an executor's bag, robot r2 in namespace r2) written again by rosbags with r2's
    topics under ``namespace`` instead (and, unless ``keep_root``, without the root robot's)."""
    with AnyReader([source]) as reader:
        store = typestore_for("ros1")
        store.register({k: v for k, v in reader.typestore.fielddefs.items() if k not in store.fielddefs})
        found: dict[tuple[str, str], list[tuple[int, Any]]] = {}
        for connection, time_ns, raw in reader.messages():
            message = reader.deserialize(raw, connection.msgtype)
            found.setdefault((connection.topic, connection.msgtype), []).append((time_ns, message))
    topics = [
        Topic(topic.replace("/r2/", f"/{namespace}/", 1), msgtype, messages)
        for (topic, msgtype), messages in found.items()
        if keep_root or topic.startswith("/r2/")
    ]
    write_bag(target, FORMATS["ros1"], topics, store)
    return target


@pytest.mark.parametrize("namespace", ['r"2', "..", "r'2", "r2\n  robot evil"])
def test_init_drafts_that_check_for_namespaces_with_quotes_or_dots(
    in_tmp: Path, tmp_path_factory: pytest.TempPathFactory, namespace: str
) -> None:
    recorded = tmp_path_factory.mktemp("recorded")
    source = _yard_bag(recorded, "method", "ros1")
    bag = _renamed_bag(source, recorded / "odd.bag", namespace)
    _ok("init", "--from-bag", str(bag), "-o", "odd.exsce")
    _ok("check", "odd.exsce")  # the draft checks: the namespace is left out, saying why
    text = Path("odd.exsce").read_text()
    assert "// Left out: namespace " in text and "is not a valid ROS name" in text
    assert all(line.lstrip().startswith("//") or "evil" not in line for line in text.splitlines())
    # a bag whose every robot is in such a namespace: no draft, and why (not one that fails check)
    only = _renamed_bag(source, recorded / "only.bag", namespace, keep_root=False)
    done = exscec_here("init", "--from-bag", str(only), "-o", "only.exsce")
    assert done.returncode == 2 and "no robot to draft a specification for" in done.stderr
    assert not Path("only.exsce").exists()
