"""``exscec --timings CMD``: each store query CMD ran, with its calls, times and rows, on stderr at
its end (issue 52, item 4); nothing without the flag."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from tests.support.cli import exscec_here
from tests.support.help_examples import collected
from tests.support.paths import EXAMPLES
from tests.support.shared_baseline import copy_of_baseline_project
from tests.support.store_servers import oxigraph_server

TIMED_LINE = r"^  {name}\s+{calls}\s+(?P<total>[\d,.]+)\s+(?P<longest>[\d,.]+)\s+{rows}$"


@pytest.fixture(scope="module")
def project(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """scenario_c compiled into the project's store, three runs ingested (and baselined)."""
    return copy_of_baseline_project(tmp_path_factory, tmp_path_factory.mktemp("timings"))


def _timed(stderr: str, name: str, calls: int, rows: int) -> float:
    """The total milliseconds of query ``name``'s line in the timings (which must be there)."""
    found = re.search(TIMED_LINE.format(name=re.escape(name), calls=calls, rows=rows), stderr, re.MULTILINE)
    assert found, stderr
    assert float(found["longest"].replace(",", "")) <= float(found["total"].replace(",", ""))
    return float(found["total"].replace(",", ""))


def test_timings_of_runs_name_the_runs_query_with_its_time(project: Path) -> None:
    plain = exscec_here("runs", "scenario_c", cwd=project)
    timed = exscec_here("--timings", "runs", "scenario_c", cwd=project)
    assert plain.returncode == timed.returncode == 0, timed.stderr
    assert timed.stdout == plain.stdout  # the answer is the same; the timings go to stderr
    assert "timings" not in plain.stderr and "ms" not in plain.stderr
    assert timed.stderr.startswith(plain.stderr)
    lines = timed.stderr[len(plain.stderr) :].splitlines()
    assert lines[0] == "timings: the store queries of this command, slowest first"
    assert lines[1].split() == ["query", "calls", "total", "ms", "max", "ms", "rows"]
    total = _timed(timed.stderr, "runs", calls=1, rows=3)
    # and the look that the store has run summaries (two ASKs, once per store): in the sum too
    everything = re.fullmatch(r"  all\s+(\d+)\s+([\d,.]+)", lines[-1])
    assert everything is not None and int(everything[1]) == len(lines) - 3 == 3
    assert 0 < total <= float(everything[2].replace(",", ""))


def test_timings_are_printed_when_the_command_fails(project: Path) -> None:
    """An unknown run is looked up by prefix (``run_ids``) before the error: its time is shown too."""
    failed = exscec_here("--timings", "explain", "ffffffff", "distance_travelled", cwd=project)
    assert failed.returncode == 2 and "Traceback" not in failed.stderr
    assert "the store holds no run ffffffff" in failed.stderr
    _timed(failed.stderr, "run_ids", calls=1, rows=0)


def test_timings_without_store_queries_say_so(in_tmp: Path) -> None:
    done = exscec_here("--timings", "check", str(EXAMPLES / "brsu_building_c" / "scenario_c.exsce"))
    assert done.returncode == 0 and done.stderr.splitlines()[-1] == "timings: no store query"


def test_timings_on_a_remote_store(in_tmp: Path) -> None:
    shutil.copytree(EXAMPLES / "brsu_building_c", in_tmp / "bc")
    with oxigraph_server(in_tmp / "oxigraph") as server:
        url = f"oxigraph+{server.url}"
        assert exscec_here("compile", "bc/scenario_c.exsce", "--store", url).returncode == 0
        listed = exscec_here("--timings", "query", "robots", "-p", "scenario=scenario_c", "--store", url)
    assert listed.returncode == 0, listed.stderr
    _timed(listed.stderr, "robots", calls=1, rows=2)


def test_the_help_example_of_timings_runs_as_written(project: Path) -> None:
    (example,) = [e for e in collected() if "--timings" in e.line]
    assert example.command == ("runs",) and example.line.startswith("exscec --timings runs scenario_c")
    env = {k: v for k, v in os.environ.items() if k not in ("EXSCE_STORE", "EXSCE_STORE_TOKEN")}
    env["PATH"] = f"{Path(sys.executable).parent}{os.pathsep}{os.environ['PATH']}"  # as the walk runs it
    done = subprocess.run(
        ["bash", "-c", example.line], cwd=project, capture_output=True, text=True, env=env, timeout=120
    )
    assert done.returncode == 0, done.stderr
    _timed(done.stderr, "runs", calls=1, rows=3)
