"""Compile the oracles of a scenario into W3C PROV, in the method's shape (report Listings 16, 17, 36).

:func:`compile_oracles` writes one bundle, ``oracle:<scenario>_bundle``, with, for
each metric (and robot) that has oracles:

* the oracle activity ``<scenario>:[<robot>-]<metric>`` (``prov:type=exsce:oracle``,
  ``oracle:metric``, ``oracle:robot`` for a robot's metric, ``exsce:scenario``);
* ``used(oracle, topic:<topic>, [prov:role="topic"])`` for each topic the values it learnt
  from were computed from (the topics declared as ``ros:Topics`` entities), as the stored
  values name them (:mod:`exsce_dsl.oracles.sources`);
* one usage of the scenario whose runs it compares against, per oracle type:
  ``used(<scenario>:<oracle>-baseline; oracle, exsce:<base>, [oracle:relationship,
  oracle:type, oracle:value, oracle:limit, oracle:delta, oracle:tolerance,
  oracle:package])`` (``-metamorphic`` for a metamorphic one);
* for each scenario whose runs the oracles learnt from (its own, a metamorphic clause's base),
  the entity ``<scenario>:baseline_runs-<that scenario>`` (``prov:type=exsce:baseline_runs``,
  ``exsce:scenario``, ``oracle:runs`` the uuids of the runs used, separated by spaces), which
  each oracle used (role ``baseline_runs``), and for each of its stored runs left out (it failed or
  was inconclusive when verified, its mission did not complete, it broke a safety limit) the
  entity ``<scenario>:left_out-<uuid>`` (``prov:type=exsce:left_out_run``, ``exsce:run``,
  ``exsce:scenario``, ``oracle:reason``).  A clause
  written ``at 99 %`` adds ``oracle:confidence`` (0.99) and ``oracle:sampleSize`` (n, the
  runs its prediction interval comes from) to its usage.

Where exsce differs from the method, on purpose:

* the oracles have a bundle of their own, not the scenario's: the scenario bundle
  is compiled from the specification and may be replaced in the store without
  losing the baselines learnt from runs;
* the activity says which scenario it judges (``exsce:scenario``), where the
  method's queries matched the oracle's identifier against the scenario id as text;
* a mission oracle has no ``oracle:robot`` (the method wrote the string ``"None"``);
* the topics an oracle used are those its values were read from (a Nav2 robot's ``/cmd_vel``,
  odometry, TF), not the method's topics for its metric (``/nav_vel`` for every robot); an
  oracle no stored run gave a value to names the method's topics only for robots that declare
  no signals of their own;
* the usages of the base scenario have identifiers (one baseline and one
  metamorphic usage per oracle), so that a baseline can be updated in place;
* every number is an ``xsd:double`` (the method wrote ``xsd:float`` and, for
  ``waypoints_visited``, an integer).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

from prov.constants import PROV_ROLE, PROV_TYPE
from prov.identifier import Namespace, QualifiedName
from prov.model import ProvDocument

from exsce_dsl.errors import ExsceError
from exsce_dsl.model.oracles import Oracle
from exsce_dsl.prov import identifiers as ids
from exsce_dsl.prov.identifiers import DEFAULT_NAMESPACE, Namespaces
from exsce_dsl.prov.records import Attributes, BundleWriter, DocumentWriter

__all__ = ["compile_oracles"]


def compile_oracles(
    scenario_id: str,
    oracles: Sequence[Oracle],
    namespace: str = DEFAULT_NAMESPACE,
    *,
    checked: bool = False,
    runs: Mapping[str, Sequence[str]] | None = None,
    left_out: Mapping[str, Mapping[str, str]] | None = None,
) -> ProvDocument:
    """The PROV document of the oracles that judge runs of scenario ``scenario_id``; ``runs``:
    the runs the oracles learnt from, by the scenario they are runs of, and ``left_out`` the
    runs of those scenarios that they did not learn from, with why (uuid → reason)."""
    if not oracles:
        raise ExsceError(f"scenario '{scenario_id}' has no oracles to write")
    names = Namespaces(namespace)
    writer = DocumentWriter(names, checked)
    for prefix in (ids.EXSCE, ids.ORACLE, ids.ROS, ids.TOPIC):
        writer.document_namespace(prefix)
    ids.check_name(scenario_id, "scenario id")
    bundle_ns = writer.document_namespace(ids.ORACLE)
    w = writer.bundle(bundle_ns[ids.bundle_name(scenario_id)], f"the oracles of '{scenario_id}'")
    parts = w.of_element(scenario_id, names.of_scenario(scenario_id), "scenario")
    exsce, topic_ns = w.fixed(ids.EXSCE), w.fixed(ids.TOPIC)

    groups: dict[tuple[str, str | None, str | None], list[Oracle]] = {}
    for oracle in oracles:
        groups.setdefault((oracle.metric, oracle.robot, oracle.window), []).append(oracle)

    learnt = _learnt_from(w, parts, scenario_id, runs or {}, left_out or {})
    topics = _Topics(topic_ns, {PROV_TYPE: w.term(ids.ROS_TOPICS)})
    for (metric, robot, window), group in groups.items():
        name = ids.check_name(group[0].name, "oracle name")
        activity = parts[name]
        writer.claim(activity, f"the oracle of '{metric}'" + (f" of robot '{robot}'" if robot else ""))
        w.activity(activity, _oracle_facts(w, scenario_id, metric, robot, window, group))
        for compared in dict.fromkeys(oracle.base_scenario for oracle in group):
            if compared in learnt:
                w.used(activity, learnt[compared], {PROV_ROLE: "baseline_runs"})
        _use_topics(w, activity, group, topics)
        _use_bases(writer, w, parts, exsce, name, group)
    return writer.document


def _oracle_facts(
    w: BundleWriter,
    scenario_id: str,
    metric: str,
    robot: str | None,
    window: str | None,
    group: Sequence[Oracle],
) -> Attributes:
    """The oracle activity's attributes: its metric, scenario, robot, window and criteria."""
    t = w.term
    facts: Attributes = {
        PROV_TYPE: t(ids.ORACLE_TYPE_VALUE),
        t(ids.ORACLE_METRIC): metric,
        t(ids.SCENARIO_ATTR): scenario_id,
    }
    if robot is not None:
        facts[t(ids.ORACLE_ROBOT)] = robot
    if window is not None:
        facts[t(ids.ORACLE_WINDOW)] = window
    criteria = sorted({oracle.criterion for oracle in group if oracle.criterion})
    if criteria:
        facts[t(ids.ORACLE_CRITERION)] = "; ".join(criteria)
    return facts


@dataclass
class _Topics:
    """The bundle's topic entities: their namespace and type, and those declared so far."""

    namespace: Namespace
    type: Attributes
    declared: set[QualifiedName] = field(default_factory=set)


def _use_topics(w: BundleWriter, activity: QualifiedName, group: Sequence[Oracle], topics: _Topics) -> None:
    """The oracle uses each topic its metric is computed from (each declared once per bundle)."""
    for topic in dict.fromkeys(topic for oracle in group for topic in oracle.topics):
        topic_id = topics.namespace[ids.topic_local_name(topic)]
        if topic_id not in topics.declared:
            topics.declared.add(topic_id)
            w.entity(topic_id, topics.type)
        w.used(activity, topic_id, {PROV_ROLE: ids.TOPIC_ROLE})


def _use_bases(
    writer: DocumentWriter,
    w: BundleWriter,
    parts: Namespace,
    exsce: Namespace,
    name: str,
    group: Sequence[Oracle],
) -> None:
    """One usage of the scenario each clause compares against, per oracle type (a type twice,
    a range: above and below, names its usages by relation too), carrying the clause."""
    activity = parts[name]
    kinds = [oracle.type for oracle in group]
    for oracle in group:
        suffix = oracle.type.value
        if kinds.count(oracle.type) > 1:
            suffix += f"-{oracle.relation}"
        usage = parts[f"{name}-{suffix}"]
        whose = f" of '{oracle.robot}'" if oracle.robot else ""
        writer.claim(usage, f"the {oracle.type.value} oracle of '{oracle.metric}'{whose}")
        base = exsce[ids.check_name(oracle.base_scenario, "base scenario id")]
        w.used(activity, base, _clause(w, oracle), identifier=usage)


def _clause(w: BundleWriter, oracle: Oracle) -> Attributes:
    """A usage's attributes: the clause's relation, type, bounds, package and runs."""
    t = w.term
    relation: Attributes = {
        t(ids.ORACLE_RELATIONSHIP): oracle.relation,
        t(ids.ORACLE_KIND): oracle.type.value,
    }
    for term, value in (
        (ids.ORACLE_VALUE, oracle.value),
        (ids.ORACLE_LIMIT, oracle.limit),
        (ids.ORACLE_DELTA, oracle.delta),
        (ids.ORACLE_TOLERANCE, oracle.tolerance),
    ):
        if value is not None:
            relation[t(term)] = float(value)
    if oracle.package is not None:
        relation[t(ids.ORACLE_PACKAGE)] = oracle.package
    if oracle.sources:
        relation[t(ids.ORACLE_RUNS)] = " ".join(oracle.sources)
    if oracle.confidence is not None:
        relation[t(ids.ORACLE_CONFIDENCE)] = float(oracle.confidence)
        relation[t(ids.ORACLE_SAMPLE_SIZE)] = len(oracle.sources)
    return relation


def _learnt_from(
    w: BundleWriter,
    parts: Namespace,
    scenario_id: str,
    runs: Mapping[str, Sequence[str]],
    left_out: Mapping[str, Mapping[str, str]],
) -> dict[str, QualifiedName]:
    """The entities of the runs the oracles learnt from (by scenario), and one per run left out."""
    t = w.term
    made = {}
    for base, used in runs.items():
        entity = parts[f"baseline_runs-{ids.check_name(base, 'scenario id')}"]
        facts: Attributes = {
            PROV_TYPE: t(ids.BASELINE_RUNS_TYPE),
            t(ids.SCENARIO_ATTR): base,
            t(ids.ORACLE_RUNS): " ".join(used),
        }
        w.entity(entity, facts)
        made[base] = entity
    for base, reasons in left_out.items():
        for run, reason in reasons.items():
            entity = parts[f"left_out-{ids.check_name(run, 'run uuid')}"]
            w.entity(
                entity,
                {
                    PROV_TYPE: t(ids.LEFT_OUT_RUN_TYPE),
                    t(ids.RUN_ATTR): run,
                    t(ids.SCENARIO_ATTR): base,
                    t(ids.ORACLE_REASON): reason,
                },
            )
    return made
