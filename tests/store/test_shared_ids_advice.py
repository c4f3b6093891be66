"""A robot, environment, area or task bundle is named by the element's id alone (issue 48, item 2,
not done: identities scoped by scenario): two scenarios that declare one robot id otherwise cannot
share a store.  Until they can, the refusal says why and warns that --replace would change the
other scenario's robot too, where it used to advise --replace alone."""

from __future__ import annotations

from pathlib import Path

import pytest

from exsce_dsl.lang import load_spec
from exsce_dsl.prov import compile_scenario
from exsce_dsl.store.base import StoreConflictError
from exsce_dsl.store.embedded import EmbeddedStore
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


def test_a_robot_id_declared_otherwise_by_another_scenario_is_refused_with_why(tmp_path: Path) -> None:
    store = EmbeddedStore()
    for name, namespace in (("first", ""), ("second", "elsewhere")):
        path = tmp_path / f"{name}.exsce"
        path.write_text(DRAFTED.format(name=name, namespace=namespace), encoding="utf-8")
        document = compile_scenario(load_spec(path).scenario())
        if name == "first":
            add_prov(store, document)
            continue
        with pytest.raises(StoreConflictError) as raised:
            add_prov(store, document)
        message = str(raised.value)
        assert "robot:root_robot_bundle: root_robot:software-config differs" in message
        assert "robot 'root_robot' is named by id alone" in message
        assert "--replace would change the other scenario's too" in message


def test_a_scenario_edited_in_place_keeps_the_plain_replace_advice(tmp_path: Path) -> None:
    store = EmbeddedStore()
    path = tmp_path / "only.exsce"
    path.write_text(DRAFTED.format(name="only", namespace=""), encoding="utf-8")
    add_prov(store, compile_scenario(load_spec(path).scenario()))
    path.write_text(DRAFTED.format(name="only", namespace="").replace("sequential", "parallel"))
    with pytest.raises(StoreConflictError) as raised:
        add_prov(store, compile_scenario(load_spec(path).scenario()))
    message = str(raised.value)
    assert "`exscec compile SPEC --store --replace`" in message
    assert "exsce:only_bundle" in message
    assert "named by id alone" not in message  # the scenario's own graph
