"""exscec demo against a remote SPARQL endpoint (a real ``oxigraph serve``) instead of its embedded
store, with the robots on Nav2's topics: the whole method, the same verdicts as on the method's
topics (the demo itself: tests/cli/test_help_examples_live.py).  One demo run checks both (each
costs a minute).  The whole loop on move_base's topics is ``exscec demo --ros1``, whose stand-in
robots speak move_base (tests/execute/test_live_loop.py)."""

from __future__ import annotations

import csv
import io
import re
from pathlib import Path

from tests.support.cli import run_exscec
from tests.support.stack_demo import check_stack_demo
from tests.support.store_servers import oxigraph_server


def test_the_demo_on_nav2_runs_unchanged_against_a_remote_sparql_endpoint(tmp_path: Path) -> None:
    with oxigraph_server(tmp_path / "oxigraph") as server:
        store = ("--store", f"{server.url}/query")
        done = run_exscec(
            "demo", "remote-demo", *store, "--convention", "nav2", cwd=tmp_path, timeout=600
        )
        check_stack_demo(done, tmp_path / "remote-demo", "nav2", *store)
        listed = run_exscec("runs", *store, "-f", "csv", cwd=tmp_path)
    summary = done.stderr[done.stderr.index("Summary") :]
    assert re.search(r"failed, as expected\s+run of scenario_c with the over-speed fault", summary)
    assert f"store: {server.url}/query" in summary
    assert not (tmp_path / "remote-demo" / ".exsce").exists()  # nothing went to an embedded store
    rows = list(csv.DictReader(io.StringIO(listed.stdout)))
    scenarios = [row["scenario_id"] for row in rows]
    # the demo's five runs of scenario_c and one of c_one; the campaign's, of its derived scenarios
    assert scenarios.count("scenario_c") == 5 and scenarios.count("c_one") == 1
    assert len(rows) > 6 and all(
        s.startswith("scenario_c_") for s in scenarios if s not in ("scenario_c", "c_one")
    )
