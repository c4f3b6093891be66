"""Oracles: from acceptance criteria and stored runs to verdicts on runs."""

# mypy: implicit-reexport
from __future__ import annotations

from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from exsce_dsl.oracles.baseline import learn_baseline
    from exsce_dsl.oracles.campaign_junit import campaign_junit_xml, run_seconds, steps_text
    from exsce_dsl.oracles.good_runs import good_runs_of
    from exsce_dsl.oracles.judging import Baseline, Verification, build_baseline, compile_learnt, verify_runs
    from exsce_dsl.oracles.plan import PlannedOracle, plan_oracles
    from exsce_dsl.oracles.relations import relation, relation_names
    from exsce_dsl.oracles.report import expectation, junit_xml, verdict_table, verdicts_json
    from exsce_dsl.oracles.trial_report import (
        interval,
        pass_rate_table,
        pass_rates_csv,
        pass_rates_json,
        trial_junit_xml,
    )
    from exsce_dsl.oracles.trial_runs import (
        REPEAT_FOLDER,
        REPEAT_SEED,
        stored_pass_rates,
        trial_of,
        verify_trial,
    )
    from exsce_dsl.oracles.trials import (
        CONFIDENCE,
        REQUIRED_PASS_RATE,
        clause_trials,
        lowest_pass_rate_first,
        percent,
    )
else:
    from exsce_dsl.faces import lazy_face

    __getattr__, __dir__ = lazy_face(__name__, __file__)
