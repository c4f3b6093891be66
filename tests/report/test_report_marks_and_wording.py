"""exscec report on a store of one scenario and one run: the path segments marked where they start
(on the figure and in the run page's table, at the start poses the store's actions name), the
no-map message that says why there is no map (no --spec, or a scenario without one), and counts
that agree with their nouns ("1 run", never "1 runs")."""

from __future__ import annotations

import re
import shutil
from html.parser import HTMLParser
from pathlib import Path

import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg

from exsce_dsl.lang import load_spec
from exsce_dsl.report.contents import gather
from exsce_dsl.report.plots import trajectory_figure
from exsce_dsl.runs.signals.trajectories import trajectories
from exsce_dsl.sim.run import simulate
from exsce_dsl.store.embedded import EmbeddedStore
from exsce_dsl.wording import counted, noun

from tests.support.cli import exscec_here
from tests.support.paths import EXAMPLES

_HEADING = re.compile(r"-R[-0-9.]+_P[-0-9.]+_Y[-0-9.]+$")
_PLURALS = r"scenarios|runs|robots|oracles|segments|hotspots|verdicts|steps|derivations|clusters|relations"


@pytest.fixture(scope="module")
def project(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """One run of scenario_c ingested; its report with the spec (``out``), without any spec
    (``plain``) and with a copy of the spec whose environment names no map file (``nomap``)."""
    folder = tmp_path_factory.mktemp("one-run")
    shutil.copytree(EXAMPLES / "brsu_building_c", folder / "c")
    shutil.copytree(EXAMPLES / "brsu_building_c", folder / "nomap")
    environment = folder / "nomap" / "environment.exsce"
    text = environment.read_text(encoding="utf-8")
    without = text.replace(' file "maps/brsu_building_c_with_doorways.yaml"', "")
    assert without != text
    environment.write_text(without, encoding="utf-8")
    scenario = load_spec(folder / "c" / "scenario_c.exsce").scenario("scenario_c")
    [run] = simulate(scenario, folder / "runs", 1, seed=4)
    done = exscec_here("ingest", str(run.bag), "--scenario", "c/scenario_c.exsce", cwd=folder)
    assert done.returncode == 0, done.stderr
    for output, specs in (("out", ["c/scenario_c.exsce"]), ("plain", []), ("nomap", ["nomap/scenario_c.exsce"])):
        made = exscec_here("report", "-o", output, *[a for s in specs for a in ("--spec", s)], cwd=folder)
        assert made.returncode == 0, made.stderr
        (folder / f"{output}.stderr").write_text(made.stderr, encoding="utf-8")
    return folder


def _run_page(project: Path, output: str) -> str:
    [page] = (project / output).glob("run-*.html")
    return page.read_text(encoding="utf-8")


def _stored_starts(project: Path) -> dict[str, str]:
    """Action id → the name of the pose it started from, read from the run's own PROV in the store."""
    with EmbeddedStore(project / ".exsce" / "store") as store:
        rows = store.select(
            "SELECT ?action ?start WHERE { GRAPH ?g { "
            "?action a <https://www.sesame-project.org/scenarios/action> ; "
            "<http://www.w3.org/ns/prov#wasStartedBy> ?start } }"
        )
    return {a.value.rsplit("/", 1)[-1]: s.value.rsplit("/", 1)[-1] for a, s in rows.rows}


def _positions(project: Path) -> dict[str, tuple[float, float]]:
    """Pose id → x, y, as the specification declares them."""
    environment = load_spec(project / "c" / "scenario_c.exsce").scenario("scenario_c").environment
    return {p.id: (p.position.x, p.position.y) for p in environment.poses()}


class _SegmentRows(HTMLParser):
    """The rows of the run page's table of path segments: label, action, start pose, x and y."""

    def __init__(self) -> None:
        super().__init__()
        self.rows: list[list[str]] = []
        self.where: list[tuple[float, float]] = []
        self._in_table = False
        self._cell: list[str] | None = None

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        found = dict(attrs)
        if tag == "table" and found.get("class") == "segments":
            self._in_table = True
        elif self._in_table and tag == "tr" and "data-x" in found:
            self.rows.append([])
            self.where.append((float(found["data-x"] or "nan"), float(found["data-y"] or "nan")))
        elif self._in_table and tag == "td":
            self._cell = []

    def handle_data(self, data: str) -> None:
        if self._cell is not None:
            self._cell.append(data)

    def handle_endtag(self, tag: str) -> None:
        if tag == "td" and self._cell is not None:
            self.rows[-1].append("".join(self._cell).strip())
            self._cell = None
        elif tag == "table":
            self._in_table = False


def test_segment_boundaries_are_marked_on_paths(project: Path) -> None:
    stored = _stored_starts(project)
    declared = _positions(project)
    assert len(stored) == 6  # scenario_c: two robots, three waypoints each after its start pose
    table = _SegmentRows()
    table.feed(_run_page(project, "out"))
    assert [row[0] for row in table.rows] == [f"S{i}" for i in range(1, len(stored) + 1)]
    assert {row[2]: row[3] for row in table.rows} == stored  # one row per action, at its start pose
    for row, (x, y) in zip(table.rows, table.where, strict=True):
        px, py = declared[_HEADING.sub("", row[3])]
        assert (x, y) == pytest.approx((px, py), abs=1e-6)
        assert row[4] == f"{px:.4g} m" and row[5] == f"{py:.4g} m"  # shown with their unit
        assert re.fullmatch(r"\d+(\.\d+)? m", row[7]) and re.fullmatch(r"\d+(\.\d+)? s", row[8]), row
    # the figure: a ring at each segment's start pose, labelled as in the table
    with EmbeddedStore(project / ".exsce" / "store") as store:
        contents = gather(store, [project / "c" / "scenario_c.exsce"])
    scenario = contents.scenario("scenario_c")
    [run] = scenario.runs
    assert run.run.path is not None
    figure = trajectory_figure(scenario, run, trajectories(Path(run.run.path)))
    FigureCanvasAgg(figure).draw()
    [axes] = figure.axes
    marks = {c.get_gid(): c.get_offsets()[0] for c in axes.collections if str(c.get_gid()).startswith("segment")}
    assert sorted(marks) == sorted(f"segment-start-{i}" for i in range(1, len(stored) + 1))
    for i, (x, y) in enumerate(table.where, start=1):
        assert tuple(marks[f"segment-start-{i}"]) == pytest.approx((x, y))
    labels = {t.get_text(): t.xy for t in axes.texts if t.get_text().startswith("S")}
    assert set(labels) == {f"S{i}" for i in range(1, len(stored) + 1)}  # each ring has its label
    legend = [t.get_text() for legend in figure.legends for t in legend.get_texts()]
    assert any(text.startswith("segment start") for text in legend), legend


def test_the_report_says_no_spec_was_given_when_none_was(project: Path) -> None:
    page = _run_page(project, "plain")
    assert "no <code>--spec</code> was given: pass the scenario's file to <code>exscec report --spec" in page
    assert "has no map" not in page
    assert "note: no occupancy grid: no --spec was given" in (project / "plain.stderr").read_text("utf-8")


def test_the_report_says_the_scenario_has_no_map_when_spec_was_given(project: Path) -> None:
    page = _run_page(project, "nomap")
    assert 'scenario <span class="id">scenario_c</span> has no map' in page
    assert 'environment <span class="id">brsu_building_c_with_doors</span> names no map file' in page
    assert "was given" not in page and "pass the scenario's file" not in page
    with_map = _run_page(project, "out")
    assert "No occupancy grid" not in with_map


def test_one_scenario_is_not_plural(project: Path) -> None:
    assert "(1 scenario, 1 run)" in (project / "out.stderr").read_text(encoding="utf-8")
    for page in sorted((project / "out").glob("*.html")):
        text = re.sub(r"\s+", " ", re.sub(r"<[^>]+>", " ", page.read_text(encoding="utf-8")))
        wrong = re.findall(rf"\b1 (?:{_PLURALS})\b", text)
        assert not wrong, f"{page.name}: {wrong}"
    index = (project / "out" / "index.html").read_text(encoding="utf-8")
    assert re.search(r'<div class="big">1</div>scenario</div>', index)
    assert re.search(r'<div class="big">1</div>run</div>', index)
    assert re.search(r'<div class="big">0</div>runs failed</div>', index)


def test_counted_nouns_agree_with_their_number() -> None:
    assert [counted(n, "run") for n in (0, 1, 2)] == ["0 runs", "1 run", "2 runs"]
    assert counted(1, "hotspot") == "1 hotspot" and counted(3, "match") == "3 matches"
    assert noun("smaller derivation", 2) == "smaller derivations" and noun("analysis", 2) == "analyses"
