"""exscec report: a page per exploration campaign, linked from the overview.

The campaign goes into a real store through the real write path (compile_campaign,
compile_trial, compile_shrinking, add_prov), beside scenario_c and the one derived scenario of
the campaign the store holds, and the report is gathered from that store.
"""

from __future__ import annotations

import datetime
import re
from html.parser import HTMLParser
from pathlib import Path

import pytest
from test_report import ARTIFACTS, _chromium

from exsce_dsl.lang import load_spec
from exsce_dsl.model.campaign import CampaignPlan, CampaignRecord, CampaignTrial
from exsce_dsl.prov import compile_scenario
from exsce_dsl.prov.campaign import compile_campaign, compile_shrinking, compile_trial
from exsce_dsl.prov.derivation import compile_derivation
from exsce_dsl.report.campaigns import campaign_contents
from exsce_dsl.report.contents import ReportContents, gather
from exsce_dsl.report.html import write_report
from exsce_dsl.report.plots import campaign_figure
from exsce_dsl.store.open import open_store
from exsce_dsl.store.writing import add_prov
from exsce_dsl.transform.derivation import derive

from tests.support.campaign_samples import DISTANCE, DURATION, REMOVE, SHRINKINGS, sample_trials
from tests.support.paths import EXAMPLES

SPEC = EXAMPLES / "brsu_building_c" / "scenario_c.exsce"
PLAN = CampaignPlan(
    "c_explore",
    "scenario_c",
    12,
    7,
    3,
    2,
    ("remove_robot", "reverse_waypoint_order"),
    "simulator --fault slow-area:classroom_c069",
    "random",
    True,
    10.0,
)
TRIALS = sample_trials((("r1", "r2", "r3"), ("r4", "r5", "r6"), ("r7", "r8", "r9")))
STEPS_OF_3 = "reverse_waypoint_order(task=delivery_a) → remove_robot(robot=tiago2, reassign=tiago1)"


@pytest.fixture(scope="module")
def report(tmp_path_factory: pytest.TempPathFactory) -> tuple[Path, ReportContents]:
    """The report of a store holding scenario_c, c_explore_0001 (trial 1's scenario) and the campaign."""
    folder = tmp_path_factory.mktemp("campaign-report")
    base = load_spec(SPEC).scenario("scenario_c")
    derived = derive(base, [REMOVE], "c_explore_0001")
    with open_store("memory:") as store:
        for document in (
            compile_scenario(base),
            compile_scenario(derived.scenario),
            compile_derivation(derived.derivation),
            compile_campaign(PLAN, datetime.datetime(2025, 3, 1, 12, 0, tzinfo=datetime.timezone.utc)),
            *(compile_trial(t) for t in TRIALS),
            *(compile_shrinking(s) for s in SHRINKINGS),
        ):
            add_prov(store, document)
        contents = gather(store, [SPEC])
    write_report(contents, folder / "out")
    return folder / "out", contents


class _Tables(HTMLParser):
    """Every table's body rows: a row's id and class, and each cell's text and links."""

    def __init__(self) -> None:
        super().__init__()
        self.tables: dict[str, list[dict[str, object]]] = {}
        self._table: list[dict[str, object]] | None = None
        self._row: dict[str, object] | None = None
        self._cell: list[str] | None = None
        self._in_body = False

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        given = dict(attrs)
        if tag == "table":
            self._table = self.tables.setdefault(given.get("class") or "", [])
        elif tag == "tbody":
            self._in_body = True
        elif tag == "tr" and self._in_body and self._table is not None:
            self._row = {"id": given.get("id"), "class": given.get("class"), "cells": [], "links": []}
            self._table.append(self._row)
        elif tag in ("td", "th") and self._row is not None:
            self._cell = []
        elif tag == "a" and self._row is not None:
            links = self._row["links"]
            assert isinstance(links, list)
            links.append(given.get("href"))

    def handle_endtag(self, tag: str) -> None:
        if tag in ("td", "th") and self._row is not None and self._cell is not None:
            cells = self._row["cells"]
            assert isinstance(cells, list)
            cells.append(" ".join("".join(self._cell).split()))
            self._cell = None
        elif tag == "tr":
            self._row = None
        elif tag == "tbody":
            self._in_body = False

    def handle_data(self, data: str) -> None:
        if self._cell is not None:
            self._cell.append(data)


def _tables(page: Path) -> dict[str, list[dict[str, object]]]:
    parser = _Tables()
    parser.feed(page.read_text(encoding="utf-8"))
    return parser.tables


def test_the_store_gives_each_campaign_its_trials_and_shrinkings(report: tuple[Path, ReportContents]) -> None:
    _, contents = report
    (campaign,) = contents.campaigns
    assert campaign.plan == PLAN and campaign.started is not None
    assert [t.number for t in campaign.trials] == [1, 2, 3, 4]
    assert campaign.found == (1, 1, 2, 2)  # distinct relations violated after each trial
    assert [t.new for t in campaign.trials] == [(DURATION.text,), (), (DISTANCE.text,), ()]
    assert campaign.checked == 2 and campaign.violated == 2 and campaign.violated_trials == 2
    assert [s.relation for s in campaign.shrinkings] == [DURATION.text, DISTANCE.text]
    assert [len(s.tries) for s in campaign.shrinkings] == [1, 2]
    assert campaign.shrinkings[1].original_steps == 2 and campaign.shrinkings[1].steps == 1


def test_the_overview_lists_the_campaign_and_links_its_page(report: tuple[Path, ReportContents]) -> None:
    out, _ = report
    index = (out / "index.html").read_text(encoding="utf-8")
    assert (
        '<a href="index.html#campaigns">Campaigns</a>' in index
        and '<h2 id="campaigns">Campaigns</h2>' in index
    )
    (row,) = _tables(out / "index.html")["campaigns"]
    # campaign, base, derivations tried of budget, runs per scenario, relations checked, violated, minimal
    assert row["cells"] == ["c_explore", "scenario_c", "4 of 12", "3", "2", "2", "2"]
    assert row["links"] == ["campaign-c_explore.html", "scenario-scenario_c.html"]
    assert (out / "campaign-c_explore.html").is_file()


def test_the_page_shows_the_plan_with_units(report: tuple[Path, ReportContents]) -> None:
    out, _ = report
    rows = _tables(out / "campaign-c_explore.html")["plan"]
    plan = {r["cells"][0]: r["cells"][1] for r in rows[:10]}  # type: ignore[index]
    assert plan == {
        "base scenario": "scenario_c",
        "seed": "7",
        "budget": "12 derivations",
        "runs per scenario": "3 runs",
        "max steps": "2 steps per derivation",
        "transformations": "remove_robot, reverse_waypoint_order",
        "executor": "simulator --fault slow-area:classroom_c069",
        "strategy": "random",
        "checked against": "their metamorphic relations",
        "tolerance": "10 % of an expected value",
    }


def test_the_page_has_a_row_per_trial_linking_the_scenarios_the_report_has(
    report: tuple[Path, ReportContents],
) -> None:
    out, _ = report
    rows = _tables(out / "campaign-c_explore.html")["trials"]
    assert [r["cells"] for r in rows] == [
        [
            "1",
            "c_explore_0001",
            "remove_robot(robot=tiago2, reassign=tiago1)",
            "3",
            "2",
            DURATION.text,
            "violated",
        ],
        ["2", "c_explore_0002", "reverse_waypoint_order(task=delivery_a)", "3", "2", "", "passed"],
        ["3", "c_explore_0003", STEPS_OF_3, "3", "2", f"{DURATION.text}{DISTANCE.text}", "violated"],
        ["4", "c_explore_0004", "reverse_waypoint_order(task=delivery_a)", "0", "0", "", "unchecked"],
    ]
    assert [r["id"] for r in rows] == ["trial-1", "trial-2", "trial-3", "trial-4"]
    assert [r["class"] for r in rows] == ["violated", "passed", "violated", "unchecked"]
    # only c_explore_0001 is in the store, so only it has a page to link to
    assert [r["links"] for r in rows] == [["scenario-c_explore_0001.html"], [], [], []]
    assert (out / "scenario-c_explore_0001.html").is_file()
    page = (out / "campaign-c_explore.html").read_text(encoding="utf-8")
    assert f"<strong>{DISTANCE.text}</strong>" in page  # found first in trial 3, in bold there


def test_each_minimal_failing_derivation_has_a_block_with_its_tries(
    report: tuple[Path, ReportContents],
) -> None:
    out, _ = report
    page = (out / "campaign-c_explore.html").read_text(encoding="utf-8")
    blocks = re.findall(r'<section class="shrinking" id="shrinking-(\d+)">(.*?)</section>', page, re.S)
    assert [number for number, _ in blocks] == ["1", "2"]
    second = blocks[1][1]
    assert f"<h3>{DISTANCE.text}</h3>" in second
    assert '<a href="#trial-3">trial 3</a>' in second and "(2 steps)" in second
    assert "c_explore_s2_1" in second and "remove_robot(robot=tiago2, reassign=tiago1)</span>" in second
    assert "2 smaller derivations tried" in second
    tries = _tables(out / "campaign-c_explore.html")["tries"]
    assert [r["cells"] for r in tries] == [
        ["1", "scenario_c", "base scenario", "no"],
        ["1", "c_explore_s2_1", "remove_robot(robot=tiago2, reassign=tiago1)", "yes"],
        ["2", "c_explore_s2_2", "reverse_waypoint_order(task=delivery_a)", "no"],
    ]
    assert "(no smaller derivation violates it)" in blocks[0][1]  # trial 1's one step was already minimal


def test_the_chart_steps_up_once_per_trial_that_found_a_relation(report: tuple[Path, ReportContents]) -> None:
    out, contents = report
    page = (out / "campaign-c_explore.html").read_text(encoding="utf-8")
    assert '<img src="images/campaign-c_explore.svg"' in page
    svg = (out / "images" / "campaign-c_explore.svg").read_text(encoding="utf-8")
    assert svg.lstrip().startswith("<?xml") and '<g id="found-over-trials">' in svg
    assert re.findall(r'<g id="found-(\d+)">', svg) == ["1", "2"]  # trials 1 and 3 each found one
    assert "violations found over budget" in svg and "budget: 12 derivations" in svg
    figure = campaign_figure(contents.campaigns[0])
    (axes,) = figure.axes
    line = next(line for line in axes.lines if line.get_gid() == "found-over-trials")
    assert list(line.get_xdata()) == [0, 1, 2, 3, 4] and list(line.get_ydata()) == [0, 1, 1, 2, 2]
    assert line.get_drawstyle() == "steps-post"
    assert axes.get_xlabel() == "derivations tried (count)" and "(distinct, count)" in axes.get_ylabel()


def test_text_from_a_campaign_is_escaped(tmp_path: Path) -> None:
    nasty = '<script>alert("x")</script>'
    plan = CampaignPlan("c_nasty", "s", 2, 1, 1, 1, (), nasty, nasty, False, 5.0)
    trial = CampaignTrial("c_nasty", 1, "s_1", (("remove_robot", {"robot": nasty}),), ("r",), (), ())
    contents = ReportContents(
        (), (), None, campaigns=(campaign_contents(CampaignRecord(plan, None, (trial,), ())),)
    )
    write_report(contents, tmp_path)
    for page in ("index.html", "campaign-c_nasty.html"):
        assert "<script" not in (tmp_path / page).read_text(encoding="utf-8"), page
    page = (tmp_path / "campaign-c_nasty.html").read_text(encoding="utf-8")
    assert (
        "remove_robot(robot=&lt;script&gt;" in page and "the base scenario&#39;s safety limits only" in page
    )
    assert "No relation was violated." in page


def test_in_chromium_the_campaign_page_shows_its_chart_and_fits_the_window(
    report: tuple[Path, ReportContents],
) -> None:
    out, _ = report
    ARTIFACTS.mkdir(parents=True, exist_ok=True)
    problems: list[str] = []
    with _chromium() as browser:
        for width in (1280, 1024):
            page = browser.new_page(viewport={"width": width, "height": 900})
            page.on("console", lambda m: problems.append(m.text) if m.type in ("error", "warning") else None)
            page.on("requestfailed", lambda r: problems.append(f"failed to load {r.url}"))
            for name in ("index.html", "campaign-c_explore.html"):
                page.goto((out / name).as_uri(), wait_until="load")
                images = page.evaluate(
                    "Array.from(document.images).map(i => [i.getAttribute('src'), i.complete, i.naturalWidth])"
                )
                assert all(complete and w > 0 for _, complete, w in images), (name, images)
                scroll, inner = page.evaluate("[document.documentElement.scrollWidth, window.innerWidth]")
                assert scroll <= inner, f"{name} at {width} px is {scroll} px wide"
                boxes = page.evaluate(
                    "Array.from(document.querySelectorAll('.table-box')).map(b => [b.scrollWidth, b.clientWidth])"
                )
                assert all(s <= c for s, c in boxes), f"{name} at {width} px: a table scrolls: {boxes}"
                if name.startswith("campaign") and width == 1280:
                    assert [src for src, _, _ in images] == ["images/campaign-c_explore.svg"]
                    page.screenshot(path=str(ARTIFACTS / "report-campaign.png"), full_page=True)
            page.close()
    assert not problems, problems
    assert (ARTIFACTS / "report-campaign.png").stat().st_size > 10_000
