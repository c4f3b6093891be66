"""Writing the report: static HTML pages, their images and a style sheet, in one folder.

The pages need no network and no script: images are files beside them, and
the style sheet is local.  Every text from the store goes through Jinja2's
HTML escaping; file names made from ids are checked (:func:`page_name`).
"""

from __future__ import annotations

import datetime
import hashlib
import re
import shutil
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import jinja2

from exsce_dsl import __version__
from exsce_dsl.errors import BagError, ExsceError
from exsce_dsl.figures import save_figure
from exsce_dsl.model.derivation import Derivation
from exsce_dsl.model.verdicts import Verdict
from exsce_dsl.oracles import expectation, interval, percent
from exsce_dsl.output_folder import written_whole
from exsce_dsl.report.contents import ReportContents, RunContents, ScenarioContents
from exsce_dsl.report.plots import campaign_figure, metrics_figure, trajectory_figure
from exsce_dsl.resources import resource_dir
from exsce_dsl.runs import Trajectory, trajectories
from exsce_dsl.similarity.dendrogram import dendrogram_figure
from exsce_dsl.wording import counted, noun

_SAFE = re.compile(r"[A-Za-z0-9_.-]+")


def page_name(kind: str, key: str) -> str:
    """``kind-key``, with ``key`` kept only if it is a safe file name; otherwise a digest of it."""
    if _SAFE.fullmatch(key) and not key.startswith("."):
        return f"{kind}-{key}"
    return f"{kind}-{hashlib.sha256(key.encode()).hexdigest()[:16]}"


@dataclass(frozen=True)
class RunImage:
    file: str | None
    """The image, relative to the report folder (None: nothing to draw)."""
    note: str = ""
    """Why the driven paths are missing, if they are."""


def _environment() -> jinja2.Environment:
    env = jinja2.Environment(
        loader=jinja2.FileSystemLoader(resource_dir("templates") / "report"),
        autoescape=True,
        undefined=jinja2.StrictUndefined,
        trim_blocks=True,
        lstrip_blocks=True,
    )
    env.filters["measure"] = _measure
    env.filters["expectation"] = _expectation
    env.filters["steps"] = _steps
    env.filters["counted"] = counted
    env.filters["noun"] = noun
    env.filters["percent"] = percent
    env.filters["interval"] = interval
    env.globals["scenario_page"] = lambda s: page_name("scenario", s) + ".html"
    env.globals["run_page"] = lambda r: page_name("run", r) + ".html"
    env.globals["campaign_page"] = lambda c: page_name("campaign", c) + ".html"
    return env


def _number(value: float | None) -> str:
    return "" if value is None else f"{value:.4g}"


def _measure(value: float | None, unit: str) -> str:
    """``1.418 m/s``: a value with its unit ('' for no value)."""
    if value is None:
        return ""
    return f"{_number(value)} {unit}" if unit else _number(value)


def _expectation(verdict: Verdict, unit: str) -> str:
    """What ``verdict`` expected, as ``exscec verify`` prints it, with the unit: ``50.5 + 59.8 ± 16.5 m``."""
    text = expectation(verdict)
    return f"{text} {unit}" if text and unit else text


def _steps(derivation: Derivation) -> str:
    """``remove_robot(robot=tiago2, reassign=tiago1), reverse_waypoints(task=delivery_b)``."""
    return ", ".join(
        f"{s.transformation}({', '.join(f'{k}={v}' for k, v in s.parameters)})" for s in derivation.steps
    )


def write_report(
    contents: ReportContents, folder: Path, progress: Callable[[int], None] | None = None
) -> Path:
    """Write the report into ``folder`` and return its index page.

    The report is written into a new hidden folder first and renamed into ``folder`` when
    complete: a report that fails half-way leaves an earlier one as it was, and a link
    planted in ``folder`` is replaced, not written through.
    ``progress`` is told of every run drawn (bags are read for the paths driven).
    """
    with written_whole(folder) as staging:
        _write_pages(contents, staging, progress)
    return folder / "index.html"


def _write_pages(contents: ReportContents, folder: Path, progress: Callable[[int], None] | None) -> None:
    """Every page and image of the report, into ``folder`` (new and empty)."""
    images = folder / "images"
    images.mkdir()
    env = _environment()
    generated = datetime.datetime.now(datetime.timezone.utc).replace(microsecond=0)
    common = {"contents": contents, "version": __version__, "generated": generated.isoformat()}
    shutil.copyfile(resource_dir("templates") / "report" / "style.css", folder / "style.css")
    dendrogram = None
    if contents.clustering is not None:
        figure = dendrogram_figure(contents.clustering)
        dendrogram = "images/dendrogram.svg"
        save_figure(figure, folder / dendrogram)
        save_figure(figure, folder / "images" / "dendrogram.png")
    _write(env, "index.html.j2", folder / "index.html", dendrogram=dendrogram, **common)
    for campaign in contents.campaigns:
        chart = f"images/{page_name('campaign', campaign.id)}.svg"
        save_figure(campaign_figure(campaign), folder / chart)
        page = folder / f"{page_name('campaign', campaign.id)}.html"
        _write(env, "campaign.html.j2", page, campaign=campaign, chart=chart, **common)
    for scenario in contents.scenarios:
        metrics_image = None
        metrics = metrics_figure(scenario, contents.units)
        if metrics is not None:
            metrics_image = f"images/{page_name('metrics', scenario.id)}.svg"
            save_figure(metrics, folder / metrics_image)
        page = folder / f"{page_name('scenario', scenario.id)}.html"
        _write(env, "scenario.html.j2", page, scenario=scenario, metrics_image=metrics_image, **common)
        for run in scenario.runs:
            image = _run_image(scenario, run, folder)
            _write(
                env,
                "run.html.j2",
                folder / f"{page_name('run', run.run.uuid)}.html",
                scenario=scenario,
                run=run,
                image=image,
                **common,
            )
            if progress is not None:
                progress(1)


def _run_image(scenario: ScenarioContents, run: RunContents, folder: Path) -> RunImage:
    paths: list[Trajectory] = []
    note = ""
    if run.run.path is None:
        note = "the store does not say where the bag was: only the plan and hotspots are drawn"
    else:
        try:
            paths = trajectories(Path(run.run.path))
        except BagError as exc:
            note = f"paths not drawn: {exc.message}"
    if not paths and not run.hotspots and not any(scenario.waypoints.values()):
        return RunImage(None, note or "nothing to draw: no poses in the bag, no plan, no hotspots")
    file = f"images/{page_name('run', run.run.uuid)}.png"
    save_figure(trajectory_figure(scenario, run, paths), folder / file)
    return RunImage(file, note)


def _write(env: jinja2.Environment, template: str, path: Path, **values: object) -> None:
    try:
        path.write_text(env.get_template(template).render(**values), encoding="utf-8")
    except OSError as exc:
        raise ExsceError(f"cannot write {path}: {exc.strerror}") from None
