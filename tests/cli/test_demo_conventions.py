"""exscec demo with the robots on a navigation stack's topics (Nav2, move_base): the whole method,
the same verdicts as on the method's topics (tests/cli/test_tutorial.py)."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from exsce_dsl.runs.bags.reading import bag_topics

from tests.support.cli import run_exscec


@pytest.mark.parametrize("convention", ["nav2", "move_base"])
def test_the_whole_method_runs_on_a_navigation_stacks_runs(tmp_path: Path, convention: str) -> None:
    """The demo with the robots on Nav2's (move_base's) topics: the same verdicts, and its bags,
    metric sources and report are the stack's."""
    done = run_exscec("demo", "demo", "--convention", convention, cwd=tmp_path)
    assert done.returncode == 0, done.stderr[-3000:]
    summary = done.stderr[done.stderr.index("Summary") :]
    assert re.search(r"passed, as expected\s+new run of scenario_c", summary)
    assert re.search(r"failed, as expected\s+run of scenario_c with the over-speed fault", summary)
    assert re.search(r"passed, as expected\s+run of derived c_one", summary)
    assert (tmp_path / "demo" / "campaign.xml").is_file() and list(
        (tmp_path / "demo" / "explore").rglob("minimal/*.exsce")
    )
    project = tmp_path / "demo"
    assert f"convention {convention}" in (project / "scenarios" / "robots.exsce").read_text(encoding="utf-8")
    (bag,) = (project / "runs" / "new").glob("*.bag")
    goals = "/tiago1/navigate_to_pose/_action/status" if convention == "nav2" else "/tiago1/move_base/status"
    assert goals in bag_topics(bag) and "/tiago1/robot_pose" not in bag_topics(bag)
    listed = run_exscec("runs", "--format", "json", cwd=project)
    run = json.loads(listed.stdout)["results"]["bindings"][0]["run"]["value"]
    sources = run_exscec(
        "query", "metric_sources", "-p", f"run={run}", "-p", "metric=max_velocity", "-f", "csv", cwd=project
    )
    assert sources.returncode == 0, sources.stderr
    assert "/tiago1/cmd_vel" in sources.stdout and "/tiago1/nav_vel" not in sources.stdout
    page = next((project / "report").glob("run-*.html")).read_text(encoding="utf-8")
    assert "<img" in page
