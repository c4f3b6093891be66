"""``exscec explore``: a metamorphic test campaign on a scenario, and with ``compare_random`` the
same budget drawn uniformly at random beside it, its figures for comparison."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from contextlib import AbstractContextManager
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

from exsce_dsl.errors import Remedied
from exsce_dsl.model.campaign import CampaignTrial
from exsce_dsl.remedies import REPLAY_IN_IRSIM, REPLAY_IT, REPRODUCE_IT
from exsce_dsl.runs import ROS1_BAG
from exsce_dsl.wording import counted

if TYPE_CHECKING:
    from exsce_dsl.explore.campaign import CampaignOptions, CampaignResult
    from exsce_dsl.explore.executors import Executor


@dataclass(frozen=True)
class ExploreRequest:
    """A campaign, as ``exscec explore``'s arguments and options give it."""

    spec: str
    budget: int
    scenario_id: str | None = None
    seed: int = 0
    runs_per_scenario: int = 3
    transformations: tuple[str, ...] = ()
    max_steps: int = 2
    strategy: str = "covering"
    tolerance: float = 25.0
    no_shrink: bool = False
    stop_at_violation: bool = False
    compare_random: bool = False
    faults: tuple[str, ...] = ()
    simulator: str = "kinematic"
    """What plays the runs when no other executor is named: ``kinematic`` or ``irsim``."""
    behaviour: str | None = None
    """``irsim``: IR-SIM's behaviour."""
    scans: str | None = None
    """``irsim``: who measures the scans."""
    executor_command: str | None = None
    plugin: str | None = None
    """An executor by name: ``ros1``, or an ``exsce.executors`` plug-in."""
    stand_in: bool = False
    """With ``plugin="ros1"``: exsce's stand-in robots serve the goals."""
    start_master: bool = False
    speed_up: float | None = None
    jobs: int = 1
    """Bags analysed in parallel."""
    dask_address: str | None = None
    """A Dask scheduler whose workers play the simulator's runs and analyse the bags (default:
    ``$EXSCE_DASK_SCHEDULER``)."""
    output: str | None = None
    """The campaign's folder (default: ``explore/<campaign id>``)."""
    junit: str | None = None
    """Also write the campaign as JUnit XML to this file."""
    store_url: str | None = None

    @property
    def trials(self) -> int:
        """The trials the campaign (and its random baseline) may draw."""
        return self.budget * (2 if self.compare_random else 1)


@dataclass(frozen=True)
class Exploration:
    """A campaign's result, and its random baseline's (``compare_random``)."""

    result: CampaignResult
    random: CampaignResult | None
    replay: tuple[str, ...] | None = None
    """How a finding's runs are played again by its seed: ``()`` by the kinematic executor, IR-SIM's
    (behaviour, scans) by IR-SIM; None: they cannot be (another executor, or faults planted)."""

    @property
    def violated(self) -> bool:
        return any(t.violated for t in self.result.record.trials)

    @property
    def inconclusive(self) -> bool:
        return any(t.inconclusive for t in self.result.record.trials)

    def summary_lines(self, wording: Mapping[str, str] | None = None) -> list[str]:
        """What the campaign found, its figures (beside the random baseline's) and its shrinkings;
        how to reproduce one in ``wording`` (the command line's, ``cli.common.REMEDIES``) if given."""
        from exsce_dsl.explore.campaign import scenario_seed
        from exsce_dsl.explore.figures import figures_table, first_failure, per_100
        from exsce_dsl.oracles import steps_text

        result, random = self.result, self.random
        record, figures = result.record, result.figures
        # relations on the first line, trials on the second: one meaning per number, said with it
        tried = counted(figures.trials, "derivation")
        found = f"{tried} tried, {counted(figures.violated_relations, 'relation')} violated"
        if figures.inconclusive_relations:
            found += f", {counted(figures.inconclusive_relations, 'relation')} inconclusive"
        lines = [f"campaign {record.plan.id}: {found}", f"  files: {result.folder}"]
        if random is None:
            trials = counted(figures.inconclusive, "trial")
            inconclusive = f"; {trials} inconclusive" if figures.inconclusive else ""
            found = counted(figures.counterexamples, "counterexample")
            lines.append(
                f"  {counted(figures.executions, 'execution')}, {found}"
                f" ({per_100(figures)} per 100 executions), first failure after: {first_failure(figures)}"
                f"{inconclusive}"
            )
        else:
            lines.append(f"  random baseline {random.record.plan.id}: {random.folder}")
            compared = figures_table([(record.plan.strategy, figures), ("random", random.figures)])
            lines += [f"  {line}" for line in compared]
        for shrinking in record.shrinkings:
            file = result.minimal_files.get(shrinking.relation.text)
            lines.append(f"violated: {shrinking.relation.text} (trial {shrinking.trial})")
            count = len(shrinking.minimal_steps)
            steps = steps_text(shrinking.minimal_steps)
            lines.append(f"  smallest derivation ({counted(count, 'step')}): {steps}")
            if file is not None:
                bags = result.folder / "runs" / shrinking.minimal
                # ROS 1 bags are files; ROS 2 bags (--executor ros2) folders
                ros1 = f"*{ROS1_BAG.suffix}"
                pattern = f"{bags}/{ros1}" if any(bags.glob(ros1)) else f"{bags}/*/"
                lines.append(Remedied("  reproduce", REPRODUCE_IT, (pattern, str(file))).said(wording))
                if self.replay is not None:
                    seed = scenario_seed(record.plan.seed, shrinking.minimal)
                    played = (str(file), str(seed), str(record.plan.runs_per_scenario), *self.replay)
                    remedy = REPLAY_IN_IRSIM if self.replay else REPLAY_IT
                    lines.append(Remedied("  replay", remedy, played).said(wording))
        return lines


def explore(
    request: ExploreRequest,
    said: Callable[[str], None] | None = None,
    trial_done: Callable[[str, CampaignTrial, bool], None] | None = None,
) -> Exploration:
    """Run the campaign (and its random baseline); ``said`` gets what the campaign says as it goes,
    ``trial_done`` each trial as it ends (``"random: "`` first for the baseline's, and whether it
    was done before: the store is the campaign's state, so the same request goes on where it
    stopped).  Interrupted, an :class:`~exsce_dsl.errors.ExecutionInterrupted`."""
    from exsce_dsl.api.store import open_store
    from exsce_dsl.explore.campaign import CampaignEvents, run_campaign
    from exsce_dsl.explore.figures import random_baseline
    from exsce_dsl.lang import load_spec
    from exsce_dsl.oracles import campaign_junit_xml, run_seconds

    chosen, campaign = _executor(request)
    baseline = random_baseline(campaign) if request.compare_random else None
    parsed = load_spec(request.spec)

    def events(who: str) -> CampaignEvents:
        def done(trial: CampaignTrial, resumed: bool) -> None:
            if trial_done is not None:
                trial_done(who, trial, resumed)

        return CampaignEvents(said=said or (lambda line: None), trial_done=done)

    with chosen as executor, open_store(request.store_url) as store:

        def run(plan: CampaignOptions, output: str | None, who: str) -> CampaignResult:
            return run_campaign(
                store, parsed, request.spec, plan, executor, output,
                scenario_id=request.scenario_id, events=events(who),
            )  # fmt: skip

        result = run(campaign, request.output, "")
        random = None
        if baseline is not None:
            where = f"{request.output.rstrip('/')}-random" if request.output else None
            random = run(baseline, where, "random: ")
        durations = run_seconds(store, result.record) if request.junit else {}
    if request.junit:
        Path(request.junit).write_text(campaign_junit_xml(result.record, durations), encoding="utf-8")
    return Exploration(result, random, _replay(request))


def _replay(request: ExploreRequest) -> tuple[str, ...] | None:
    """How the campaign's runs are played again by a seed, when exsce's simulators played them."""
    if request.executor_command or request.plugin or request.faults:
        return None
    if request.simulator == "kinematic":
        return ()
    if request.simulator == "irsim":
        from exsce_dsl.sim.simulators import IrsimSimulator

        default = IrsimSimulator()
        chosen = IrsimSimulator(request.behaviour or default.behaviour, request.scans or default.scans)
        return (chosen.behaviour, chosen.scans)
    return None


def _executor(request: ExploreRequest) -> tuple[AbstractContextManager[Executor], CampaignOptions]:
    """What runs the scenarios and the campaign's plan, from the request."""
    from exsce_dsl.explore.campaign import CampaignOptions
    from exsce_dsl.explore.executors import ExecutorOptions, chosen_executor
    from exsce_dsl.parallel.dask_client import dask_address as scheduler_address

    o = request
    address = scheduler_address(o.dask_address)
    given = ExecutorOptions(
        o.faults, o.stand_in, o.start_master, None, o.speed_up, o.simulator, o.behaviour, o.scans
    )
    chosen = chosen_executor(o.executor_command, o.plugin, given, address)
    campaign = CampaignOptions(
        budget=o.budget, seed=o.seed, runs_per_scenario=o.runs_per_scenario, max_steps=o.max_steps,
        transformations=o.transformations, strategy=o.strategy, tolerance=o.tolerance,
        shrink=not o.no_shrink, stop_at_violation=o.stop_at_violation, jobs=o.jobs, dask_address=address,
    )  # fmt: skip
    return chosen, campaign
