"""Issue 48, item 1: specifications drafted from many bags share one store.  Two recordings of the
yard, each ``run.bag`` in a folder of its own, are drafted where they are (``exscec init
--from-bag run.bag`` writes ``run.exsce`` in each), ingested into one store and judged: two
scenarios, two runs, each robot at the root a robot of its own (``root_robot`` in each draft),
no conflict.  Before, the second draft was refused: its scenario, areas, tasks and root robot had
the first one's ids.
"""

from __future__ import annotations

import shutil
from pathlib import Path

from exsce_dsl.lang import load_spec
from exsce_dsl.sim.run import simulate

from tests.support.cli import exscec_here
from tests.support.yard_spec import yard_text


def _ok(*args: str, cwd: Path, codes: tuple[int, ...] = (0,)) -> str:
    done = exscec_here(*args, cwd=cwd)
    assert done.returncode in codes, f"exscec {' '.join(args)}:\n{done.stdout}\n{done.stderr}"
    assert "Traceback" not in done.stderr, done.stderr
    return done.stdout


def test_drafts_of_two_bags_of_one_name_share_a_store_and_are_judged(tmp_path: Path) -> None:
    spec = tmp_path / "yard.exsce"
    spec.write_text(yard_text("torso no"))
    store = tmp_path / "store"
    scenarios = []
    for folder, seed in (("monday", 7), ("tuesday", 8)):
        (run,) = simulate(load_spec(spec).scenario(), tmp_path / f"sim_{seed}", fmt="ros1", seed=seed)
        (tmp_path / folder).mkdir()
        shutil.copy(run.bag, tmp_path / folder / "run.bag")
        _ok("init", "--from-bag", "run.bag", cwd=tmp_path / folder)
        scenarios.append(load_spec(tmp_path / folder / "run.exsce").scenario())
        _ok("ingest", "run.bag", "--scenario", "run.exsce", "--store", str(store), cwd=tmp_path / folder)
    first, second = scenarios
    assert first.id != second.id and first.id.startswith("run_") and second.id.startswith("run_")
    assert [r.id for r in first.robots] == [r.id for r in second.robots] == ["root_robot", "r2"]

    listed = _ok("runs", "--store", str(store), cwd=tmp_path)
    assert listed.count("/run.bag") == 2 and "monday/run.bag" in listed and "tuesday/run.bag" in listed, (
        listed
    )
    for scenario in scenarios:
        assert scenario.id in listed
        asked = ("query", "robots", "-p", f"scenario={scenario.id}", "--format", "csv", "--store", str(store))
        robots = _ok(*asked, cwd=tmp_path)
        assert [line.split(",")[0] for line in robots.splitlines()[1:]] == ["r2", "root_robot"]
    for folder in ("monday", "tuesday"):
        _ok("baseline", "run.exsce", "--all-runs", "--store", str(store), cwd=tmp_path / folder)
        args = ("verify", "run.bag", "--scenario", "run.exsce", "--store", str(store))
        judged = _ok(*args, cwd=tmp_path / folder, codes=(0, 1, 3))
        assert "max_velocity" in judged, judged
    verdicts = _ok("query", "verdicts", "--format", "csv", "--store", str(store), cwd=tmp_path)
    assert {scenario.id for scenario in scenarios} <= set(verdicts.replace("\n", ",").split(",")), verdicts
    assert "no problem found" in _ok("store", "check", "--store", str(store), cwd=tmp_path)
