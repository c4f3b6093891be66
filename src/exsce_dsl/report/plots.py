"""The report's figures: a run's paths over its occupancy grid, metric values against their oracles,
and the violations a campaign found over its budget."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator
from matplotlib.transforms import Bbox

from exsce_dsl.figures import plain
from exsce_dsl.maps.grid import OccupancyGrid
from exsce_dsl.model.oracles import Oracle
from exsce_dsl.report.campaigns import CampaignContents
from exsce_dsl.report.contents import RunContents, ScenarioContents
from exsce_dsl.runs import Trajectory
from exsce_dsl.store import MetricReading
from exsce_dsl.wording import counted

MARGIN = 2.5
"""Metres of map shown around what a run's figure draws."""
_LONG_SIDE = 7.0  # inches of the map's longer side in a run's figure
_SHORT_SIDE = 2.5  # inches at least of its shorter side
_AROUND = (0.8, 0.2, 0.4, 0.55)
"""Inches left, right, above and below the map: tick labels, axis labels and title."""
_LEGEND_ROW = 0.2  # inches per row of the legend below the map
_LEGEND_COLUMN = 2.3  # inches per column of it (its longest entries are ~2 inches long)
_LABEL_POINTS = 7.0  # font size of the hotspots' numbers
_LABEL_GAP = 1.5  # points kept free around a hotspot's number
_RINGS = (2.0, 6.0, 11.0, 17.0, 24.0, 32.0, 41.0, 51.0, 62.0, 74.0, 87.0, 101.0)
"""Points from a hotspot's marker to where its number may go, nearest first."""
_DIRECTIONS = 24
_SEGMENT_SIZE = 70.0  # points² of the ring where a path segment starts
_SEGMENT_COLOUR = "#6c3483"
_STATUS_COLOURS = {
    "failed": "#c0392b",
    "inconclusive": "#d68910",
    "passed": "#1e8449",
    "not verified": "#5d6d7e",
}

Box = tuple[float, float, float, float]
"""x_min, x_max, y_min, y_max."""


def trajectory_figure(scenario: ScenarioContents, run: RunContents, paths: Sequence[Trajectory]) -> Figure:
    """Each robot's path in ``run`` over the scenario's grid, its planned waypoints, where each of
    its path segments starts (S1, S2...), and the hotspots, numbered (as the run page's tables)
    without two labels overlapping.

    The map shows what is drawn and :data:`MARGIN` around it (cut to the grid), at equal scale, and
    the figure takes the shape of that area, so that the map fills it; a map too long and thin for
    that shows more around it across its length.
    """
    points = [p.xy for p in paths]
    points += [np.array([(x, y) for _, x, y in path]) for path in scenario.waypoints.values() if path]
    points += [np.array([(h.position.x, h.position.y) for h in run.hotspots])] if run.hotspots else []
    points += [np.array([(s.x, s.y) for s in run.segments])] if run.segments else []
    box = fitted_box(points, scenario.grid) or (-MARGIN, MARGIN, -MARGIN, MARGIN)
    markers = dict(zip(sorted({h.metric for h in run.hotspots}), "XDP^v*", strict=False))
    entries = len(paths) + any(scenario.waypoints.values()) + len(markers) + bool(run.segments)
    figure, axes, box, columns = _map_figure(box, entries)
    if scenario.grid is not None:
        _draw_grid(axes, scenario.grid, box)
    _draw_paths(axes, paths, scenario)
    _mark_segment_starts(axes, run)
    sizes = _draw_hotspots(axes, run, markers)
    axes.set_xlim(box[0], box[1])
    axes.set_ylim(box[2], box[3])
    axes.set_aspect("equal")
    axes.set_xlabel("x (m)")
    axes.set_ylabel("y (m)")
    axes.set_title(plain(f"run {run.run.uuid[:8]} of {scenario.id}"))
    handles, labels = axes.get_legend_handles_labels()
    if handles:  # below the map, not over it
        figure.legend(
            handles,
            labels,
            loc="lower center",
            bbox_to_anchor=(0.5, 0.0),
            ncols=columns,
            fontsize=7,
            frameon=False,
        )
    _label_markers(axes, run, sizes)
    return figure


def _draw_paths(axes: Axes, paths: Sequence[Trajectory], scenario: ScenarioContents) -> None:
    """Each robot's driven path (a dot where it starts) and the planned waypoints."""
    colours = [f"C{i}" for i in range(10)]
    for i, path in enumerate(paths):
        colour = colours[i % len(colours)]
        axes.plot(
            path.xy[:, 0], path.xy[:, 1], color=colour, linewidth=1.4, label=plain(f"{path.topic} (driven)")
        )
        axes.plot(*path.xy[0], marker="o", color=colour, markersize=6)
    planned_paths = [planned for _, planned in sorted(scenario.waypoints.items()) if planned]
    for i, planned in enumerate(planned_paths):
        xy = np.array([(x, y) for _, x, y in planned])
        axes.scatter(
            xy[1:, 0],
            xy[1:, 1],
            marker="s",
            s=18,
            color="#34495e",
            zorder=3,
            label="planned waypoints" if i == 0 else None,
        )


def _draw_hotspots(axes: Axes, run: RunContents, markers: Mapping[str, str]) -> list[float]:
    """A marker per hotspot, one shape per metric, larger the longer it lasted: their sizes."""
    labelled: set[str] = set()
    sizes = []
    for spot in run.hotspots:
        label = None if spot.metric in labelled else plain(f"hotspot: {spot.metric}")
        labelled.add(spot.metric)
        sizes.append(60 + 30 * math.sqrt(spot.duration))
        axes.scatter(
            [spot.position.x],
            [spot.position.y],
            s=sizes[-1],
            marker=markers.get(spot.metric, "X"),
            color="#c0392b",
            edgecolor="white",
            linewidth=0.8,
            zorder=4,
            label=label,
        )
    return sizes


def _label_markers(axes: Axes, run: RunContents, sizes: Sequence[float]) -> None:
    """The hotspots' numbers first, nearest their markers; then the segments' labels, around both."""
    starts = [(seg.x, seg.y) for seg in run.segments]
    taken = _marker_boxes(axes, starts, [_SEGMENT_SIZE] * len(starts))
    if run.hotspots:
        positions = [(h.position.x, h.position.y) for h in run.hotspots]
        numbers = [str(i) for i in range(1, len(positions) + 1)]
        taken = _place_labels(axes, positions, sizes, numbers, "#922b21", taken)
    if run.segments:
        labels = [f"S{i}" for i in range(1, len(starts) + 1)]
        _place_labels(axes, starts, [_SEGMENT_SIZE] * len(starts), labels, _SEGMENT_COLOUR, taken)


def _mark_segment_starts(axes: Axes, run: RunContents) -> None:
    """A ring where each of the run's path segments starts (its start pose), SVG id
    ``segment-start-N`` (N as in the run page's table of segments)."""
    for number, segment in enumerate(run.segments, start=1):
        axes.scatter(
            [segment.x],
            [segment.y],
            s=_SEGMENT_SIZE,
            marker="o",
            facecolor="none",
            edgecolor=_SEGMENT_COLOUR,
            linewidth=1.3,
            zorder=4,
            gid=f"segment-start-{number}",
            label="segment start (S1, S2... as in the table)" if number == 1 else None,
        )


def _map_figure(box: Box, entries: int) -> tuple[Figure, Axes, Box, int]:
    """A figure whose axes have the shape of ``box`` (its longer side :data:`_LONG_SIDE` long, its
    shorter one at least :data:`_SHORT_SIDE`), with room around for labels and a legend of
    ``entries`` below; ``box`` grown across where the shorter side had to be made longer; and how
    many columns the legend fits in."""
    width, height = box[1] - box[0], box[3] - box[2]
    if width >= height:
        inches = (_LONG_SIDE, max(_SHORT_SIDE, _LONG_SIDE * height / width))
    else:
        inches = (max(_SHORT_SIDE, _LONG_SIDE * width / height), _LONG_SIDE)
    box = _grown(box, inches[0] / inches[1])
    left, right, top, bottom = _AROUND
    columns = max(1, min(entries, int((left + inches[0] + right) // _LEGEND_COLUMN)))
    bottom += math.ceil(entries / columns) * _LEGEND_ROW
    size = (left + inches[0] + right, bottom + inches[1] + top)
    figure = Figure(figsize=size)
    axes = figure.add_axes((left / size[0], bottom / size[1], inches[0] / size[0], inches[1] / size[1]))
    return figure, axes, box, columns


def _grown(box: Box, shape: float) -> Box:
    """``box`` grown about its centre in one direction to the width / height ratio ``shape``."""
    width, height = box[1] - box[0], box[3] - box[2]
    if width < height * shape:
        grow = (height * shape - width) / 2
        return box[0] - grow, box[1] + grow, box[2], box[3]
    grow = (width / shape - height) / 2
    return box[0], box[1], box[2] - grow, box[3] + grow


def fitted_box(points: Sequence[np.ndarray], grid: OccupancyGrid | None = None) -> Box | None:
    """What ``points`` cover, and :data:`MARGIN` around them, but no more of the margin than the
    ``grid`` has (beyond the map there is nothing to see); None when there are no points."""
    drawn = [p for p in points if p.size]
    if not drawn:
        return None
    every = np.vstack(drawn)
    (x0, y0), (x1, y1) = every.min(axis=0), every.max(axis=0)
    box = (float(x0) - MARGIN, float(x1) + MARGIN, float(y0) - MARGIN, float(y1) + MARGIN)
    if grid is None:
        return box
    gx0, gx1, gy0, gy1 = grid.bounds()
    return (
        max(box[0], min(gx0, float(x0))),
        min(box[1], max(gx1, float(x1))),
        max(box[2], min(gy0, float(y0))),
        min(box[3], max(gy1, float(y1))),
    )


def _place_labels(
    axes: Axes,
    positions: Sequence[tuple[float, float]],
    sizes: Sequence[float],
    texts: Sequence[str],
    colour: str,
    taken: np.ndarray | None = None,
) -> np.ndarray:
    """Write each of ``texts`` beside its marker (at ``positions``, of area ``sizes`` in points²)
    where it covers no other label, no marker and nothing in ``taken`` (pixel boxes x0, x1, y0,
    y1): the nearest free place on rings around it, with a leader line when it had to go further.
    Returns the boxes now taken.  (The figure's layout is fixed: what is measured here stays where
    it is.)"""
    pixels = axes.figure.dpi / 72.0
    frame = axes.get_window_extent()
    markers = _marker_boxes(axes, positions, sizes)
    taken = markers if taken is None else np.vstack([taken, markers])
    anchors = axes.transData.transform(np.asarray(positions, dtype=float))
    radii = (markers[:, 1] - markers[:, 0]) / 2
    for index, ((x, y), radius) in enumerate(zip(anchors, radii, strict=True)):
        text = axes.text(0, 0, texts[index], fontsize=_LABEL_POINTS, fontweight="bold")
        extent = text.get_window_extent()
        text.remove()
        half = (extent.width / 2 + _LABEL_GAP * pixels, extent.height / 2 + _LABEL_GAP * pixels)
        places = _places(float(x), float(y), float(radius), half, pixels)
        clashes = _covered(places, taken) + _outside(places, frame)
        free = np.flatnonzero(clashes == 0)
        chosen = int(free[0]) if free.size else int(np.argmin(clashes))  # else where it covers least
        taken = np.vstack([taken, places[chosen]])
        cx, cy = (places[chosen, 0] + places[chosen, 1]) / 2, (places[chosen, 2] + places[chosen, 3]) / 2
        leader = chosen >= _DIRECTIONS  # not on the first ring, right by its marker
        axes.annotate(
            texts[index],
            positions[index],
            xytext=(float(cx - x) / pixels, float(cy - y) / pixels),
            textcoords="offset points",
            ha="center",
            va="center",
            fontsize=_LABEL_POINTS,
            fontweight="bold",
            color=colour,
            zorder=5,
            arrowprops=(
                {
                    "arrowstyle": "-",
                    "color": colour,
                    "linewidth": 0.6,
                    "shrinkA": 0,
                    "shrinkB": float(radius) / pixels,
                }
                if leader
                else None
            ),
        )
    return taken


def _marker_boxes(axes: Axes, positions: Sequence[tuple[float, float]], sizes: Sequence[float]) -> np.ndarray:
    """The pixel boxes (x0, x1, y0, y1) of markers of area ``sizes`` (points²) at ``positions``."""
    axes.apply_aspect()
    if not positions:
        return np.empty((0, 4))
    pixels = axes.figure.dpi / 72.0
    anchors = axes.transData.transform(np.asarray(positions, dtype=float))
    radii = np.sqrt(np.asarray(sizes, dtype=float)) / 2 * pixels  # a marker of area s points² spans √s points
    return np.column_stack(
        [anchors[:, 0] - radii, anchors[:, 0] + radii, anchors[:, 1] - radii, anchors[:, 1] + radii]
    )


def _places(x: float, y: float, radius: float, half: tuple[float, float], pixels: float) -> np.ndarray:
    """Where a label of half-size ``half`` may go around a marker of ``radius`` at (x, y): boxes
    (x0, x1, y0, y1) in pixels, nearest first, and on each ring up and to the right first."""
    reach = radius + np.repeat(np.asarray(_RINGS), _DIRECTIONS) * pixels
    angles = np.tile(math.pi / 4 + 2 * math.pi * np.arange(_DIRECTIONS) / _DIRECTIONS, len(_RINGS))
    cx = x + np.cos(angles) * (reach + half[0])
    cy = y + np.sin(angles) * (reach + half[1])
    return np.column_stack([cx - half[0], cx + half[0], cy - half[1], cy + half[1]])


def _covered(places: np.ndarray, taken: np.ndarray) -> np.ndarray:
    """For each of ``places``, the area it shares with the boxes ``taken``."""
    wide = np.minimum(places[:, None, 1], taken[None, :, 1]) - np.maximum(
        places[:, None, 0], taken[None, :, 0]
    )
    high = np.minimum(places[:, None, 3], taken[None, :, 3]) - np.maximum(
        places[:, None, 2], taken[None, :, 2]
    )
    shared: np.ndarray = (np.clip(wide, 0.0, None) * np.clip(high, 0.0, None)).sum(axis=1)
    return shared


def _outside(places: np.ndarray, frame: Bbox) -> np.ndarray:
    """For each of ``places``, its area outside ``frame``."""
    wide = np.minimum(places[:, 1], frame.x1) - np.maximum(places[:, 0], frame.x0)
    high = np.minimum(places[:, 3], frame.y1) - np.maximum(places[:, 2], frame.y0)
    whole = (places[:, 1] - places[:, 0]) * (places[:, 3] - places[:, 2])
    outside: np.ndarray = whole - np.clip(wide, 0.0, None) * np.clip(high, 0.0, None)
    return outside


def _draw_grid(axes: Axes, grid: OccupancyGrid, box: Box | None) -> None:
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
    axes.imshow(
        image,
        cmap="gray",
        vmin=0,
        vmax=255,
        extent=extent,
        origin="upper",
        interpolation="nearest",
        alpha=0.9,
    )


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


def metrics_figure(scenario: ScenarioContents, units: Mapping[str, str]) -> Figure | None:
    """One panel per metric: each run's value per robot (coloured by the run's verdict) over the
    band of values the scenario's whole-run oracles accept; its axis says the metric's unit (from
    ``units``, metric name → unit)."""
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
                axes.barh(
                    y, right - left, left=left, height=0.7, color="#27ae60", alpha=0.16, edgecolor="#1e8449"
                )
            else:  # a single accepted value (invariant within 0): a bar too thin to see, so a line
                axes.plot([left, left], [y - 0.35, y + 0.35], color="#1e8449", linewidth=2.5, alpha=0.6)
        for value in values:
            colour = _STATUS_COLOURS[status.get(value.run, "not verified")]
            axes.scatter([value.value], [row_of[_row(value)]], s=26, color=colour, zorder=3)
        axes.set_xlim(low, high)
        axes.set_yticks(range(len(rows)), [plain(row) for row in rows], fontsize=8)
        axes.set_ylim(-0.6, len(rows) - 0.4)
        unit = units.get(metric)
        axes.set_xlabel(plain(f"{metric} ({unit})" if unit else metric), fontsize=8)
        axes.tick_params(axis="x", labelsize=8)
        axes.spines[["top", "right"]].set_visible(False)
    figure.suptitle(
        plain(f"{scenario.id}: run values (dots) and what the oracles accept (green)"), fontsize=10
    )
    return figure


# -- a campaign's violations over its budget ---------------------------------------------------


def campaign_figure(campaign: CampaignContents) -> Figure:
    """How many distinct relations the campaign had found violated after each derivation it tried:
    a step line from (0, 0) (SVG id ``found-over-trials``), a dot where the count rose (SVG id
    ``found-N``, N the count it rose to), labelled with the relations found there; the budget, when
    it was not used up, as a dashed line."""
    tried = len(campaign.trials)
    found = campaign.found
    figure = Figure(figsize=(9.0, 3.4), layout="constrained")
    axes = figure.add_subplot()
    axes.step(
        range(tried + 1), (0, *found), where="post", color="#c0392b", linewidth=1.6, gid="found-over-trials"
    )
    budget = campaign.plan.budget
    right = max(budget, tried, 1) + 0.5
    count = 0
    for tried_so_far, trial in enumerate(campaign.trials, start=1):
        if not trial.new:
            continue
        count += len(trial.new)
        axes.plot([tried_so_far], [count], marker="o", color="#c0392b", markersize=5, gid=f"found-{count}")
        axes.annotate(
            "\n".join(plain(relation) for relation in trial.new),
            (tried_so_far, count),
            # below and right of the dot the line never goes (it only rises, to the right); too
            # near the right end, below and left
            xytext=(5, -5) if tried_so_far < 0.75 * right else (-5, -5),
            textcoords="offset points",
            fontsize=7,
            ha="left" if tried_so_far < 0.75 * right else "right",
            va="top",
            color="#922b21",
        )
    if budget > tried:
        axes.axvline(budget, color="#5d6d7e", linestyle="--", linewidth=1.0)
        axes.annotate(
            f"budget: {counted(budget, 'derivation')}",
            (budget, 1.0),
            xycoords=("data", "axes fraction"),
            xytext=(-4, -2),
            textcoords="offset points",
            ha="right",
            va="top",
            fontsize=8,
            color="#5d6d7e",
        )
    axes.set_xlim(0, right)
    axes.set_ylim(0, max(count, 1) * 1.25 + 0.2)
    axes.xaxis.set_major_locator(MaxNLocator(integer=True))
    axes.yaxis.set_major_locator(MaxNLocator(integer=True))
    axes.set_xlabel("derivations tried (count)", fontsize=9)
    axes.set_ylabel("relations violated\n(distinct, count)", fontsize=9)
    axes.tick_params(labelsize=8)
    axes.spines[["top", "right"]].set_visible(False)
    axes.set_title(plain(f"campaign {campaign.id}: violations found over budget"), fontsize=10)
    return figure
