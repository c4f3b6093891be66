"""The real ``exscec`` command, run in a temporary folder."""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import yaml

from tests.support.cli import run_exscec
from tests.support.paths import EXAMPLES, FIXTURES

SCENARIO_C = EXAMPLES / "brsu_building_c" / "scenario_c.exsce"


def _copy_examples(tmp: Path) -> Path:
    shutil.copytree(EXAMPLES / "brsu_building_c", tmp / "bc")
    return tmp / "bc"


def test_help_lists_the_commands_with_examples() -> None:
    result = run_exscec("--help")
    assert result.returncode == 0
    for command in ("check", "compile", "fmt", "import", "export"):
        assert command in result.stdout
    compile_help = run_exscec("compile", "--help").stdout
    assert "Example:" in compile_help and "provn" in compile_help


def test_compile_prints_prov_n_of_scenario_c() -> None:
    result = run_exscec("compile", str(SCENARIO_C))
    assert result.returncode == 0, result.stderr
    out = result.stdout
    assert out.startswith("document\n")
    assert "bundle exsce:scenario_c_bundle" in out
    assert "entity(mission:mission_c, [prov:type='exsce:mission', exsce:missionType=\"parallel\"])" in out
    assert "wasDerivedFrom(mission_c:tiago1-task_02, task:navigate_home_1" in out
    assert "pose:classroom_c025-w001-R0.00_P0.00_Y0.925" in out
    assert out.rstrip().endswith("endDocument")


def test_compile_writes_prov_json_to_a_file(in_tmp: Path) -> None:
    result = run_exscec("compile", str(SCENARIO_C), "-f", "json", "-o", "c.json")
    assert result.returncode == 0, result.stderr
    bundles = json.loads((in_tmp / "c.json").read_text())["bundle"]
    assert "exsce:scenario_c_bundle" in bundles
    assert "robot:tiago2_bundle" in bundles


def test_check_reports_every_error_as_file_line_col_and_exits_2(in_tmp: Path) -> None:
    folder = _copy_examples(in_tmp)
    text = (folder / "scenario_c.exsce").read_text()
    text = text.replace("tiago2: tiago", "tiago2: tiagoo").replace("then navigate_home_1", "")
    text = text.replace("tiago1 does navigate_home_1", "tiago3 does navigate_home_1")
    (folder / "scenario_c.exsce").write_text(text)
    result = run_exscec("check", "bc/scenario_c.exsce")
    assert result.returncode == 2
    assert "Traceback" not in result.stderr
    lines = result.stderr.splitlines()
    assert "bc/scenario_c.exsce:10:13: error: unknown robot type 'tiagoo'; did you mean 'tiago'?" in lines
    assert any(
        line.startswith("bc/scenario_c.exsce:15:5: error: robot 'tiago3' is not in the fleet")
        for line in lines
    )
    assert "bc/scenario_c.exsce: 2 errors" in lines


def test_syntax_error_is_worded_and_has_no_traceback(in_tmp: Path) -> None:
    (in_tmp / "bad.exsce").write_text("robot type tiago {\n  base\n}\n")
    result = run_exscec("compile", "bad.exsce")
    assert result.returncode == 2
    assert result.stderr.strip() == "bad.exsce:3:1: error: expected a name, found '}'"
    assert result.stdout == ""


def test_debug_shows_the_traceback(in_tmp: Path) -> None:
    (in_tmp / "bad.exsce").write_text("robot type tiago {\n  base\n}\n")
    result = run_exscec("--debug", "compile", "bad.exsce")
    assert result.returncode == 2  # the exit status it has without --debug
    assert "Traceback" in result.stderr


def test_usage_errors_exit_2(in_tmp: Path) -> None:
    assert run_exscec("compile").returncode == 2
    assert run_exscec("compile", str(SCENARIO_C), "-f", "dot").returncode == 2


def test_missing_file_is_an_error_not_a_crash(in_tmp: Path) -> None:
    result = run_exscec("check", "nope.exsce")
    assert result.returncode == 2
    assert "cannot read nope.exsce" in result.stderr
    assert "Traceback" not in result.stderr


def test_fmt_check_and_rewrite(in_tmp: Path) -> None:
    folder = _copy_examples(in_tmp)
    assert run_exscec("fmt", "--check", "bc/scenario_c.exsce").returncode == 0
    messy = (folder / "scenario_c.exsce").read_text().replace("  robots {", "robots{   ")
    (folder / "scenario_c.exsce").write_text("// keep me\n" + messy)
    result = run_exscec("fmt", "--check", "bc/scenario_c.exsce")
    assert result.returncode == 1 and "would reformat bc/scenario_c.exsce" in result.stderr
    assert run_exscec("fmt", "bc/scenario_c.exsce").returncode == 0
    assert (folder / "scenario_c.exsce").read_text() == "// keep me\n" + (SCENARIO_C.read_text())


def test_import_then_compile_and_export(in_tmp: Path) -> None:
    result = run_exscec(
        "import", str(FIXTURES / "scenarios" / "scenario_d.yaml"), "-t", str(FIXTURES / "tasks"), "-o", "spec"
    )
    assert result.returncode == 0, result.stderr
    assert (in_tmp / "spec" / "scenario_d.exsce").is_file()
    assert (in_tmp / "spec" / "tasks" / "delivery_b.exsce").is_file()
    assert run_exscec("check", "spec/scenario_d.exsce").returncode == 0
    again = run_exscec(
        "import", str(FIXTURES / "scenarios" / "scenario_d.yaml"), "-t", str(FIXTURES / "tasks"), "-o", "spec"
    )
    assert again.returncode == 2 and "use --force" in again.stderr
    exported = run_exscec("export", "spec/scenario_d.exsce", "--to", "yaml", "-o", "out")
    assert exported.returncode == 0, exported.stderr
    data = yaml.safe_load((in_tmp / "out" / "scenarios" / "scenario_d.yaml").read_text())
    assert data["mission"]["type"] == "sequential"
    assert [a["file_path"] for a in data["mission"]["allocation"]] == [
        "config/tasks/delivery_a.yaml",
        "config/tasks/delivery_b.yaml",
        "config/tasks/navigate_home_1.yaml",
    ]


def test_textx_knows_the_language() -> None:
    import subprocess
    import sys

    textx = Path(sys.executable).with_name("textx")
    languages = subprocess.run([str(textx), "list-languages"], capture_output=True, text=True)
    assert "exsce (*.exsce)" in languages.stdout + languages.stderr
    checked = subprocess.run([str(textx), "check", str(SCENARIO_C)], capture_output=True, text=True)
    assert checked.returncode == 0 and "OK" in checked.stdout + checked.stderr


def test_textx_generators_write_prov(in_tmp: Path) -> None:
    import subprocess
    import sys

    folder = _copy_examples(in_tmp)
    textx = Path(sys.executable).with_name("textx")
    for target, name in (("provjson", "c.prov.json"), ("provn", "c.provn")):
        done = subprocess.run(
            [str(textx), "generate", str(folder / "scenario_c.exsce"), "--target", target, "-o", name],
            capture_output=True,
            text=True,
        )
        assert done.returncode == 0, done.stderr
    assert "exsce:scenario_c_bundle" in json.loads((in_tmp / "c.prov.json").read_text())["bundle"]
    assert "bundle exsce:scenario_c_bundle" in (in_tmp / "c.provn").read_text()


def test_textx_generate_and_exscec_compile_write_the_same_prov_for_a_derived_scenario(in_tmp: Path) -> None:
    """Both go through one library function: the derived scenario comes with its generation."""
    import subprocess
    import sys

    folder = _copy_examples(in_tmp)
    derived = folder / "scenario_c_alone.exsce"
    textx = Path(sys.executable).with_name("textx")
    done = subprocess.run(
        [str(textx), "generate", str(derived), "--target", "provjson", "-o", "by_textx.json"],
        capture_output=True,
        text=True,
    )
    assert done.returncode == 0, done.stderr
    compiled = run_exscec("compile", str(derived), "-f", "json", "-o", "by_exscec.json")
    assert compiled.returncode == 0, compiled.stderr
    by_textx = json.loads((in_tmp / "by_textx.json").read_text())
    assert by_textx == json.loads((in_tmp / "by_exscec.json").read_text())
    assert any("generation" in name for name in by_textx["bundle"]), sorted(by_textx["bundle"])


def test_version_is_the_installed_distributions() -> None:
    from importlib.metadata import version

    result = run_exscec("--version")
    assert result.returncode == 0 and result.stdout.strip() == f"exscec, version {version('exsce')}"
    changelog = (Path(__file__).resolve().parents[2] / "CHANGELOG.md").read_text(encoding="utf-8")
    assert f"## [{version('exsce')}]" in changelog  # every released version has its entry


def test_check_a_folder_checks_every_exsce_file_below_it_in_sorted_order(in_tmp: Path) -> None:
    project = in_tmp / "specs"
    (project / "nested" / ".hidden").mkdir(parents=True)
    (project / "b_good.exsce").write_text("robot type tiago {\n  base diff_drive\n}\n")
    (project / "nested" / "a_bad.exsce").write_text("robot type tiago {\n  base\n}\n")
    (project / "nested" / ".hidden" / "ignored.exsce").write_text("not exsce at all\n")
    (project / "notes.txt").write_text("not a spec\n")
    result = run_exscec("check", "specs")
    assert result.returncode == 2
    assert "Traceback" not in result.stderr
    assert result.stderr.splitlines() == [
        "specs/b_good.exsce: ok (0 scenarios)",
        "specs/nested/a_bad.exsce:3:1: error: expected a name, found '}'",
        "specs/nested/a_bad.exsce: 1 error",
    ]
    (project / "nested" / "a_bad.exsce").unlink()
    assert run_exscec("check", "specs").returncode == 0


def test_check_and_fmt_of_a_folder_without_specs_say_so(in_tmp: Path) -> None:
    (in_tmp / "empty").mkdir()
    for command in ("check", "fmt"):
        result = run_exscec(command, "empty")
        assert result.returncode == 2 and "empty is a folder without .exsce files" in result.stderr


def test_fmt_check_of_a_folder_names_the_files_that_would_change(in_tmp: Path) -> None:
    folder = _copy_examples(in_tmp)
    assert run_exscec("fmt", "--check", "bc").returncode == 0
    tasks = folder / "tasks" / "navigation.exsce"
    tasks.write_text(tasks.read_text().replace("task navigate_home_1 {", "task   navigate_home_1{"))
    result = run_exscec("fmt", "--check", "bc")
    assert result.returncode == 1
    assert result.stderr.splitlines() == ["would reformat bc/tasks/navigation.exsce"]


def test_progress_leaves_no_blank_lines_or_escape_codes_when_stderr_is_not_a_terminal(in_tmp: Path) -> None:
    """A CI log is not a terminal: no bar, only the lines, one per run (it was a bar label and blank
    lines)."""
    simulated = run_exscec("simulate", str(SCENARIO_C), "--runs", "2", "-o", "runs")
    assert simulated.returncode == 0, simulated.stderr
    bags = sorted((in_tmp / "runs").glob("*.bag"))
    ingested = run_exscec("ingest", *map(str, bags), "--scenario", str(SCENARIO_C))
    assert ingested.returncode == 0, ingested.stderr
    reported = run_exscec("report", "-o", "report")
    assert reported.returncode == 0, reported.stderr
    for done in (simulated, ingested, reported):
        lines = done.stderr.splitlines()
        assert lines and all(line.strip() for line in lines), done.stderr
        assert "\x1b" not in done.stderr and "\r" not in done.stderr, repr(done.stderr)
    wrote = [line.split(" (")[0] for line in simulated.stderr.splitlines()]
    assert wrote == [f"wrote runs/{bag.name}" for bag in bags]
    # a line per bag, what ingestion detected (said once for both bags: the same), the summary
    lines = ingested.stderr.splitlines()
    assert [line.split(": run ")[0] for line in lines if ": run " in line] == [str(b) for b in bags]
    detected = [line.strip() for line in lines if line.startswith("  ")]
    assert detected == [
        f"robot '{r}': convention method (detected from /{r}/waypoint_dispatcher/feedback)"
        for r in ("tiago1", "tiago2")
    ]
    assert len(lines) == 5
    assert ingested.stderr.endswith("2 ingested, 0 skipped, 0 failed\n")
    assert reported.stderr.splitlines()[-1].startswith("wrote report/index.html")
