"""Oracles: a metric, a relation and the scenario whose runs a run is compared against."""

from __future__ import annotations

import enum
from dataclasses import dataclass

from exsce_dsl.errors import ExsceError


class OracleType(enum.Enum):
    BASELINE = "baseline"
    """New runs of a scenario against its own past runs."""
    METAMORPHIC = "metamorphic"
    """Runs of a derived scenario against the runs of the scenario it was derived from."""


@dataclass(frozen=True)
class Oracle:
    """One relation a metric must keep: ``relation(result, value, limit, delta, tolerance)``.

    ``robot`` is ``None`` for mission metrics.  ``base_scenario`` provides the runs
    compared against (the scenario itself for a baseline).  ``relation`` is the
    method's name (``invariant``, ``increasing``, ``decreasing``, ``below_max``,
    ``above_min``); ``package`` is where the method's tool found it, kept for the
    method's YAML.
    """

    metric: str
    robot: str | None
    relation: str
    type: OracleType
    base_scenario: str
    topics: tuple[str, ...] = ()
    value: float | None = None
    limit: float | None = None
    delta: float | None = None
    tolerance: float | None = None
    package: str | None = None
    window: str | None = None
    """The part of a run the oracle looks at (``during delivery_a``, ``before tiago1 reaches
    classroom_c018-w001``), None for the whole run."""
    criterion: str = ""
    """The title of the acceptance scenario it comes from."""
    sources: tuple[str, ...] = ()
    """The runs (uuids) its value and tolerance were computed from."""
    confidence: float | None = None
    """``at 99 %``: 0.99, the tolerance being the half-width of the prediction interval for one
    new run, from the ``len(sources)`` runs (see :mod:`exsce_dsl.oracles.intervals`)."""

    @property
    def name(self) -> str:
        """``tiago1-max_velocity``, ``mission_duration``, ``tiago1-max_velocity-during-delivery_a``."""
        base = f"{self.robot}-{self.metric}" if self.robot else self.metric
        if self.window is None:
            return base
        return f"{base}-{self.window.replace(' ', '-')}"

    def __post_init__(self) -> None:
        if not self.relation:
            raise ExsceError(f"the oracle of '{self.metric}' names no relation")
