"""exscec report: what it gathers from the store, the pages it writes, and those pages in a real browser."""

from __future__ import annotations

import itertools
import json
import os
import re
import shutil
from collections.abc import Iterator
from contextlib import contextmanager
from html.parser import HTMLParser
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import pytest
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg, RendererAgg
from matplotlib.figure import Figure
from matplotlib.text import Annotation, Text
from matplotlib.transforms import Bbox

from exsce_dsl.lang import load_spec
from exsce_dsl.model.geometry import Position
from exsce_dsl.model.runs import Hotspot
from exsce_dsl.model.verdicts import Outcome, Verdict
from exsce_dsl.report.contents import (
    ReportContents,
    RunContents,
    RunSegment,
    ScenarioContents,
    failures_first,
    gather,
)
from exsce_dsl.report.html import page_name, write_report
from exsce_dsl.report.plots import MARGIN, trajectory_figure
from exsce_dsl.report.units import metric_units
from exsce_dsl.runs.signals.trajectories import Trajectory, trajectories
from exsce_dsl.sim.executor import Fault
from exsce_dsl.sim.run import simulate
from exsce_dsl.store.embedded import EmbeddedStore
from exsce_dsl.store.queries import MetricReading, StoredRun

from tests.support.cli import exscec_here
from tests.support.paths import EXAMPLES, ROOT

if TYPE_CHECKING:
    from playwright.sync_api import Browser

ARTIFACTS = Path(os.environ.get("EXSCE_TEST_ARTIFACTS", ROOT / "build" / "test-artifacts"))


@pytest.fixture(scope="module")
def project(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Three baseline runs of scenario_c, the first verified (it passes), a verified over-speed run
    (it fails), and c_one derived from scenario_c with its expectations, one run of it verified.

    ``verify-c_one.txt`` holds what ``exscec verify`` printed for c_one's run."""
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
        ("verify", bags[0], "--scenario", "c/scenario_c.exsce"),  # an earlier run that passes
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
            "--expect",
            "--add-to-store",
        ),
    ]
    for step in steps:
        done = exscec_here(*step, cwd=folder)
        assert done.returncode == 0, (step, done.stdout, done.stderr)
    verified = exscec_here("verify", *fast, "--scenario", "c/scenario_c.exsce", cwd=folder)
    assert verified.returncode == 1, verified.stderr  # the over-speed run fails its limits
    one = load_spec(folder / "c" / "c_one.exsce").scenario("c_one")
    one_bags = [str(run.bag) for run in simulate(one, folder / "one", 1, seed=3)]
    judged = exscec_here("verify", *one_bags, "--scenario", "c/c_one.exsce", cwd=folder)
    assert judged.returncode in (0, 1) and "increasing" in judged.stdout, judged.stderr
    (folder / "verify-c_one.txt").write_text(judged.stdout, encoding="utf-8")
    made = exscec_here("report", "-o", "out", "--spec", "c/scenario_c.exsce", cwd=folder)
    assert made.returncode == 0, made.stderr
    assert "wrote out/index.html (2 scenarios, 5 runs)" in made.stderr
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
    assert len(base.runs) == 4 and len(derived.runs) == 1
    failed = [r for r in base.runs if r.status == "failed"]
    assert len(failed) == 1 and [r.status for r in base.runs].count("not verified") == 2
    assert [r.status for r in base.runs].index("passed") < [r.status for r in base.runs].index("failed")
    fault = failed[0]
    assert fault.hotspots and all(h.metric for h in fault.hotspots)
    assert any(h.metric == "max_velocity" and h.robot == "tiago1" for h in fault.hotspots)
    rank = [Outcome.FAILED, Outcome.INCONCLUSIVE, Outcome.PASSED].index
    for verdicts in (contents.verdicts, base.verdicts, *(r.verdicts for r in base.runs)):
        outcomes = [v.outcome for v in verdicts]
        assert outcomes == sorted(outcomes, key=rank)
    assert {v.outcome for v in base.verdicts} == {Outcome.FAILED, Outcome.PASSED}
    assert any(v.oracle == "tiago1-max_velocity" and v.outcome is Outcome.FAILED for v in contents.verdicts)
    assert set(base.waypoints) == {"tiago1", "tiago2"} and len(base.waypoints["tiago1"]) == 4  # start + 3
    assert contents.clustering is not None and set(contents.clustering.scenarios) == {"scenario_c", "c_one"}
    assert any(o.type.value == "baseline" and o.value is not None for o in base.oracles)


def test_each_run_page_names_the_run_its_dispatcher_recorded(project: Path) -> None:
    """simulate wrote each run's .prov.json beside its bag: its run id is on the run's page."""
    recorded = sorted(project.glob("*/*.prov.json"))
    assert len(recorded) == 5
    pages = "\n".join(p.read_text(encoding="utf-8") for p in _pages(project) if p.name.startswith("run-"))
    shown = set(re.findall(r'<span class="id dispatched">([0-9a-f-]{36})</span>', pages))
    assert shown == {_run_of(p) for p in recorded}


def _run_of(prov: Path) -> str:
    """The dispatcher's run id, from the run activity of its .prov.json."""
    bundles = json.loads(prov.read_text(encoding="utf-8"))["bundle"].values()
    (run,) = [
        a["exsce:run"]
        for b in bundles
        for a in b.get("activity", {}).values()
        if a.get("prov:type", {}).get("$") == "exsce:run"
    ]
    return str(run)


def test_every_page_is_written_and_every_link_and_image_is_there(project: Path) -> None:
    pages = {p.name for p in _pages(project)}
    assert {"index.html", "scenario-scenario_c.html", "scenario-c_one.html"} <= pages
    assert len([p for p in pages if p.startswith("run-")]) == 5
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


@contextmanager
def _chromium() -> Iterator[Browser]:
    """Debian's chromium, headless, through Playwright."""
    from playwright.sync_api import sync_playwright

    chromium = (
        os.environ.get("EXSCE_CHROMIUM") or shutil.which("chromium") or shutil.which("chromium-browser")
    )
    assert chromium, "Debian's chromium is needed (sh scripts/install-test-browser)"
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
            yield browser
        finally:
            browser.close()


def test_the_report_opens_in_chromium_with_every_image_and_no_console_error(project: Path) -> None:
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    problems: list[str] = []
    shots = {
        "index.html": "report-index.png",
        "scenario-scenario_c.html": "report-scenario_c.png",
        _failed_run_page(project).name: "report-run-failed.png",
    }
    with _chromium() as browser:
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
            if html.name in shots:
                page.screenshot(path=str(ARTIFACTS / shots[html.name]), full_page=True)
    assert not problems, problems
    assert all((ARTIFACTS / shot).stat().st_size > 10_000 for shot in shots.values())


def _failed_run_page(project: Path) -> Path:
    """The over-speed run's page (the one run with hotspots)."""
    return next(p for p in (project / "out").glob("run-*.html") if ">violations</th>" in p.read_text("utf-8"))


_TABLES = """() => Array.from(document.querySelectorAll('table')).map(table => ({
  headers: Array.from(table.querySelectorAll('thead th')).map(th => th.innerText.trim()),
  boxed: table.parentElement.classList.contains('table-box'),
  rows: Array.from(table.querySelectorAll('tbody tr')).map(tr => ({
    outcome: tr.className,
    cells: Array.from(tr.cells).map(td => [td.tagName, td.classList.contains('num'), td.innerText.trim()]),
  })),
}))"""

_NUMBER = r"-?\d+(?:\.\d+)?(?:e[+-]?\d+)?"
_MEASURE = re.compile(rf"(?:[<>]= )?{_NUMBER}(?: [+\-±] {_NUMBER})* (?P<unit>m|s|m/s|rad/s|waypoints)")
_COUNT_HEADERS = {
    "runs",
    "runs failed",
    "runs inconclusive",
    "runs passed",
    "runs not verified",
    "oracles",
    "from runs",
    "#",
    "cluster",
    "violations",
}
"""Columns of counts, whose header says what they count."""
_RANK = {"failed": 0, "inconclusive": 1, "passed": 2}
_RATE = {"pass rate": r"[01]\.\d\d", "95 % interval": r"\[[01]\.\d\d, [01]\.\d\d\]"}
"""Columns of pass rates (no unit: a fraction of runs), and the text each cell must be."""


def _cells(tables: list[dict[str, Any]]) -> Iterator[tuple[str, bool, str]]:
    """(column header, is a number cell, text) of every body cell of every table."""
    for table in tables:
        headers = table["headers"]
        for row in table["rows"]:
            for i, (tag, numeric, text) in enumerate(row["cells"]):
                header = headers[i] if headers else ""
                yield header, numeric and tag == "TD", text


def test_in_chromium_every_number_has_its_unit_failures_come_first_and_nothing_overflows(
    project: Path,
) -> None:
    pages = _pages(project)
    units_seen: set[str] = set()
    with _chromium() as browser:
        for width in (1280, 1024):
            page = browser.new_page(viewport={"width": width, "height": 900})
            for html in pages:
                page.goto(html.as_uri(), wait_until="load")
                where = f"{html.name} at {width} px"
                page_width, viewport = page.evaluate(
                    "[document.documentElement.scrollWidth, window.innerWidth]"
                )
                assert page_width <= viewport, f"{where}: the page is {page_width} px wide"
                boxes = page.evaluate(
                    "Array.from(document.querySelectorAll('.table-box')).map(b => [b.scrollWidth, b.clientWidth])"
                )
                assert all(scroll <= client for scroll, client in boxes), f"{where}: a table scrolls: {boxes}"
                tables = page.evaluate(_TABLES)
                assert all(t["boxed"] for t in tables), f"{where}: a table outside a scroll box"
                for header, numeric, text in _cells(tables):
                    if not numeric or not text:
                        continue
                    if header in _COUNT_HEADERS:
                        assert re.fullmatch(r"\d+", text), f"{where}: {header} {text!r} is not a count"
                        continue
                    if header in _RATE:
                        assert re.fullmatch(_RATE[header], text), f"{where}: {header} {text!r} is not a rate"
                        continue
                    found = _MEASURE.fullmatch(text)
                    assert found, f"{where}: {header} {text!r} has no unit"
                    units_seen.add(found["unit"])
                for table in tables:
                    if "pass rate" in table["headers"]:  # lowest first
                        at = table["headers"].index("pass rate")
                        rates = [float(r["cells"][at][2] or 2) for r in table["rows"]]  # none judged: last
                        assert rates == sorted(rates), f"{where}: pass rates not lowest first: {rates}"
                    if "outcome" in table["headers"]:
                        ranks = [_RANK[r["outcome"]] for r in table["rows"]]
                        assert ranks == sorted(ranks), f"{where}: verdicts not failures first: {ranks}"
                        if html.name == "scenario-scenario_c.html":  # its run that passed comes first
                            assert {0, 2} <= set(ranks), ranks
            page.close()
    assert {"m", "s", "m/s", "rad/s", "waypoints"} <= units_seen


def test_in_chromium_a_metamorphic_verdict_expects_what_the_cli_prints(project: Path) -> None:
    printed = (project / "verify-c_one.txt").read_text(encoding="utf-8").splitlines()
    header = re.split(r"\s{2,}", printed[0])
    cli = {}
    for line in printed[1:]:
        row = dict(zip(header, re.split(r"\s{2,}", line), strict=False))
        if row.get("relation") in ("increasing", "decreasing"):
            cli[(row["oracle"], row["relation"])] = row["expected"]
    assert len(cli) == 3 and all(" + " in e or " - " in e for e in cli.values()), cli
    with _chromium() as browser:
        page = browser.new_page(viewport={"width": 1280, "height": 900})
        page.goto((project / "out" / "scenario-c_one.html").as_uri(), wait_until="load")
        tables = page.evaluate(_TABLES)
    verdicts = next(t for t in tables if "outcome" in t["headers"])
    column = {name.split(" (")[0]: i for i, name in enumerate(verdicts["headers"])}
    shown = {}
    for row in verdicts["rows"]:
        cells = [text for _, _, text in row["cells"]]
        oracle = cells[column["oracle"]].splitlines()[0]
        shown[(oracle, cells[column["relation"]])] = cells[column["expected"]]
    unit = {"distance_travelled": "m", "task_duration": "s", "waypoints_visited": "waypoints"}
    for (oracle, relation), expected in cli.items():
        assert shown[(oracle, relation)] == f"{expected} {unit[oracle.split('-', 1)[1]]}"


def test_run_pages_show_the_hotspots_and_say_what_is_missing_without_a_map(project: Path) -> None:
    done = exscec_here("report", "-o", "plain", cwd=project)
    assert done.returncode == 0, done.stderr
    assert "note: no occupancy grid" in done.stderr
    index = (project / "plain" / "index.html").read_text(encoding="utf-8")
    assert "no occupancy grid" in index
    run_pages = [p.read_text(encoding="utf-8") for p in (project / "plain").glob("run-*.html")]
    with_table = [p for p in run_pages if ">violations</th>" in p]
    assert len(with_table) == 1 and "<td>max_velocity</td><td>tiago1</td>" in with_table[0]
    assert sum("No hotspots: no safety limit was broken." in p for p in run_pages) == 4
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
    done = exscec_here(
        "cluster", "--k", "2", "--dendrogram", "tree.png", "--dendrogram", "tree.svg", cwd=project
    )
    assert done.returncode == 0, done.stderr
    assert (project / "tree.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    svg = (project / "tree.svg").read_text(encoding="utf-8")
    assert svg.lstrip().startswith("<?xml") and "<!-- scenario_c -->" in svg and "<!-- c_one -->" in svg
    again = exscec_here("cluster", "--k", "2", "--dendrogram", "tree.svg", cwd=project)
    assert again.returncode == 0 and (project / "tree.svg").read_text(encoding="utf-8") == svg  # reproducible
    bad = exscec_here("cluster", "--dendrogram", "tree.pdf", cwd=project)
    assert bad.returncode == 2 and ".png or .svg" in bad.stderr


def test_every_metric_value_on_a_run_page_has_its_unit(project: Path) -> None:
    done = exscec_here("report", "-o", "units", cwd=project)  # no --spec: units from the store alone
    assert done.returncode == 0, done.stderr
    page = _failed_run_page(project).name
    text = (project / "units" / page).read_text(encoding="utf-8")
    table = text[text.index("<h2>Metric values</h2>") :]
    rows = re.findall(r'<tr><td>(\w+)[^<]*</td><td>\w+</td><td class="num">([^<]+)</td></tr>', table)
    units = {metric: value.split(" ", 1)[1] for metric, value in rows if " " in value}
    assert units["distance_travelled"] == "m" and units["max_velocity"] == "m/s"
    assert units["task_duration"] == "s" and units["waypoints_visited"] == "waypoints"
    assert units["mean_turn_rate"] == "rad/s" and units["fast_driving_time"] == "s"  # the spec's own metrics
    assert all(" " in value for _, value in rows) and len(rows) == table.count(
        "<tr><td>"
    )  # every row has one


def _verdict(run: str, oracle: str, outcome: Outcome) -> Verdict:
    return Verdict(run, "s", "", oracle, "max_velocity", "r1", "below_max", outcome, observed=1.0, limit=1.0)


def test_a_scenario_lists_its_runs_verdicts_failures_first_and_keeps_their_order_otherwise() -> None:
    first = StoredRun("a", "s", None, None, "a.bag", None)
    second = StoredRun("b", "s", None, None, "b.bag", None)
    p1, p2 = _verdict("a", "p1", Outcome.PASSED), _verdict("a", "p2", Outcome.PASSED)
    p3, f1 = _verdict("b", "p3", Outcome.PASSED), _verdict("b", "f1", Outcome.FAILED)
    u1, f2 = _verdict("b", "u1", Outcome.INCONCLUSIVE), _verdict("b", "f2", Outcome.FAILED)
    runs = (RunContents(first, (p1, p2), ()), RunContents(second, (p3, f1, u1, f2), ()))
    scenario = ScenarioContents("s", None, (), runs, (), (), {})
    assert [v.oracle for v in scenario.verdicts] == ["f1", "f2", "u1", "p1", "p2", "p3"]
    assert [v.oracle for v in failures_first((p3, f1, u1, f2))] == ["f1", "f2", "u1", "p3"]


def test_units_come_from_the_metrics_declarations_and_the_store() -> None:
    declared = load_spec(EXAMPLES / "brsu_building_c" / "scenario_c.exsce").scenario("scenario_c").metrics
    readings = [
        MetricReading("r", "distance_travelled", "r1", 12.0, unit="m"),
        MetricReading("r", "waypoints_visited", "r1", 3.0),
        MetricReading("r", "doors_opened", "r1", 2.0),  # declared nowhere, no unit stored: a count
        MetricReading("r", "battery_used", "r1", 0.2, unit="Wh"),  # a unit the language does not know
    ]
    units = metric_units(readings, declared)
    assert units["distance_travelled"] == "m" and units["max_velocity"] == "m/s"
    assert units["mission_duration"] == "s" and units["distance_between_robots"] == "m"
    assert units["waypoints_visited"] == "waypoints" and units["doors_opened"] == "(count)"
    assert units["mean_turn_rate"] == "rad/s" and units["fast_driving_time"] == "s"
    assert units["battery_used"] == "Wh"


# -- the run figure: hotspot numbers apart, axes fitted to what is drawn -------------------------


def _drawn(figure: Figure) -> tuple[Axes, RendererAgg]:
    """The figure drawn (laid out as the report saves it), its map axes and the renderer that drew them."""
    canvas = FigureCanvasAgg(figure)
    canvas.draw()
    return figure.axes[0], canvas.get_renderer()


def _label_boxes(axes: Axes, renderer: RendererAgg) -> list[Bbox]:
    """The hotspots' numbers and the segments' labels, as drawn (the text only, not its leader line)."""
    labels = [t for t in axes.texts if isinstance(t, Annotation)]
    for label in labels:
        label.update_positions(renderer)
    return [Text.get_window_extent(label, renderer) for label in labels]


def _assert_numbers_apart(
    axes: Axes, renderer: RendererAgg, spots: list[tuple[float, float]], segments: int = 0
) -> None:
    """No two labels overlap (the hotspots' numbers and the ``segments`` labels S1, S2...), none
    covers a hotspot, and all are inside the map."""
    boxes = _label_boxes(axes, renderer)
    assert len(boxes) == len(spots) + segments
    for a, b in itertools.combinations(boxes, 2):
        shared = max(0.0, min(a.x1, b.x1) - max(a.x0, b.x0)) * max(0.0, min(a.y1, b.y1) - max(a.y0, b.y0))
        assert shared < 0.5, f"numbers overlap: {a} and {b}"
    centres = axes.transData.transform(np.array(spots))
    frame = axes.get_window_extent()
    for box in boxes:
        assert not any(box.contains(x, y) for x, y in centres), "a number covers a hotspot"
        assert frame.x0 - 1 <= box.x0 and box.x1 <= frame.x1 + 1 and frame.y0 - 1 <= box.y0 <= frame.y1 + 1


def _assert_fitted(figure: Figure, axes: Axes, points: np.ndarray) -> None:
    """The axes hold every point, show at most the margin (and a little to fill the axes) around
    them, and fill the figure: no empty half beside the map."""
    (x0, y0), (x1, y1) = points.min(axis=0), points.max(axis=0)
    slack = 0.12 * max(x1 - x0, y1 - y0)
    (left, right), (bottom, top) = axes.get_xlim(), axes.get_ylim()
    assert left <= x0 and right >= x1 and bottom <= y0 and top >= y1
    for shown in (x0 - left, right - x1, y0 - bottom, top - y1):
        assert shown <= MARGIN + slack, (
            shown,
            axes.get_xlim(),
            axes.get_ylim(),
            points.min(0),
            points.max(0),
        )
    box, whole = axes.get_window_extent(), figure.bbox
    assert box.width >= 0.8 * whole.width and box.height >= 0.7 * whole.height, (box, whole)
    assert axes.get_aspect() == 1.0


def test_the_run_figure_numbers_hotspots_apart_and_fits_the_axes_to_the_paths(project: Path) -> None:
    with EmbeddedStore(project / ".exsce" / "store") as store:
        contents = gather(store, [project / "c" / "scenario_c.exsce"])
    scenario = contents.scenario("scenario_c")
    run = next(r for r in scenario.runs if r.status == "failed")
    assert run.run.path is not None and len(run.hotspots) >= 10
    paths = trajectories(Path(run.run.path))
    figure = trajectory_figure(scenario, run, paths)
    axes, renderer = _drawn(figure)
    spots = [(h.position.x, h.position.y) for h in run.hotspots]
    assert len(run.segments) == 6  # two robots, three segments each
    _assert_numbers_apart(axes, renderer, spots, segments=len(run.segments))
    planned = [(x, y) for path in scenario.waypoints.values() for _, x, y in path]
    _assert_fitted(figure, axes, np.vstack([*(p.xy for p in paths), np.array(planned), np.array(spots)]))


def test_a_crowd_of_hotspots_gets_numbers_that_do_not_overlap() -> None:
    """Thirty hotspots within a metre, on a long straight corridor (a wide figure) without a map,
    with a path segment starting among them (its label S2 must find room too)."""
    rng = np.random.default_rng(7)
    crowd = rng.uniform(0.0, 1.0, size=(30, 2)) + (20.0, 2.0)
    spots = tuple(
        Hotspot("max_velocity", Position(float(x), float(y)), 5, float(d), "r1")
        for (x, y), d in zip(crowd, rng.uniform(0.0, 3.0, 30), strict=True)
    )
    xy = np.column_stack([np.linspace(0.0, 40.0, 200), np.linspace(2.0, 3.0, 200)])
    starts = [("start", 0.0, 2.0), ("middle", 20.5, 2.5), ("late", 30.0, 2.75)]
    segments = tuple(
        RunSegment("r1", f"r1-task_01-subtask_001-w_00{i}", n, "end", x, y, ())
        for i, (n, x, y) in enumerate(starts, 1)
    )
    run = RunContents(
        StoredRun("0fcc1782-0c63-5500-b8af-3de8573bc05f", "s", None, None, None, None), (), spots, segments
    )
    scenario = ScenarioContents(
        "s", None, (), (run,), (), (), {"r1": (("start", 0.0, 2.0), ("end", 40.0, 3.0))}
    )
    figure = trajectory_figure(scenario, run, [Trajectory("/r1/robot_pose", np.linspace(0, 60, 200), xy)])
    axes, renderer = _drawn(figure)
    _assert_numbers_apart(axes, renderer, [(h.position.x, h.position.y) for h in spots], segments=3)
    # a corridor gets a wide figure, as wide as the corridor and the margin (its height has a minimum)
    assert axes.get_xlim() == pytest.approx((0.0 - MARGIN, 40.0 + MARGIN), abs=0.01)
    assert axes.get_window_extent().width >= 0.8 * figure.bbox.width
    assert figure.get_figwidth() > 1.5 * figure.get_figheight()  # the figure takes the corridor's shape
