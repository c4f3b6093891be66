"""Robot identities in a store (issue 48, item 1).  A robot whose namespace is its id is named by its
id alone, as the method names its robots (``robot:tiago1``); any other is named by its id and a
digest of its declaration (:func:`~exsce_dsl.prov.identifiers.robot_name`), so scenarios drafted
from many bags (each with its ``root_robot``) share a store, and the queries still answer with the
robot's id.  Two scenarios that give one plain-named robot two declarations are refused, with why."""

from __future__ import annotations

from pathlib import Path

import pytest

from exsce_dsl.cli.common import REMEDIES
from exsce_dsl.errors import StoreConflictError
from exsce_dsl.lang import load_spec
from exsce_dsl.prov import compile_scenario
from exsce_dsl.prov.identifiers import DEFAULT_NAMESPACE
from exsce_dsl.store.embedded import EmbeddedStore
from exsce_dsl.store.queries.terms import run_query
from exsce_dsl.store.writing import add_prov

DRAFTED = """robot type detected_robot {{
  window whole recording
}}

environment {name}_environment {{
  area {name}_places {{
    pose {name}-start at (1.0, 0.0)
    pose {name}-end at (2.0, 0.0)
  }}
}}

task {name}_path {{
  visit {name}-end
}}

scenario {name} in {name}_environment {{
  robots {{
    root_robot: detected_robot namespace "{namespace}" starts at {name}-start
  }}
  mission {name}_mission sequential {{
    root_robot does {name}_path
  }}
}}
"""


ROBOTS = DEFAULT_NAMESPACE + "robots/"


def add(
    store: EmbeddedStore, folder: Path, name: str, namespace: str, robot: str = "root_robot", kind: str = ""
) -> None:
    """Scenario ``name`` with one robot ``robot`` in ``namespace``, of type ``detected_robot<kind>``."""
    path = folder / f"{name}.exsce"
    text = DRAFTED.format(name=name, namespace=namespace).replace("root_robot", robot)
    text = text.replace("detected_robot", f"detected_robot{kind}")
    path.write_text(text, encoding="utf-8")
    add_prov(store, compile_scenario(load_spec(path).scenario()))


def robot_entities(store: EmbeddedStore) -> list[str]:
    query = f"SELECT DISTINCT ?r WHERE {{ GRAPH ?g {{ ?r a <{DEFAULT_NAMESPACE}robot> }} }} ORDER BY ?r"
    rows = store.select(query)
    return [str(row[0].value).removeprefix(ROBOTS) for row in rows.rows]


def test_one_robot_id_in_two_namespaces_is_two_robots_of_one_store(tmp_path: Path) -> None:
    store = EmbeddedStore()
    add(store, tmp_path, "first", "")
    add(store, tmp_path, "second", "elsewhere")
    add(store, tmp_path, "third", "/")  # the root again: the first scenario's robot
    first, second = robot_entities(store)
    assert first.startswith("root_robot.") and second.startswith("root_robot.") and first != second
    for scenario in ("first", "second", "third"):
        rows = run_query(store, "robots", {"scenario": scenario})
        assert [row[0].value for row in rows.rows] == ["root_robot"]  # the id, not the digest
    assert [row[0].value for row in run_query(store, "robot_names", {}).rows] == ["root_robot"]
    segments = run_query(store, "path_segments", {"scenario": "second"})
    assert {row[0].value for row in segments.rows} == {"root_robot"}


def test_a_robot_in_the_namespace_of_its_id_keeps_the_methods_name(tmp_path: Path) -> None:
    store = EmbeddedStore()
    add(store, tmp_path, "first", "r1", robot="r1")
    add(store, tmp_path, "second", "r1", robot="r1")  # the same robot: one bundle
    assert robot_entities(store) == ["r1"]


def test_a_plain_named_robot_declared_otherwise_by_another_scenario_is_refused_with_why(
    tmp_path: Path,
) -> None:
    store = EmbeddedStore()
    add(store, tmp_path, "first", "r1", robot="r1")
    with pytest.raises(StoreConflictError) as raised:
        add(store, tmp_path, "second", "r1", robot="r1", kind="_2")  # another type
    message = str(raised.value)
    assert "robot 'r1' is named by id alone" in message
    assert "replacing would change the other scenario's too" in message  # the library's words
    assert raised.value.remedied is not None  # the command line's, with its option:
    assert "--replace would change the other scenario's too" in raised.value.remedied.said(REMEDIES)


def test_a_scenario_edited_in_place_keeps_the_plain_replace_advice(tmp_path: Path) -> None:
    store = EmbeddedStore()
    path = tmp_path / "only.exsce"
    path.write_text(DRAFTED.format(name="only", namespace=""), encoding="utf-8")
    add_prov(store, compile_scenario(load_spec(path).scenario()))
    path.write_text(DRAFTED.format(name="only", namespace="").replace("sequential", "parallel"))
    with pytest.raises(StoreConflictError) as raised:
        add_prov(store, compile_scenario(load_spec(path).scenario()))
    message = str(raised.value)
    assert "to replace it, add it again with replace" in message
    assert raised.value.remedied is not None
    assert "\nto replace it, add it again with replace (`exscec compile SPEC --store --replace`)" in (
        raised.value.remedied.said(REMEDIES)
    )
    assert "exsce:only_bundle" in message
    assert "named by id alone" not in message  # the scenario's own graph
