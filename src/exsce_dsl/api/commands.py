"""The ``exscec`` commands as Python functions, with typed results.

Each function is what the command of the same name does, minus the printing: the CLI is a thin
layer over the same library calls.  Each imports what it needs when called, so that a command
pays only for its own (``exscec verify`` does not import SciPy for ``cluster``).  Functions that
read or write runs take the store first (open one with :func:`open_store`, a context manager);
specifications are loaded once with :func:`load` and passed on.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING

from exsce_dsl.model import Scenario
from exsce_dsl.model.document import Specification

if TYPE_CHECKING:
    from prov.model import ProvDocument

    from exsce_dsl.derive import DerivedSpec, ExpectedValue, StoredDerivation
    from exsce_dsl.oracles import Baseline, Verification
    from exsce_dsl.rdf.spec_check import SpecCheck
    from exsce_dsl.runs import IngestResult
    from exsce_dsl.sim.run import SimulatedRun
    from exsce_dsl.similarity.clustering import Clustering
    from exsce_dsl.store import Store
    from exsce_dsl.transform import Request


def load(path: str | Path) -> Specification:
    """Parse, resolve and check a specification (its imports too); a :class:`SpecError` lists
    every error found."""
    from exsce_dsl.lang import load_spec

    return load_spec(path)


def check(path: str | Path) -> SpecCheck:
    """``exscec check``: every diagnostic of the language's checks, then of the SHACL shapes."""
    from exsce_dsl.rdf.spec_check import check_spec

    return check_spec(path)


def compile_prov(
    spec: Specification, scenario: str | None = None, format: str | None = None
) -> ProvDocument | str:
    """``exscec compile``: the PROV of a scenario (and of its generation, when derived); as text in
    ``format`` (``provn``, ``json``, ``xml``, ``ttl``, ``trig``, ``nq``, ``jsonld``) when given."""
    from exsce_dsl.prov.spec import compile_spec_scenario
    from exsce_dsl.rdf import serialize

    document = compile_spec_scenario(spec, scenario)
    return serialize(document, format) if format is not None else document


def prov_text(document: ProvDocument, format: str = "provn") -> str:
    """A compiled PROV document as text in ``format`` (as :func:`compile_prov` gives it)."""
    from exsce_dsl.rdf import serialize

    return serialize(document, format)


def _scenario(spec: Specification | Scenario, scenario: str | None) -> Scenario:
    return spec if isinstance(spec, Scenario) else spec.scenario(scenario)


def simulate(
    spec: Specification | Scenario,
    out_dir: str | Path,
    runs: int = 1,
    *,
    scenario: str | None = None,
    format: str = "ros1",
    seed: int = 0,
    faults: Sequence[str] = (),
    convention: str | None = None,
    cmd_vel_stamped: bool = False,
    dask_address: str | None = None,
    simulator: str = "kinematic",
    behaviour: str | None = None,
    scans: str | None = None,
) -> list[SimulatedRun]:
    """``exscec simulate``: play a scenario ``runs`` times with ``simulator`` (``kinematic``, exsce's
    own executor, or ``irsim``, IR-SIM with ``behaviour`` and ``scans``), one bag per
    run in ``out_dir`` (``faults`` as on the command line: ``overspeed:tiago1``).  With ``dask_address``
    (a Dask scheduler's address) each run is a task on the cluster's workers, which write the bags
    into ``out_dir``: the same path on every worker (a shared filesystem); the same bytes as here."""
    return list(
        simulating(
            spec, out_dir, runs, scenario=scenario, format=format, seed=seed, faults=faults,
            convention=convention, cmd_vel_stamped=cmd_vel_stamped, dask_address=dask_address,
            simulator=simulator, behaviour=behaviour, scans=scans,
        )
    )  # fmt: skip


def simulating(
    spec: Specification | Scenario, out_dir: str | Path, runs: int = 1, *, scenario: str | None = None,
    format: str = "ros1", seed: int = 0, faults: Sequence[str] = (), convention: str | None = None,
    cmd_vel_stamped: bool = False, dask_address: str | None = None, simulator: str = "kinematic",
    behaviour: str | None = None, scans: str | None = None,
) -> Iterator[SimulatedRun]:  # fmt: skip
    """:func:`simulate`, each run given as soon as its bag is written (``exscec simulate`` says
    each as it comes); ``cmd_vel_stamped``: nav2's and move_base's cmd_vel as TwistStamped."""
    from exsce_dsl.sim.executor import Fault
    from exsce_dsl.sim.run import simulate as play
    from exsce_dsl.sim.simulators import simulator_named

    chosen = _scenario(spec, scenario)
    parsed = tuple(Fault.parse(f) for f in faults)
    player = simulator_named(simulator, behaviour, scans)
    return iter(
        play(
            chosen, Path(out_dir), runs, format, seed, parsed, convention, cmd_vel_stamped, dask_address,
            player,
        )
    )  # fmt: skip


def ingest(
    store: Store, spec: Specification | Scenario, bags: Sequence[str | Path], *, scenario: str | None = None,
    jobs: int = 1, dask_address: str | None = None, replace: bool = False, strict: bool = False,
) -> list[IngestResult]:  # fmt: skip
    """``exscec ingest``: each bag's metrics and run PROV into ``store``, one transaction per run
    (a bag that fails is reported in its result, and nothing of it is written); the bags are
    analysed by ``jobs`` processes, or on the Dask cluster whose scheduler is at ``dask_address``.
    With ``replace``, a bag already stored as a run of the scenario is analysed again and its run
    replaced in one transaction (its verdicts dropped), as ``exscec ingest --replace``;
    ``strict``: a bag whose run would lack a metric value fails (``exscec ingest --strict``)."""
    from exsce_dsl.runs import ingest_bags

    chosen = _scenario(spec, scenario)
    return ingest_bags(
        [Path(b) for b in bags],
        chosen,
        store,
        jobs,
        dask_address=dask_address,
        replace=replace,
        strict=strict,
    )


def baseline(
    store: Store, spec: Specification, scenario: str | None = None, *, include_all: bool = False
) -> Baseline:
    """``exscec baseline``: the oracles of a scenario from its acceptance criteria and its good
    stored runs (``include_all``: every run, ``--all-runs``); ``result.runs`` says which runs were
    used and why the others were left out."""
    from exsce_dsl.oracles import build_baseline

    return build_baseline(store, spec, scenario, include_all=include_all)


def verify(
    store: Store, spec: Specification | Scenario, runs: Sequence[str | Path], *, scenario: str | None = None,
    record: bool = True,
) -> Verification:  # fmt: skip
    """``exscec verify``: judge runs (stored uuids or unique prefixes of them, or bags, ingested
    first) against every oracle
    of their scenario; the verdicts go to the store unless ``record`` is False."""
    from exsce_dsl.oracles import verify_runs

    return verify_runs(store, _scenario(spec, scenario), runs, record=record)


def derive(
    spec: Specification,
    steps: Sequence[Request],
    *,
    new_id: str | None = None,
    scenario: str | None = None,
    target: str | Path | None = None,
    expect_from: Store | None = None,
    tolerance: float | None = None,
    include_all: bool = False,
    source: str | Path | None = None,
) -> DerivedSpec:
    """``exscec derive``: a scenario of ``spec`` transformed by ``steps`` in order, e.g.
    ``[("remove_robot", {"robot": "tiago2", "reassign": "tiago1"})]``; the result's ``text`` is
    the new file (write it to ``result.target``).  With ``expect_from``, the file holds the
    acceptance criteria the good stored runs imply (``exscec derive --expect``; ``tolerance``: how
    far from the expected change a run may be, in percent of it, default 10; ``include_all``:
    every stored run, ``--all-runs``); ``source``: the file ``spec`` was read from, as the user
    named it (default: its root file)."""
    from exsce_dsl.derive import RELATIVE_TOLERANCE, derive_spec

    return derive_spec(
        spec,
        spec.root if source is None else source,
        steps,
        new_id=new_id,
        scenario_id=scenario,
        target=target,
        expect_from=expect_from,
        tolerance=RELATIVE_TOLERANCE if tolerance is None else tolerance,
        include_all=include_all,
    )


def add_derived(store: Store, derived: DerivedSpec, *, include_all: bool = False) -> StoredDerivation:
    """``exscec derive --add-to-store``: the derived scenario, its generation and its oracles
    (from the base's good runs; ``include_all``: every run)."""
    from exsce_dsl.derive import add_derivation

    return add_derivation(store, derived, include_all=include_all)


def expect(
    store: Store, spec: Specification | Scenario, scenario: str | None = None, *, include_all: bool = False
) -> list[ExpectedValue]:
    """``exscec expect``: each robot's expected distance travelled and task duration, and the path
    segments each value comes from, from the good stored runs (``include_all``: every run)."""
    from exsce_dsl.derive import SUMMED, expected_metric, learning_runs

    chosen = _scenario(spec, scenario)
    runs = learning_runs(store, include_all)
    return [
        expected_metric(store, chosen, robot.id, metric, runs=runs)
        for robot in chosen.robots
        for metric in SUMMED
    ]


def cluster(
    store: Store,
    scenarios: Sequence[str] = (),
    *,
    method: str = "average",
    k: int | None = None,
    threshold: float | None = None,
    weights: Mapping[str, float] | None = None,
) -> Clustering:
    """``exscec cluster``: stored scenarios clustered by the method's distances."""
    from exsce_dsl.similarity.clustering import cluster_stored

    return cluster_stored(store, scenarios, method, k, threshold, weights)
