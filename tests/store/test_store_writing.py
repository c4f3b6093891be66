"""Adding compiled scenarios to a store: new, unchanged, merged, conflicting, replaced."""

from __future__ import annotations

import shutil
from collections.abc import Iterator
from pathlib import Path

import pytest
from prov.model import ProvDocument
from pyoxigraph import Literal, NamedNode, Quad

from exsce_dsl.cli.common import REMEDIES
from exsce_dsl.errors import StoreConflictError, StoreError
from exsce_dsl.lang import load_spec
from exsce_dsl.prov import compile_scenario
from exsce_dsl.rdf import to_quads
from exsce_dsl.store.base import Store
from exsce_dsl.store.embedded import EmbeddedStore
from exsce_dsl.store.remote import RemoteStore
from exsce_dsl.store.writing import add_graphs, add_prov, is_revision, revision_name

from tests.support.paths import EXAMPLES
from tests.support.store_servers import Server, oxigraph_server

BASE = "https://www.sesame-project.org/scenarios/"
SCENARIO_GRAPH = f"{BASE}scenario_c_bundle"
AREA_GRAPH = f"{BASE}environments/classroom_c025_bundle"
PROV = "http://www.w3.org/ns/prov#"


def compiled(spec: Path) -> ProvDocument:
    return compile_scenario(load_spec(str(spec)).scenario(None))


@pytest.fixture(scope="module")
def specs(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A copy of the building C examples, with changed variants of scenario_c."""
    folder = tmp_path_factory.mktemp("specs") / "bc"
    shutil.copytree(EXAMPLES / "brsu_building_c", folder)
    text = (folder / "scenario_c.exsce").read_text()
    reallocated = text.replace("tiago2 does navigate_home_2", "tiago1 does navigate_home_2")
    assert reallocated != text
    (folder / "scenario_c_reallocated.exsce").write_text(reallocated)
    moved = folder.parent / "moved"
    shutil.copytree(folder, moved)
    environment = (moved / "environment.exsce").read_text()
    changed = environment.replace(
        "pose classroom_c025-w001 at (44.80387496948242", "pose classroom_c025-w001 at (44.9"
    )
    assert changed != environment
    (moved / "environment.exsce").write_text(changed)
    return folder


@pytest.fixture(scope="module")
def documents(specs: Path) -> dict[str, ProvDocument]:
    found = {
        name: compiled(specs / f"{name}.exsce")
        for name in ("scenario_a", "scenario_c", "scenario_c_reallocated")
    }
    found["scenario_c_moved"] = compiled(specs.parent / "moved" / "scenario_c.exsce")
    return found


@pytest.fixture(scope="module")
def oxigraph(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Server]:
    with oxigraph_server(tmp_path_factory.mktemp("oxigraph")) as server:
        yield server


@pytest.fixture(params=["memory", "oxigraph"])
def store(request: pytest.FixtureRequest) -> Iterator[Store]:
    found: Store
    if request.param == "memory":
        found = EmbeddedStore(None)
    else:
        url = request.getfixturevalue("oxigraph").url
        found = RemoteStore(f"{url}/query", update_url=f"{url}/update", timeout=20)
        found.clear()
    yield found
    found.close()


def snapshot(store: Store) -> dict[str, int]:
    return store.graph_sizes()


def test_a_scenario_is_added_as_one_named_graph_per_bundle(
    store: Store, documents: dict[str, ProvDocument]
) -> None:
    report = add_prov(store, documents["scenario_c"])
    bundles = {str(b.identifier.uri) for b in documents["scenario_c"].bundles}
    assert set(report.added) == bundles == store.graph_names()
    assert report.statements == sum(snapshot(store).values()) == len(to_quads(documents["scenario_c"]))
    assert report.changed and "added 14 graphs" in report.summary()


def test_adding_the_same_spec_twice_changes_nothing(store: Store, documents: dict[str, ProvDocument]) -> None:
    add_prov(store, documents["scenario_c"])
    before = snapshot(store)
    report = add_prov(store, documents["scenario_c"])  # blank nodes, "0.0" read back as "0": still the same
    assert not report.changed
    assert report.statements == 0 and len(report.unchanged) == 14
    assert "no change" in report.summary()
    assert snapshot(store) == before


def test_area_bundles_are_shared_and_merged(store: Store, documents: dict[str, ProvDocument]) -> None:
    add_prov(store, documents["scenario_a"])
    area_before = len(store.graph(AREA_GRAPH))
    report = add_prov(store, documents["scenario_c"])
    assert AREA_GRAPH in report.merged
    assert len(store.graph(AREA_GRAPH)) > area_before
    for name in ("scenario_a", "scenario_c"):
        assert not add_prov(store, documents[name]).changed


def test_a_changed_scenario_is_refused_with_what_differs(
    store: Store, documents: dict[str, ProvDocument]
) -> None:
    add_prov(store, documents["scenario_c"])
    before = snapshot(store)
    with pytest.raises(StoreConflictError) as refused:
        add_prov(store, documents["scenario_c_reallocated"])
    message = str(refused.value)
    assert refused.value.graphs == (SCENARIO_GRAPH,)
    assert "another version of scenario exsce:scenario_c" in message
    assert "exsce:scenario_c_bundle: mission:mission_c differs" in message
    assert "mission_c:tiago2-task_02 only in the store" in message
    assert "to replace it, add it again with replace" in message  # the library's words
    assert "--replace" in refused.value.remedied.said(REMEDIES)  # the command line's
    assert snapshot(store) == before


def test_a_pose_with_other_coordinates_is_a_conflict(
    store: Store, documents: dict[str, ProvDocument]
) -> None:
    add_prov(store, documents["scenario_c"])
    with pytest.raises(StoreConflictError) as refused:
        add_prov(store, documents["scenario_c_moved"])
    assert refused.value.graphs == (AREA_GRAPH,)
    assert "env:classroom_c025_bundle: point:classroom_c025-w001 has other values (coord:x)" in str(
        refused.value
    )


def test_replace_keeps_the_old_version_as_a_revision(
    store: Store, documents: dict[str, ProvDocument]
) -> None:
    add_prov(store, documents["scenario_c"])
    old = store.graph(SCENARIO_GRAPH)
    report = add_prov(store, documents["scenario_c_reallocated"], replace=True)
    revision = revision_name(SCENARIO_GRAPH, 1)
    assert report.replaced == (SCENARIO_GRAPH,) and report.revisions == (revision,)
    assert is_revision(revision) and not is_revision(SCENARIO_GRAPH)
    # the current graph is the new version, exactly
    assert not add_prov(store, documents["scenario_c_reallocated"]).changed
    # the old version is kept, the scenario entity renamed, and linked by prov:wasRevisionOf
    kept = store.graph(revision)
    assert len(kept) == len(old) + 2
    scenario, old_scenario = NamedNode(f"{BASE}scenario_c"), NamedNode(f"{BASE}scenario_c?revision=1")
    assert store.ask(
        "PREFIX prov: <http://www.w3.org/ns/prov#> "
        "ASK { GRAPH ?g { ?new prov:wasRevisionOf ?old . ?old prov:invalidatedAtTime ?t ; prov:hadMember ?m } }",
        {"g": NamedNode(revision), "new": scenario, "old": old_scenario},
    )
    assert not any(q.subject == scenario and q.predicate.value.endswith("hadMember") for q in kept)
    # a second replacement is revision 2
    report = add_prov(store, documents["scenario_c"], replace=True)
    assert report.revisions == (revision_name(SCENARIO_GRAPH, 2),)
    assert not add_prov(store, documents["scenario_c"]).changed


def test_replacing_a_moved_pose_keeps_the_other_poses(
    store: Store, documents: dict[str, ProvDocument]
) -> None:
    add_prov(store, documents["scenario_a"])
    add_prov(store, documents["scenario_c"])
    poses = {q.subject for q in store.graph(AREA_GRAPH)}
    report = add_prov(store, documents["scenario_c_moved"], replace=True)
    assert report.replaced == (AREA_GRAPH,)
    area = store.graph(AREA_GRAPH)
    assert {q.subject for q in area} == poses
    x = NamedNode("https://robot-schema.org/coordinates/x")
    point = NamedNode(f"{BASE}tasks/points/classroom_c025-w001")
    assert [float(q.object.value) for q in area if q.subject == point and q.predicate == x] == [44.9]
    assert revision_name(AREA_GRAPH, 1) in store.graph_names()
    assert store.ask(
        f"ASK {{ GRAPH ?g {{ ?g2 <{PROV}wasRevisionOf> ?old }} }}",
        {"g2": NamedNode(AREA_GRAPH), "old": NamedNode(revision_name(AREA_GRAPH, 1))},
    )


def test_records_outside_bundles_are_refused(store: Store) -> None:
    document = ProvDocument()
    document.add_namespace("ex", "http://example.org/")
    document.entity("ex:loose")
    with pytest.raises(StoreError, match="outside any bundle"):
        add_prov(store, document)


def test_literals_are_compared_by_value(store: Store) -> None:
    graph = "http://example.org/g"
    xsd = "http://www.w3.org/2001/XMLSchema#"

    def quads(*objects: Literal) -> dict[str, list[Quad]]:
        s, p = NamedNode("http://example.org/s"), NamedNode("http://example.org/p")
        return {graph: [Quad(s, p, o, NamedNode(graph)) for o in objects]}

    written = (
        Literal("0.0", datatype=NamedNode(xsd + "double")),
        Literal("07", datatype=NamedNode(xsd + "int")),
        Literal("1", datatype=NamedNode(xsd + "boolean")),
        Literal("2024-01-01T10:00:00.000+01:00", datatype=NamedNode(xsd + "dateTime")),
    )
    assert add_graphs(store, quads(*written)).added == (graph,)
    assert not add_graphs(store, quads(*written)).changed
    with pytest.raises(StoreConflictError):
        add_graphs(
            store,
            quads(*written[:3], Literal("2024-01-01T10:00:01+01:00", datatype=NamedNode(xsd + "dateTime"))),
        )
