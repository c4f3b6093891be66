"""The dendrogram of a clustering, as PNG or SVG (matplotlib, no display needed)."""

from __future__ import annotations

from pathlib import Path

from matplotlib.figure import Figure
from scipy.cluster.hierarchy import dendrogram

from exsce_dsl.figures import plain, save_figure
from exsce_dsl.similarity.clustering import Clustering
from exsce_dsl.wording import counted


def dendrogram_figure(result: Clustering) -> Figure:
    """Scenarios as leaves, joined at their combined distance; the cut that gave the clusters
    colours the branches below it."""
    height = max(2.5, 0.35 * len(result.scenarios) + 1.2)
    figure = Figure(figsize=(7.0, height), layout="constrained")
    axes = figure.add_subplot()
    cut = _cut_height(result)
    dendrogram(
        result.linkage,
        labels=[plain(s) for s in result.scenarios],
        orientation="right",
        color_threshold=cut,
        above_threshold_color="#888888",
        ax=axes,
    )
    axes.axvline(cut, color="#c0392b", linestyle="--", linewidth=1)
    axes.set_xlabel("combined distance (0 = alike, 1 = as far apart as the stored scenarios go)")
    clusters = len(set(result.clusters.values()))
    axes.set_title(f"{counted(len(result.scenarios), 'scenario')}, {counted(clusters, 'cluster')}")
    axes.spines[["top", "right"]].set_visible(False)
    return figure


def _cut_height(result: Clustering) -> float:
    """A height between the last merge inside a cluster and the first across clusters."""
    heights = result.linkage[:, 2]
    n_clusters = len(set(result.clusters.values()))
    merges_inside = len(heights) - (n_clusters - 1)
    below = float(heights[merges_inside - 1]) if merges_inside > 0 else 0.0
    above = float(heights[merges_inside]) if merges_inside < len(heights) else below
    return (below + above) / 2 if above > below else below


def save_dendrogram(result: Clustering, path: Path) -> None:
    save_figure(dendrogram_figure(result), path)
