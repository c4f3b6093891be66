"""Exploration campaigns as the store holds them (see :mod:`exsce_dsl.prov.campaign`)."""

from __future__ import annotations

import datetime
import json

from exsce_dsl.model.campaign import (
    CampaignPlan,
    CampaignRecord,
    CampaignTrial,
    CheckedRelation,
    Request,
    Shrinking,
    ShrinkTry,
)
from exsce_dsl.prov.identifiers import DEFAULT_NAMESPACE
from exsce_dsl.store.base import Store
from exsce_dsl.store.queries.terms import float_of, int_of, run_query, text_of

__all__ = ["campaign_record", "campaign_trials", "campaigns", "shrinkings"]


def _steps(text: str | None) -> tuple[Request, ...]:
    return tuple(
        (str(name), {str(k): str(v) for k, v in arguments.items()})
        for name, arguments in json.loads(text or "[]")
    )


def _relations(text: str | None) -> tuple[CheckedRelation, ...]:
    return tuple(CheckedRelation.parse(part) for part in (text or "").split(";") if part.strip())


def _plans(
    store: Store, base: str | None, namespace: str
) -> list[tuple[CampaignPlan, datetime.datetime | None]]:
    """Every campaign's plan and start (of the base scenario ``base`` only, when given), oldest first."""
    rows = run_query(store, "campaigns", {"scenario": base} if base else {}, namespace)
    found = []
    for row in rows:
        transformations = text_of(row["transformations"]) or "all"
        plan = CampaignPlan(
            id=text_of(row["campaign"]) or "",
            base=text_of(row["base"]) or "",
            budget=int_of(row["budget"]),
            seed=int_of(row["seed"]),
            runs_per_scenario=int_of(row["runs_per_scenario"]),
            max_steps=int_of(row["max_steps"]),
            transformations=() if transformations == "all" else tuple(transformations.split()),
            executor=text_of(row["executor"]) or "",
            strategy=text_of(row["strategy"]) or "",
            relations=(text_of(row["relations"]) or "").lower() in ("true", "1"),
            tolerance=float_of(row["tolerance"]) or 0.0,
        )
        started = text_of(row["started"])
        found.append((plan, datetime.datetime.fromisoformat(started) if started else None))
    return found


def campaigns(
    store: Store, base: str | None = None, namespace: str = DEFAULT_NAMESPACE
) -> list[CampaignPlan]:
    """Every campaign's plan (of the base scenario ``base`` only, when given), oldest first."""
    return [plan for plan, _ in _plans(store, base, namespace)]


def campaign_trials(store: Store, campaign: str, namespace: str = DEFAULT_NAMESPACE) -> list[CampaignTrial]:
    """The trials of ``campaign`` written so far, in the order they were drawn."""
    return [
        CampaignTrial(
            campaign,
            int_of(row["order"]),
            text_of(row["scenario"]) or "",
            _steps(text_of(row["steps"])),
            tuple((text_of(row["runs"]) or "").split()),
            _relations(text_of(row["checked"])),
            _relations(text_of(row["violated"])),
            inconclusive=_relations(text_of(row["inconclusive"])),
        )
        for row in run_query(store, "campaign_trials", {"campaign": campaign}, namespace)
    ]


def shrinkings(store: Store, campaign: str, namespace: str = DEFAULT_NAMESPACE) -> list[Shrinking]:
    """The shrinkings of ``campaign`` written so far, with their tries in order."""
    found: dict[int, Shrinking] = {}
    tries: dict[int, list[ShrinkTry]] = {}
    for row in run_query(store, "campaign_shrinkings", {"campaign": campaign}, namespace):
        number = int_of(row["order"])
        if number not in found:
            found[number] = Shrinking(
                campaign,
                number,
                CheckedRelation.parse(text_of(row["relation"]) or ""),
                int_of(row["trial"]),
                text_of(row["original"]) or "",
                text_of(row["minimal"]) or "",
                _steps(text_of(row["steps"])),
                (),
            )
            tries[number] = []
        if row["try_order"] is not None:
            violated = (text_of(row["try_violated"]) or "").lower() in ("true", "1")
            tries[number].append(
                ShrinkTry(text_of(row["try_scenario"]) or "", _steps(text_of(row["try_steps"])), violated)
            )
    return [
        Shrinking(
            s.campaign, s.number, s.relation, s.trial, s.original, s.minimal, s.minimal_steps, tuple(tries[n])
        )
        for n, s in sorted(found.items())
    ]


def campaign_record(store: Store, campaign: str, namespace: str = DEFAULT_NAMESPACE) -> CampaignRecord | None:
    """All the store holds of ``campaign`` (None when it holds nothing)."""
    found = [(plan, started) for plan, started in _plans(store, None, namespace) if plan.id == campaign]
    if not found:
        return None
    plan, started = found[-1]
    return CampaignRecord(
        plan,
        started,
        tuple(campaign_trials(store, campaign, namespace)),
        tuple(shrinkings(store, campaign, namespace)),
    )
