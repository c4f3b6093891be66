"""What a trial's runs say of a relation: violated when it failed in more than half of them,
inconclusive when the runs that could not judge it (cut short, not covered by their recordings)
could have made it so, else passed.  Hand-made verdicts, counted by hand."""

from __future__ import annotations

from exsce_dsl.explore.campaign import _violations
from exsce_dsl.model.campaign import Relation
from exsce_dsl.model.verdicts import Outcome, Verdict

SPEED = Relation("max_velocity", "tiago1", "below_max")


def _verdicts(*outcomes: Outcome) -> list[Verdict]:
    return [
        Verdict(f"run{n}", "s", "c", "tiago1-max_velocity", "max_velocity", "tiago1", "below_max", outcome)
        for n, outcome in enumerate(outcomes)
    ]


P, F, U = Outcome.PASSED, Outcome.FAILED, Outcome.INCONCLUSIVE  # U: undecided


def test_a_single_run_cut_short_leaves_its_relation_inconclusive_not_passed() -> None:
    found = _violations(_verdicts(U), 1)
    assert found.checked == (SPEED,) and found.violated == () and found.inconclusive == (SPEED,)


def test_a_majority_failing_violates_and_one_that_undecided_runs_could_make_is_inconclusive() -> None:
    cases = {
        (F, F, P): ("violated", ()),  # 2 of 3 failed
        (F, U, P): ("inconclusive", (SPEED,)),  # 1 failed; with the undecided one, 2 of 3
        (U, U, P): ("inconclusive", (SPEED,)),  # nothing failed, but 2 of 3 could have
        (U, P, P): ("passed", ()),  # 2 of 3 passed: the third cannot change it
        (F, P, P): ("passed", ()),
        (F, P): ("passed", ()),  # half is not more than half, as before
        (U, P): ("passed", ()),
        (F, U): ("inconclusive", (SPEED,)),
    }
    for outcomes, (expected, undecided) in cases.items():
        found = _violations(_verdicts(*outcomes), len(outcomes))
        outcome = "violated" if found.violated else "inconclusive" if found.inconclusive else "passed"
        assert (outcome, found.inconclusive) == (expected, undecided), outcomes
        if found.violated:
            assert found.failing == tuple(
                (f"run{n}", "verdict-tiago1-max_velocity-below_max") for n, o in enumerate(outcomes) if o is F
            )
