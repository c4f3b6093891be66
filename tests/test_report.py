"""exscec report: what it gathers from the store, the pages it writes, and those pages in a real browser."""

from __future__ import annotations

import os
import re
import shutil
from html.parser import HTMLParser
from pathlib import Path

import pytest

from exsce_dsl.lang.build import load_spec
from exsce_dsl.model.geometry import Position
from exsce_dsl.model.runs import Hotspot
from exsce_dsl.model.verdicts import Outcome, Verdict
from exsce_dsl.report.contents import ReportContents, RunContents, ScenarioContents, gather
from exsce_dsl.report.html import page_name, write_report
from exsce_dsl.sim.executor import Fault
from exsce_dsl.sim.run import simulate
from exsce_dsl.store.embedded import EmbeddedStore
from exsce_dsl.store.queries import StoredRun

from conftest import EXAMPLES, ROOT, run_exscec

ARTIFACTS = Path(os.environ.get("EXSCE_TEST_ARTIFACTS", ROOT / "build" / "test-artifacts"))


@pytest.fixture(scope="module")
def project(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Three baseline runs of scenario_c, a verified over-speed run, and c_one derived from scenario_c."""
    folder = tmp_path_factory.mktemp("report")
    shutil.copytree(EXAMPLES / "brsu_building_c", folder / "c")
    scenario = load_spec(folder / "c" / "scenario_c.exsce").scenario("scenario_c")
    bags = [str(run.bag) for run in simulate(scenario, folder / "base", 3, seed=1)]
    fast = [
        str(run.bag)
        for run in simulate(scenario, folder / "fast", 1, seed=2, faults=(Fault.parse("overspeed:tiago1"),))
    ]
    steps = [
        ("ingest", *bags, "--scenario", "c/scenario_c.exsce"),
        ("baseline", "c/scenario_c.exsce"),
        (
            "derive",
            "c/scenario_c.exsce",
            "-t",
            "remove_robot",
            "--robot",
            "tiago2",
            "--reassign",
            "tiago1",
            "--id",
            "c_one",
            "-o",
            "c/c_one.exsce",
            "--add-to-store",
        ),
    ]
    for step in steps:
        done = run_exscec(*step, cwd=folder)
        assert done.returncode == 0, (step, done.stderr)
    verified = run_exscec("verify", *fast, "--scenario", "c/scenario_c.exsce", cwd=folder)
    assert verified.returncode == 1, verified.stderr  # the over-speed run fails its limits
    made = run_exscec("report", "-o", "out", "--spec", "c/scenario_c.exsce", cwd=folder)
    assert made.returncode == 0, made.stderr
    assert "wrote out/index.html (2 scenarios, 4 runs)" in made.stderr
    return folder


def _pages(project: Path) -> list[Path]:
    return sorted((project / "out").glob("*.html"))


class _Links(HTMLParser):
    def __init__(self) -> None:
        super().__init__()
        self.targets: list[str] = []

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        for name, value in attrs:
            if name in ("href", "src") and value:
                self.targets.append(value)


def test_the_store_gives_lineage_runs_verdicts_hotspots_and_maps(project: Path) -> None:
    with EmbeddedStore(project / ".exsce" / "store") as store:
        contents = gather(store, [project / "c" / "scenario_c.exsce"])
    assert contents.roots() == ("scenario_c",)
    base, derived = contents.scenario("scenario_c"), contents.scenario("c_one")
    assert base.children == ("c_one",) and derived.derivation is not None
    assert derived.derivation.base == "scenario_c"
    assert [s.transformation for s in derived.derivation.steps] == ["remove_robot"]
    assert (
        derived.grid is not None and derived.grid is base.grid
    )  # a derived scenario is drawn on its base's map
    assert len(base.runs) == 4 and derived.runs == ()
    failed = [r for r in base.runs if r.status == "failed"]
    assert len(failed) == 1 and [r.status for r in base.runs].count("not verified") == 3
    fault = failed[0]
    assert fault.hotspots and all(h.metric for h in fault.hotspots)
    assert any(h.metric == "max_velocity" and h.robot == "tiago1" for h in fault.hotspots)
    outcomes = [v.outcome for v in contents.verdicts]
    assert outcomes == sorted(outcomes, key=[Outcome.FAILED, Outcome.UNJUDGED, Outcome.PASSED].index)
    assert any(v.oracle == "tiago1-max_velocity" and v.outcome is Outcome.FAILED for v in contents.verdicts)
    assert set(base.waypoints) == {"tiago1", "tiago2"} and len(base.waypoints["tiago1"]) == 4  # start + 3
    assert contents.clustering is not None and set(contents.clustering.scenarios) == {"scenario_c", "c_one"}
    assert any(o.type.value == "baseline" and o.value is not None for o in base.oracles)


def test_every_page_is_written_and_every_link_and_image_is_there(project: Path) -> None:
    pages = {p.name for p in _pages(project)}
    assert {"index.html", "scenario-scenario_c.html", "scenario-c_one.html"} <= pages
    assert len([p for p in pages if p.startswith("run-")]) == 4
    for page in _pages(project):
        links = _Links()
        links.feed(page.read_text(encoding="utf-8"))
        assert links.targets, page.name
        for target in links.targets:
            assert not re.match(r"[a-z]+://", target), f"{page.name} links outside the report: {target}"
            local = target.split("#", 1)[0]
            if local:
                assert (project / "out" / local).is_file(), f"{page.name}: {target} is missing"
    index = (project / "out" / "index.html").read_text(encoding="utf-8")
    table = index[index.index('id="verdicts"') :]
    assert 0 <= table.index("badge failed") < table.index("badge passed")  # failures first


def test_the_report_opens_in_chromium_with_every_image_and_no_console_error(project: Path) -> None:
    from playwright.sync_api import sync_playwright

    chromium = (
        os.environ.get("EXSCE_CHROMIUM") or shutil.which("chromium") or shutil.which("chromium-browser")
    )
    assert chromium, "Debian's chromium is needed (sh scripts/install-test-browser)"
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    problems: list[str] = []
    with sync_playwright() as playwright:
        browser = playwright.chromium.launch(
            executable_path=chromium,
            args=[
                "--no-sandbox",
                "--disable-gpu",
                "--disable-background-networking",
                "--disable-component-update",
                "--disable-sync",
                "--no-first-run",
                "--disable-quic",
            ],
        )
        try:
            page = browser.new_page(viewport={"width": 1280, "height": 900})
            page.on(
                "console",
                lambda m: (
                    problems.append(f"console {m.type}: {m.text}") if m.type in ("error", "warning") else None
                ),
            )
            page.on("pageerror", lambda e: problems.append(f"page error: {e}"))
            page.on("requestfailed", lambda r: problems.append(f"failed to load {r.url}"))
            for html in _pages(project):
                page.goto(html.as_uri(), wait_until="load")
                images = page.evaluate(
                    "Array.from(document.images).map(i => [i.getAttribute('src'), i.complete, i.naturalWidth])"
                )
                broken = [src for src, complete, width in images if not complete or width == 0]
                assert not broken, f"{html.name}: images that did not load: {broken}"
                if html.name == "index.html" or html.name.startswith("run-"):
                    assert images, f"{html.name} shows no image"
                if html.name == "index.html":
                    page.screenshot(path=str(ARTIFACTS / "report-index.png"), full_page=True)
                elif html.name == "scenario-scenario_c.html":
                    page.screenshot(path=str(ARTIFACTS / "report-scenario_c.png"), full_page=True)
        finally:
            browser.close()
    assert not problems, problems
    assert (ARTIFACTS / "report-index.png").stat().st_size > 10_000


def test_run_pages_show_the_hotspots_and_say_what_is_missing_without_a_map(project: Path) -> None:
    done = run_exscec("report", "-o", "plain", cwd=project)
    assert done.returncode == 0, done.stderr
    assert "note: no occupancy grid" in done.stderr
    index = (project / "plain" / "index.html").read_text(encoding="utf-8")
    assert "no occupancy grid" in index
    run_pages = [p.read_text(encoding="utf-8") for p in (project / "plain").glob("run-*.html")]
    with_table = [p for p in run_pages if "<th>violations</th>" in p]
    assert len(with_table) == 1 and "<td>max_velocity</td><td>tiago1</td>" in with_table[0]
    assert sum("No hotspots: no safety limit was broken." in p for p in run_pages) == 3
    assert run_pages and all("pass the scenario's file to" in p for p in run_pages)


def test_text_from_the_store_is_escaped(tmp_path: Path) -> None:
    nasty = '<script>alert("x")</script>'
    run = StoredRun("0fcc1782-0c63-5500-b8af-3de8573bc05f", "s", None, None, "a.bag", None)
    verdict = Verdict(
        run.uuid,
        "s",
        nasty,
        "o",
        "max_velocity",
        "r1",
        "below_max",
        Outcome.FAILED,
        observed=2.0,
        limit=1.0,
        reason=nasty,
    )
    spot = Hotspot("max_velocity", Position(1.0, 2.0), 3, 1.5, "r1")
    scenario = ScenarioContents("s", None, (), (RunContents(run, (verdict,), (spot,)),), (), (), {})
    write_report(ReportContents((scenario,), (verdict,), None), tmp_path)
    for page in tmp_path.glob("*.html"):
        text = page.read_text(encoding="utf-8")
        assert "<script" not in text, page.name
    assert "&lt;script&gt;" in (tmp_path / "index.html").read_text(encoding="utf-8")
    assert (tmp_path / f"{page_name('run', run.uuid)}.html").is_file()


def test_page_names_keep_safe_ids_and_digest_the_others() -> None:
    assert page_name("scenario", "scenario_c") == "scenario-scenario_c"
    for unsafe in ("../etc/passwd", "a/b", ".hidden", "x y", "é"):
        name = page_name("scenario", unsafe)
        assert re.fullmatch(r"scenario-[0-9a-f]{16}", name), unsafe
    assert page_name("scenario", "a/b") != page_name("scenario", "a/c")


def test_cluster_draws_the_dendrogram_as_png_and_svg(project: Path) -> None:
    done = run_exscec(
        "cluster", "--k", "2", "--dendrogram", "tree.png", "--dendrogram", "tree.svg", cwd=project
    )
    assert done.returncode == 0, done.stderr
    assert (project / "tree.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    svg = (project / "tree.svg").read_text(encoding="utf-8")
    assert svg.lstrip().startswith("<?xml") and "<!-- scenario_c -->" in svg and "<!-- c_one -->" in svg
    again = run_exscec("cluster", "--k", "2", "--dendrogram", "tree.svg", cwd=project)
    assert again.returncode == 0 and (project / "tree.svg").read_text(encoding="utf-8") == svg  # reproducible
    bad = run_exscec("cluster", "--dendrogram", "tree.pdf", cwd=project)
    assert bad.returncode == 2 and ".png or .svg" in bad.stderr


def test_every_metric_value_on_a_run_page_has_its_unit(project: Path) -> None:
    done = run_exscec("report", "-o", "units", cwd=project)
    assert done.returncode == 0, done.stderr
    page = next((project / "units").glob("run-*.html")).read_text(encoding="utf-8")
    table = page[page.index("<h2>Metric values</h2>") :]
    rows = re.findall(
        r"<tr><td>(\w+)[^<]*</td><td>\w+</td><td class=\"num\">[^<]+</td><td>([^<]+)</td></tr>", table
    )
    units = dict(rows)
    assert units["distance_travelled"] == "m" and units["max_velocity"] == "m/s"
    assert units["task_duration"] == "s" and units["waypoints_visited"] == "(count)"
    assert len(rows) == table.count("<tr><td>")  # every row has one
