"""Hierarchical clustering of scenarios by their combined distance (scipy)."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np
from scipy.cluster.hierarchy import fcluster, linkage
from scipy.spatial.distance import squareform

from exsce_dsl.errors import ExsceError
from exsce_dsl.similarity.distances import Distances, Norms, ScenarioFacts, distances
from exsce_dsl.similarity.facts import scenario_facts
from exsce_dsl.store import Store, scenario_ids

METHODS = ("average", "complete", "single", "ward")


@dataclass(frozen=True)
class Clustering:
    scenarios: tuple[str, ...]
    matrix: np.ndarray
    """Combined distances, scenarios × scenarios."""
    pairs: Mapping[tuple[str, str], Distances]
    """d1–d6 of each pair (first id before second in ``scenarios``' order)."""
    linkage: np.ndarray
    """scipy's linkage matrix (for a dendrogram)."""
    clusters: Mapping[str, int]
    """Scenario → its cluster, numbered from 1 in order of first scenario."""


def distance_matrix(
    facts: Sequence[ScenarioFacts], weights: Mapping[str, float] | None = None
) -> tuple[np.ndarray, dict[tuple[str, str], Distances]]:
    norms = Norms.of(facts)
    n = len(facts)
    matrix = np.zeros((n, n))
    pairs: dict[tuple[str, str], Distances] = {}
    for i in range(n):
        for j in range(i + 1, n):
            found = distances(facts[i], facts[j], norms)
            pairs[(facts[i].id, facts[j].id)] = found
            matrix[i, j] = matrix[j, i] = found.combined(weights)
    return matrix, pairs


def cluster(
    facts: Sequence[ScenarioFacts],
    method: str = "average",
    k: int | None = None,
    threshold: float | None = None,
    weights: Mapping[str, float] | None = None,
) -> Clustering:
    """Cluster ``facts`` into ``k`` clusters, or cut the tree at distance ``threshold``
    (neither: at half the largest distance)."""
    if method not in METHODS:
        raise ExsceError(f"unknown clustering method '{method}' (use {', '.join(METHODS)})")
    if len(facts) < 2:
        raise ExsceError(f"clustering needs at least two scenarios, not {len(facts)}")
    ids = tuple(f.id for f in facts)
    matrix, pairs = distance_matrix(facts, weights)
    tree = linkage(squareform(matrix, checks=False), method=method)
    if k is not None:
        labels = fcluster(tree, t=k, criterion="maxclust")
    else:
        cut = threshold if threshold is not None else float(matrix.max()) / 2
        labels = fcluster(tree, t=cut, criterion="distance")
    renumbered: dict[int, int] = {}
    for label in labels:
        renumbered.setdefault(int(label), len(renumbered) + 1)
    clusters = {s: renumbered[int(label)] for s, label in zip(ids, labels, strict=True)}
    return Clustering(ids, matrix, pairs, tree, clusters)


def cluster_stored(
    store: Store,
    scenarios: Sequence[str] = (),
    method: str = "average",
    k: int | None = None,
    threshold: float | None = None,
    weights: Mapping[str, float] | None = None,
) -> Clustering:
    """:func:`cluster` of scenarios in ``store`` (all of them when ``scenarios`` is empty)."""
    if k is not None and threshold is not None:
        raise ExsceError("give k or threshold, not both")
    stored = scenario_ids(store)
    chosen = list(scenarios) or stored
    unknown = [s for s in chosen if s not in stored]
    if unknown:
        raise ExsceError(f"not in the store: {', '.join(unknown)} (stored: {', '.join(stored) or 'none'})")
    return cluster([scenario_facts(store, s) for s in chosen], method, k, threshold, weights)
