"""``exscec cluster``: scenario distances (d1–d6) and hierarchical clustering."""

from __future__ import annotations

import json
from pathlib import Path

import click

from exsce_dsl.cli.common import reports_errors
from exsce_dsl.cli.store_commands import store_option

_WEIGHTS = ("d1", "d2", "d3", "d4", "metrics", "d5", "d6")


def _weight(text: str) -> tuple[str, float]:
    name, _, value = text.partition("=")
    if name not in _WEIGHTS or not value:
        raise click.BadParameter(f"'{text}': write NAME=W with NAME one of {', '.join(_WEIGHTS)}")
    try:
        weight = float(value)
    except ValueError:
        raise click.BadParameter(f"'{text}': the weight is not a number") from None
    if not weight >= 0:
        raise click.BadParameter(f"'{text}': a weight is a number ≥ 0")
    return name, weight


@click.command()
@click.option("--scenario", "-s", "scenarios", multiple=True, help="A scenario to cluster (default: all).")
@click.option(
    "--method",
    type=click.Choice(["average", "complete", "single", "ward"]),
    default="average",
    show_default=True,
    help="Linkage of scipy's hierarchical clustering.",
)
@click.option("--k", "k", type=click.IntRange(1), help="Cut into this many clusters.")
@click.option("--threshold", type=click.FloatRange(0), help="Cut at this combined distance.")
@click.option("--weight", "-w", "weights", multiple=True, metavar="NAME=W", help="Weight of d1…d6, metrics.")
@click.option("--json", "as_json", is_flag=True, help="The matrix, each pair's distances, the clusters.")
@click.option(
    "--dendrogram",
    "images",
    multiple=True,
    type=click.Path(dir_okay=False),
    help="Draw the tree into this .png or .svg file (repeatable).",
)
@store_option
@reports_errors
def cluster(
    scenarios: tuple[str, ...],
    method: str,
    k: int | None,
    threshold: float | None,
    weights: tuple[str, ...],
    as_json: bool,
    images: tuple[str, ...],
    store_url: str | None,
) -> None:
    """Cluster stored scenarios by the method's distances.

    d1–d3 compare the fleets (size, base types, torsos), d4 the path segments
    (shared, between the same areas, or not), `metrics` the means of their runs'
    metrics, d5 the violation time and d6 the hotspot counts; each is divided by
    the largest value among the scenarios, and the combined distance is their
    weighted mean (those needing runs count only when both scenarios have runs).
    Without --k or --threshold the tree is cut at half the largest distance.

    \b
    Example:
      exscec cluster --k 2 --dendrogram clusters.svg
      exscec cluster -s scenario_c -s c_one -w d4=2 --json
    """
    from exsce_dsl.api import cluster as cluster_stored
    from exsce_dsl.api import open_store

    if k is not None and threshold is not None:
        raise click.UsageError("give --k or --threshold, not both")
    for image in images:
        if Path(image).suffix.lower() not in (".png", ".svg"):
            raise click.BadParameter(
                f"'{image}': write the dendrogram to a .png or .svg file", param_hint="--dendrogram"
            )
    with open_store(store_url) as store:
        weighted = dict(_weight(w) for w in weights)
        result = cluster_stored(store, scenarios, method=method, k=k, threshold=threshold, weights=weighted)
    if images:
        from exsce_dsl.api import save_dendrogram

        for image in images:
            save_dendrogram(result, Path(image))
            click.echo(f"wrote {image}", err=True)
    if as_json:
        click.echo(
            json.dumps(
                {
                    "scenarios": list(result.scenarios),
                    "matrix": result.matrix.round(6).tolist(),
                    "pairs": [
                        {"a": a, "b": b, **{n: v for n, v in d.as_dict().items()}}
                        for (a, b), d in result.pairs.items()
                    ],
                    "clusters": result.clusters,
                },
                indent=2,
            )
        )
        return
    width = max(len(s) for s in result.scenarios)
    click.echo(f"{'scenario':{width}}  cluster")
    for scenario in sorted(result.scenarios, key=lambda s: (result.clusters[s], s)):
        click.echo(f"{scenario:{width}}  {result.clusters[scenario]}")


COMMANDS = [cluster]
