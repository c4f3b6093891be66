"""Input nested or long past what the parser, the generators and Python can take is a located
error, never an internal one (issue 46, item 9): parentheses in a metric's expression, a long
sum, and the method's YAML nested deep.  Each runs the real command, in this process."""

from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest

from exsce_dsl.lang.parser import MAX_NESTING
from exsce_dsl.lang.yaml.located import MAX_DEPTH as MAX_YAML_DEPTH
from exsce_dsl.model.expressions import MAX_DEPTH

from tests.support.cli import exscec_here

FIELD = "o.twist.twist.linear.x"


def _metric(folder: Path, value: str) -> Path:
    spec = folder / "metric.exsce"
    spec.write_text(
        'metric speedy for each robot {\n  reads o: nav_msgs/Odometry on "/{ns}/odom"\n'
        f"  value {value}\n}}\n"
    )
    return spec


def _refused(done: subprocess.CompletedProcess[str], pattern: str) -> None:
    assert done.returncode == 2, done.stderr
    err = done.stderr + done.stdout
    assert re.search(pattern, err), err
    assert "Traceback" not in err and "internal error" not in err


@pytest.mark.parametrize("levels", [MAX_NESTING + 1, 28, 1000])
def test_deeply_nested_parentheses_located(tmp_path: Path, levels: int) -> None:
    spec = _metric(tmp_path, "max(" + "(" * levels + FIELD + ")" * levels + ")")
    column = len("  value max(") + MAX_NESTING  # the first parenthesis too many (max's is one)
    for command in (("check",), ("generate", "monitors")):
        out = ("-o", str(tmp_path / "out")) if command[0] == "generate" else ()
        done = exscec_here(*command, "metric.exsce", *out, cwd=tmp_path)
        _refused(done, rf"metric\.exsce:3:{column}: error: parentheses nested more than {MAX_NESTING} deep")
    assert spec.exists() and not (tmp_path / "out").exists()


def test_parentheses_up_to_the_limit_are_read(tmp_path: Path) -> None:
    inner = MAX_NESTING - 1  # and max's own
    _metric(tmp_path, "max(" + "(" * inner + FIELD + ")" * inner + ")")
    done = exscec_here("check", "metric.exsce", cwd=tmp_path)
    assert done.returncode == 0, done.stderr


def test_long_sum_checks_and_generates_alike(tmp_path: Path) -> None:
    _metric(tmp_path, " + ".join([f"max({FIELD})"] * 500))
    for command in (("check",), ("generate", "monitors")):
        out = ("-o", str(tmp_path / "out")) if command[0] == "generate" else ()
        done = exscec_here(*command, "metric.exsce", *out, cwd=tmp_path)
        _refused(
            done, rf"metric\.exsce:3:9: error: this expression nests 500 operations deep.*at most {MAX_DEPTH}"
        )
    # as long as allowed: both accept it, and the generated module compiles
    _metric(tmp_path, " + ".join([f"max({FIELD})"] * MAX_DEPTH))
    assert exscec_here("check", "metric.exsce", cwd=tmp_path).returncode == 0
    done = exscec_here("generate", "monitors", "metric.exsce", "-o", "out", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    module = tmp_path / "out" / "exsce_monitors" / "monitors.py"
    compile(module.read_text(), str(module), "exec")


@pytest.mark.parametrize("depth", [MAX_YAML_DEPTH + 1, 50_000])
def test_deep_yaml_import_located(tmp_path: Path, depth: int) -> None:
    (tmp_path / "scenario.yaml").write_text("mission:\n  tasks: " + "[" * depth + "]" * depth + "\n")
    done = exscec_here("import", "scenario.yaml", "-o", "out", cwd=tmp_path)
    # where the level too many starts (the top mapping and mission's are the first two)
    column = len("  tasks: ") + MAX_YAML_DEPTH - 1
    _refused(
        done,
        rf"scenario\.yaml:2:{column}: error: not valid YAML: nested more than {MAX_YAML_DEPTH} levels deep",
    )
    assert not list((tmp_path).glob("out/*.exsce"))


def test_the_editor_s_parse_reports_deep_parentheses_too(tmp_path: Path) -> None:
    """The language server parses a piece at a time (ParseCache): the same located error, not a
    RecursionError that leaves the editor without diagnostics."""
    from exsce_dsl.lang.incremental import ParseCache

    text = _metric(tmp_path, "max(" + "(" * 1000 + FIELD + ")" * 1000 + ")").read_text()
    tree, diagnostics = ParseCache().parse(text, "metric.exsce")
    assert tree is None
    (error,) = diagnostics
    assert error.location is not None and (error.location.line, error.location.column) == (3, 32)
    assert f"parentheses nested more than {MAX_NESTING} deep" in error.message


def test_a_parser_recursion_past_the_count_is_located_too(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Should the parser recurse past Python's limit on text the count lets through (a deeper
    caller, a construct it does not foresee), the parse still ends in a located syntax error."""
    from exsce_dsl.errors import ExsceSyntaxError
    from exsce_dsl.lang import parser

    monkeypatch.setattr(parser, "MAX_NESTING", 10_000)  # the count lets everything through
    text = _metric(tmp_path, "max(" + "(" * 200 + FIELD + ")" * 200 + ")").read_text()
    with pytest.raises(ExsceSyntaxError) as raised:
        parser.parse_text(text, "metric.exsce")
    (error,) = raised.value.diagnostics
    assert "nests too deeply to be read" in error.message
    assert error.location is not None
    assert (error.location.line, error.location.column) == (3, len("  value max(") + 200)
    assert parser.parse_text(text.replace("(" * 200, "").replace(")" * 200, ""), "metric.exsce")  # parses on
