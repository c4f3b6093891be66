"""Issue 46, "generated code from data, never from text": hostile strings in every string slot of
the grammar that reaches a generator (tests/support/hostile_specs.py) are refused with a located
error, or give files that read back in their language and hold nothing the template did not write.

Per generated Python file: it compiles, it calls nothing and names nothing outside literals that
the same file of the harmless spec does not; the texts that are data come back exactly (the
criterion's title from ``config.py``, the metric's meaning as its method's docstring, the
namespace from the dispatcher's YAML).  YAML and XML parse, CMakeLists.txt keeps its commands,
the READMEs and the Gherkin features keep their lines and tags."""

from __future__ import annotations

import ast
import functools
import tempfile
from collections.abc import Callable
from pathlib import Path

import pytest
import yaml
from hypothesis import given, settings

from exsce_dsl.codegen.dispatcher import MISSION_FILE, dispatcher_files
from exsce_dsl.codegen.monitors import monitor_files
from exsce_dsl.codegen.ros_monitor import ros1_monitor_files, ros2_monitor_files
from exsce_dsl.errors import GenerationError, SpecError
from exsce_dsl.lang import load_spec
from exsce_dsl.lang.format.gherkin import gherkin_features
from exsce_dsl.model import Specification

from tests.support.hostile_specs import (
    HOSTILE,
    SLOTS,
    called_names,
    check_files_read_back,
    names_outside_literals,
    python_files,
    spec_text,
    write_spec,
)

Generator = Callable[[Specification], dict[str, str]]
TARGETS: dict[str, Generator] = {
    "monitors": monitor_files,
    "ros1-monitor": lambda spec: ros1_monitor_files(spec, None),
    "ros2-monitor": lambda spec: ros2_monitor_files(spec, None),
    "dispatcher-config": lambda spec: dispatcher_files(spec.scenario(), Path(spec.root).name),
}
REFUSED = {
    ("ros1-monitor", "TOPIC"),
    ("ros2-monitor", "TOPIC"),
    ("ros1-monitor", "NAMESPACE"),
    ("ros2-monitor", "NAMESPACE"),
    ("dispatcher-config", "NAMESPACE"),
}
"""Where a generator may refuse a checked spec: names it cannot make a ROS name or a folder of."""


@functools.cache
def _baseline(target: str) -> dict[str, str]:
    """The files of the harmless spec, by their name."""
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "plain.exsce"
        path.write_text(spec_text(), encoding="utf-8")
        return TARGETS[target](load_spec(path))


@functools.cache
def _gherkin_lines() -> int:
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "plain.exsce"
        path.write_text(spec_text(), encoding="utf-8")
        spec = load_spec(path)
    acceptance = spec.acceptance_of(spec.scenario().id)
    assert acceptance is not None
    return len(gherkin_features(acceptance, spec.scenario()).splitlines())


@functools.cache
def _template_names(target: str, name: str) -> tuple[set[str], set[str]]:
    """What the harmless spec's file ``name`` calls, and the names it holds outside literals."""
    text = _baseline(target)[name]
    return called_names(text), names_outside_literals(text)


def _check_python(target: str, files: dict[str, str]) -> None:
    expected = _baseline(target)
    for name, text in python_files(files).items():
        if text == expected[name]:
            continue  # copied as it is (the metric core, the runtime)
        calls, names = _template_names(target, name)
        assert called_names(text) <= calls, name
        assert names_outside_literals(text) <= names, name


def _check_data(slot: str, value: str, spec: Specification, files: dict[str, str]) -> None:
    """The slot's text comes back exactly where a file holds it as data."""
    for name, text in python_files(files).items():
        tree = ast.parse(text)
        if slot == "TITLE" and name.endswith("/config.py"):
            oracles = [
                ast.literal_eval(node.value)
                for node in tree.body
                if isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name)
                if node.target.id in ("ORACLES", "NOT_JUDGED") and node.value is not None
            ]
            assert {o["criterion"] for entries in oracles for o in entries} == {value}
        if slot == "MEANING" and name.endswith("monitors.py"):
            method = next(
                n for n in ast.walk(tree) if isinstance(n, ast.FunctionDef) and n.name == "get_frame_height"
            )
            assert ast.get_docstring(method, clean=False) == (value or "frame_height")  # or its name
    if MISSION_FILE in files:
        mission = yaml.safe_load(files[MISSION_FILE])
        assert [r["robot_namespace"] for r in mission["robots"]] == [
            r.namespace for r in spec.scenario().robots
        ]


def _check_text(target: str, files: dict[str, str]) -> None:
    """A README's first line is one comment (no ``--`` inside it); the rest keeps its tags and
    headings (the text's ``<`` is escaped, its line breaks gone)."""
    expected = _baseline(target)
    for name, text in files.items():
        if name.endswith("README.md"):
            comment, _, rest = text.partition("\n")
            assert comment.startswith("<!--") and comment.endswith("-->"), comment
            assert "--" not in comment[4:-3], comment
            for mark in ("<", "\n#"):
                assert rest.count(mark) == expected[name].partition("\n")[2].count(mark), (name, mark)


@pytest.mark.parametrize("slot", SLOTS)
@settings(max_examples=25, deadline=None)
@given(value=HOSTILE)
def test_a_hostile_string_is_refused_where_it_is_or_stays_data(slot: str, value: str) -> None:
    if slot == "TOPIC":
        value = "/{ns}/" + value  # each robot's topic: what the checks ask of it first
    with tempfile.TemporaryDirectory() as folder:
        path = write_spec(Path(folder), slot, value)
        try:
            spec = load_spec(path)
        except SpecError as exc:  # refused by the checks: each error says where
            assert exc.diagnostics
            for d in exc.diagnostics:
                assert d.location is not None and d.location.line and d.location.column, d
            return
    for target, generate in TARGETS.items():
        try:
            files = generate(spec)
        except GenerationError as exc:
            assert (target, slot) in REFUSED and exc.location is not None, (target, exc.message)
            continue
        check_files_read_back(files)
        _check_python(target, files)
        _check_data(slot, value, spec, files)
        _check_text(target, files)
    acceptance = spec.acceptance_of(spec.scenario().id)
    assert acceptance is not None
    assert len(gherkin_features(acceptance, spec.scenario()).splitlines()) == _gherkin_lines()
