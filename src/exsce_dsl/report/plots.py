"""The report's figures: a run's paths over its occupancy grid, and metric values against their oracles."""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from matplotlib.figure import Figure

from exsce_dsl.lang.occupancy import OccupancyGrid
from exsce_dsl.model.oracles import Oracle
from exsce_dsl.report.contents import RunContents, ScenarioContents
from exsce_dsl.runs.trajectories import Trajectory
from exsce_dsl.store.queries import MetricReading

_MARGIN = 2.5  # metres of map shown around what is drawn
_STATUS_COLOURS = {"failed": "#c0392b", "unjudged": "#d68910", "passed": "#1e8449", "not verified": "#5d6d7e"}


def trajectory_figure(
    scenario: ScenarioContents, run: RunContents, paths: Sequence[Trajectory]
) -> Figure:
    """Each robot's path in ``run`` over the scenario's grid, its planned waypoints, and the hotspots."""
    figure = Figure(figsize=(7.5, 6.0), layout="constrained")
    axes = figure.add_subplot()
    points = [p.xy for p in paths]
    points += [np.array([(x, y) for _, x, y in path]) for path in scenario.waypoints.values() if path]
    points += [np.array([(h.position.x, h.position.y) for h in run.hotspots])] if run.hotspots else []
    box = _bounding_box(points)
    if scenario.grid is not None:
        _draw_grid(axes, scenario.grid, box)
    colours = [f"C{i}" for i in range(10)]
    for i, path in enumerate(paths):
        colour = colours[i % len(colours)]
        axes.plot(path.xy[:, 0], path.xy[:, 1], color=colour, linewidth=1.4, label=f"{path.topic} (driven)")
        axes.plot(*path.xy[0], marker="o", color=colour, markersize=6)
    for i, (_, planned) in enumerate(sorted(scenario.waypoints.items())):
        if not planned:
            continue
        xy = np.array([(x, y) for _, x, y in planned])
        axes.scatter(xy[1:, 0], xy[1:, 1], marker="s", s=18, color="#34495e", zorder=3,
                     label="planned waypoints" if i == 0 else None)
    markers = dict(zip(sorted({h.metric for h in run.hotspots}), "XDP^v*", strict=False))
    labelled: set[str] = set()
    for number, spot in enumerate(run.hotspots, start=1):
        label = None if spot.metric in labelled else f"hotspot: {spot.metric}"
        labelled.add(spot.metric)
        axes.scatter([spot.position.x], [spot.position.y], s=60 + 30 * math.sqrt(spot.duration),
                     marker=markers.get(spot.metric, "X"), color="#c0392b", edgecolor="white", linewidth=0.8,
                     zorder=4, label=label)
        axes.annotate(str(number), (spot.position.x, spot.position.y), textcoords="offset points",
                      xytext=(5, 4), fontsize=7, color="#922b21", fontweight="bold")
    if box is not None:
        axes.set_xlim(box[0], box[1])
        axes.set_ylim(box[2], box[3])
    axes.set_aspect("equal")
    axes.set_xlabel("x (m)")
    axes.set_ylabel("y (m)")
    axes.set_title(f"run {run.run.uuid[:8]} of {scenario.id}")
    if axes.get_legend_handles_labels()[0]:
        axes.legend(loc="best", fontsize=7, framealpha=0.85)
    return figure


def _bounding_box(points: Sequence[np.ndarray]) -> tuple[float, float, float, float] | None:
    drawn = [p for p in points if p.size]
    if not drawn:
        return None
    every = np.vstack(drawn)
    (x0, y0), (x1, y1) = every.min(axis=0), every.max(axis=0)
    return float(x0) - _MARGIN, float(x1) + _MARGIN, float(y0) - _MARGIN, float(y1) + _MARGIN


def _draw_grid(axes: object, grid: OccupancyGrid, box: tuple[float, float, float, float] | None) -> None:
    """The grid as a grey image, cut to ``box`` (drawing a whole building's map for every run is slow)."""
    x0, _, y0, _ = grid.bounds()
    res = grid.resolution
    first_col, last_col, first_row, last_row = 0, grid.width, 0, grid.height  # rows from the bottom
    if box is not None:
        first_col = max(0, int((box[0] - x0) / res))
        last_col = min(grid.width, int((box[1] - x0) / res) + 1)
        first_row = max(0, int((box[2] - y0) / res))
        last_row = min(grid.height, int((box[3] - y0) / res) + 1)
    if first_col >= last_col or first_row >= last_row:
        return
    cells = grid.cells[grid.height - last_row : grid.height - first_row, first_col:last_col]
    image = cells if not grid.negate else 255 - cells
    extent = (x0 + first_col * res, x0 + last_col * res, y0 + first_row * res, y0 + last_row * res)
    axes.imshow(image, cmap="gray", vmin=0, vmax=255, extent=extent, origin="upper",  # type: ignore[attr-defined]
                interpolation="nearest", alpha=0.9)


# -- metrics against their oracles -----------------------------------------------------------


def _accepted(oracle: Oracle) -> tuple[float, float] | None:
    """The values ``oracle`` accepts, as an interval (None for a relation it cannot draw)."""
    value, tolerance, delta = oracle.value, oracle.tolerance or 0.0, oracle.delta or 0.0
    if oracle.relation == "below_max" and oracle.limit is not None:
        return -math.inf, oracle.limit
    if oracle.relation == "above_min" and oracle.limit is not None:
        return oracle.limit, math.inf
    if value is None:
        return None
    if oracle.relation == "invariant":
        return value - tolerance, value + tolerance
    if oracle.relation == "increasing":
        return value + delta - tolerance, math.inf
    if oracle.relation == "decreasing":
        return -math.inf, value - delta + tolerance
    return None


def _row(value: MetricReading) -> str:
    """The robot (or the mission), and for a violation time the safety metric it is of."""
    who = value.robot or "mission"
    return f"{who} · {value.safety}" if value.safety else who


def metrics_figure(scenario: ScenarioContents) -> Figure | None:
    """One panel per metric: each run's value per robot (coloured by the run's verdict) over the
    band of values the scenario's whole-run oracles accept."""
    status = {r.run.uuid: r.status for r in scenario.runs}
    judged = {o.metric for o in scenario.oracles if o.window is None}
    metrics = sorted({v.metric for v in scenario.values} | judged)
    if not metrics:
        return None
    panels_rows = []
    for metric in metrics:
        values = [v for v in scenario.values if v.metric == metric and v.action is None]
        oracles = [o for o in scenario.oracles if o.metric == metric and o.window is None]
        rows = sorted({_row(v) for v in values} | {o.robot or "mission" for o in oracles})
        panels_rows.append((metric, values, oracles, rows))
    heights = [0.55 + 0.28 * max(1, len(rows)) for *_, rows in panels_rows]
    figure = Figure(figsize=(7.5, 0.6 + sum(heights)), layout="constrained")
    panels = figure.subplots(len(metrics), 1, squeeze=False, gridspec_kw={"height_ratios": heights})[:, 0]
    for axes, (metric, values, oracles, rows) in zip(panels, panels_rows, strict=True):
        row_of = {name: i for i, name in enumerate(rows)}
        bounds = [b for o in oracles for b in (_accepted(o) or ()) if math.isfinite(b)]
        finite = [v.value for v in values] + bounds
        low, high = (min(finite), max(finite)) if finite else (0.0, 1.0)
        pad = (high - low) * 0.08 or max(abs(high) * 0.1, 0.5)
        low, high = low - pad, high + pad
        for oracle in oracles:
            band = _accepted(oracle)
            if band is None:
                continue
            left, right = max(band[0], low), min(band[1], high)
            y = row_of[oracle.robot or "mission"]
            if right - left > (high - low) * 0.004:
                axes.barh(y, right - left, left=left, height=0.7, color="#27ae60", alpha=0.16,
                          edgecolor="#1e8449")
            else:  # a single accepted value (invariant within 0): a bar too thin to see, so a line
                axes.plot([left, left], [y - 0.35, y + 0.35], color="#1e8449", linewidth=2.5, alpha=0.6)
        for value in values:
            colour = _STATUS_COLOURS[status.get(value.run, "not verified")]
            axes.scatter([value.value], [row_of[_row(value)]], s=26, color=colour, zorder=3)
        axes.set_xlim(low, high)
        axes.set_yticks(range(len(rows)), rows, fontsize=8)
        axes.set_ylim(-0.6, len(rows) - 0.4)
        axes.set_title(metric, fontsize=9, loc="left")
        axes.tick_params(axis="x", labelsize=8)
        axes.spines[["top", "right"]].set_visible(False)
    figure.suptitle(f"{scenario.id}: run values (dots) and what the oracles accept (green)", fontsize=10)
    return figure
