"""Issue 46, item 9: a topic containing ``$x^^$`` stopped ``exscec report`` (matplotlib read it as
mathtext, exit 70) and left a half-written report; ``-o`` followed links planted in the folder.

Reports here are made from contents built by hand (no store, no bag): cheap, and the texts are
the hostile ones."""

from __future__ import annotations

import functools
import tempfile
import xml.etree.ElementTree as ET
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from matplotlib.figure import Figure

from exsce_dsl.figures import save_figure
from exsce_dsl.model.campaign import CampaignPlan, CampaignRecord, CampaignTrial, CheckedRelation
from exsce_dsl.model.geometry import Position
from exsce_dsl.model.runs import Hotspot
from exsce_dsl.model.verdicts import Outcome, Verdict
from exsce_dsl.report import html
from exsce_dsl.report.campaigns import campaign_contents
from exsce_dsl.report.contents import ReportContents, RunContents, ScenarioContents
from exsce_dsl.report.html import page_name, write_report
from exsce_dsl.report.plots import campaign_figure, trajectory_figure
from exsce_dsl.runs.signals.trajectories import Trajectory
from exsce_dsl.store.queries import MetricReading, StoredRun

from tests.support.cli import exscec_here
from tests.support.hostile_specs import HOSTILE

MATH = "$x^^$"
UUID = "0fcc1782-0c63-5500-b8af-3de8573bc05f"


def _contents(name: str = MATH) -> ReportContents:
    """One scenario with one run, whose ids, robot, metric and hotspot all hold ``name``."""
    run = StoredRun(UUID, f"s{name}", None, None, "a.bag", None)
    verdict = Verdict(
        UUID,
        run.scenario,
        "o",
        "c",
        f"m{name}",
        f"r{name}",
        "below_max",
        Outcome.FAILED,
        observed=2.0,
        limit=1.0,
    )
    spot = Hotspot(f"m{name}", Position(1.0, 2.0), 3, 1.5, f"r{name}")
    values = (MetricReading(UUID, f"m{name}", f"r{name}", 2.0, safety=f"k{name}"),)
    waypoints = {f"r{name}": ((f"p{name}", 0.0, 0.0), ("q", 3.0, 1.0))}
    scenario = ScenarioContents(
        run.scenario, None, (), (RunContents(run, (verdict,), (spot,)),), (), values, waypoints
    )
    return ReportContents((scenario,), (verdict,), None)


def _texts(figure: Figure) -> list[str]:
    return [t.get_text() for t in figure.findobj(lambda a: hasattr(a, "get_text"))]


def test_report_topic_with_mathtext_chars(tmp_path: Path) -> None:
    scenario = _contents().scenarios[0]
    path = Trajectory(f"/{MATH}/odom", np.array([0.0, 1.0]), np.array([[0.0, 0.0], [2.0, 1.0]]))
    figure = trajectory_figure(scenario, scenario.runs[0], [path])
    save_figure(figure, tmp_path / "run.svg")  # matplotlib raised a ValueError here
    legend = [t for t in _texts(figure) if "odom" in t]
    assert legend and all(not t.startswith("$") for t in legend)
    index = write_report(_contents(), tmp_path / "report")
    assert index.is_file()
    page = (tmp_path / "report" / f"{page_name('run', UUID)}.html").read_text(encoding="utf-8")
    assert "$x^^$" in page  # the HTML shows the text as it is


def test_report_folder_written_whole(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    folder = tmp_path / "report"
    write_report(_contents("plain"), folder)
    before = {p.relative_to(folder): p.read_bytes() for p in folder.rglob("*") if p.is_file()}
    assert Path("index.html") in before

    def broken(*_: object) -> Figure:
        raise RuntimeError("drawing failed half-way")

    monkeypatch.setattr(html, "trajectory_figure", broken)
    with pytest.raises(RuntimeError, match="half-way"):
        write_report(_contents(), folder)
    after = {p.relative_to(folder): p.read_bytes() for p in folder.rglob("*") if p.is_file()}
    assert after == before  # the earlier report, as it was
    assert sorted(p.name for p in tmp_path.iterdir()) == ["report"]  # no partial folder beside it
    assert not [p for p in folder.iterdir() if p.name.startswith(".")]  # nor inside it


def test_a_new_report_folder_appears_only_complete(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    def broken(*_: object) -> Figure:
        raise RuntimeError("drawing failed half-way")

    monkeypatch.setattr(html, "trajectory_figure", broken)
    with pytest.raises(RuntimeError):
        write_report(_contents(), tmp_path / "new" / "report")
    assert list((tmp_path / "new").iterdir()) == []


def test_report_output_refuses_planted_symlink(tmp_path: Path) -> None:
    """A link planted where the report writes a page or its images is replaced, never written
    through; files of the folder that are not the report's stay."""
    folder = tmp_path / "report"
    folder.mkdir()
    outside = tmp_path / "outside.html"
    outside.write_text("mine\n")
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    (folder / "index.html").symlink_to(outside)
    (folder / "images").symlink_to(elsewhere, target_is_directory=True)
    (folder / "notes.txt").write_text("kept\n")
    done = exscec_here("report", "-o", str(folder), cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert outside.read_text() == "mine\n" and list(elsewhere.iterdir()) == []
    assert not (folder / "index.html").is_symlink() and "<html" in (folder / "index.html").read_text()
    assert (folder / "images").is_dir() and not (folder / "images").is_symlink()
    assert (folder / "notes.txt").read_text() == "kept\n"


class _Tags(HTMLParser):
    """The start tags of a page, with their attributes' names."""

    def __init__(self) -> None:
        super().__init__()
        self.tags: list[tuple[str, tuple[str, ...]]] = []

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        self.tags.append((tag, tuple(name for name, _ in attrs)))


def _page_tags(folder: Path) -> dict[str, list[tuple[str, tuple[str, ...]]]]:
    """Each page's tags, pages named by kind (run, scenario, index): their names hold ids."""
    found = {}
    for page in folder.glob("*.html"):
        parser = _Tags()
        parser.feed(page.read_text(encoding="utf-8"))
        found[page.name.split("-", 1)[0]] = parser.tags
    return found


@functools.cache
def _plain_tags() -> dict[str, list[tuple[str, tuple[str, ...]]]]:
    with tempfile.TemporaryDirectory() as folder:
        return _page_tags(write_report(_contents("plain"), Path(folder) / "plain").parent)


@pytest.mark.filterwarnings("ignore:Glyph .* missing from font")
@settings(max_examples=10, deadline=None)
@given(name=HOSTILE)
def test_hostile_text_in_the_report_stays_text(name: str) -> None:
    """Every page has the tags and attributes of a report of harmless names, and every image
    is drawn (each SVG parses): the text never becomes markup nor mathtext."""
    with tempfile.TemporaryDirectory() as folder:
        write_report(_contents(name), Path(folder) / "hostile")
        assert _page_tags(Path(folder) / "hostile") == _plain_tags()
        for image in (Path(folder) / "hostile" / "images").glob("*.svg"):
            ET.parse(image)


def test_a_campaigns_relations_with_mathtext_chars_are_drawn_one_per_line(tmp_path: Path) -> None:
    plan = CampaignPlan("c", "s", 2, 1, 1, 1, (), "walk", "kinematic", False, 5.0)
    violated = (
        CheckedRelation("task_duration", f"r{MATH}", "increasing"),
        CheckedRelation("distance_travelled", "r1", "invariant"),
    )
    trial = CampaignTrial("c", 1, "s_1", (), ("run",), violated, violated)
    figure = campaign_figure(campaign_contents(CampaignRecord(plan, None, (trial,), ())))
    save_figure(figure, tmp_path / "campaign.svg")
    (label,) = [t for t in _texts(figure) if "task_duration" in t]
    assert len(label.split("\n")) == 2 and "\\$" in label
