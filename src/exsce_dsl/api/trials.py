"""Trials from Python: repeated runs judged as one, and the store's pass rates per clause.

``verify_trial`` is ``exscec verify --trial`` / ``--repeat N``; ``flaky`` is ``exscec flaky``.
Both give each clause a :class:`~exsce_dsl.model.trials.ClauseTrial`: the runs that passed,
failed and were inconclusive, the pass rate with its Wilson interval (``low``, ``high``) and the
outcome (passed, failed, flaky, inconclusive) against the required pass rate.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from exsce_dsl.model import Scenario
from exsce_dsl.model.document import Specification
from exsce_dsl.model.trials import ClauseTrial, Trial
from exsce_dsl.oracles import CONFIDENCE, REPEAT_FOLDER, REPEAT_SEED, REQUIRED_PASS_RATE, stored_pass_rates
from exsce_dsl.oracles import verify_trial as judge
from exsce_dsl.store import Store


def verify_trial(
    store: Store, spec: Specification | Scenario, runs: Sequence[str | Path] = (), *,
    scenario: str | None = None, repeat: int = 0, out_dir: str | Path = REPEAT_FOLDER,
    seed: int = REPEAT_SEED, faults: Sequence[str] = (), record: bool = True,
    required_pass_rate: float = REQUIRED_PASS_RATE, confidence: float = CONFIDENCE,
) -> Trial:  # fmt: skip
    """``exscec verify --trial`` (and ``--repeat N``): ``runs`` (stored uuids, unique prefixes or
    bags) and ``repeat`` new runs of the kinematic executor (``seed``, ``faults`` as on the
    command line, bags into ``out_dir``) judged as one trial; the verdicts go to the store unless
    ``record`` is False.  The result's ``clauses`` hold each clause's pass rate and outcome, its
    ``outcome`` the trial's (failed, else flaky, else inconclusive, else passed)."""
    chosen = spec if isinstance(spec, Scenario) else spec.scenario(scenario)
    return judge(
        store, chosen, runs, repeat=repeat, out_dir=out_dir, seed=seed, faults=faults, record=record,
        required_pass_rate=required_pass_rate, confidence=confidence,
    )  # fmt: skip


def flaky(
    store: Store,
    scenario: str | None = None,
    *,
    required_pass_rate: float = REQUIRED_PASS_RATE,
    confidence: float = CONFIDENCE,
) -> list[ClauseTrial]:
    """``exscec flaky``: every clause's pass rate over the stored verdicts (each run's last; of
    ``scenario``'s runs, or all), lowest first."""
    return stored_pass_rates(store, scenario, required_pass_rate=required_pass_rate, confidence=confidence)
