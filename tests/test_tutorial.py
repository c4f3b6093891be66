"""docs/tutorial.md, run as written, and exscec demo, which runs the same commands."""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

from exsce_dsl.cli.demo_commands import STEPS
from exsce_dsl.runs.bagdata import bag_topics

from conftest import ROOT, run_exscec

TUTORIAL = ROOT / "docs" / "tutorial.md"


def _shell_lines() -> list[str]:
    blocks = re.findall(r"```sh\n(.*?)```", TUTORIAL.read_text(encoding="utf-8"), flags=re.S)
    return [line.strip() for block in blocks for line in block.splitlines() if line.strip()]


def _expected_exit(line: str) -> int:
    found = re.search(r"#\s*exits (\d+)\s*$", line)
    return int(found.group(1)) if found else 0


def _without_comment(line: str) -> str:
    return re.sub(r"\s+#.*$", "", line)


def test_the_demo_runs_the_commands_of_the_tutorial() -> None:
    lines = _shell_lines()
    assert lines[:2] == ["exscec demo my-project --setup-only", "cd my-project"]
    assert [_without_comment(line) for line in lines[2:]] == [step.command for step in STEPS]
    assert [_expected_exit(line) for line in lines[2:]] == [step.expected_exit for step in STEPS]


def test_every_command_of_the_tutorial_works_as_written(tmp_path: Path) -> None:
    env = {**os.environ, "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}", "COLUMNS": "120"}
    env.pop("EXSCE_STORE", None)
    cwd = tmp_path
    for line in _shell_lines():
        command = _without_comment(line)
        if command.startswith("cd "):
            cwd = cwd / command[3:]
            continue
        done = subprocess.run(["bash", "-c", command], cwd=cwd, env=env, capture_output=True, text=True,
                              timeout=300)
        assert done.returncode == _expected_exit(line), f"{command}\n{done.stdout}\n{done.stderr}"
        assert "Traceback" not in done.stderr, command
    project = tmp_path / "my-project"
    junit = ET.parse(project / "verdicts-new.xml").getroot()
    assert int(junit.get("failures", junit.find("testsuite").get("failures"))) == 0  # type: ignore[union-attr]
    assert (project / "report" / "index.html").is_file() and (project / "clusters.svg").is_file()
    assert (project / "scenario_c.provn").read_text(encoding="utf-8").startswith("document")


def test_exscec_demo_shows_the_fault_run_failing_and_the_others_passing(tmp_path: Path) -> None:
    done = run_exscec("demo", "demo", cwd=tmp_path)
    assert done.returncode == 0, done.stderr[-3000:]
    summary = done.stderr[done.stderr.index("Summary"):]
    assert re.search(r"passed\s+new run of scenario_c", summary)
    assert re.search(r"FAILED\s+run of scenario_c with the over-speed fault", summary)
    assert re.search(r"passed\s+run of derived c_one", summary)
    assert (tmp_path / "demo" / "report" / "index.html").is_file()
    assert f"[{len(STEPS)}/{len(STEPS)}]" in done.stderr and "$ exscec verify runs/faulty/" in done.stderr
    again = run_exscec("demo", "demo", cwd=tmp_path)
    assert again.returncode == 1 and "is not empty" in again.stderr and "Traceback" not in again.stderr


@pytest.mark.parametrize("convention", ["nav2", "move_base"])
def test_the_whole_method_runs_on_a_navigation_stacks_runs(tmp_path: Path, convention: str) -> None:
    """The demo with the robots on Nav2's (move_base's) topics: the same verdicts, and its bags,
    metric sources and report are the stack's."""
    done = run_exscec("demo", "demo", "--convention", convention, cwd=tmp_path)
    assert done.returncode == 0, done.stderr[-3000:]
    summary = done.stderr[done.stderr.index("Summary"):]
    assert re.search(r"passed\s+new run of scenario_c", summary)
    assert re.search(r"FAILED\s+run of scenario_c with the over-speed fault", summary)
    assert re.search(r"passed\s+run of derived c_one", summary)
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


def test_the_demo_runs_unchanged_against_a_remote_sparql_endpoint(tmp_path: Path) -> None:
    from store_servers import oxigraph_server

    with oxigraph_server(tmp_path / "oxigraph") as server:
        done = run_exscec("demo", "remote-demo", "--store", f"{server.url}/query", cwd=tmp_path)
        assert done.returncode == 0, done.stderr[-3000:]
        listed = run_exscec("runs", "--store", f"{server.url}/query", "-f", "csv", cwd=tmp_path)
    summary = done.stderr[done.stderr.index("Summary"):]
    assert re.search(r"FAILED\s+run of scenario_c with the over-speed fault", summary)
    assert f"store      {server.url}/query" in summary
    assert not (tmp_path / "remote-demo" / ".exsce").exists()  # nothing went to an embedded store
    assert len(listed.stdout.strip().splitlines()) == 1 + 6  # the header and the six runs of the demo
