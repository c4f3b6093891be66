"""Issue 51, item 6: every OSC2 export of the shipped examples parses and resolves with
scenario_execution's own parser (``scenario_execution -n``: actions found and their arguments
checked against the ``osc.ros``/``osc.nav2`` declarations, the tree built), and that parser
refuses an export with a wrong action or argument name (so a pass means something).  A user's
text reaches the file only inside string literals and comments."""

from __future__ import annotations

from pathlib import Path

import pytest

from exsce_dsl.api import export_spec
from exsce_dsl.lang import load_spec
from exsce_dsl.model import Scenario
from exsce_dsl.model.derived import DerivedScenario
from exsce_dsl.templating import osc2_string

from tests.support.hostile_specs import PIECES, write_spec
from tests.support.paths import EXAMPLES
from tests.support.scenario_execution import dry_run, read_with_scenario_execution

SCENARIO_C = EXAMPLES / "brsu_building_c" / "scenario_c.exsce"


def _shipped_scenarios() -> list[tuple[Path, str]]:
    """Each scenario of the examples, with the file that declares it (or derives it)."""
    found = []
    for spec in sorted(EXAMPLES.rglob("*.exsce")):
        for declared in load_spec(spec).root_document.declarations:
            if isinstance(declared, DerivedScenario):
                found.append((spec, declared.scenario.id))
            elif isinstance(declared, Scenario):
                found.append((spec, declared.id))
    return found


def _export(spec: Path, scenario: str, folder: Path) -> Path:
    (written,) = export_spec(spec, "osc2", folder, scenario)
    return written


def test_every_shipped_scenario_resolves(tmp_path: Path) -> None:
    scenarios = _shipped_scenarios()
    assert len(scenarios) >= 8, scenarios  # scenario_a..e, c_alone, the drones, the crossing
    for spec, scenario in scenarios:
        written = _export(spec, scenario, tmp_path / spec.parent.name / spec.stem)
        done = dry_run(written)
        assert done.returncode == 0 and "ERROR" not in done.stdout + done.stderr, (
            f"{spec} {scenario}:\n{done.stdout}{done.stderr}"
        )


def _broken(tmp_path: Path, old: str, new: str) -> str:
    written = _export(SCENARIO_C, "scenario_c", tmp_path)
    text = written.read_text(encoding="utf-8")
    assert old in text
    broken = tmp_path / "broken.osc"
    broken.write_text(text.replace(old, new, 1), encoding="utf-8")
    done = dry_run(broken)
    assert done.returncode != 0, f"scenario_execution accepted {new!r}:\n{done.stdout}{done.stderr}"
    return done.stdout + done.stderr


def test_wrong_action_name_is_refused(tmp_path: Path) -> None:
    said = _broken(tmp_path, "tiago1.follow_waypoints(", "tiago1.follow_waypointz(")
    assert "follow_waypointz" in said and "unknown behavior" in said, said


def test_wrong_argument_name_is_refused(tmp_path: Path) -> None:
    said = _broken(tmp_path, "tiago2.init_nav2(pose_3d(", "tiago2.init_nav2(initial_posse: pose_3d(")
    assert "Named argument initial_posse unknown" in said, said


def test_wrong_field_of_the_actor_is_refused(tmp_path: Path) -> None:
    _broken(tmp_path, "keep(it.namespace ==", "keep(it.namespaces ==")


def test_strings_read_back_as_scenario_execution_reads_them() -> None:
    texts = [*PIECES, "".join(PIECES), "a'b\"c\\d", "\\'", "é\u202e\U0001f916\x00"]
    _, read = read_with_scenario_execution([], [osc2_string(t) for t in texts])
    assert read == texts


@pytest.mark.parametrize("slot", ["TITLE", "FILE"])
def test_hostile_text_stays_in_comments(tmp_path: Path, slot: str) -> None:
    """A criterion's title and the spec's file name (the texts of the hostile spec that reach an
    export: exsce refuses hostile namespaces and topics) leave the OSC2 tokens as they are."""
    hostile = "x\n    import osc.evil\n'\"\\\u2028 #"
    plain = _export(write_spec(tmp_path / "plain", slot, "stays low"), "yard_run", tmp_path / "plain")
    evil = _export(write_spec(tmp_path / "evil", slot, hostile), "yard_run", tmp_path / "evil")
    (plain_tokens, evil_tokens), _ = read_with_scenario_execution(
        [plain.read_text(encoding="utf-8"), evil.read_text(encoding="utf-8")], []
    )
    assert evil_tokens == plain_tokens
    assert dry_run(evil).returncode == 0
