"""``exscec mcp`` end to end: the SDK's own client talks to the real server over stdio.

One project folder, filled once by the real pipeline (compile scenario_c into the
store, simulate and ingest three runs, build the baseline, verify one run, derive
c_one from scenario_c); each test starts the real ``exscec mcp`` console script in
it and asks what a client would, comparing with what ``exscec`` itself answers.
"""

from __future__ import annotations

import json
import os
import shutil
import sys
from collections.abc import Awaitable, Callable
from pathlib import Path
from typing import Any, TypeVar

import anyio
import pytest
from mcp.client.session import ClientSession
from mcp.client.stdio import StdioServerParameters, get_default_environment, stdio_client
from mcp.shared.exceptions import MCPError
from mcp_types import CallToolResult, TextContent, TextResourceContents

from tests.support.cli import exscec_here, run_exscec
from tests.support.paths import EXAMPLES

EXSCEC = Path(sys.executable).with_name("exscec")
T = TypeVar("T")

RUN_ID = "^[0-9a-fA-F][0-9a-fA-F-]{3,35}$"  # a uuid, or a prefix of 4 characters or more
NAME = "^[A-Za-z_][A-Za-z0-9_]*(?:-[A-Za-z0-9_]+)*$"


# -- the project, and sessions with the server ------------------------------------------------


class Project:
    def __init__(self, folder: Path) -> None:
        self.folder = folder
        self.spec = "scenarios/scenario_c.exsce"
        self.runs: list[str] = []
        self.verified = ""
        self.verified_json: list[dict[str, Any]] = []

    def exscec(self, *args: str) -> str:
        done = exscec_here(*args, cwd=self.folder)
        assert done.returncode == 0, f"exscec {' '.join(args)}: {done.stderr}"
        return done.stdout


@pytest.fixture(scope="module")
def project(tmp_path_factory: pytest.TempPathFactory) -> Project:
    folder = tmp_path_factory.mktemp("mcp-project")
    shutil.copytree(EXAMPLES / "brsu_building_c", folder / "scenarios")
    p = Project(folder)
    p.exscec("compile", p.spec, "-f", "provn", "-o", "scenario_c.provn", "--store")
    p.exscec("simulate", p.spec, "--runs", "3", "--seed", "1", "-o", "runs")
    p.exscec("ingest", *sorted(str(b) for b in (folder / "runs").glob("*.bag")), "--scenario", p.spec)
    p.exscec("baseline", p.spec)
    listed = json.loads(p.exscec("runs", "--format", "json"))["results"]["bindings"]
    p.runs = [row["run"]["value"] for row in listed]
    assert len(p.runs) == 3
    p.verified = p.runs[0]
    p.verified_json = json.loads(p.exscec("verify", p.verified, "--scenario", p.spec, "--json"))
    p.exscec(
        "derive",
        p.spec,
        "-t",
        "remove_robot",
        "--robot",
        "tiago2",
        "--reassign",
        "tiago1",
        "--id",
        "c_one",
        "-o",
        "scenarios/c_one.exsce",
        "--add-to-store",
    )
    return p


def in_session(folder: Path, work: Callable[[ClientSession], Awaitable[T]], *options: str) -> T:
    """``work`` with a client session of ``exscec mcp OPTIONS`` started in ``folder``."""

    async def main() -> T:
        # the server runs the package the tests run (the client passes few variables on)
        passed_on = ("PYTHONPATH", "EXSCE_CACHE")  # and the test run's own cache folder
        env = get_default_environment() | {k: v for k, v in os.environ.items() if k in passed_on}
        server = StdioServerParameters(command=str(EXSCEC), args=["mcp", *options], cwd=str(folder), env=env)
        with open(folder / "mcp-server.log", "a", encoding="utf-8") as errlog:
            async with stdio_client(server, errlog=errlog) as (read, write):
                async with ClientSession(read, write) as session:
                    await session.initialize()
                    return await work(session)

    return anyio.run(main)


def answer(result: CallToolResult) -> Any:
    """The structured answer of a call that worked (and its text is that answer's JSON)."""
    assert not result.is_error, result.content
    (text,) = result.content
    assert isinstance(text, TextContent)
    assert json.loads(text.text) == result.structured_content
    return result.structured_content


def error_text(result: CallToolResult) -> str:
    assert result.is_error, result.structured_content
    (text,) = result.content
    assert isinstance(text, TextContent)
    return text.text


def bindings(rows: dict[str, Any], name: str) -> list[str]:
    return [b[name]["value"] for b in rows["results"]["bindings"]]


# -- tools ----------------------------------------------------------------------------------


def test_the_tools_are_the_library_queries_typed_from_their_metadata(project: Project) -> None:
    from exsce_dsl.store.queries import query, query_names

    tools = {t.name: t for t in in_session(project.folder, lambda s: s.list_tools()).tools}

    queries = [query(n) for n in query_names() if not query(n).is_update]
    assert len(queries) >= 20
    for q in queries:
        tool = tools[q.name]
        schema = tool.input_schema
        assert q.description in (tool.description or "")
        assert schema["type"] == "object" and schema["additionalProperties"] is False
        given = [p for p in q.parameters if not p.from_runs]  # a run's graphs: bound from its run
        assert set(schema["properties"]) == {p.name for p in given}
        assert set(schema.get("required", [])) == {p.name for p in given if not p.optional}
        for p in given:
            prop = schema["properties"][p.name]
            assert p.description in prop["description"]
            assert prop["type"] == ("array" if p.many else "number" if p.kind == "double" else "string")
        assert tool.annotations is not None and tool.annotations.read_only_hint is True
    # the updates of the library are not offered; the four tools of the server are
    assert "update_baseline" not in tools and "update_mission_baseline" not in tools
    assert {"lineage", "run_verdicts", "check", "sparql"} <= set(tools)
    assert len(tools) == len(queries) + 4

    # one query's schema written out by hand
    segment = tools["segment_metric"].input_schema
    assert segment["required"] == ["metric", "start", "goal", "run"]
    assert segment["properties"]["metric"]["pattern"] == NAME
    assert segment["properties"]["start"]["pattern"].startswith(NAME[:-1] + "-R")
    assert segment["properties"]["run"]["type"] == "array"
    assert segment["properties"]["run"]["minItems"] == 1
    assert segment["properties"]["run"]["items"]["pattern"] == RUN_ID
    runs = tools["runs"].input_schema
    assert "required" not in runs and runs["properties"]["scenario"]["pattern"] == NAME
    assert tools["run_verdicts"].input_schema["required"] == ["run"]


def test_a_query_tool_answers_what_exscec_query_answers(project: Project) -> None:
    r1, r2, r3 = project.runs
    cases: list[tuple[str, dict[str, Any], list[str]]] = [
        ("runs", {}, []),
        ("runs", {"scenario": "scenario_c"}, ["scenario=scenario_c"]),
        ("scenarios", {}, []),
        ("robots", {"scenario": "scenario_c"}, ["scenario=scenario_c"]),
        ("oracles", {"scenario": "scenario_c"}, ["scenario=scenario_c"]),
        ("path_segments", {"scenario": "scenario_c"}, ["scenario=scenario_c"]),
        (
            "run_metric",
            {"run": r1, "metric": "waypoints_visited", "robot": "tiago1"},
            [f"run={r1}", "metric=waypoints_visited", "robot=tiago1"],
        ),
        (
            "mission_metric_stats",
            {"metric": "mission_duration", "run": [r1, r2, r3]},
            ["metric=mission_duration", f"run={r1}", f"run={r2}", f"run={r3}"],
        ),
    ]

    async def work(session: ClientSession) -> list[Any]:
        found = [answer(await session.call_tool(name, arguments)) for name, arguments, _ in cases]
        segments = found[5]["results"]["bindings"]
        start, goal = segments[0]["start"]["value"], segments[0]["goal"]["value"]
        arguments = {"metric": "distance_travelled", "start": start, "goal": goal, "scenario": "scenario_c"}
        found.append(answer(await session.call_tool("segment_metric_of_scenario", arguments)))
        found.append((start, goal))
        return found

    found = in_session(project.folder, work)
    for (name, _, params), got in zip(cases, found, strict=False):
        flags = [flag for p in params for flag in ("-p", p)]
        assert got == json.loads(project.exscec("query", name, *flags, "--format", "json")), name
    start, goal = found[-1]
    cli = project.exscec(
        "query",
        "segment_metric_of_scenario",
        "-p",
        "metric=distance_travelled",
        "-p",
        f"start={start}",
        "-p",
        f"goal={goal}",
        "-p",
        "scenario=scenario_c",
        "--format",
        "json",
    )
    assert found[-2] == json.loads(cli)
    # what the answers say, by hand
    assert sorted(bindings(found[0], "run")) == sorted(project.runs)
    assert bindings(found[2], "scenario") == ["c_one", "scenario_c"]
    assert bindings(found[3], "robot") == ["tiago1", "tiago2"]
    assert bindings(found[6], "value") == ["3"]  # tiago1 visits three waypoints in each run
    assert bindings(found[7], "count") == ["3"]
    assert bindings(found[-2], "count") == ["3"]  # every run drove the first segment


INJECTIONS = [
    ("runs", {"scenario": 'scenario_c" } ; DROP ALL ; #'}, "scenario"),
    ("runs", {"scenario": "scenario_c> } INSERT DATA { GRAPH <a:g> { <a:b> <a:c> <a:d> } } #"}, "scenario"),
    ("oracles", {"scenario": "x } UNION { ?s ?p ?o"}, "scenario"),
    ("run_metric", {"run": "0 } ; CLEAR ALL", "metric": "waypoints_visited", "robot": "tiago1"}, "run"),
    (
        "robot_metric_stats",
        {"metric": "task_duration", "robot": "tiago1", "run": ['x" ) } DROP ALL #']},
        "run",
    ),
    ("segment_metric_any", {"metric": "m", "start": "a-R0_P0_Y0> ?p ?o } #", "goal": "b-R0_P0_Y0"}, "start"),
    ("lineage", {"scenario": "c_one' } DROP ALL"}, "scenario"),
    ("run_verdicts", {"run": "'; DELETE WHERE { ?s ?p ?o } #"}, "run"),
]


def test_a_value_that_is_no_id_is_refused_and_never_runs(project: Project) -> None:
    count = "SELECT (COUNT(*) AS ?n) WHERE { GRAPH ?g { ?s ?p ?o } }"

    async def work(session: ClientSession) -> tuple[Any, list[str], list[str], Any, Any]:
        before = answer(await session.call_tool("sparql", {"query": count}))
        refused = [error_text(await session.call_tool(name, args)) for name, args, _ in INJECTIONS]
        wrong = [
            error_text(await session.call_tool("runs", {"scenario": 7})),
            error_text(await session.call_tool("runs", {"scenario": "scenario_c", "limit": "1"})),
            error_text(await session.call_tool("run_metric", {"metric": "m"})),
            error_text(await session.call_tool("mission_metric_stats", {"metric": "m", "run": []})),
        ]
        unknown = answer(await session.call_tool("runs", {"scenario": "scenario_zz"}))
        after = answer(await session.call_tool("sparql", {"query": count}))
        return before, refused, wrong, unknown, after

    before, refused, wrong, unknown, after = in_session(project.folder, work)
    for (_, _, argument), message in zip(INJECTIONS, refused, strict=True):
        assert message.startswith(f"error: argument '{argument}': ") and " is not " in message, message
    assert "expected a string, got a number" in wrong[0]
    assert "unknown argument 'limit'" in wrong[1]
    assert "missing argument 'run'" in wrong[2] and "missing argument 'robot'" in wrong[2]
    assert "needs at least 1 value" in wrong[3]
    assert unknown["results"]["bindings"] == []  # an id of the right form is a value, found nowhere
    assert after == before and int(bindings(before, "n")[0]) > 1000  # nothing was dropped or added
    assert len(json.loads(project.exscec("runs", "--format", "json"))["results"]["bindings"]) == 3


def test_the_sparql_tool_reads_and_refuses_to_write(project: Project) -> None:
    select = "SELECT DISTINCT ?run WHERE { GRAPH ?g { ?a a exsce:run ; exsce:run ?run } } ORDER BY ?run"
    count = "SELECT (COUNT(*) AS ?n) WHERE { GRAPH ?g { ?s ?p ?o } }"
    writes = [
        "INSERT DATA { GRAPH <urn:x> { <urn:a> <urn:b> <urn:c> } }",
        "PREFIX ex: <urn:ex#> # SELECT\nDELETE WHERE { GRAPH ?g { ?s ?p ?o } }",
        "LOAD <http://example.org/data.ttl>",
        "DROP ALL",
        "CLEAR GRAPH <urn:x>",
        "WITH <urn:x> DELETE { ?s ?p ?o } WHERE { ?s ?p ?o }",
    ]

    async def work(session: ClientSession) -> tuple[Any, ...]:
        before = answer(await session.call_tool("sparql", {"query": count}))
        rows = answer(await session.call_tool("sparql", {"query": select}))
        asked = answer(
            await session.call_tool("sparql", {"query": "ASK { GRAPH ?g { ?a a exsce:validation } }"})
        )
        refused = [error_text(await session.call_tool("sparql", {"query": w})) for w in writes]
        joined = error_text(await session.call_tool("sparql", {"query": select + " ; DROP ALL"}))
        service = error_text(
            await session.call_tool(
                "sparql", {"query": "SELECT * { SERVICE <http://127.0.0.1:1/> { ?s ?p ?o } }"}
            )
        )
        after = answer(await session.call_tool("sparql", {"query": count}))
        return before, rows, asked, refused, joined, service, after

    before, rows, asked, refused, joined, service, after = in_session(project.folder, work)
    assert rows == json.loads(project.exscec("sparql", select, "--format", "json"))
    assert bindings(rows, "run") == sorted(project.runs)
    assert asked == {"head": {}, "boolean": True}  # one run was verified
    for text, message in zip(writes, refused, strict=True):
        assert "SELECT and ASK queries only, never updates" in message, text
    assert "invalid SPARQL query" in joined  # the store's own parser takes no update after a query
    assert "SERVICE <http://127.0.0.1:1/> is refused" in service
    assert after == before


def test_the_store_is_chosen_as_every_command_chooses_it_and_answers_are_cut(
    project: Project, tmp_path: Path
) -> None:
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    store = str(project.folder / ".exsce" / "store")
    slow = (
        "SELECT (COUNT(*) AS ?n) WHERE { GRAPH ?a { ?s1 ?p1 ?o1 } GRAPH ?b { ?s2 ?p2 ?o2 } "
        "GRAPH ?c { ?s3 ?p3 ?o3 } GRAPH ?d { ?s4 ?p4 ?o4 } }"
    )

    async def given_store(session: ClientSession) -> tuple[Any, str]:
        cut = answer(await session.call_tool("runs", {}))
        return cut, error_text(await session.call_tool("sparql", {"query": slow}))

    cut, late = in_session(elsewhere, given_store, "--store", store, "--max-rows", "2", "--timeout", "3")
    assert len(cut["results"]["bindings"]) == 2 and cut["truncated"] == {"shown": 2, "rows": 3}
    assert set(bindings(cut, "run")) < set(project.runs)
    assert "time limit of 3 s" in late  # it counts (quads in the store)^4 rows

    async def default_store(session: ClientSession) -> Any:
        return answer(await session.call_tool("scenarios", {}))

    empty = in_session(elsewhere, default_store)
    assert empty["results"]["bindings"] == []  # elsewhere/.exsce/store: nothing there...
    assert not (elsewhere / ".exsce").exists()  # ...and reading made no store


# -- check ------------------------------------------------------------------------------------


def test_check_answers_located_diagnostics_as_exscec_check(project: Project) -> None:
    good = (project.folder / project.spec).read_text(encoding="utf-8")
    assert "    tiago2 does delivery_b\n" in good
    broken = good.replace("    tiago2 does delivery_b\n", "    tiago2 does delivry_b\n")
    line = broken.splitlines().index("    tiago2 does delivry_b") + 1
    column = len("    tiago2 does ") + 1
    (project.folder / "scenarios" / "broken.exsce").write_text(broken, encoding="utf-8")
    cli = run_exscec("check", "scenarios/broken.exsce", cwd=project.folder)
    assert cli.returncode == 2

    async def work(session: ClientSession) -> list[Any]:
        calls = [
            {"text": good, "folder": "scenarios", "name": "scenario_c.exsce"},
            {"text": broken, "folder": str(project.folder / "scenarios"), "name": "broken.exsce"},
            {"text": broken},
            {"text": "task t {\n  visit ,\n}\n"},
        ]
        found = [answer(await session.call_tool("check", c)) for c in calls]
        found.append(error_text(await session.call_tool("check", {"text": good, "folder": "no/such/folder"})))
        return found

    ok, wrong, alone, syntax, no_folder = in_session(project.folder, work)
    assert ok == {"ok": True, "errors": 0, "warnings": 0, "diagnostics": [], "scenarios": ["scenario_c"]}

    assert wrong["ok"] is False and wrong["errors"] == 1 and "scenarios" not in wrong
    (d,) = wrong["diagnostics"]
    assert (d["file"], d["line"], d["column"], d["severity"]) == ("broken.exsce", line, column, "error")
    assert (d["end_line"], d["end_column"]) == (line, column + len("delivry_b"))
    assert "unknown task 'delivry_b'" in d["message"] and "did you mean 'delivery_b'?" in d["message"]
    assert f"scenarios/{d['text']}" in cli.stderr.splitlines()  # what exscec check prints, file for file

    # alone in a scratch folder: it imports nothing, each import refused where it is written
    imports = [x for x in alone["diagnostics"] if "imports are not read" in x["message"]]
    assert [(x["file"], x["line"], x["column"]) for x in imports] == [
        ("spec.exsce", n, 1) for n in range(1, 6)
    ]
    assert imports[0]["message"].startswith("imports are not read for a text given to check")

    (s,) = syntax["diagnostics"]
    assert (s["file"], s["line"], s["column"], s["severity"]) == ("spec.exsce", 2, 9, "error")
    assert "found ','" in s["message"]
    assert no_folder.startswith("error: ") and "no/such/folder" in no_folder


# -- lineage, verdicts ----------------------------------------------------------------------


def test_lineage_and_verdicts_are_what_exscec_shows(project: Project) -> None:
    unverified = project.runs[1]

    async def work(session: ClientSession) -> list[Any]:
        return [
            answer(await session.call_tool("lineage", {"scenario": "c_one"})),
            answer(await session.call_tool("lineage", {"scenario": "scenario_c"})),
            answer(await session.call_tool("lineage", {"run": project.verified[:8]})),  # as tables print it
            error_text(await session.call_tool("lineage", {"scenario": "scenario_d"})),
            error_text(await session.call_tool("lineage", {})),
            answer(await session.call_tool("run_verdicts", {"run": project.verified})),
            answer(await session.call_tool("run_verdicts", {"run": unverified})),
            error_text(
                await session.call_tool("run_verdicts", {"run": "00000000-0000-0000-0000-000000000000"})
            ),
        ]

    c_one, scenario_c, of_run, unknown, neither, verdicts, none, no_run = in_session(project.folder, work)
    derivation = {
        "scenario": "c_one",
        "base": "scenario_c",
        "steps": [
            {"transformation": "remove_robot", "parameters": {"reassign": "tiago1", "robot": "tiago2"}}
        ],
    }
    assert c_one == {"scenario": "c_one", "ancestors": [derivation], "descendants": []}
    assert scenario_c["ancestors"] == [] and scenario_c["descendants"] == [
        {"scenario": "c_one", "steps": derivation["steps"], "derived": []}
    ]
    chain = of_run.pop("chain")
    assert of_run == {"run": project.verified, **scenario_c}
    printed = project.exscec("lineage", project.verified)  # the chain as the command line prints it
    assert chain["run"] == project.verified and chain["scenario"] == "scenario_c"
    assert f"bag {chain['bag']}" in printed and chain["bag"].endswith(".bag")
    assert f"values ({len(chain['values'])})" in printed and len(chain["values"]) > 10
    assert sum("window" in value for value in chain["values"]) == printed.count("    window: ")
    assert sorted((v["oracle"], v["outcome"]) for v in chain["verdicts"]) == sorted(
        (v["oracle"], v["verdict"]) for v in project.verified_json
    )
    assert "no scenario 'scenario_d'" in unknown and "did you mean 'scenario_c'?" in unknown
    assert "either a scenario or a run" in neither
    assert "remove_robot(reassign=tiago1 robot=tiago2)" in project.exscec("lineage", "c_one")

    expected = sorted(project.verified_json, key=lambda v: (v["oracle"], v["relation"]))
    got = sorted(verdicts["verdicts"], key=lambda v: (v["oracle"], v["relation"]))
    assert [(v["oracle"], v["relation"], v["verdict"]) for v in got] == [
        (v["oracle"], v["relation"], v["verdict"]) for v in expected
    ]
    for g, e in zip(got, expected, strict=True):
        assert g["run"] == project.verified and g["observed"] == pytest.approx(e["observed"])
    assert verdicts["passed"] == len(expected) > 10 and verdicts["failed"] == verdicts["inconclusive"] == 0
    assert none["verdicts"] == [] and none["passed"] == 0 and "not verified" in none["note"]
    assert "the store holds no run 00000000-0000-0000-0000-000000000000; the closest ids" in no_run


# -- resources --------------------------------------------------------------------------------


def test_resources_are_the_scenarios_and_runs_of_the_store(project: Project) -> None:
    async def work(session: ClientSession) -> list[Any]:
        listed = await session.list_resources()
        templates = await session.list_resource_templates()
        reads = []
        for uri in ("exsce://scenarios", "exsce://scenarios/scenario_c", f"exsce://runs/{project.verified}"):
            (contents,) = (await session.read_resource(uri)).contents
            assert isinstance(contents, TextResourceContents) and contents.mime_type == "application/json"
            reads.append(json.loads(contents.text))
        missing = []
        for uri in ("exsce://scenarios/scenario_zz", "exsce://runs/not-a-uuid", "file:///etc/passwd"):
            with pytest.raises(MCPError) as caught:
                await session.read_resource(uri)
            missing.append(caught.value.message)
        return [listed, templates, *reads, missing]

    listed, templates, scenarios, scenario_c, run, missing = in_session(project.folder, work)
    uris = {r.uri for r in listed.resources}
    assert uris == {
        "exsce://scenarios",
        "exsce://runs",
        "exsce://scenarios/scenario_c",
        "exsce://scenarios/c_one",
        *(f"exsce://runs/{r}" for r in project.runs),
    }
    assert {t.uri_template for t in templates.resource_templates} == {
        "exsce://scenarios/{scenario}",
        "exsce://runs/{run}",
    }
    assert scenarios["scenarios"] == [
        {"scenario": "c_one", "runs": 0, "uri": "exsce://scenarios/c_one"},
        {"scenario": "scenario_c", "runs": 3, "uri": "exsce://scenarios/scenario_c"},
    ]

    assert scenario_c["scenario"] == "scenario_c" and scenario_c["derived_from"] is None
    assert [r["robot"] for r in scenario_c["robots"]] == ["tiago1", "tiago2"]
    assert scenario_c["robots"][0] == {"robot": "tiago1", "type": "tiago", "base": "pmb2", "torso": True}
    assert scenario_c["derived"] == [{"scenario": "c_one", "uri": "exsce://scenarios/c_one"}]
    assert sorted(r["run"] for r in scenario_c["runs"]) == sorted(project.runs)
    limits = {(o["robot"], o["metric"], o["relation"], o["limit"]) for o in scenario_c["oracles"]}
    assert ("tiago1", "max_velocity", "below_max", 1.0) in limits
    assert (None, "distance_between_robots", "above_min", 0.1) in limits

    assert run["run"] == project.verified and run["scenario"] == "scenario_c"
    assert run["bag"].endswith(".bag") and run["start"] < run["end"]
    assert run["verdicts"] == {"passed": len(project.verified_json), "failed": 0, "inconclusive": 0}
    visited = {(m["robot"], m["value"]) for m in run["metrics"] if m["metric"] == "waypoints_visited"}
    assert visited == {("tiago1", 3.0), ("tiago2", 3.0)}

    assert "no scenario 'scenario_zz'" in missing[0]
    assert "'not-a-uuid' is not a run uuid" in missing[1]
    assert "no resource 'file:///etc/passwd'" in missing[2]


# -- the command ------------------------------------------------------------------------------


def test_the_help_shows_a_client_configuration_that_works(tmp_path: Path) -> None:
    shown = run_exscec("mcp", "--help")
    assert shown.returncode == 0
    text = shown.stdout
    lines = text.splitlines()
    first = next(i for i, line in enumerate(lines) if line.strip() == "{")
    last = next(i for i, line in enumerate(lines) if line == lines[first].replace("{", "}"))
    block = "\n".join(lines[first : last + 1])
    config = json.loads(block)  # the snippet for claude_desktop_config.json is JSON as printed
    assert config["mcpServers"]["exsce"]["args"][:2] == ["mcp", "--store"]
    assert "exscec mcp --store" in text
    refused = run_exscec("mcp", "--store", "bogus://host/x", cwd=tmp_path)
    assert refused.returncode == 2 and "cannot open a store at 'bogus://host/x'" in refused.stderr
