"""PROV in RDF: the PROV-O mapping (quads, named graphs per bundle), the text
formats written from it, the vocabulary and the packaged resources."""

from __future__ import annotations

import datetime
import importlib.util
import os
import subprocess
import sys
import textwrap
from importlib.resources import files
from pathlib import Path

import pytest
from prov.constants import PROV as PROV_NAMES
from prov.constants import XSD_DECIMAL
from prov.model import Literal as ProvLiteral
from prov.model import ProvDocument
from pyoxigraph import DefaultGraph, Quad
from pyoxigraph import Literal as OxLiteral
from pyoxigraph import NamedNode as OxNamedNode
from pyoxigraph import Store as OxStore
from rdflib import RDF, RDFS, Dataset, Graph, Literal, Namespace, URIRef
from rdflib.compare import isomorphic

from exsce_dsl.errors import ExportError
from exsce_dsl.lang import load_spec
from exsce_dsl.prov import compile_scenario, identifiers
from exsce_dsl.prov.identifiers import DEFAULT_NAMESPACE, Namespaces
from exsce_dsl.rdf import FORMATS, as_dataset, serialize, text, to_dataset, to_quads
from exsce_dsl.rdf.shacl import shape_names, shapes_graph, vocabulary_graph

from tests.support.paths import EXAMPLES
from tests.support.scenario_builders import large_scenario, merged, scenario_c

HAS_LXML = importlib.util.find_spec("lxml") is not None

EXSCE = Namespace(DEFAULT_NAMESPACE)
PROV = Namespace("http://www.w3.org/ns/prov#")
TASK = Namespace(DEFAULT_NAMESPACE + "tasks/")
POSE = Namespace(DEFAULT_NAMESPACE + "tasks/waypoints/")
POINT = Namespace(DEFAULT_NAMESPACE + "tasks/points/")
ENV = Namespace(DEFAULT_NAMESPACE + "environments/")
ROBOT = Namespace(DEFAULT_NAMESPACE + "robots/")
MISSION_C = Namespace(DEFAULT_NAMESPACE + "missions/mission_c/")
COORD = Namespace("https://robot-schema.org/coordinates/")
XSD_DOUBLE = URIRef("http://www.w3.org/2001/XMLSchema#double")
XSD_DATETIME = URIRef("http://www.w3.org/2001/XMLSchema#dateTime")


# -- every format ----------------------------------------------------------------


def every_format(document: ProvDocument) -> dict[str, str]:
    return {fmt: serialize(document, fmt) for fmt in FORMATS if fmt != "xml" or HAS_LXML}


def test_compiling_twice_gives_the_same_text_in_every_format() -> None:
    assert every_format(compile_scenario(scenario_c())) == every_format(compile_scenario(scenario_c()))


def test_the_text_does_not_depend_on_the_process() -> None:
    """rdflib keeps named graphs in a set: string hashing must not reorder them."""
    script = textwrap.dedent(
        f"""
        import hashlib, sys
        sys.path[:0] = [{str(Path(__file__).parent)!r}, {str(Path(__file__).parents[1])!r}]
        from test_rdf import every_format
        from tests.support.scenario_builders import scenario_c
        from exsce_dsl.prov import compile_scenario
        texts = every_format(compile_scenario(scenario_c()))
        print(hashlib.sha256(repr(sorted(texts.items())).encode()).hexdigest())
        """
    )
    digests = {
        subprocess.run(
            [sys.executable, "-c", script],
            capture_output=True,
            text=True,
            check=True,
            env={**os.environ, "PYTHONHASHSEED": seed},
        ).stdout
        for seed in ("1", "2", "3")
    }
    assert len(digests) == 1


def test_an_unknown_format_is_refused() -> None:
    with pytest.raises(ExportError, match="unknown PROV format 'dot'"):
        serialize(compile_scenario(scenario_c()), "dot")


# -- PROV-O in named graphs ----------------------------------------------------


BUNDLES_C = {
    EXSCE["scenario_c_bundle"],
    ENV["brsu_building_c_with_doors_bundle"],
    ENV["classroom_c025_bundle"],
    ENV["classroom_c022_bundle"],
    ENV["classroom_c018_bundle"],
    ROBOT["tiago1_bundle"],
    ROBOT["tiago2_bundle"],
    TASK["delivery_a_bundle"],
    TASK["delivery_b_bundle"],
    TASK["navigate_home_1_bundle"],
    TASK["navigate_home_2_bundle"],
}


@pytest.mark.filterwarnings("ignore:.*(default_context|ConjunctiveGraph) is deprecated")
@pytest.mark.parametrize(
    ("fmt", "rdflib_format"), [("trig", "trig"), ("nq", "nquads"), ("jsonld", "json-ld")]
)
def test_rdf_with_named_graphs_reads_back(fmt: str, rdflib_format: str) -> None:
    document = compile_scenario(scenario_c())
    dataset = Dataset()
    dataset.parse(data=serialize(document, fmt), format=rdflib_format)
    graphs = {g.identifier: g for g in dataset.graphs() if len(g)}
    assert set(graphs) == BUNDLES_C

    def holds(bundle: URIRef, s: URIRef, p: URIRef, o: URIRef | Literal) -> bool:
        return (s, p, o) in graphs[bundle]

    scenario, c025 = EXSCE["scenario_c_bundle"], ENV["classroom_c025_bundle"]
    assert holds(scenario, EXSCE["scenario_c"], RDF.type, EXSCE["ConcreteScenario"])
    assert holds(scenario, EXSCE["scenario_c"], PROV.hadMember, ROBOT["tiago1"])
    plan = MISSION_C["tiago1-task_01"]
    assert holds(scenario, plan, PROV.wasDerivedFrom, TASK["delivery_a"])
    assert holds(scenario, plan, PROV.hadPrimarySource, TASK["delivery_a"])
    start = URIRef(DEFAULT_NAMESPACE + "scenario_c/tiago1-start-pose")
    gazebo = URIRef(DEFAULT_NAMESPACE + "robots/tiago1/gazebo_model")
    assert holds(scenario, gazebo, PROV.qualifiedDerivation, start)
    assert holds(scenario, start, RDF.type, PROV.Derivation)
    assert holds(scenario, start, PROV.entity, POSE["classroom_c025-w001-R0.00_P0.00_Y0.00"])
    assert holds(scenario, start, PROV.hadRole, Literal("start_pose"))
    assert holds(scenario, start, EXSCE.scenario, Literal("scenario_c"))
    x = Literal("44.80387496948242", datatype=XSD_DOUBLE)
    assert holds(c025, POINT["classroom_c025-w001"], COORD.x, x)
    assert holds(c025, POINT["classroom_c025-w001"], RDF.type, PROV.Entity)
    hardware = URIRef(DEFAULT_NAMESPACE + "robots/tiago1/hardware-config")
    assert holds(ROBOT["tiago1_bundle"], hardware, EXSCE.torso, Literal(True))
    assert holds(ROBOT["tiago1_bundle"], hardware, PROV.type, Literal("hardware-config"))
    waypoint = URIRef(DEFAULT_NAMESPACE + "tasks/delivery_a-subtask_001/w_002")
    subtask = TASK["delivery_a-subtask_001"]
    assert holds(TASK["delivery_a_bundle"], subtask, PROV.qualifiedDerivation, waypoint)
    assert holds(TASK["delivery_a_bundle"], waypoint, PROV.hadRole, Literal("waypoint"))
    # The pose belongs to its area's graph, not the task's.
    assert (POSE["classroom_c018-w001-R0.00_P0.00_Y-0.641"], RDF.type, PROV.Entity) not in graphs[
        TASK["delivery_a_bundle"]
    ]
    # Each format reads back as the same dataset.
    reference = to_dataset(document)
    for graph in reference.graphs():
        if len(graph):
            assert isomorphic(graphs[graph.identifier], graph)


def odd_document() -> ProvDocument:
    """Every kind of record and value the mapping knows, with text that needs escaping."""
    document = ProvDocument()
    ex = document.add_namespace("ex", "https://example.org/ns/")
    bundle = document.bundle(ex["b"])
    when = datetime.datetime(2023, 6, 26, 21, 47, 9, tzinfo=datetime.timezone.utc)
    bundle.entity(
        ex["e"],
        {
            "ex:text": 'say "hi"\\ now\nand then\tafter, ünïcode',
            "ex:label": ProvLiteral("bonjour", langtag="fr"),
            "ex:count": 3,
            "ex:big": 2**40,
            "ex:flag": False,
            "ex:when": when,
            "ex:typed": ProvLiteral("1.50", XSD_DECIMAL),
            "prov:label": "an entity",
        },
    )
    bundle.entity(ex["odd.local."], {"prov:type": "plain-type"})
    bundle.activity(ex["run"], when, when, {"prov:type": ex["Run"]})
    bundle.agent(ex["robot"])
    bundle.usage(ex["run"], ex["e"], when, identifier=ex["u1"], other_attributes={"prov:role": "in"})
    bundle.generation(ex["odd.local."], ex["run"], when)
    bundle.association(ex["run"], ex["robot"], ex["e"])
    bundle.start(ex["run"], ex["e"], None, when)
    bundle.end(ex["run"], ex["e"])
    bundle.communication(ex["run"], ex["run"])
    bundle.attribution(ex["e"], ex["robot"])
    bundle.delegation(ex["robot"], ex["robot"], ex["run"])
    bundle.influence(ex["e"], ex["robot"])
    bundle.invalidation(ex["e"], ex["run"])
    bundle.specialization(ex["e"], ex["odd.local."])
    bundle.alternate(ex["e"], ex["odd.local."])
    bundle.derivation(ex["e"], ex["odd.local."], other_attributes={"prov:type": PROV_NAMES["Revision"]})
    document.entity(ex["top"])
    return document


@pytest.mark.filterwarnings("ignore:.*(default_context|ConjunctiveGraph) is deprecated")
def test_rdf_texts_read_back_for_every_kind_of_record_and_value() -> None:
    document = odd_document()
    reference = to_dataset(document)
    for fmt, rdflib_format in [("trig", "trig"), ("nq", "nquads"), ("jsonld", "json-ld")]:
        dataset = Dataset()
        dataset.parse(data=serialize(document, fmt), format=rdflib_format)
        for graph in reference.graphs():
            assert isomorphic(dataset.graph(graph.identifier), graph), fmt
    turtle = Graph().parse(data=serialize(document, "ttl"), format="turtle")
    assert isomorphic(turtle, merged(document))
    ex = Namespace("https://example.org/ns/")
    triples = merged(document)
    assert (ex["e"], ex["label"], Literal("bonjour", lang="fr")) in triples
    assert (ex["run"], PROV.used, ex["e"]) in triples
    assert (ex["run"], PROV.qualifiedUsage, ex["u1"]) in triples
    assert (ex["u1"], PROV.atTime, Literal(when_text(), datatype=XSD_DATETIME)) in triples
    assert (ex["e"], PROV.wasRevisionOf, ex["odd.local."]) in triples
    assert (ex["odd.local."], PROV.type, Literal("plain-type")) in triples
    assert "<https://example.org/ns/odd.local.>" in serialize(document, "ttl")


def when_text() -> str:
    return "2023-06-26T21:47:09+00:00"


def test_turtle_merges_the_bundles_and_keeps_numbers_whole() -> None:
    document = compile_scenario(scenario_c())
    text = serialize(document, "ttl")
    graph = Graph().parse(data=text, format="turtle")
    assert isomorphic(graph, merged(document))
    assert '"44.80387496948242"^^xsd:double' in text
    assert (EXSCE["scenario_c"], PROV.hadMember, ENV["brsu_building_c_with_doors"]) in graph


def test_relations_without_qualifiers_are_plain_triples() -> None:
    document = compile_scenario(scenario_c())
    dataset = to_dataset(document)
    graph = dataset.graph(ENV["classroom_c025_bundle"])
    assert not list(graph.triples((None, RDF.type, PROV.Membership)))
    assert len(list(graph.triples((None, PROV.hadMember, None)))) == 8


# -- quads -------------------------------------------------------------------------


def test_to_quads_gives_each_bundle_its_named_graph_and_each_quad_once() -> None:
    document = compile_scenario(scenario_c())
    quads = to_quads(document)
    assert all(isinstance(q, Quad) for q in quads)
    assert len(set(quads)) == len(quads)
    assert {URIRef(q.graph_name.value) for q in quads if isinstance(q.graph_name, OxNamedNode)} == BUNDLES_C
    assert not [q for q in quads if isinstance(q.graph_name, DefaultGraph)]
    x = OxLiteral("44.80387496948242", datatype=OxNamedNode(str(XSD_DOUBLE)))
    point = OxNamedNode(str(POINT["classroom_c025-w001"]))
    assert Quad(point, OxNamedNode(str(COORD.x)), x, OxNamedNode(str(ENV["classroom_c025_bundle"]))) in quads


def test_the_quads_are_what_every_text_format_holds() -> None:
    for document in (compile_scenario(scenario_c()), odd_document()):
        quads = to_quads(document)
        assert text.nquads(quads) == serialize(document, "nq")
        assert isomorphic_datasets(as_dataset(quads), to_dataset(document))


def isomorphic_datasets(a: Dataset, b: Dataset) -> bool:
    names = {g.identifier for g in a.graphs() if len(g)} | {g.identifier for g in b.graphs() if len(g)}
    return all(isomorphic(a.graph(name), b.graph(name)) for name in names)


def test_records_outside_bundles_are_in_the_default_graph() -> None:
    quads = to_quads(odd_document())
    top = [q for q in quads if q.subject == OxNamedNode("https://example.org/ns/top")]
    assert top and all(isinstance(q.graph_name, DefaultGraph) for q in top)


def test_a_name_that_is_no_iri_is_refused() -> None:
    document = ProvDocument()
    ex = document.add_namespace("ex", "https://example.org/a b/")
    document.entity(ex["e"])
    with pytest.raises(ExportError, match="'https://example.org/a b/e' is not an absolute IRI"):
        to_quads(document)


def test_the_store_takes_the_quads_as_they_are() -> None:
    store = OxStore()
    quads = to_quads(compile_scenario(large_scenario(robots=5, poses=100, tasks=10)))
    store.extend(quads)
    assert len(store) == len(quads)
    assert {g.value for g in store.named_graphs()} == {
        q.graph_name.value for q in quads if isinstance(q.graph_name, OxNamedNode)
    }


# -- the vocabulary ------------------------------------------------------------------

RDFS_NS = "http://www.w3.org/2000/01/rdf-schema#"
OURS = (DEFAULT_NAMESPACE, "https://robot-schema.org/", "http://wiki.ros.org/")
PROV_CLASSES = {PROV.Entity, PROV.Activity, PROV.Agent, PROV.Collection}


def declared(vocabulary: Graph, kind: URIRef) -> set[URIRef]:
    return {s for s in vocabulary.subjects(RDF.type, kind) if isinstance(s, URIRef)}


def test_every_class_and_property_the_examples_use_is_in_the_vocabulary() -> None:
    vocabulary = vocabulary_graph()
    classes, properties = declared(vocabulary, RDFS.Class), declared(vocabulary, RDF.Property)
    used_classes: set[URIRef] = set()
    used_properties: set[URIRef] = set()
    for path in sorted(EXAMPLES.rglob("scenario*.exsce")) + [EXAMPLES / "drones" / "orchard.exsce"]:
        for q in to_quads(compile_scenario(load_spec(path).scenario())):
            if q.predicate.value == str(RDF.type):
                used_classes.add(URIRef(q.object.value))  # type: ignore[union-attr]
            else:
                used_properties.add(URIRef(q.predicate.value))
    assert {c for c in used_classes if c.startswith(OURS)} - classes == set()
    assert {p for p in used_properties if p.startswith(OURS)} - properties == set()


def test_every_term_of_the_identifiers_module_is_in_the_vocabulary() -> None:
    """Every class and property exsce writes is named in prov/identifiers (one place for all)."""
    vocabulary = vocabulary_graph()
    known = declared(vocabulary, RDFS.Class) | declared(vocabulary, RDF.Property)
    names = Namespaces()
    terms = {k: t for k, t in vars(identifiers).items() if isinstance(t, identifiers.Term)}
    assert len(terms) > 40
    missing = {k: str(t) for k, t in terms.items() if t.prefix != "prov" and URIRef(names.iri(t)) not in known}
    assert missing == {}


def test_the_method_s_run_oracle_and_transformation_terms_are_in_the_vocabulary() -> None:
    vocabulary = vocabulary_graph()
    classes, properties = declared(vocabulary, RDFS.Class), declared(vocabulary, RDF.Property)
    runs, oracle = Namespace(DEFAULT_NAMESPACE + "runs/"), Namespace(DEFAULT_NAMESPACE + "oracles/")
    ros = Namespace("http://wiki.ros.org/")
    assert {
        EXSCE.run, EXSCE.task_execution, EXSCE.action, ros.Bags, ros.Topics, EXSCE.topic,
        EXSCE.output_metric, EXSCE.oracle, EXSCE.transform, EXSCE.generation, EXSCE.hotspot,
        ros.Parameter_Server,
    } <= classes
    assert {
        runs.metricType, EXSCE.run, EXSCE.runs, EXSCE.robot, EXSCE.file_path, EXSCE.metric,
        oracle.metric, oracle.robot, oracle.relationship, oracle.package, oracle.type, oracle.value,
        oracle.limit, oracle.delta, oracle.tolerance, EXSCE.transform, EXSCE.pkg, EXSCE.allocation_order,
    } <= properties


def test_every_term_has_a_label_a_comment_and_a_place_under_prov_o() -> None:
    vocabulary = vocabulary_graph()
    label, comment = URIRef(RDFS_NS + "label"), URIRef(RDFS_NS + "comment")
    terms = declared(vocabulary, RDFS.Class) | declared(vocabulary, RDF.Property)
    assert len(terms) > 50
    for name in terms:
        assert vocabulary.value(name, label) is not None, name
        assert vocabulary.value(name, comment) is not None, name
    for name in declared(vocabulary, RDFS.Class):
        assert set(vocabulary.transitive_objects(name, RDFS.subClassOf)) & PROV_CLASSES, name


def test_every_constraint_of_the_shapes_says_what_is_expected() -> None:
    """Each property shape (and each node shape with constraints of its own, but no nested
    helper shape) carries a message, which is what `exscec check` prints."""
    shapes = shapes_graph()
    sh = Namespace("http://www.w3.org/ns/shacl#")
    nested = set(shapes.objects(None, sh.node))
    for owner, property_shape in shapes.subject_objects(sh.property):
        if owner in nested or not isinstance(owner, URIRef):  # helpers, and parts of sh:or / sh:not
            continue
        assert shapes.value(property_shape, sh.message) is not None, (owner, property_shape)
    for shape in set(shapes.subjects(RDF.type, sh.NodeShape)) - nested:
        if shapes.value(shape, sh["class"]) is not None or shapes.value(shape, sh["or"]) is not None:
            assert shapes.value(shape, sh.message) is not None, shape


def test_the_vocabulary_and_shapes_are_package_resources() -> None:
    folder = files("exsce_dsl") / "rdf"
    assert (folder / "vocabulary.ttl").is_file()
    assert {"spec", "oracles", "derivations"} <= set(shape_names())
    for name in shape_names():
        assert len(shapes_graph((name,))) > 0


def test_exscec_compile_offers_every_format() -> None:
    from exsce_dsl.cli.spec_commands import PROV_FORMATS

    assert PROV_FORMATS == FORMATS
