"""What the report shows, gathered from the store (and the maps of the specs given).

Everything here comes from the query library, so a report of a remote store is
the same as one of the embedded store.  Occupancy grids are not in the store
(it only names the map's ROS package), so they come from the specifications
the user passes: a scenario's map is its own spec's, or that of the scenario it
was derived from.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path

from exsce_dsl.errors import ExsceError, Remedied
from exsce_dsl.lang import load_spec
from exsce_dsl.maps.grid import OccupancyGrid, load_occupancy_grid
from exsce_dsl.model.derivation import Derivation
from exsce_dsl.model.metrics import MetricDefinition
from exsce_dsl.model.oracles import Oracle
from exsce_dsl.model.runs import Hotspot
from exsce_dsl.model.scenario import Scenario
from exsce_dsl.model.trials import ClauseTrial
from exsce_dsl.model.verdicts import Outcome, Verdict
from exsce_dsl.oracles import clause_trials, lowest_pass_rate_first
from exsce_dsl.remedies import ADD_ITS_SPEC, GIVE_THE_SPECS
from exsce_dsl.report.campaigns import CampaignContents, gather_campaigns
from exsce_dsl.report.units import metric_units
from exsce_dsl.similarity.clustering import Clustering, cluster
from exsce_dsl.similarity.facts import scenario_facts
from exsce_dsl.store import (
    MetricReading,
    Store,
    StoredRun,
    ValueAccount,
    derivation_of,
    dispatched_runs,
    hotspots,
    path_segments,
    pose_positions,
    run_metric_values,
    run_segment_values,
    scenario_ids,
    value_accounts,
    verdicts,
)
from exsce_dsl.store import (
    oracles as stored_oracles,
)
from exsce_dsl.store import (
    runs as stored_runs,
)

_RANK = {Outcome.FAILED: 0, Outcome.PASSED: 2}
"""Where verdicts of each outcome go when failures come first; any other outcome goes between."""


def failures_first(verdicts: Iterable[Verdict]) -> tuple[Verdict, ...]:
    """``verdicts`` failed first, then those not judged, then the passed, each kept in its order."""
    return tuple(sorted(verdicts, key=lambda v: _RANK.get(v.outcome, 1)))


@dataclass(frozen=True)
class RunSegment:
    """One path segment a robot drove in a run (one action of the run), where it started, and
    the values measured over it."""

    robot: str
    action: str
    """Its id in the run: ``tiago1-task_01-subtask_001-w_001``."""
    start: str
    goal: str
    x: float
    """Where the start pose is (m, map frame)."""
    y: float
    values: tuple[MetricReading, ...]

    def value(self, metric: str) -> MetricReading | None:
        return next((v for v in self.values if v.metric == metric), None)


@dataclass(frozen=True)
class RunContents:
    run: StoredRun
    verdicts: tuple[Verdict, ...]
    hotspots: tuple[Hotspot, ...]
    segments: tuple[RunSegment, ...] = ()
    """Its path segments, by robot then in the order it drove them (the report numbers them S1, S2...)."""
    accounts: tuple[ValueAccount, ...] = ()
    """What each of its values used (window, why, samples per source, findings)."""
    dispatched: str | None = None
    """The id its dispatcher gave the run (its run-time PROV's), when the bag came with one."""

    def used(
        self, metric: str, robot: str | None, safety: str | None = None, action: str | None = None
    ) -> str:
        """What the value of ``metric`` (of ``robot``, about ``safety``, over segment ``action``)
        used, in a few lines; '' when the store does not say."""
        for a in self.accounts:
            if (a.metric, a.robot, a.safety_metric, a.action) == (metric, robot, safety, action):
                return a.summary()
        return ""

    @property
    def failed(self) -> int:
        return sum(v.outcome is Outcome.FAILED for v in self.verdicts)

    @property
    def inconclusive(self) -> int:
        return sum(v.outcome is Outcome.INCONCLUSIVE for v in self.verdicts)

    @property
    def passed(self) -> int:
        return sum(v.outcome is Outcome.PASSED for v in self.verdicts)

    @property
    def status(self) -> str:
        """failed, inconclusive, passed, or 'not verified'."""
        if not self.verdicts:
            return "not verified"
        return "failed" if self.failed else "inconclusive" if self.inconclusive else "passed"


@dataclass(frozen=True)
class MissingMap:
    """Why a scenario's paths are drawn without a map: ``kind`` is ``no_spec`` (no --spec given),
    ``no_map`` (its specification names no map file), ``not_given`` (no --spec file declares it or
    a scenario it was derived from) or ``unreadable`` (its map file could not be read)."""

    kind: str
    scenario: str
    """The scenario whose specification was looked at (itself, or the one it was derived from)."""
    environment: str = ""
    detail: str = ""

    @property
    def text(self) -> str | Remedied:
        """What to tell the user, and what to do about it (a remedy the command line says with
        its options: :meth:`~exsce_dsl.errors.Remedied.said`)."""
        if self.kind == "no_spec":
            return Remedied("no occupancy grid: no specification was given", GIVE_THE_SPECS)
        if self.kind == "no_map":
            return (
                f"no occupancy grid: scenario '{self.scenario}' has no map: its environment "
                f"'{self.environment}' names no map file; give its map line a file (the map_server YAML)"
            )
        if self.kind == "unreadable":
            return f"no occupancy grid: cannot read the map of scenario '{self.scenario}': {self.detail}"
        problem = (
            f"no occupancy grid: no file given declares scenario '{self.scenario}' "
            "(or one it was derived from)"
        )
        return Remedied(problem, ADD_ITS_SPEC, self.scenario)


@dataclass(frozen=True)
class ScenarioContents:
    id: str
    derivation: Derivation | None
    """How it was derived (None: written by hand)."""
    children: tuple[str, ...]
    runs: tuple[RunContents, ...]
    oracles: tuple[Oracle, ...]
    values: tuple[MetricReading, ...]
    """Whole-run metric values of its runs."""
    waypoints: Mapping[str, tuple[tuple[str, float, float], ...]]
    """Robot → its planned path: (pose name, x, y) from its start pose on."""
    grid: OccupancyGrid | None = None
    missing_map: MissingMap | None = None
    """Why there is no ``grid`` (None when there is one)."""

    @property
    def verdicts(self) -> tuple[Verdict, ...]:
        """The verdicts of all its runs, failures first (then run by run)."""
        return failures_first(v for r in self.runs for v in r.verdicts)

    @property
    def pass_rates(self) -> tuple[ClauseTrial, ...]:
        """Each clause's pass rate over its runs' last verdicts, lowest first, with the default
        required pass rate and confidence (as ``exscec flaky`` lists them)."""
        return tuple(lowest_pass_rate_first(clause_trials(v for r in self.runs for v in r.verdicts)))


@dataclass(frozen=True)
class ReportContents:
    scenarios: tuple[ScenarioContents, ...]
    verdicts: tuple[Verdict, ...]
    """Every run's last verdicts, failed first."""
    clustering: Clustering | None
    """Of all scenarios (None with fewer than two)."""
    notes: tuple[str | Remedied, ...] = field(default=())
    """What could not be shown, and why (a remedy in words; ``str()`` of one says it so)."""
    units: Mapping[str, str] = field(default_factory=dict)
    """Metric name → the unit its numbers are shown with (see :mod:`.units`)."""
    campaigns: tuple[CampaignContents, ...] = field(default=())
    """Every exploration campaign of the store, oldest first (see :mod:`.campaigns`)."""

    def unit(self, metric: str) -> str:
        """The unit of ``metric``'s numbers ('' for a metric nothing declares)."""
        return self.units.get(metric, "")

    def scenario(self, scenario_id: str) -> ScenarioContents:
        return next(s for s in self.scenarios if s.id == scenario_id)

    def has_scenario(self, scenario_id: str) -> bool:
        """Whether the report has a page of the scenario (the store holds it)."""
        return any(s.id == scenario_id for s in self.scenarios)

    def roots(self) -> tuple[str, ...]:
        """Scenarios written by hand, or whose base is not in the store: the lineage trees' roots."""
        known = {s.id for s in self.scenarios}
        return tuple(s.id for s in self.scenarios if s.derivation is None or s.derivation.base not in known)


def gather(store: Store, specs: Sequence[Path] = ()) -> ReportContents:
    """Read everything the report shows from ``store``; ``specs`` give occupancy grids and the
    units of the metrics they declare."""
    declared = [scenario for spec in specs for scenario in load_spec(spec).scenarios]
    grids, missing, notes = _grids(declared)
    ids = scenario_ids(store)
    all_verdicts = verdicts(store)
    dispatched = dict(dispatched_runs(store, ""))  # every run's dispatcher's id, in one query
    derivations = {s: derivation_of(store, s) for s in ids}
    children: dict[str, list[str]] = {}
    for scenario_id, derivation in derivations.items():
        if derivation is not None:
            children.setdefault(derivation.base, []).append(scenario_id)
    scenarios = []
    for scenario_id in ids:
        runs = stored_runs(store, scenario_id)
        uuids = [r.uuid for r in runs]
        spots: dict[str, list[Hotspot]] = {}
        for found in hotspots(store, uuids):
            spots.setdefault(found.run, []).append(found.hotspot)
        driven = _segments(store, uuids)
        judged: dict[str, list[Verdict]] = {}
        for verdict in all_verdicts:
            if verdict.scenario == scenario_id:
                judged.setdefault(verdict.run, []).append(verdict)
        scenarios.append(
            ScenarioContents(
                id=scenario_id,
                derivation=derivations[scenario_id],
                children=tuple(sorted(children.get(scenario_id, ()))),
                runs=tuple(
                    RunContents(
                        r,
                        failures_first(judged.get(r.uuid, ())),
                        tuple(spots.get(r.uuid, ())),
                        tuple(driven.get(r.uuid, ())),
                        tuple(value_accounts(store, r.uuid)),
                        dispatched.get(r.uuid),
                    )
                    for r in runs
                ),
                oracles=tuple(stored_oracles(store, scenario_id)),
                values=tuple(run_metric_values(store, uuids)),
                waypoints=_waypoints(store, scenario_id),
                grid=_grid_of(scenario_id, derivations, grids),
                missing_map=_missing_map(scenario_id, derivations, grids, missing, given=bool(specs)),
            )
        )
    clustering = None
    if len(ids) >= 2:
        clustering = cluster([scenario_facts(store, s) for s in ids])
    if not specs and any(s.waypoints for s in scenarios):
        notes.append(MissingMap("no_spec", "").text)
    definitions: list[MetricDefinition] = [d for scenario in declared for d in scenario.metrics]
    units = metric_units((v for s in scenarios for v in s.values), definitions)
    return ReportContents(
        tuple(scenarios),
        failures_first(all_verdicts),
        clustering,
        tuple(notes),
        units,
        gather_campaigns(store),
    )


def _waypoints(store: Store, scenario_id: str) -> dict[str, tuple[tuple[str, float, float], ...]]:
    segments = path_segments(store, scenario_id)
    where = pose_positions(store, [p for s in segments for p in (s.start, s.goal)])
    paths: dict[str, list[str]] = {}
    for segment in segments:
        path = paths.setdefault(segment.robot, [segment.start])
        path.append(segment.goal)
    return {
        robot: tuple((pose, *where[pose]) for pose in path if pose in where) for robot, path in paths.items()
    }


def _grids(
    scenarios: Sequence[Scenario],
) -> tuple[dict[str, OccupancyGrid], dict[str, MissingMap], list[str | Remedied]]:
    """Scenario id → the occupancy grid of its environment, for every one of ``scenarios``; for
    those without one, scenario id → why; and the notes the report prints."""
    grids: dict[str, OccupancyGrid] = {}
    missing: dict[str, MissingMap] = {}
    loaded: dict[str, OccupancyGrid] = {}
    notes: list[str | Remedied] = []
    for scenario in scenarios:
        map_model = scenario.environment.map
        if map_model is None or map_model.file is None:
            missing[scenario.id] = MissingMap("no_map", scenario.id, scenario.environment.id)
            notes.append(f"scenario '{scenario.id}' names no map file: its paths are drawn without one")
            continue
        if map_model.file not in loaded:
            try:
                loaded[map_model.file] = load_occupancy_grid(Path(map_model.file))
            except ExsceError as exc:
                missing[scenario.id] = MissingMap("unreadable", scenario.id, detail=exc.message)
                notes.append(f"scenario '{scenario.id}': {exc.message}")
                continue
        grids[scenario.id] = loaded[map_model.file]
    return grids, missing, notes


def _missing_map(
    scenario_id: str,
    derivations: Mapping[str, Derivation | None],
    grids: Mapping[str, OccupancyGrid],
    missing: Mapping[str, MissingMap],
    given: bool,
) -> MissingMap | None:
    """Why the scenario's paths have no map under them (None when they have one)."""
    if _grid_of(scenario_id, derivations, grids) is not None:
        return None
    if not given:
        return MissingMap("no_spec", scenario_id)
    for known in _lineage(scenario_id, derivations):
        if known in missing:
            return missing[known]
    return MissingMap("not_given", scenario_id)


def _lineage(scenario_id: str, derivations: Mapping[str, Derivation | None]) -> list[str]:
    """The scenario, the one it was derived from, and so on."""
    found: list[str] = []
    current: str | None = scenario_id
    while current is not None and current not in found:
        found.append(current)
        derivation = derivations.get(current)
        current = derivation.base if derivation is not None else None
    return found


def _segments(store: Store, runs: Sequence[str]) -> dict[str, list[RunSegment]]:
    """Run uuid → the path segments its robots drove, by robot then in order, each at its start pose."""
    readings = run_segment_values(store, runs)
    where = pose_positions(store, [r.start for r in readings if r.start is not None])
    by_action: dict[tuple[str, str], list[MetricReading]] = {}
    for reading in readings:
        if reading.action is not None and reading.start in where:
            by_action.setdefault((reading.run, reading.action), []).append(reading)
    found: dict[str, list[RunSegment]] = {}
    for (run, action), values in sorted(by_action.items(), key=lambda item: (item[0][0], _order(item[1][0]))):
        first = values[0]
        x, y = where[first.start or ""]
        name = action.rsplit("/", 1)[-1]
        robot = first.robot or name.split("-task_", 1)[0]
        found.setdefault(run, []).append(
            RunSegment(robot, name, first.start or "", first.goal or "", x, y, tuple(values))
        )
    return found


def _order(reading: MetricReading) -> tuple[str, str]:
    """Robot, then the action's id (its task, subtask and waypoint numbers are zero-padded)."""
    action = (reading.action or "").rsplit("/", 1)[-1]
    return reading.robot or action.split("-task_", 1)[0], action


def _grid_of(
    scenario_id: str, derivations: Mapping[str, Derivation | None], grids: Mapping[str, OccupancyGrid]
) -> OccupancyGrid | None:
    """The grid of the scenario, or of the nearest scenario it was derived from that has one."""
    return next((grids[s] for s in _lineage(scenario_id, derivations) if s in grids), None)
