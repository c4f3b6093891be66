"""Import and export of the method's oracle files.

The round trip is the method's own file: oracles/scenario_c.yaml imports as acceptance
criteria of scenario_c, which print as DSL text that parses back to the same criteria,
and export as YAML whose data is the file's (numbers compared as floats; comments are
not data, and key order is compared separately).
"""

from __future__ import annotations

import shutil
import tempfile
from pathlib import Path
from typing import Any

import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from exsce_dsl.errors import ExportError, ImportFormatError
from exsce_dsl.lang import format_document, load_spec
from exsce_dsl.lang.yaml.oracles import (
    default_topics,
    export_oracle_yaml,
    import_oracle_yaml,
    import_oracles,
    is_oracle_yaml,
    oracles_to_yaml,
)
from exsce_dsl.model import Document, Scenario
from exsce_dsl.model.acceptance import (
    Acceptance,
    BasicRelation,
    Criterion,
    Expectation,
    Moment,
    Quantifier,
    Quantity,
    Subject,
    When,
    Window,
)

from tests.support.cli import exscec_here
from tests.support.paths import EXAMPLES, FIXTURES

ORACLES = FIXTURES / "oracles" / "scenario_c.yaml"
EXAMPLE = EXAMPLES / "brsu_building_c"
MISSION = Subject(Quantifier.MISSION)
EACH = Subject(Quantifier.EACH_ROBOT)
TIAGO1 = Subject(Quantifier.ROBOT, "tiago1")


@pytest.fixture(scope="module")
def scenario_c() -> Scenario:
    return load_spec(EXAMPLE / "scenario_c.exsce").scenario("scenario_c")


def example_without_acceptance(folder: Path) -> Path:
    """A copy of the example folder whose scenario_c.exsce has no acceptance block."""
    shutil.copytree(EXAMPLE, folder)
    spec = folder / "scenario_c.exsce"
    spec.write_text(spec.read_text().split("acceptance for scenario_c")[0], encoding="utf-8")
    return spec


def dsl_text(acceptance: Acceptance) -> str:
    return format_document(Document("", (), (acceptance,)), {})


def as_floats(data: Any) -> Any:
    if isinstance(data, dict):
        return {k: as_floats(v) for k, v in data.items()}
    if isinstance(data, list):
        return [as_floats(v) for v in data]
    return float(data) if isinstance(data, int | float) and not isinstance(data, bool) else data


def key_order(data: Any) -> Any:
    if isinstance(data, dict):
        return [(k, key_order(v)) for k, v in data.items()]
    return None


def s(value: float, written: str) -> Quantity:
    return Quantity(value, "s", written)


def m(value: float, written: str) -> Quantity:
    return Quantity(value, "m", written)


# -- the method's file ----------------------------------------------------------------------


def test_the_method_file_imports_as_these_criteria(scenario_c: Scenario) -> None:
    acceptance = import_oracle_yaml(ORACLES, scenario_c)
    (criterion,) = acceptance.criteria
    assert acceptance.scenario == "scenario_c"
    assert (criterion.title, criterion.givens, criterion.when) == ("baseline", (), When(mission="mission_c"))
    t1 = [e for e in criterion.expectations if e.subject == TIAGO1]
    assert criterion.expectations[:2] == (
        Expectation(MISSION, "mission_duration", BasicRelation.INVARIANT, value=s(97.606, ""), tolerance=s(10.0, "")),
        Expectation(MISSION, "distance_between_robots", BasicRelation.ABOVE_MIN, limit=m(0.1, "")),
    )
    assert t1 == [
        Expectation(TIAGO1, "task_duration", BasicRelation.INVARIANT, value=s(97.606, ""), tolerance=s(5.0, "")),
        Expectation(TIAGO1, "waypoints_visited", BasicRelation.INVARIANT, value=Quantity(3.0)),
        Expectation(
            TIAGO1, "distance_travelled", BasicRelation.INVARIANT, value=m(50.702942669287076, ""), tolerance=m(2.0, "")
        ),
        Expectation(TIAGO1, "distance_to_obstacles", BasicRelation.ABOVE_MIN, limit=m(0.1, "")),
        Expectation(TIAGO1, "max_velocity", BasicRelation.BELOW_MAX, limit=Quantity(1.0, "m/s")),
    ]
    assert len(criterion.expectations) == 12
    # the numbers are written as the file writes them
    assert "tiago1 distance_travelled is invariant around 50.702942669287076 m within 2.0 m" in dsl_text(acceptance)
    assert "tiago1 waypoints_visited is invariant around 3\n" in dsl_text(acceptance)


def test_round_trip_yaml_to_dsl_to_yaml(scenario_c: Scenario, tmp_path: Path) -> None:
    imported = import_oracle_yaml(ORACLES, scenario_c)
    spec_file = example_without_acceptance(tmp_path / "example")
    spec_file.write_text(spec_file.read_text() + "\n" + dsl_text(imported), encoding="utf-8")
    spec = load_spec(spec_file)
    parsed = spec.acceptance_of("scenario_c")
    assert parsed == imported

    exported = yaml.safe_load(export_oracle_yaml(parsed, spec.scenario("scenario_c")))
    fixture = yaml.safe_load(ORACLES.read_text())
    assert as_floats(exported) == as_floats(fixture)
    assert key_order(exported) == key_order(fixture)


def test_a_metamorphic_section_compares_with_the_base_scenario(tmp_path: Path) -> None:
    oracles = tmp_path / "scenario_c.yaml"
    oracles.write_text(
        "id: scenario_c\n"
        "metamorphic:\n"
        "  base_scenario: scenario_b\n"
        "  robots:\n"
        "    tiago1:\n"
        "      distance_travelled:\n"
        "        topics:\n"
        "        - /tiago1/distance_travelled\n"
        "        baseline:\n"
        "          value: 50.7\n"
        "          delta: 47.5\n"
        "          tolerance: 0.0\n"
        "        relationship:\n"
        "          package: exsce.metamorphic.relationships\n"
        "          name: increasing\n"
    )
    folder = tmp_path / "example"
    example_without_acceptance(folder)
    (folder / "both.exsce").write_text('import "scenario_c.exsce"\nimport "scenario_b.exsce"\n')
    spec = load_spec(folder / "both.exsce")
    acceptance = import_oracles(oracles, spec)
    (criterion,) = acceptance.criteria
    assert criterion.title == "against scenario_b"
    assert criterion.expectations == (
        Expectation(TIAGO1, "distance_travelled", BasicRelation.INCREASING, value=m(50.7, ""), delta=m(47.5, ""),
                    tolerance=m(0.0, ""), against="scenario_b"),
    )
    text = dsl_text(acceptance)
    assert "then tiago1 distance_travelled is increasing from 50.7 m by 47.5 m within 0.0 m of scenario_b" in text
    (folder / "both.exsce").write_text('import "scenario_c.exsce"\nimport "scenario_b.exsce"\n\n' + text)
    assert load_spec(folder / "both.exsce").acceptance_of("scenario_c") == acceptance
    exported = yaml.safe_load(export_oracle_yaml(acceptance, spec.scenario("scenario_c")))
    assert exported == yaml.safe_load(oracles.read_text())


def test_an_oracle_file_is_told_from_a_scenario_file() -> None:
    assert is_oracle_yaml(ORACLES)
    assert not is_oracle_yaml(FIXTURES / "scenarios" / "scenario_c.yaml")


# -- import errors: each planted mistake at its line and column ------------------------------

ORACLE_FILE = """\
id: scenario_c
baseline:
  base_scenario: scenario_c
  mission:
    mission_duration:
      topics:
        - /tiago1/waypoint_dispatcher/feedback
        - /tiago2/waypoint_dispatcher/feedback
      baseline:
        value: 97.606
        tolerance: 10.0
      relationship:
        package: exsce.metamorphic.relationships
        name: invariant
  robots:
    tiago1:
      max_velocity:
        topics:
        - /tiago1/nav_vel
        baseline:
          limit: 1.0
        relationship:
          package: exsce.metamorphic.relationships
          name: below_max
"""

# (line to change, its text, the new text, where the error is, what it says)
IMPORT_ERRORS = [
    (1, "scenario_c", "scenario_b", "1:5", "these are oracles of scenario 'scenario_b', not of 'scenario_c'"),
    (3, "scenario_c", "scenario c", "3:18", "scenario id 'scenario c'"),
    (5, "mission_duration", "mission_durration", "5:5", "unknown metric 'mission_durration'; did you mean 'mission_duration'?"),
    (5, "mission_duration", "tiago2", "5:5", "unknown metric 'tiago2'; 'tiago2' is a robot: put it under 'robots'"),
    (5, "mission_duration", "task_duration", "5:5", "'task_duration' is measured per robot"),
    (17, "max_velocity", "distance_between_robots", "17:7", "'distance_between_robots' is measured for the whole mission"),
    (16, "tiago1", "tiago3", "16:5", "robot 'tiago3' is not in the fleet of scenario 'scenario_c'; did you mean 'tiago1'?"),
    (23, "exsce.metamorphic.relationships", "my_lab.relations", "23:20", "never from module names in data files"),
    (24, "below_max", "below_maximum", "24:17", "unknown relationship 'below_maximum'; did you mean 'below_max'?"),
    (24, "below_max", "equal", "24:17", "unknown relationship 'equal'; the method's relations are below_max, above_min, invariant, increasing, decreasing"),
    (10, "value", "mean", "10:9", "'invariant' needs a value: add 'value: <number>'"),
    (10, "value", "mean", "10:9", "'mean' does not go with 'invariant', which takes value and tolerance"),
    (21, "limit", "value", "21:11", "'below_max' needs a limit"),
    (10, "97.606", "fast", "10:16", "should be a number, not str 'fast'"),
    (11, "10.0", "-1.0", "11:20", "a tolerance cannot be negative (-1.0)"),
    (19, "nav_vel", "cmd_vel", "19:11", "topic '/tiago1/cmd_vel' is not one exsce computes max_velocity of 'tiago1' from (/tiago1/nav_vel); the DSL cannot override a metric's topics yet"),
    (8, "tiago2", "tiago1", "7:9", "the topics of mission_duration of the mission lack /tiago2/waypoint_dispatcher/feedback"),
    (8, "tiago2", "tiago3", "8:11", "topic '/tiago3/waypoint_dispatcher/feedback' is not one exsce computes mission_duration of the mission from"),
    (2, "baseline", "baselines", "2:1", "unknown section 'baselines'; did you mean 'baseline'?"),
    (15, "robots", "robot", "15:3", "unknown key 'robot' in baseline; did you mean 'robots'?"),
]


def planted(line: int, old: str, new: str) -> str:
    lines = ORACLE_FILE.splitlines(keepends=True)
    assert old in lines[line - 1]
    lines[line - 1] = lines[line - 1].replace(old, new)
    return "".join(lines)


@pytest.mark.parametrize(("line", "old", "new", "where", "message"), IMPORT_ERRORS)
def test_import_error_is_reported_where_it_is(
    scenario_c: Scenario, tmp_path: Path, line: int, old: str, new: str, where: str, message: str
) -> None:
    oracles = tmp_path / "scenario_c.yaml"
    oracles.write_text(planted(line, old, new))
    with pytest.raises(ImportFormatError) as raised:
        import_oracle_yaml(oracles, scenario_c)
    found = [str(d) for d in raised.value.diagnostics]
    assert any(d.startswith(f"{oracles}:{where}: error: ") and message in d for d in found), found


def test_the_unplanted_file_imports(scenario_c: Scenario, tmp_path: Path) -> None:
    oracles = tmp_path / "scenario_c.yaml"
    oracles.write_text(ORACLE_FILE)
    assert len(import_oracle_yaml(oracles, scenario_c).expectations()) == 2


def test_every_import_error_is_reported_at_once(scenario_c: Scenario, tmp_path: Path) -> None:
    oracles = tmp_path / "scenario_c.yaml"
    text = planted(5, "mission_duration", "mission_durration")
    oracles.write_text(text.replace("name: below_max", "name: below_maximum"))
    with pytest.raises(ImportFormatError) as raised:
        import_oracle_yaml(oracles, scenario_c)
    assert [(d.location.line, d.location.column) for d in raised.value.diagnostics if d.location] == [
        (5, 5),
        (24, 17),
    ]


def test_a_relationship_package_is_never_imported(
    scenario_c: Scenario, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    (tmp_path / "planted_relations.py").write_text("import pathlib\npathlib.Path(__file__).with_name('ran').touch()\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    oracles = tmp_path / "scenario_c.yaml"
    oracles.write_text(ORACLE_FILE.replace("exsce.metamorphic.relationships", "planted_relations"))
    with pytest.raises(ImportFormatError, match="nothing named here is imported"):
        import_oracle_yaml(oracles, scenario_c)
    assert not (tmp_path / "ran").exists()


# -- export ---------------------------------------------------------------------------------


def criteria(*expectations: Expectation, when: When | None = None) -> Acceptance:
    return Acceptance("scenario_c", (Criterion("c", (), when or When(mission="mission_c"), expectations),))


def test_each_robot_is_every_robot_in_fleet_order(scenario_c: Scenario) -> None:
    data = oracles_to_yaml(
        criteria(Expectation(EACH, "max_velocity", BasicRelation.BELOW_MAX, limit=Quantity(1.0, "m/s"))), scenario_c
    )
    assert data == {
        "id": "scenario_c",
        "baseline": {
            "base_scenario": "scenario_c",
            "robots": {
                robot: {
                    "max_velocity": {
                        "topics": [f"/{robot}/nav_vel"],
                        "baseline": {"limit": 1.0},
                        "relationship": {"package": "exsce.metamorphic.relationships", "name": "below_max"},
                    }
                }
                for robot in ("tiago1", "tiago2")
            },
        },
    }


@pytest.mark.parametrize(
    ("tolerance", "expected"),
    [(None, 4.0), (Quantity(2.0, "std"), 8.0), (Quantity(5.0, "%"), 5.0), (Quantity(10.0, "s"), 10.0)],
)
def test_a_clause_without_value_takes_the_baseline(
    scenario_c: Scenario, tolerance: Quantity | None, expected: float
) -> None:
    clause = Expectation(MISSION, "mission_duration", BasicRelation.INVARIANT, tolerance=tolerance)
    data = oracles_to_yaml(criteria(clause), scenario_c, {("mission_duration", None): (100.0, 4.0)})
    assert data["baseline"]["mission"]["mission_duration"]["baseline"] == {"value": 100.0, "tolerance": expected}


def test_a_change_without_value_starts_from_the_base_mean(scenario_c: Scenario) -> None:
    clause = Expectation(TIAGO1, "waypoints_visited", BasicRelation.INCREASING, delta=Quantity(2.0), against="scenario_b")
    data = oracles_to_yaml(criteria(clause), scenario_c, {("waypoints_visited", "tiago1"): (3.0, 0.0)})
    assert data["metamorphic"]["base_scenario"] == "scenario_b"
    entry = data["metamorphic"]["robots"]["tiago1"]["waypoints_visited"]
    assert entry["baseline"] == {"value": 3, "delta": 2}
    assert entry["relationship"]["name"] == "increasing"


def test_a_clause_without_value_and_no_baseline_cannot_be_written(scenario_c: Scenario) -> None:
    acceptance = load_spec(EXAMPLE / "scenario_c.exsce").acceptance_of("scenario_c")
    assert acceptance is not None
    with pytest.raises(ExportError) as raised:
        export_oracle_yaml(acceptance, scenario_c)
    (diagnostic,) = raised.value.diagnostics
    assert diagnostic.location is not None
    assert (Path(diagnostic.location.file).name, diagnostic.location.line) == ("scenario_c.exsce", 35)
    assert diagnostic.message.startswith(
        "'each robot task_duration is invariant within 3 std' needs the mean of stored runs of task_duration "
        "of tiago1, and no baseline was given"
    )


@pytest.mark.parametrize(
    ("acceptance", "message"),
    [
        (
            criteria(Expectation(TIAGO1, "max_velocity", BasicRelation.BELOW_MAX, limit=Quantity(0.8, "m/s"),
                                 window=Window(Moment.AFTER, "tiago1", pose="classroom_c022-w001"))),
            "'tiago1 max_velocity stays below 0.8 m/s after tiago1 reaches classroom_c022-w001' looks at part "
            "of a run",
        ),
        (
            criteria(Expectation(TIAGO1, "max_velocity", BasicRelation.BELOW_MAX, limit=Quantity(0.8, "m/s")),
                     when=When(robot="tiago1", task="delivery_a")),
            "looks at part of a run (during delivery_a, as 'when tiago1 does delivery_a' says)",
        ),
        (
            criteria(Expectation(EACH, "max_velocity", BasicRelation.BELOW_MAX, limit=Quantity(1.0, "m/s")),
                     Expectation(TIAGO1, "max_velocity", BasicRelation.BELOW_MAX, limit=Quantity(0.8, "m/s"))),
            "are both about max_velocity of tiago1",
        ),
        (
            criteria(Expectation(MISSION, "mission_duration", BasicRelation.INVARIANT, value=s(97.6, "97.6"),
                                 tolerance=Quantity(1.0, "std"))),
            "'mission_duration is invariant around 97.6 s within 1 std' needs the standard deviation of stored "
            "runs of mission_duration of the mission, and no baseline was given: write a tolerance in the "
            "metric's unit",
        ),
    ],
)
def test_clauses_the_method_cannot_hold_are_refused(
    scenario_c: Scenario, acceptance: Acceptance, message: str
) -> None:
    with pytest.raises(ExportError, match=message.replace("(", r"\(").replace(")", r"\)")):
        export_oracle_yaml(acceptance, scenario_c)


def test_default_topics_follow_the_robot_namespaces(scenario_c: Scenario) -> None:
    assert default_topics(scenario_c, "distance_between_robots", None) == ("/tiago1/robot_pose", "/tiago2/robot_pose")
    assert default_topics(scenario_c, "waypoints_visited", "tiago2") == ("/tiago2/waypoint_dispatcher/result",)


finite = st.floats(min_value=-1e6, max_value=1e6, allow_nan=False)


@settings(max_examples=40, deadline=None)
@given(value=finite, tolerance=st.floats(min_value=0, max_value=1e6), limit=finite)
def test_export_then_import_gives_the_same_criteria(value: float, tolerance: float, limit: float) -> None:
    scenario = load_spec(EXAMPLE / "scenario_c.exsce").scenario("scenario_c")
    acceptance = Acceptance(
        "scenario_c",
        (Criterion("baseline", (), When(mission="mission_c"), (
            Expectation(MISSION, "mission_duration", BasicRelation.INVARIANT, value=s(value, ""), tolerance=s(tolerance, "")),
            Expectation(TIAGO1, "distance_to_obstacles", BasicRelation.ABOVE_MIN, limit=m(limit, "")),
        )),),
    )
    with tempfile.TemporaryDirectory() as folder:
        oracles = Path(folder) / "scenario_c.yaml"
        oracles.write_text(export_oracle_yaml(acceptance, scenario))
        imported = import_oracle_yaml(oracles, scenario)
    assert imported == acceptance


# -- the command line -------------------------------------------------------------------------


def test_cli_imports_and_exports_an_oracle_file(tmp_path: Path) -> None:
    spec = example_without_acceptance(tmp_path / "example")
    printed = exscec_here("import", str(ORACLES), "--spec", str(spec))
    assert printed.returncode == 0, printed.stderr
    assert printed.stdout.startswith('acceptance for scenario_c {\n  scenario "baseline" {\n    when mission_c runs\n')

    written = exscec_here("import", str(ORACLES), "--spec", str(spec), "-o", str(tmp_path / "specs"))
    assert written.returncode == 0, written.stderr
    criteria_file = tmp_path / "specs" / "scenario_c_acceptance.exsce"
    assert criteria_file.read_text().startswith('import "../example/scenario_c.exsce"\n\nacceptance for')

    exported = exscec_here("export", str(criteria_file), "--to", "oracle-yaml", "--scenario", "scenario_c",
                           "-o", str(tmp_path / "out"))
    assert exported.returncode == 0, exported.stderr
    data = yaml.safe_load((tmp_path / "out" / "oracles" / "scenario_c.yaml").read_text())
    assert as_floats(data) == as_floats(yaml.safe_load(ORACLES.read_text()))


def test_cli_oracle_import_needs_the_spec_and_export_says_which_clause(tmp_path: Path) -> None:
    no_spec = exscec_here("import", str(ORACLES))
    assert no_spec.returncode == 2
    assert "name the spec of its scenario with --spec" in no_spec.stderr

    no_baseline = exscec_here("export", str(EXAMPLE / "scenario_c.exsce"), "--to", "oracle-yaml", "-o", str(tmp_path))
    assert no_baseline.returncode == 2
    assert "scenario_c.exsce:35:10: error: 'each robot task_duration is invariant within 3 std' needs the mean" in (
        no_baseline.stderr
    )
    assert not (tmp_path / "oracles").exists()


def test_the_file_s_values_reach_the_oracle_prov_through_exscec_baseline(scenario_c: Scenario) -> None:
    """Imported criteria carry fixed values, so a baseline needs no runs: the method's numbers
    go straight into the oracle PROV (Listing 17's shape)."""
    from exsce_dsl.model.oracles import OracleType
    from exsce_dsl.oracles.baseline import baseline_oracles
    from exsce_dsl.prov.oracle import compile_oracles
    from exsce_dsl.store.embedded import EmbeddedStore

    acceptance = import_oracle_yaml(ORACLES, scenario_c)
    oracles = {o.name: o for o in baseline_oracles(EmbeddedStore(None), acceptance, scenario_c)}
    assert {o.type for o in oracles.values()} == {OracleType.BASELINE}
    mission = oracles["mission_duration"]
    assert (mission.relation, mission.value, mission.tolerance) == ("invariant", 97.606, 10.0)
    assert mission.topics == ("/tiago1/waypoint_dispatcher/feedback", "/tiago2/waypoint_dispatcher/feedback")
    assert (oracles["tiago1-max_velocity"].relation, oracles["tiago1-max_velocity"].limit) == ("below_max", 1.0)
    assert oracles["tiago1-distance_travelled"].value == 50.702942669287076
    provn = compile_oracles("scenario_c", list(oracles.values())).get_provn()
    assert 'oracle:value="97.606" %% xsd:double' in provn and 'oracle:tolerance="10.0" %% xsd:double' in provn
    assert 'oracle:limit="0.1" %% xsd:double' in provn and 'oracle:relationship="above_min"' in provn
    assert 'oracle:value="50.702942669287076" %% xsd:double' in provn
