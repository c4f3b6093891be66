"""The real ``exscec`` on stores: compile --store, store info|graphs|export|clear."""

from __future__ import annotations

import shutil
from collections.abc import Iterator
from pathlib import Path

import pytest
from pyoxigraph import RdfFormat, parse

from tests.support.cli import exscec_here
from tests.support.paths import EXAMPLES
from tests.support.store_servers import Server, oxigraph_server

SCENARIO_C = EXAMPLES / "brsu_building_c" / "scenario_c.exsce"


@pytest.fixture(scope="module")
def oxigraph(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Server]:
    with oxigraph_server(tmp_path_factory.mktemp("oxigraph")) as server:
        yield server


def test_compile_adds_to_the_project_store_and_store_commands_show_it(in_tmp: Path) -> None:
    added = exscec_here("compile", str(SCENARIO_C), "--store")
    assert added.returncode == 0, added.stderr
    assert added.stdout == ""  # no PROV printed unless -f or -o
    assert added.stderr.strip() == ".exsce/store: added 14 graphs (377 statements written)"
    again = exscec_here("compile", str(SCENARIO_C), "--store", "-f", "nq")
    assert again.returncode == 0 and "no change" in again.stderr and again.stdout.count(" .\n") == 377

    info = exscec_here("store", "info")
    assert info.returncode == 0, info.stderr
    assert info.stdout.splitlines() == [
        "store:      .exsce/store (embedded Oxigraph)",
        "graphs:     14 (+ 0 revisions, + 0 of its indexes)",
        "statements: 377",
    ]
    graphs = exscec_here("store", "graphs")
    assert "https://www.sesame-project.org/scenarios/scenario_c_bundle" in graphs.stdout
    assert len(graphs.stdout.splitlines()) == 14 and "14 graphs, 377 statements" in graphs.stderr

    exported = exscec_here("store", "export", "-f", "nq", "-o", "all.nq")
    assert exported.returncode == 0, exported.stderr
    quads = list(parse((in_tmp / "all.nq").read_bytes(), format=RdfFormat.N_QUADS))
    assert len(quads) == 377 and len({q.graph_name for q in quads}) == 14
    trig = exscec_here("store", "export")
    assert len(list(parse(trig.stdout, format=RdfFormat.TRIG))) == 377

    refused = exscec_here("store", "clear")  # asks; no answer on stdin
    assert refused.returncode != 0
    cleared = exscec_here("store", "clear", "--yes")
    assert cleared.returncode == 0 and "removed 14 graphs" in cleared.stderr
    assert exscec_here("store", "graphs").stdout == ""


def test_compile_to_a_sparql_endpoint_refuses_a_changed_scenario_then_replaces_it(
    in_tmp: Path, oxigraph: Server
) -> None:
    shutil.copytree(EXAMPLES / "brsu_building_c", in_tmp / "bc")
    url = f"oxigraph+{oxigraph.url}"
    assert exscec_here("compile", "bc/scenario_c.exsce", "--store", url).returncode == 0
    spec = in_tmp / "bc" / "scenario_c.exsce"
    spec.write_text(spec.read_text().replace("tiago2 does navigate_home_2", "tiago1 does navigate_home_2"))
    refused = exscec_here("compile", "bc/scenario_c.exsce", "--store", url)
    assert refused.returncode == 2
    lines = refused.stderr.splitlines()
    assert lines[0] == (
        f"error: {oxigraph.url}/query already holds another version of scenario exsce:scenario_c: 1 graph differs"
    )
    assert lines[1].startswith("  exsce:scenario_c_bundle: mission:mission_c differs")
    replaced = exscec_here("compile", "bc/scenario_c.exsce", "--store", url, "--replace")
    assert replaced.returncode == 0, replaced.stderr
    assert "replaced 1 graph" in replaced.stderr and "exsce:scenario_c_bundle?revision=1" in replaced.stderr
    info = exscec_here("store", "info", "--store", url)
    assert "graphs:     14 (+ 1 revisions, + 0 of its indexes)" in info.stdout and "SPARQL 1.1 endpoint" in info.stdout


def test_an_unreachable_endpoint_is_named(in_tmp: Path) -> None:
    from tests.support.store_servers import free_port

    url = f"http://127.0.0.1:{free_port()}/sparql"
    result = exscec_here("store", "graphs", "--store", url)
    assert result.returncode == 2
    assert (
        f"cannot reach the SPARQL endpoint {url}" in result.stderr and "connection refused" in result.stderr
    )
    assert "Traceback" not in result.stderr
