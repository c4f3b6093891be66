"""The one plug-in loader (:mod:`exsce_dsl.plugins`), with real entry points of a distribution
installed in a temporary folder: one policy for every kind of plug-in."""

from __future__ import annotations

import re
import warnings
from collections.abc import Iterator
from pathlib import Path

import pytest

from exsce_dsl import plugins
from exsce_dsl.errors import ExsceError
from exsce_dsl.explore import executors
from exsce_dsl.explore.executors import EXECUTORS, ExecutorOptions, named_executor
from exsce_dsl.oracles.relations import RELATIONS
from exsce_dsl.plugins import GROUPS, Registry
from exsce_dsl.runs.bags.reading import BAG_READERS
from exsce_dsl.sim.simulators import SIMULATORS
from exsce_dsl.store.flavours import FLAVOURS

from tests.support.plugin_packages import installed_plugins

DOCS = Path(__file__).resolve().parents[1] / "docs"

PLUGIN = """\
from pathlib import Path


class Played:
    name = "played"

    def execute(self, scenario, scenario_file, out_dir, runs, seed):
        return [Path(out_dir) / f"run{i}.bag" for i in range(runs)]


def make_played():
    return Played()


def make_nothing():
    return 42


raise_on_import = None
"""

ENTRY_POINTS = """\
[exsce.executors]
played = exsce_test_plugins:make_played
nothing = exsce_test_plugins:make_nothing
ros1 = exsce_test_plugins:make_played
missing = exsce_test_plugins:no_such_factory
not_callable = exsce_test_plugins:raise_on_import
"""


@pytest.fixture
def installed(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> Iterator[None]:
    """A distribution installed in ``tmp_path`` that registers executors, good and broken."""
    yield from installed_plugins(tmp_path, monkeypatch, EXECUTORS, "exsce_test_plugins", PLUGIN, ENTRY_POINTS)


@pytest.mark.usefixtures("installed")
def test_a_broken_plugin_is_skipped_with_a_warning_and_the_others_load() -> None:
    with pytest.warns(UserWarning) as warned:
        names = EXECUTORS.names()
    said = [str(w.message) for w in warned]
    assert names == ("ros1", "ros2", "played", "nothing")  # the built-ins first, then the good plug-ins
    assert any("'missing'" in s and "cannot be loaded" in s for s in said)
    assert any("'not_callable'" in s and "is not an executor factory named 'not_callable'" in s for s in said)


@pytest.mark.usefixtures("installed")
def test_a_plugin_cannot_replace_a_built_in_executor() -> None:
    with pytest.warns(UserWarning) as warned:
        chosen = EXECUTORS.get("ros1")
    assert chosen is executors.BUILT_IN_EXECUTORS["ros1"]
    replace = "the plug-in executor 'ros1' (exsce_test_plugins:make_played) cannot replace exsce's own 'ros1'"
    assert any(str(w.message).startswith(replace) for w in warned)


@pytest.mark.usefixtures("installed")
def test_a_plugin_executor_is_chosen_by_its_name(tmp_path: Path) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with named_executor("played") as executor:
            assert executor.name == "played"
            assert executor.execute(None, tmp_path, tmp_path, 2, 0) == [
                tmp_path / "run0.bag",
                tmp_path / "run1.bag",
            ]
        with pytest.raises(ExsceError, match="'nothing' .* did not give an Executor"):
            named_executor("nothing").__enter__()
        with pytest.raises(ExsceError, match="not the plug-in 'played'"):
            named_executor("played", ExecutorOptions(faults=("slow",)))
        with pytest.raises(ExsceError, match=r"no executor 'playd'; did you mean 'played'\?"):
            named_executor("playd")


def test_every_kind_has_its_group_and_its_registry() -> None:
    kinds = {registry.kind for registry in (RELATIONS, EXECUTORS, SIMULATORS, BAG_READERS, FLAVOURS)}
    assert kinds == set(GROUPS)
    assert {registry.group for registry in plugins.registries()} == set(GROUPS.values())


def test_the_documented_groups_are_the_ones_the_code_loads() -> None:
    text = (DOCS / "development.md").read_text(encoding="utf-8")
    section = text.split("## Plug-ins", 1)[1].split("\n## ", 1)[0]
    documented = dict(re.findall(r"^\| ([a-z ]+) \| `(exsce\.[a-z_]+)` \|", section, flags=re.MULTILINE))
    assert documented == dict(GROUPS)


def test_a_registry_of_an_unknown_kind_cannot_be_made() -> None:
    with pytest.raises(KeyError):
        Registry("metric", (), lambda name, loaded: None, "a metric")
