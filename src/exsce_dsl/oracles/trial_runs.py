"""Trials as the CLI and the Python API run them.

:func:`verify_trial`: runs of a scenario (stored runs, bags, and ``repeat`` new runs played by the
kinematic executor) judged against its oracles as :func:`~exsce_dsl.oracles.judging.verify_runs`
does (the verdicts recorded), and counted per clause (:mod:`exsce_dsl.oracles.trials`).
:func:`stored_pass_rates`: the same statistics over the verdicts the store holds, each run's last.
"""

from __future__ import annotations

import datetime
from collections.abc import Sequence
from pathlib import Path

from exsce_dsl.errors import ExsceError
from exsce_dsl.model import Scenario
from exsce_dsl.model.trials import ClauseTrial, Trial
from exsce_dsl.oracles.judging import Verification, verify_runs
from exsce_dsl.oracles.trials import (
    CONFIDENCE,
    REQUIRED_PASS_RATE,
    check_rates,
    clause_trials,
    lowest_pass_rate_first,
    trial,
)
from exsce_dsl.sim.executor import Fault
from exsce_dsl.sim.run import simulate
from exsce_dsl.store import Store, scenario_ids
from exsce_dsl.store import verdicts as stored_verdicts
from exsce_dsl.suggest import did_you_mean

REPEAT_SEED = 1
"""The seed of ``verify --repeat``'s runs by default: not 0, whose runs are those ``exscec
simulate`` writes by default, which a baseline is usually built from (a run judged against a mean
it is part of passes more easily than a new one)."""
REPEAT_FOLDER = Path("runs") / "repeat"
"""Where ``verify --repeat`` writes its bags by default."""


def verify_trial(
    store: Store,
    scenario: Scenario,
    runs: Sequence[str | Path] = (),
    *,
    repeat: int = 0,
    out_dir: str | Path = REPEAT_FOLDER,
    seed: int = REPEAT_SEED,
    faults: Sequence[str] = (),
    record: bool = True,
    required_pass_rate: float = REQUIRED_PASS_RATE,
    confidence: float = CONFIDENCE,
    now: datetime.datetime | None = None,
) -> Trial:
    """Judge ``runs`` (stored runs or bags, as :func:`verify_runs` takes them) and ``repeat`` new
    runs that the kinematic executor plays (with ``seed`` and ``faults``, bags into ``out_dir``)
    as one trial of ``scenario``: every run's verdicts (recorded unless ``record`` is False) and
    each clause's pass rate, Wilson interval at ``confidence`` and outcome against
    ``required_pass_rate``."""
    check_rates(required_pass_rate, confidence)  # before any run is played
    if repeat < 0:
        raise ExsceError(f"a trial repeats a run 1 or more times, not {repeat}")
    if not runs and not repeat:
        raise ExsceError("a trial needs runs: give stored runs or bags, or repeat a simulated run")
    played: list[str | Path] = []
    if repeat:
        parsed = tuple(Fault.parse(f) for f in faults)
        played = [run.bag for run in simulate(scenario, Path(out_dir), repeat, seed=seed, faults=parsed)]
    elif faults:
        raise ExsceError("faults are planted in repeated runs only: give a number of runs to repeat")
    verification = verify_runs(store, scenario, [*runs, *played], record=record, now=now)
    return trial_of(verification, required_pass_rate, confidence)


def trial_of(
    verification: Verification,
    required_pass_rate: float = REQUIRED_PASS_RATE,
    confidence: float = CONFIDENCE,
) -> Trial:
    """The runs that :func:`verify_runs` judged, as one trial (``execute --runs N --verify``)."""
    return trial(
        verification.scenario.id,
        verification.runs,
        verification.verdicts,
        required_pass_rate,
        confidence,
        verification.warnings,
    )


def stored_pass_rates(
    store: Store,
    scenario: str | None = None,
    *,
    required_pass_rate: float = REQUIRED_PASS_RATE,
    confidence: float = CONFIDENCE,
) -> list[ClauseTrial]:
    """Every clause's pass rate over the verdicts the store holds (each run's last validation; of
    ``scenario``'s runs, or of all), lowest first: the clauses that fail most, or are flakiest,
    on top.  Raises :class:`ExsceError` for a scenario the store does not hold."""
    if scenario is not None:
        known = scenario_ids(store)
        if scenario not in known:
            raise ExsceError(f"the store holds no scenario '{scenario}'{did_you_mean(scenario, known)}")
    clauses = clause_trials(stored_verdicts(store, scenario), required_pass_rate, confidence)
    return lowest_pass_rate_first(clauses)
