"""Campaign figures side by side: a campaign and the uniform random baseline it is compared with.

The baseline is the same campaign (budget, seed, runs per scenario, steps, transformations,
relations, tolerance) with the draws of :func:`~exsce_dsl.explore.draw.draw_derivations`
instead of the covering ones, and without shrinking: it is there to count how often and how
soon random draws find a failure, so only its draws differ.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import replace

from exsce_dsl.errors import ExsceError
from exsce_dsl.explore.campaign import CampaignOptions
from exsce_dsl.model.campaign import CampaignFigures

__all__ = ["figures_table", "first_failure", "per_100", "random_baseline"]


def random_baseline(options: CampaignOptions) -> CampaignOptions:
    """The options of the random baseline of a campaign with ``options``."""
    if options.strategy == "random":
        raise ExsceError(
            "the campaign draws at random already: compare a covering campaign with random draws"
        )
    return replace(options, strategy="random", shrink=False)


def per_100(figures: CampaignFigures) -> str:
    """Counterexamples per 100 executions, one decimal ("-" when nothing was executed)."""
    rate = figures.per_100_executions
    return "-" if rate is None else f"{rate:.1f}"


def first_failure(figures: CampaignFigures) -> str:
    """Executions to the first failure, or ``none in N`` (N: the executions)."""
    first = figures.executions_to_first_failure
    return f"none in {figures.executions}" if first is None else str(first)


def figures_table(columns: Sequence[tuple[str, CampaignFigures]]) -> list[str]:
    """The figures of each named campaign in a column of its own, as lines of text."""
    rows: list[tuple[str, Callable[[CampaignFigures], str]]] = [
        ("derivations tried", lambda f: str(f.trials)),
        ("executions", lambda f: str(f.executions)),
        ("counterexamples", lambda f: str(f.counterexamples)),
        ("per 100 executions", per_100),
        ("to first failure", first_failure),
        ("relations violated", lambda f: str(f.violated_relations)),
        ("relations inconclusive", lambda f: str(f.inconclusive_relations)),
        ("inconclusive trials", lambda f: str(f.inconclusive)),
    ]
    cells = [[show(figures) for _, figures in columns] for _, show in rows]
    widths = [max(len(name), *(len(row[i]) for row in cells)) for i, (name, _) in enumerate(columns)]
    label = max(len(name) for name, _ in rows)
    lines = [" " * label + "".join(f"  {name:>{w}}" for (name, _), w in zip(columns, widths, strict=True))]
    for (name, _), row in zip(rows, cells, strict=True):
        lines.append(f"{name:<{label}}" + "".join(f"  {c:>{w}}" for c, w in zip(row, widths, strict=True)))
    return lines
