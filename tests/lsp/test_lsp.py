"""The language server end to end: a real LSP client (pytest-lsp) drives ``exscec lsp`` over
stdio, on copies of the brsu_building_c example.  Diagnostics, completion and hover here;
navigation, renaming, formatting and quick fixes in test_lsp_navigation.py."""

from __future__ import annotations

import asyncio
import shutil
from collections.abc import AsyncIterator
from pathlib import Path

import pytest
import pytest_lsp
from lsprotocol import types
from pytest_lsp import ClientServerConfig, LanguageClient

from tests.support.lsp_helpers import (
    EXSCEC,
    change_document,
    close_document,
    copy_workspace,
    diagnostics_of,
    open_document,
    position,
    start_session,
    uri_of,
)

pytestmark = pytest.mark.asyncio(loop_scope="module")


@pytest.fixture(scope="module")
def workspace(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return copy_workspace(tmp_path_factory, "lsp")


@pytest_lsp.fixture(scope="module", config=ClientServerConfig(server_command=[EXSCEC, "lsp"]))
async def client(lsp_client: LanguageClient, workspace: Path) -> AsyncIterator[None]:
    await start_session(lsp_client, workspace)
    yield
    await lsp_client.shutdown_session()


def span(diagnostic: types.Diagnostic) -> tuple[int, int, int, int]:
    r = diagnostic.range
    return (r.start.line, r.start.character, r.end.line, r.end.character)


# ------------------------------------------------------------------ diagnostics
async def test_a_valid_document_gets_empty_diagnostics(client: LanguageClient, workspace: Path) -> None:
    uri = open_document(client, workspace / "scenario_c.exsce")
    assert await diagnostics_of(client, uri) == []
    close_document(client, uri)


async def test_an_edit_with_an_unknown_pose_is_underlined_exactly(
    client: LanguageClient, workspace: Path
) -> None:
    path = workspace / "scenario_c.exsce"
    uri = open_document(client, path)
    await diagnostics_of(client, uri)
    text = path.read_text().replace("starts at classroom_c025-w002", "starts at c025-w02")
    change_document(client, uri, 2, text)
    (found,) = await diagnostics_of(client, uri, lambda ds: len(ds) > 0)
    # line 10 of the file, `    tiago2: tiago starts at c025-w02`: the name only, columns 28 to 36
    assert span(found) == (9, 28, 9, 36)
    assert found.severity == types.DiagnosticSeverity.Error
    assert found.code == "reference"
    assert found.message == "unknown pose 'c025-w02'; did you mean 'classroom_c025-w002'?"
    close_document(client, uri)


async def test_several_errors_at_once_syntax_and_semantic(client: LanguageClient, workspace: Path) -> None:
    text = (
        'import "environment.exsce"\n'
        "\n"
        "task broken {\n"
        "  visit classroom_c022-w001 facing\n"
        "}\n"
        "\n"
        "task fine {\n"
        "  visit classroom_c022-w009\n"
        "}\n"
        "\n"
        "task also_broken {\n"
        "  visit , classroom_c018-w001\n"
        "}\n"
    )
    uri = open_document(client, workspace / "several.exsce", text)
    found = sorted(await diagnostics_of(client, uri, lambda ds: len(ds) == 3), key=span)
    assert [span(d) for d in found] == [(4, 0, 4, 1), (7, 8, 7, 27), (11, 8, 11, 9)]
    assert [d.code for d in found] == ["syntax", "reference", "syntax"]
    assert found[0].message.startswith("expected an angle")
    assert found[1].message.startswith("unknown pose 'classroom_c022-w009'")
    close_document(client, uri)


async def test_an_error_in_an_imported_file_is_published_for_that_file(
    client: LanguageClient, workspace: Path
) -> None:
    folder = workspace.parent / "imported_error"
    shutil.copytree(workspace, folder)
    navigation = folder / "tasks" / "navigation.exsce"
    navigation.write_text(
        navigation.read_text().replace("classroom_c025-w002 facing", "classroom_c025-w003 facing")
    )
    uri = open_document(client, folder / "scenario_c.exsce")
    (found,) = await diagnostics_of(client, uri_of(navigation), lambda ds: len(ds) > 0)
    assert span(found) == (9, 8, 9, 27)
    assert "unknown pose 'classroom_c025-w003'" in found.message
    close_document(client, uri)


async def test_an_imported_file_open_in_the_editor_is_read_from_the_editor(
    client: LanguageClient, workspace: Path
) -> None:
    scenario = open_document(client, workspace / "scenario_c.exsce")
    await diagnostics_of(client, scenario)
    robots = workspace / "robots.exsce"
    robots_uri = open_document(client, robots)
    await diagnostics_of(client, robots_uri)
    change_document(
        client, robots_uri, 2, robots.read_text().replace("robot type tiago", "robot type tiagoo")
    )
    found = await diagnostics_of(client, scenario, lambda ds: len(ds) == 2)
    assert {span(d) for d in found} == {(8, 12, 8, 17), (9, 12, 9, 17)}
    assert all(d.message == "unknown robot type 'tiago'; did you mean 'tiagoo'?" for d in found)
    change_document(client, robots_uri, 3, robots.read_text())
    assert await diagnostics_of(client, scenario, lambda ds: len(ds) == 0) == []
    close_document(client, robots_uri)
    close_document(client, scenario)


async def test_the_shacl_stage_reports_after_the_fast_checks(client: LanguageClient, workspace: Path) -> None:
    text = (
        "robot type tiago { base pmb2 torso yes }\n"
        "environment lab {\n"
        "  area lab {\n"
        "    pose lab-w001 at (1.0, 2.0)\n"
        "  }\n"
        "}\n"
        "task t { visit lab-w001 }\n"
        "scenario s in lab {\n"
        "  robots { r1: tiago starts at lab-w001 }\n"
        "  mission m sequential { r1 does t }\n"
        "}\n"
    )
    uri = open_document(client, workspace / "lab.exsce", text)
    (found,) = await diagnostics_of(client, uri, lambda ds: len(ds) > 0)
    assert span(found) == (2, 7, 2, 10)
    assert found.code == "prov"
    assert "area 'lab' and environment 'lab' would both be written" in found.message
    close_document(client, uri)


# ------------------------------------------------------------------- completion
async def test_completion_of_a_pose_id_in_a_task(client: LanguageClient, workspace: Path) -> None:
    path = workspace / "tasks" / "deliveries.exsce"
    text = path.read_text().replace(
        "  visit classroom_c018-w001\n}", "  visit classroom_c018-w001\n  visit cla\n}", 1
    )
    uri = open_document(client, path, text)
    where = position(text, "visit cla", len("visit cla"))
    result = await client.text_document_completion_async(
        types.CompletionParams(types.TextDocumentIdentifier(uri), where)
    )
    assert isinstance(result, types.CompletionList)
    labels = {item.label for item in result.items}
    assert {"classroom_c025-w001", "classroom_c022-w002", "classroom_c069-w001"} <= labels
    assert not labels & {"delivery_a", "tiago", "left_long_corridor-point-0"}  # no 'cla' in order there
    pose = next(item for item in result.items if item.label == "classroom_c022-w001")
    assert pose.detail == "pose in classroom_c022 at (52.82560729980469, 32.562904357910156)"
    assert isinstance(pose.text_edit, types.TextEdit)
    assert (pose.text_edit.range.start.character, pose.text_edit.range.end.character) == (8, 11)
    close_document(client, uri)


async def test_completion_after_starts_at_offers_the_scenario_s_poses_and_keywords_elsewhere(
    client: LanguageClient, workspace: Path
) -> None:
    path = workspace / "scenario_c.exsce"
    text = path.read_text().replace("tiago2: tiago starts at classroom_c025-w002", "tiago2: tiago starts at ")
    uri = open_document(client, path, text)
    at = position(text, "tiago2: tiago starts at ", len("tiago2: tiago starts at "))
    result = await client.text_document_completion_async(
        types.CompletionParams(types.TextDocumentIdentifier(uri), at)
    )
    assert isinstance(result, types.CompletionList)
    labels = [item.label for item in result.items]
    assert "classroom_c025-w002" in labels and "right_long_corridor-point-0" in labels
    assert "delivery_a" not in labels
    after_type = position(text, "tiago1: tiago ", len("tiago1: tiago "))
    result = await client.text_document_completion_async(
        types.CompletionParams(types.TextDocumentIdentifier(uri), after_type)
    )
    assert isinstance(result, types.CompletionList)
    assert {"starts", "namespace"} <= {item.label for item in result.items}
    close_document(client, uri)


async def test_completion_in_a_mission_and_in_criteria(client: LanguageClient, workspace: Path) -> None:
    path = workspace / "scenario_c.exsce"
    text = path.read_text().replace(
        "    tiago2 does navigate_home_2\n", "    tiago2 does navigate_home_2\n    ti\n"
    )
    text = text.replace("    then tiago1 max_velocity stays below 0.8 m/s", "    then tiago1 max_velocity ")
    uri = open_document(client, path, text)

    async def labels(needle: str) -> set[str]:
        where = position(text, needle, len(needle))
        result = await client.text_document_completion_async(
            types.CompletionParams(types.TextDocumentIdentifier(uri), where)
        )
        assert isinstance(result, types.CompletionList)
        return {item.label for item in result.items}

    assert await labels("navigate_home_2\n    ti") == {"tiago1", "tiago2"}  # the robots, not the robot type
    assert {"delivery_a", "navigate_home_1"} <= await labels("tiago1 does ")
    assert {"stays", "is", "below_max", "above_min", "invariant"} <= await labels("then tiago1 max_velocity ")
    metrics = await labels("then each robot ")
    assert {"max_velocity", "fast_driving_time", "violation_duration"} <= metrics
    close_document(client, uri)


async def test_completion_names_come_from_the_last_model_that_parsed(
    client: LanguageClient, workspace: Path
) -> None:
    path = workspace / "tasks" / "navigation.exsce"
    uri = open_document(client, path)
    await diagnostics_of(client, uri)
    env = workspace / "environment.exsce"
    env_uri = open_document(client, env)
    await diagnostics_of(client, env_uri)
    broken = env.read_text().replace("area classroom_c025 {", "area classroom_c025 {{")
    change_document(client, env_uri, 2, broken)
    await diagnostics_of(client, env_uri, lambda ds: len(ds) > 0)
    text = path.read_text().replace("visit classroom_c025-w001 facing 0.925", "visit classroom_c025-")
    change_document(client, uri, 2, text)
    where = position(text, "visit classroom_c025-", len("visit classroom_c025-"))
    result = await client.text_document_completion_async(
        types.CompletionParams(types.TextDocumentIdentifier(uri), where)
    )
    assert isinstance(result, types.CompletionList)
    assert {"classroom_c025-w001", "classroom_c025-w002"} <= {item.label for item in result.items}
    close_document(client, env_uri)
    close_document(client, uri)


async def test_completion_of_transformations_in_a_derive_block(
    client: LanguageClient, workspace: Path
) -> None:
    text = 'import "scenario_c.exsce"\n\nderive c_two from scenario_c {\n  remove robot tiago2\n  \n}\n'
    uri = open_document(client, workspace / "derived.exsce", text)
    result = await client.text_document_completion_async(
        types.CompletionParams(types.TextDocumentIdentifier(uri), types.Position(4, 2))
    )
    assert isinstance(result, types.CompletionList)
    steps = {item.label: item for item in result.items}
    assert {"remove_robot", "add_task", "reverse_waypoint_order", "move_obstacle"} <= set(steps)
    assert isinstance(steps["add_task"].text_edit, types.TextEdit)
    assert steps["add_task"].text_edit.new_text == "add task ${1:task} to ${2:robot}"
    result = await client.text_document_completion_async(
        types.CompletionParams(types.TextDocumentIdentifier(uri), types.Position(3, 15))
    )
    assert isinstance(result, types.CompletionList)
    assert {item.label for item in result.items} == {"tiago1", "tiago2"}  # the base's robots
    close_document(client, uri)
    text = 'import "scenario_c.exsce"\n\nderive c_three from scenario_c {\n  replace robot tiago2 by tiago3 at \n}\n'
    uri = open_document(client, workspace / "replaced.exsce", text)
    result = await client.text_document_completion_async(
        types.CompletionParams(types.TextDocumentIdentifier(uri), types.Position(3, 36))
    )
    assert isinstance(result, types.CompletionList)
    poses = {item.label for item in result.items}
    assert {"classroom_c069-w001", "classroom_c025-w002"} <= poses and "tiago1" not in poses  # where it starts
    close_document(client, uri)


async def test_completion_of_a_metric_s_fields_follows_the_path_before_the_point(
    client: LanguageClient, workspace: Path
) -> None:
    path = workspace / "metrics.exsce"
    text = path.read_text().replace(
        "value mean(abs(vel.angular.z))", "value mean(abs(vel.angular.z + vel.lin))"
    )
    uri = open_document(client, path, text)

    async def items(needle: str) -> dict[str, types.CompletionItem]:
        where = position(text, needle, len(needle))
        result = await client.text_document_completion_async(
            types.CompletionParams(types.TextDocumentIdentifier(uri), where)
        )
        assert isinstance(result, types.CompletionList)
        return {item.label: item for item in result.items}

    fields = await items("vel.angular.z + vel.lin")
    assert set(fields) == {"linear"}  # 'angular' has no 'lin' in order
    linear = fields["linear"]
    assert linear.detail == "geometry_msgs/msg/Vector3 (geometry_msgs/msg/Twist)"
    assert linear.kind == types.CompletionItemKind.Field
    assert isinstance(linear.text_edit, types.TextEdit)
    assert linear.text_edit.range.end.character - linear.text_edit.range.start.character == len("lin")
    assert set(await items("vel.angular.")) == {"x", "y", "z"}
    reads = await items("value mean(abs(")
    assert reads["vel"].detail == "the robot's velocity (geometry_msgs/msg/Twist)"
    close_document(client, uri)


# ------------------------------------------------------------------------ hover
async def hover_at(client: LanguageClient, uri: str, where: types.Position) -> str:
    result = await client.text_document_hover_async(
        types.HoverParams(types.TextDocumentIdentifier(uri), where)
    )
    assert result is not None and isinstance(result.contents, types.MarkupContent)
    return result.contents.value


async def test_hover_shows_a_pose_a_task_a_metric_a_derivation_and_a_keyword(
    client: LanguageClient, workspace: Path
) -> None:
    path = workspace / "scenario_c.exsce"
    text = path.read_text()
    uri = open_document(client, path)
    pose = await hover_at(client, uri, position(text, "classroom_c025-w001", 3))
    assert pose.startswith("**pose** `classroom_c025-w001`")
    assert "- area: `classroom_c025`" in pose and "- at: `(44.80387496948242, 37.15502166748047)`" in pose
    task = await hover_at(client, uri, position(text, "does delivery_a", 6))
    assert (
        "**task** `delivery_a`" in task and "- waypoints: `classroom_c022-w001, classroom_c018-w001`" in task
    )
    metric = await hover_at(client, uri, position(text, "fast_driving_time", 2))
    assert "seconds spent faster than 0.8 m/s (unit: s)" in metric
    assert "value duration where norm(vel.linear.x, vel.linear.y) > 0.8 m/s" in metric
    builtin = await hover_at(client, uri, position(text, "max_velocity", 1))
    assert "largest linear speed (unit: m/s)" in builtin and "safe below 1.0 m/s" in builtin
    keyword = await hover_at(client, uri, position(text, "parallel", 2))
    assert keyword.startswith("**parallel** (keyword)") and "side by side" in keyword
    close_document(client, uri)
    metrics = workspace / "metrics.exsce"
    metrics_uri = open_document(client, metrics)
    field = await hover_at(client, metrics_uri, position(metrics.read_text(), "vel.angular.z", 5))
    assert field == "**field** `vel.angular`: `geometry_msgs/msg/Vector3`, of `geometry_msgs/msg/Twist`"
    close_document(client, metrics_uri)
    alone = workspace / "scenario_c_alone.exsce"
    alone_uri = open_document(client, alone)
    derived = await hover_at(client, alone_uri, position(alone.read_text(), "scenario_c_alone", 1))
    assert derived.startswith("**derived scenario** `scenario_c_alone`")
    assert "- derived from: `scenario_c`" in derived
    assert "- step 1: `remove_robot robot=tiago2 reassign=tiago1`" in derived
    assert "- step 2: `reverse_waypoint_order task=delivery_a`" in derived
    close_document(client, alone_uri)


async def test_ranges_count_utf16_code_units(client: LanguageClient, workspace: Path) -> None:
    text = 'import "environment.exsce"\n\ntask t { /* 🤖 ü */ visit c025-w02 }\n'
    uri = open_document(client, workspace / "utf16.exsce", text)
    (found,) = await diagnostics_of(client, uri, lambda ds: len(ds) > 0)
    # `task t { /* 🤖 ü */ visit ` is 25 characters, 26 UTF-16 units (the robot takes two)
    assert span(found) == (2, 26, 2, 34)
    close_document(client, uri)


async def test_a_burst_of_changes_is_analysed_once_after_the_debounce(
    client: LanguageClient, workspace: Path
) -> None:
    path = workspace / "tasks" / "navigation.exsce"
    uri = open_document(client, path)
    await diagnostics_of(client, uri)
    published: list[int | None] = []
    watching = True

    def watch(params: types.PublishDiagnosticsParams) -> None:
        if params.uri == uri:
            published.append(params.version)
        if watching:
            client.protocol.wait_for_notification(types.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS, watch)

    client.protocol.wait_for_notification(types.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS, watch)
    text = path.read_text()
    for version in range(2, 7):  # typing: a key every 30 ms
        change_document(client, uri, version, text.replace("facing 0.925", f"facing 0.{version}"))
        await asyncio.sleep(0.03)
    await diagnostics_of(client, uri)
    await asyncio.sleep(0.4)
    watching = False
    assert published == [6]
    close_document(client, uri)


async def test_completion_of_a_robot_types_signal_lines(client: LanguageClient, workspace: Path) -> None:
    path = workspace / "robots.exsce"
    text = path.read_text().replace("  torso no\n", "  torso no\n  convention \n", 1)
    uri = open_document(client, path, text)
    at = position(text, "  convention ", len("  convention "))
    result = await client.text_document_completion_async(
        types.CompletionParams(types.TextDocumentIdentifier(uri), at)
    )
    assert isinstance(result, types.CompletionList)
    assert {"method", "nav2", "move_base"} <= {item.label for item in result.items}
    line_start = position(text, "  convention ", 2)
    result = await client.text_document_completion_async(
        types.CompletionParams(types.TextDocumentIdentifier(uri), line_start)
    )
    assert isinstance(result, types.CompletionList)
    assert {"convention", "pose", "velocity", "scan", "navigation", "arrival"} <= {
        i.label for i in result.items
    }
    close_document(client, uri)


async def test_timeout_is_completed_in_a_task_and_a_mission_and_shown_on_hover(
    client: LanguageClient, workspace: Path
) -> None:
    tasks = workspace / "tasks" / "deliveries.exsce"
    text = tasks.read_text().replace("task delivery_a {\n", "task delivery_a {\n  timeout 2 min\n", 1)
    text = text.replace("task delivery_b {\n", "task delivery_b {\n  ti\n", 1)
    uri = open_document(client, tasks, text)
    result = await client.text_document_completion_async(
        types.CompletionParams(types.TextDocumentIdentifier(uri), position(text, "{\n  ti", len("{\n  ti")))
    )
    assert isinstance(result, types.CompletionList)
    assert "timeout" in {item.label for item in result.items}
    keyword = await hover_at(client, uri, position(text, "timeout 2 min", 2))
    assert keyword.startswith("**timeout** (keyword)") and "each navigation goal" in keyword
    close_document(client, uri)
    scenario = workspace / "scenario_c.exsce"
    text = scenario.read_text().replace(
        "mission_c parallel {\n", "mission_c parallel {\n    timeout 90 s\n", 1
    )
    uri = open_document(client, scenario, text)
    mission = await hover_at(client, uri, position(text, "mission_c parallel", 3))
    assert "- goal timeout: `90 s`" in mission
    close_document(client, uri)
