"""Identifiers of names from outside (a bag's topics, a bag file's name): any name gets one, the
identifier gives the name back, and it is a PROV-N qualified name and an IRI that prov, rdflib and
Oxigraph take as they are."""

from __future__ import annotations

import re

import pytest
import rdflib
from hypothesis import given, settings
from hypothesis import strategies as st
from prov.model import ProvDocument
from pyoxigraph import NamedNode

from exsce_dsl.prov import identifiers as ids

TOPICS = ids.Namespaces().fixed[ids.TOPIC]

# PN_LOCAL of PROV-N (W3C PROV-N, grammar productions 60-64), written out by hand.
_PN_CHARS_BASE = "A-Za-z\u00c0-\u00d6\u00d8-\u00f6\u00f8-\u02ff\u0370-\u037d\u037f-\u1fff"
_PN_CHARS_U = f"{_PN_CHARS_BASE}_"
_PN_CHARS = f"{_PN_CHARS_U}\\-0-9\u00b7\u0300-\u036f\u203f-\u2040"
_OTHERS = r"(?:[/@~&+*?#$!]|%[0-9A-Fa-f]{2}|\\[='(),\-:;\[\].])"
PN_LOCAL = re.compile(
    rf"(?:[{_PN_CHARS_U}0-9]|{_OTHERS})(?:(?:[{_PN_CHARS}.]|{_OTHERS})*(?:[{_PN_CHARS}]|{_OTHERS}))?"
)
# An IRI path of RFC 3987 restricted to ASCII (what the identifiers hold): pchar and '/'.
IRI_PATH = re.compile(r"(?:[A-Za-z0-9\-._~!$&'()*+,;=:@/]|%[0-9A-F]{2})*")

ODD = "/ ./-_%@~:#?\\\"'<>{}|^`\t\n\x00\x7f\u00e9\u20ac\U0001f916"
names = st.text(
    st.one_of(
        st.sampled_from(ODD),
        st.characters(exclude_categories=()),  # any code point, lone surrogates too
    ),
    max_size=40,
)
topics = st.one_of(names, names.map(lambda n: "/" + n))


def check_identifier(local: str) -> None:
    """``local`` is a PROV-N local name, and ``topic:`` + ``local`` an IRI everyone takes."""
    assert PN_LOCAL.fullmatch(local) or local == "", local
    assert local.isascii() and IRI_PATH.fullmatch(local), local
    assert not any(s in (".", "..") for s in local.split("/")), local  # no dot segment to resolve away
    iri = TOPICS + local
    assert NamedNode(iri).value == iri
    graph = rdflib.Graph()
    graph.add((rdflib.URIRef(iri), rdflib.RDF.type, rdflib.URIRef(TOPICS + "Topic")))
    for fmt in ("nt", "turtle"):
        again = rdflib.Graph().parse(data=graph.serialize(format=fmt), format=fmt)
        assert {str(s) for s in again.subjects()} == {iri}


def check_prov(local: str) -> None:
    """prov writes ``topic:<local>`` in PROV-N, and reads it back from PROV-JSON and PROV-XML."""
    document = ProvDocument()
    namespace = document.add_namespace(ids.TOPIC, TOPICS)
    document.entity(namespace[local])
    assert f"entity(topic:{local})" in document.get_provn()
    for fmt in ("json", "xml"):
        again = ProvDocument.deserialize(content=document.serialize(format=fmt), format=fmt)
        assert [r.identifier.uri for r in again.get_records() if r.identifier] == [TOPICS + local]


@settings(max_examples=300, deadline=None)
@given(topics)
def test_any_topic_name_has_an_identifier_that_gives_it_back(topic: str) -> None:
    local = ids.topic_local_name(topic)
    assert ids.topic_of_name(local) == topic
    check_identifier(local)


@settings(max_examples=40, deadline=None)
@given(topics)
def test_prov_reads_back_every_topic_identifier(topic: str) -> None:
    check_prov(ids.topic_local_name(topic))


@settings(max_examples=200, deadline=None)
@given(names)
def test_any_bag_file_name_has_an_identifier_that_gives_it_back(name: str) -> None:
    local = ids.bag_name(name)
    assert "/" not in local
    assert ids.unescape_name(local) == name
    check_identifier(local or "x")


@pytest.mark.parametrize(
    ("topic", "local"),
    [
        ("/tiago1/nav_vel", "tiago1/nav_vel"),  # the method's names keep their published IRIs
        ("/scan", "scan"),
        ("groundtruth", "@groundtruth"),  # as ROS 1 recorded a relative name
        ("ORB-SLAM", "@ORB-SLAM"),
        ("/ORB SLAM/pose", "ORB%20SLAM/pose"),
        ("/", "@/"),
        ("//x", "@//x"),
        ("/-x/./y.", "%2Dx/%2E/y%2E"),
        ("/~velocity", "%7Evelocity"),
        ("/robot\u00e9", "robot%C3%A9"),
        ("/50%", "50%25"),
    ],
)
def test_topic_identifiers_as_written(topic: str, local: str) -> None:
    assert ids.topic_local_name(topic) == local
    assert ids.topic_of_name(local) == topic
    check_identifier(local)
    check_prov(local)


def test_a_topic_with_and_without_its_slash_are_two_identifiers() -> None:
    assert ids.topic_local_name("groundtruth") != ids.topic_local_name("/groundtruth")
