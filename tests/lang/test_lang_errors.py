"""What a new user trips over, told in words (issue 19, stumble 5), through `exscec check`.

Each case writes a small specification, runs the real `exscec check` on it and reads
`file:line:col: severity: message` lines back: where each one is, and its key words.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from pathlib import Path

import pytest
from lsprotocol import types

import exsce_dsl.errors as errors_module
from exsce_dsl.errors import Diagnostic, Severity, SourceLocation
from exsce_dsl.lang import analyse
from exsce_dsl.lang.builders.references import UnknownNames, declared_in
from exsce_dsl.lang.chunks import declared_names
from exsce_dsl.lang.loader import parse_whole
from exsce_dsl.lang.parser import ParsedFile
from exsce_dsl.lsp.convert import TextLines, lsp_diagnostic

from tests.support.cli import run_exscec
from tests.support.paths import EXAMPLES, ROOT

ENV = """\
environment yard {
  area north {
    pose p at (1.0, 1.0)
    pose q at (2.0, 1.0)
  }
}
"""

TASKS = """\
import "env.exsce"

task go_b {
  visit q facing 180 deg
}

task go_home {
  visit p
}
"""

SCENARIO = """\
import "env.exsce"
import "tasks.exsce"

robot type turtle { }

scenario s1 in yard {
  robots {
    r1: turtle starts at p
    r2: turtle starts at q
  }
  mission m1 parallel {
    r1 does go_b then go_home
    r2 does go_home
  }
}
"""

_LINE = re.compile(r"^(?P<file>[^:\s]+):(?P<line>\d+):(?P<col>\d+): (?P<severity>\w+): (?P<message>.*)$")


def _check(folder: Path, files: dict[str, str], root: str = "scenario.exsce") -> list[tuple[str, str, str]]:
    """Write ``files`` (the base ones, changed), run ``exscec check root``: the
    (``file:line:col``, severity, message) of each diagnostic, in the order printed."""
    for name, text in {"env.exsce": ENV, "tasks.exsce": TASKS, "scenario.exsce": SCENARIO, **files}.items():
        (folder / name).parent.mkdir(parents=True, exist_ok=True)
        (folder / name).write_text(text)
    result = run_exscec("check", root, cwd=folder)
    assert "Traceback" not in result.stderr
    found = []
    for line in result.stderr.splitlines():
        match = _LINE.match(line)
        if match:
            where = f"{match['file']}:{match['line']}:{match['col']}"
            found.append((where, match["severity"], match["message"]))
    return found


def _errors(found: list[tuple[str, str, str]]) -> list[tuple[str, str]]:
    return [(where, message) for where, severity, message in found if severity == "error"]


def test_the_base_specification_is_clean(in_tmp: Path) -> None:
    assert _check(in_tmp, {}) == []


# ------------------------------------------------------------ a. misspelt keywords
def test_a_keyword_read_as_a_name_is_suggested_where_it_is_written(in_tmp: Path) -> None:
    found = _errors(
        _check(in_tmp, {"scenario.exsce": SCENARIO.replace("r1: turtle starts", "r1: turtle start")})
    )
    assert found == [
        ("scenario.exsce:8:16", "expected 'starts', found 'start'; did you mean 'starts'?"),
    ]


@pytest.mark.parametrize(
    ("file", "old", "new", "where", "words"),
    [
        ("env.exsce", "area north", "aera north", "env.exsce:2:3", "found 'aera'; did you mean 'area'?"),
        (
            "scenario.exsce",
            "r2 does go_home",
            "r2 dose go_home",
            "scenario.exsce:13:8",
            "did you mean 'does'?",
        ),
        ("scenario.exsce", "  mission m1", "  misson m1", "scenario.exsce:11:3", "did you mean 'mission'?"),
        ("tasks.exsce", "  visit p", "  vist p", "tasks.exsce:8:3", "did you mean 'visit'?"),
        ("tasks.exsce", "q facing 180", "q facin 180", "tasks.exsce:4:11", "did you mean 'facing'?"),
    ],
)
def test_a_misspelt_keyword_gets_a_did_you_mean(
    in_tmp: Path, file: str, old: str, new: str, where: str, words: str
) -> None:
    base = {"env.exsce": ENV, "tasks.exsce": TASKS, "scenario.exsce": SCENARIO}[file]
    assert old in base
    found = _errors(_check(in_tmp, {file: base.replace(old, new, 1)}))
    assert [m for w, m in found if w == where and m.startswith("expected ") and words in m], found


def test_a_syntax_error_near_no_keyword_suggests_none(in_tmp: Path) -> None:
    found = _errors(_check(in_tmp, {"scenario.exsce": SCENARIO.replace("r1: turtle", "r1 turtle")}))
    assert found == [("scenario.exsce:8:8", "expected ':', found 'turtle'")]


# --------------------------------------------------------------- b. unknown units
def test_an_unknown_angle_unit_is_named_first_and_alone(in_tmp: Path) -> None:
    found = _check(in_tmp, {"tasks.exsce": TASKS.replace("facing 180 deg", "facing 180 degs")})
    errors = _errors(found)
    assert errors == [("tasks.exsce:4:22", "unknown unit 'degs'; expected deg or rad; did you mean 'deg'?")]
    assert found[0][1:] == ("error", errors[0][1])  # printed first
    # the tasks the broken file declares are not reported unknown where they are used
    assert not [m for _, m in errors if "unknown task" in m]


@pytest.mark.parametrize(
    ("file", "old", "new", "where", "message"),
    [
        (
            "env.exsce",
            "(1.0, 1.0)",
            "(1.0 mt, 1.0)",
            "env.exsce:3:20",
            "unknown unit 'mt'; expected m, cm or mm; did you mean 'm'?",
        ),
        (
            "env.exsce",
            "(2.0, 1.0)",
            "(2.0, 1 meters)",
            "env.exsce:4:23",
            "unknown unit 'meters'; expected m, cm or mm; did you mean 'm'?",
        ),
        (
            "tasks.exsce",
            "facing 180 deg",
            "facing 3 radians",
            "tasks.exsce:4:20",
            "unknown unit 'radians'; expected deg or rad; did you mean 'rad'?",
        ),
    ],
)
def test_an_unknown_unit_names_the_units_of_its_place(
    in_tmp: Path, file: str, old: str, new: str, where: str, message: str
) -> None:
    base = {"env.exsce": ENV, "tasks.exsce": TASKS}[file]
    found = _errors(_check(in_tmp, {file: base.replace(old, new, 1)}))
    assert (where, message) in found, found


def test_a_unit_of_another_kind_of_quantity_says_which_fit(in_tmp: Path) -> None:
    env = ENV.replace("(1.0, 1.0)", "(1.0 deg, 1.0)").replace("(2.0, 1.0)", "(2.0, 1.0) facing 3 m")
    found = _errors(_check(in_tmp, {"env.exsce": env}))
    assert found == [("env.exsce:3:20", "unit 'deg' does not fit here; expected m, cm or mm")]
    env = ENV.replace("(2.0, 1.0)", "(2.0, 1.0) facing 3 m")
    found = _errors(_check(in_tmp, {"env.exsce": env}))
    assert found == [("env.exsce:4:35", "unit 'm' does not fit here; expected deg or rad")]


def test_an_unknown_unit_in_acceptance_criteria_and_metrics(in_tmp: Path) -> None:
    criteria = SCENARIO + (
        "\nacceptance for s1 {\n"
        '  scenario "calm" {\n'
        "    then each robot max_velocity stays below 1 mps\n"
        "  }\n"
        "}\n"
    )
    found = _errors(_check(in_tmp, {"scenario.exsce": criteria}))
    [(where, message)] = found
    assert where == "scenario.exsce:19:48"
    assert message.startswith("unknown unit 'mps'; expected ") and message.endswith("; did you mean 'm/s'?")
    assert "std or %" in message  # a criterion's tolerance may be relative
    metric = (
        "metric top for each robot {\n"
        "  unit m/s\n"
        "  safe below 2 knots\n"
        '  reads vel: geometry_msgs/msg/Twist on "/{ns}/nav_vel"\n'
        "  value max(vel.linear.x)\n"
        "}\n"
    )
    found = _errors(_check(in_tmp, {"scenario.exsce": SCENARIO, "m.exsce": metric}, root="m.exsce"))
    [(where, message)] = found
    assert where == "m.exsce:3:16"
    assert "unknown unit 'knots'; expected " in message and "m/s" in message and "std" not in message


# ------------------------------------------- c. errors that follow from a syntax error
def test_names_of_a_file_with_a_syntax_error_are_not_reported_unknown(in_tmp: Path) -> None:
    broken = TASKS.replace("task go_home {", "task go_home {{")
    found = _check(in_tmp, {"tasks.exsce": broken})
    errors = _errors(found)
    assert len(errors) == 1 and errors[0][0] == "tasks.exsce:7:15", errors
    notes = [(w, m) for w, severity, m in found if severity == "note"]
    assert notes == [
        (
            "tasks.exsce:7:15",
            "3 errors that may follow from the syntax error in tasks.exsce are not shown: "
            "unknown task 'go_b' at scenario.exsce:12:13, unknown task 'go_home' at scenario.exsce:12:23, "
            "unknown task 'go_home' at scenario.exsce:13:13",
        )
    ]


def test_a_name_the_broken_file_does_not_declare_is_still_unknown(in_tmp: Path) -> None:
    broken = TASKS.replace("task go_home {", "task go_home {{")
    scenario = SCENARIO.replace("r2 does go_home", "r2 does go_hom")
    errors = _errors(_check(in_tmp, {"tasks.exsce": broken, "scenario.exsce": scenario}))
    assert ("scenario.exsce:13:13", "unknown task 'go_hom'") in [(w, m.split(";")[0]) for w, m in errors]


def test_poses_of_a_broken_environment_are_withheld_too(in_tmp: Path) -> None:
    found = _check(in_tmp, {"env.exsce": ENV.replace("area north {", "area north")})
    errors = _errors(found)
    assert [w for w, _ in errors] == ["env.exsce:3:5"], errors
    [note] = [m for _, severity, m in found if severity == "note"]
    assert note == (
        "3 errors that may follow from the syntax error in env.exsce are not shown: "
        "unknown pose 'q' at tasks.exsce:4:9, unknown pose 'p' at tasks.exsce:8:9, "
        "unknown environment 'yard' at scenario.exsce:6:16"
    )


def test_a_file_that_does_not_parse_still_has_its_imports_read(in_tmp: Path) -> None:
    # the scenario file imports only the broken tasks file, which imports the environment
    scenario = SCENARIO.replace('import "env.exsce"\n', "")
    broken = TASKS.replace("task go_home {", "task go_home {{")
    errors = _errors(_check(in_tmp, {"scenario.exsce": scenario, "tasks.exsce": broken}))
    assert [w for w, _ in errors] == ["tasks.exsce:7:15"], errors  # no unknown environment 'yard'


@pytest.mark.parametrize("path", sorted(EXAMPLES.rglob("*.exsce")), ids=lambda p: p.name)
def test_the_words_of_a_file_name_what_its_parse_tree_declares(path: Path) -> None:
    # what a file with a syntax error is taken to declare is read from its words; on valid
    # files, the words and the parser agree
    text = path.read_text()
    pf, problems = parse_whole(text, str(path))
    assert pf is not None and not problems
    assert declared_names(text) == set(declared_in(pf))


# ---------------------------------------------------- d. declared in a file not imported
def test_a_name_declared_in_a_file_not_imported_says_which_file(in_tmp: Path) -> None:
    scenario = SCENARIO.replace('import "tasks.exsce"\n', "")
    found = _errors(_check(in_tmp, {"scenario.exsce": scenario, "junk.exsce": "task {{ broken"}))
    assert found == [
        (
            "scenario.exsce:11:13",
            "unknown task 'go_b' (declared in tasks.exsce, which this file does not import)",
        ),
        (
            "scenario.exsce:11:23",
            "unknown task 'go_home' (declared in tasks.exsce, which this file does not import)",
        ),
        (
            "scenario.exsce:12:13",
            "unknown task 'go_home' (declared in tasks.exsce, which this file does not import)",
        ),
    ]


def test_a_file_beside_an_import_is_searched_and_named_from_the_file_using_the_name(in_tmp: Path) -> None:
    scenario = SCENARIO.replace('"env.exsce"', '"site/env.exsce"').replace('import "tasks.exsce"\n', "")
    tasks = TASKS.replace('import "env.exsce"', "")
    moved = "// moved to site/\n"
    files = {
        "scenario.exsce": scenario,
        "site/env.exsce": ENV,
        "site/tasks.exsce": tasks,
        "tasks.exsce": moved,
    }
    found = _errors(_check(in_tmp, files))
    assert (
        "scenario.exsce:11:13",
        "unknown task 'go_b' (declared in site/tasks.exsce, which this file does not import)",
    ) in found


def test_files_not_imported_are_parsed_once_per_check(in_tmp: Path) -> None:
    for name, text in {"env.exsce": ENV, "tasks.exsce": TASKS, "other.exsce": "robot type x { }\n"}.items():
        (in_tmp / name).write_text(text)
    (pf, _) = parse_whole(ENV, "env.exsce")
    assert pf is not None
    parsed: list[str] = []

    def counting(text: str, path: str) -> tuple[ParsedFile | None, Sequence[Diagnostic]]:
        parsed.append(path)
        return parse_whole(text, path)

    names = UnknownNames([pf], parse=counting)
    where = SourceLocation("env.exsce", 1, 1)
    assert names.message("task", "go_b", where, []) == (
        "unknown task 'go_b' (declared in tasks.exsce, which this file does not import)"
    )
    assert names.message("robot type", "x", where, []) is not None
    assert names.message("task", "nowhere", where, ["go_c"]) == "unknown task 'nowhere'"
    assert sorted(parsed) == ["other.exsce", "tasks.exsce"]


# --------------------------------------------- e. missing imports and unknown robots
def test_a_missing_import_suggests_the_closest_file(in_tmp: Path) -> None:
    found = _errors(_check(in_tmp, {"scenario.exsce": SCENARIO.replace('"tasks.exsce"', '"taks.exsce"')}))
    assert found[0] == (
        "scenario.exsce:2:1",
        "imported file 'taks.exsce' not found (looked for taks.exsce); did you mean 'tasks.exsce'?",
    )


def test_a_missing_import_in_a_folder_suggests_with_the_folder(in_tmp: Path) -> None:
    scenario = SCENARIO.replace('"env.exsce"', '"site/envv.exsce"')
    found = _errors(_check(in_tmp, {"scenario.exsce": scenario, "site/env.exsce": ENV}))
    assert (
        "scenario.exsce:1:1",
        "imported file 'site/envv.exsce' not found (looked for site/envv.exsce); "
        "did you mean 'site/env.exsce'?",
    ) in found


def test_an_unknown_robot_in_a_mission_gets_a_did_you_mean_or_the_fleet(in_tmp: Path) -> None:
    scenario = SCENARIO.replace("r1 does go_b", "r_1 does go_b").replace(
        "r2 does go_home", "tb3 does go_home"
    )
    found = _errors(_check(in_tmp, {"scenario.exsce": scenario}))
    assert found == [
        ("scenario.exsce:12:5", "robot 'r_1' is not in the fleet of scenario 's1'; did you mean 'r1'?"),
        ("scenario.exsce:13:5", "robot 'tb3' is not in the fleet of scenario 's1' (its robots: 'r1', 'r2')"),
    ]


# ---------------------------------------------------------------------- severities
def test_severity_is_a_str_enum_that_prints_its_value() -> None:
    assert f"{Severity.ERROR}" == "error" and str(Severity.NOTE) == "note"
    warning = Diagnostic("careful", SourceLocation("a.exsce", 2, 3), "warning")
    assert warning.severity is Severity.WARNING and warning.severity == "warning"
    assert str(warning) == "a.exsce:2:3: warning: careful"
    assert not warning.is_error and Diagnostic("bad").is_error
    with pytest.raises(ValueError):
        Diagnostic("m", None, "fatal")


def test_every_severity_maps_to_an_lsp_one() -> None:
    lines = TextLines("task t { }\n")
    where = SourceLocation("t.exsce", 1, 6, 1, 7)
    wanted = {
        Severity.ERROR: types.DiagnosticSeverity.Error,
        Severity.WARNING: types.DiagnosticSeverity.Warning,
        Severity.NOTE: types.DiagnosticSeverity.Information,
        Severity.INFO: types.DiagnosticSeverity.Information,
        Severity.HINT: types.DiagnosticSeverity.Hint,
    }
    assert set(wanted) == set(Severity)
    for severity, lsp in wanted.items():
        assert lsp_diagnostic(Diagnostic("m", where, severity), lines).severity == lsp


def test_notes_do_not_make_a_specification_invalid(in_tmp: Path) -> None:
    (in_tmp / "env.exsce").write_text(ENV)
    analysis = analyse("env.exsce")
    assert analysis.spec is not None and analysis.errors == []


def test_every_error_class_is_in_the_errors_module() -> None:
    defined = set()
    for path in (ROOT / "src" / "exsce_dsl").rglob("*.py"):
        defined |= set(re.findall(r"^class (\w+Error)\(", path.read_text(), re.MULTILINE))
    assert "StoreError" in defined and "RenameError" in defined
    public = {n for n in defined if not n.startswith("_")}
    missing = sorted(n for n in public if n not in errors_module.__all__ or not hasattr(errors_module, n))
    assert missing == [], f"not in exsce_dsl.errors: {missing}"


def test_a_broken_file_whose_import_string_no_file_can_have_gives_diagnostics(tmp_path: Path) -> None:
    """Found by the parser fuzzer: the imports of a file that does not parse are read from its text,
    and a quoted run of 300 characters across lines is no file name (the OS says 'too long')."""
    from exsce_dsl.lang import analyse

    spec = tmp_path / "broken.exsce"
    spec.write_text('import "a\n' + "x" * 300 + '.exsce"\nimport "b\x00.exsce"\nscenario {\n')
    analysis = analyse(spec)
    assert analysis.spec is None and analysis.errors
    assert all(d.location is not None and d.location.file.endswith("broken.exsce") for d in analysis.errors)
