"""Issue 46: ``import "/abs/path"`` read any file and quoted its first word, and "not found" told
which files exist.  Only ``.exsce`` files are imported (anything else is refused by its name,
unread), and in a workspace (the language server's, the MCP server's folder) only files inside
it, with the same words for a file outside whether it exists or not."""

from __future__ import annotations

import os
from pathlib import Path

from exsce_dsl.lang import ImportScope, analyse

from tests.support.cli import run_exscec

SECRET = "hunter2-secret-token"


def test_import_of_non_exsce_file_not_quoted(tmp_path: Path) -> None:
    (tmp_path / "secret.txt").write_text(f"{SECRET}\n", encoding="utf-8")  # one line: its first token
    (tmp_path / "spec.exsce").write_text(
        f'import "secret.txt"\nimport "{tmp_path / "secret.txt"}"\nrobot type r {{\n}}\n', encoding="utf-8"
    )
    done = run_exscec("check", "spec.exsce", cwd=tmp_path)
    assert done.returncode == 2
    assert SECRET not in done.stdout + done.stderr
    lines = done.stderr.splitlines()
    assert "spec.exsce:1:1: error: only .exsce files are imported: 'secret.txt' is not read" in lines
    assert f"spec.exsce:2:1: error: only .exsce files are imported: '{tmp_path / 'secret.txt'}' is not read" in lines


def test_a_syntax_error_in_an_imported_exsce_file_is_still_shown(tmp_path: Path) -> None:
    """The rule does not hide the errors of the user's own specification files."""
    (tmp_path / "broken.exsce").write_text("robot type r {\n  %%%\n}\n", encoding="utf-8")
    (tmp_path / "spec.exsce").write_text('import "broken.exsce"\n', encoding="utf-8")
    done = run_exscec("check", "spec.exsce", cwd=tmp_path)
    assert done.returncode == 2 and "broken.exsce:2:" in done.stderr


def _outside_messages(workspace: Path, imports: list[str]) -> list[str]:
    spec = workspace / "spec.exsce"
    spec.write_text("".join(f'import "{i}"\n' for i in imports), encoding="utf-8")
    analysis = analyse(spec, scope=ImportScope.inside(workspace))
    found = sorted(analysis.errors, key=lambda d: d.location.line if d.location else 0)
    assert [d.location.line for d in found if d.location] == list(range(1, len(imports) + 1))
    return [d.message for d in found]


def test_import_not_found_outside_workspace_says_nothing_of_existence(tmp_path: Path) -> None:
    workspace, outside = tmp_path / "workspace", tmp_path / "outside"
    workspace.mkdir()
    outside.mkdir()
    (outside / "exists.exsce").write_text(f"robot type {SECRET.replace('-', '_')} {{\n}}\n", encoding="utf-8")
    (outside / "unreadable.exsce").write_text("robot type u {\n}\n", encoding="utf-8")
    (outside / "unreadable.exsce").chmod(0)
    (outside / "folder.exsce").mkdir()
    os.symlink(outside / "exists.exsce", workspace / "link.exsce")  # inside by name, outside in fact
    names = ["exists.exsce", "missing.exsce", "unreadable.exsce", "folder.exsce"]
    messages = _outside_messages(workspace, [f"../outside/{n}" for n in names] + ["link.exsce"])
    written = [f"../outside/{n}" for n in names] + ["link.exsce"]
    # one sentence for every file outside, whatever it is: only the name written differs
    assert {m.replace(w, "NAME") for m, w in zip(messages, written, strict=True)} == {
        f"'NAME' is outside the workspace ({workspace}): only files inside it are imported"
    }
    assert not any(SECRET.replace("-", "_") in m or "did you mean" in m for m in messages)
    # the same files imported by absolute path: the same sentence
    absolute = _outside_messages(workspace, [str(outside / n) for n in names])
    assert all("is outside the workspace" in m for m in absolute)


def test_an_import_inside_the_workspace_is_read_and_not_found_is_told_there(tmp_path: Path) -> None:
    (tmp_path / "robots.exsce").write_text("robot type r {\n}\n", encoding="utf-8")
    (tmp_path / "spec.exsce").write_text('import "robots.exsce"\nimport "robts2.exsce"\n', encoding="utf-8")
    analysis = analyse(tmp_path / "spec.exsce", scope=ImportScope.inside(tmp_path))
    (error,) = analysis.errors
    assert "imported file 'robts2.exsce' not found" in error.message and "did you mean" in error.message


def test_a_text_with_no_import_scope_imports_nothing(tmp_path: Path) -> None:
    (tmp_path / "robots.exsce").write_text("robot type r {\n}\n", encoding="utf-8")
    (tmp_path / "spec.exsce").write_text('import "robots.exsce"\n', encoding="utf-8")
    (error,) = analyse(tmp_path / "spec.exsce", scope=ImportScope.nowhere("not here")).errors
    assert error.message == "not here" and error.location is not None and error.location.line == 1
