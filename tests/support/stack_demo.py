"""What ``exscec demo --convention nav2|move_base`` must show, wherever its store is: the same
verdicts as on the method's topics, and bags, metric sources and a report that are the stack's."""

from __future__ import annotations

import json
import re
import subprocess
from pathlib import Path

from exsce_dsl.runs.bags.reading import bag_topics

from tests.support.cli import run_exscec


def check_stack_demo(done: subprocess.CompletedProcess[str], project: Path, convention: str, *store: str) -> None:
    """``done``: the demo's run; ``project``: its folder; ``store``: the ``--store URL`` it was given."""
    assert done.returncode == 0, done.stderr[-3000:]
    summary = done.stderr[done.stderr.index("Summary") :]
    assert re.search(r"passed, as expected\s+new run of scenario_c", summary)
    assert re.search(r"failed, as expected\s+run of scenario_c with the over-speed fault", summary)
    assert re.search(r"passed, as expected\s+run of derived c_one", summary)
    assert (project / "campaign.xml").is_file() and list((project / "explore").rglob("minimal/*.exsce"))
    assert f"convention {convention}" in (project / "scenarios" / "robots.exsce").read_text(encoding="utf-8")
    (bag,) = (project / "runs" / "new").glob("*.bag")
    goals = "/tiago1/navigate_to_pose/_action/status" if convention == "nav2" else "/tiago1/move_base/status"
    assert goals in bag_topics(bag) and "/tiago1/robot_pose" not in bag_topics(bag)
    listed = run_exscec("runs", *store, "--format", "json", cwd=project)
    run = json.loads(listed.stdout)["results"]["bindings"][0]["run"]["value"]
    sources = run_exscec(
        "query", "metric_sources", *store, "-p", f"run={run}", "-p", "metric=max_velocity", "-f", "csv",
        cwd=project,
    )
    assert sources.returncode == 0, sources.stderr
    assert "/tiago1/cmd_vel" in sources.stdout and "/tiago1/nav_vel" not in sources.stdout
    page = next((project / "report").glob("run-*.html")).read_text(encoding="utf-8")
    assert "<img" in page
