"""The Python API: docs/python.md's worked session runs as written, and the API is the CLI's.

The page's ``python`` blocks are run in order, in one namespace (as a notebook would), in a copy of
the examples; their own assertions check the figures against what the session did.  Beside it,
the API's answers are compared with the command line's on the same store.
"""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import pytest

from tests.support.cli import exscec_here
from tests.support.paths import EXAMPLES

DOC = Path(__file__).resolve().parents[2] / "docs" / "python.md"


def _blocks(text: str) -> list[str]:
    return re.findall(r"```python\n(.*?)```", text, flags=re.DOTALL)


@pytest.fixture(scope="module")
def session(tmp_path_factory: pytest.TempPathFactory) -> dict[str, object]:
    folder = tmp_path_factory.mktemp("notebook")
    shutil.copytree(EXAMPLES, folder, dirs_exist_ok=True)
    namespace: dict[str, object] = {}
    with pytest.MonkeyPatch.context() as patch:
        patch.chdir(folder)
        for number, block in enumerate(_blocks(DOC.read_text(encoding="utf-8")), 1):
            try:
                exec(compile(block, f"{DOC.name}, block {number}", "exec"), namespace)  # noqa: S102
            except Exception as exc:
                raise AssertionError(f"docs/python.md block {number} failed: {exc!r}\n{block}") from exc
    namespace["folder"] = folder
    return namespace


def test_the_page_has_the_whole_session() -> None:
    blocks = _blocks(DOC.read_text(encoding="utf-8"))
    assert len(blocks) >= 6
    code = "\n".join(blocks)
    caught = " ".join(re.findall(r"except [^:]*:", code))  # the API's errors, as a session catches them
    called = set(re.findall(r"exsce\.(\w+)\(", code)) | set(re.findall(r"exsce\.(\w+Error)\b", caught))
    from exsce_dsl import api
    from exsce_dsl.faces import face_blocks

    session_names, _for_the_command_line = face_blocks(Path(api.__file__).read_text(encoding="utf-8"))
    shown = set(session_names) - {"rows_frame"}
    assert shown <= called, "every public function of a session is shown on the page"


def test_the_worked_session_runs_as_written(session: dict[str, object]) -> None:
    folder = session["folder"]
    assert isinstance(folder, Path)
    assert (folder / "brsu_building_c" / "scenario_c_solo.exsce").exists()
    table = session["table"]
    import pandas as pd

    assert isinstance(table, pd.DataFrame) and set(table.columns) >= {
        "run",
        "robot",
        "metric",
        "value",
        "unit",
    }
    assert table.run.nunique() == 6 and (table.scenario == "scenario_c").all()


def test_the_api_answers_as_the_command_line_does(session: dict[str, object]) -> None:
    folder = session["folder"]
    assert isinstance(folder, Path)
    store = str(folder / "store")
    listed = exscec_here("query", "runs", "-p", "scenario=scenario_c", "-f", "json", "--store", store)
    assert listed.returncode == 0, listed.stderr
    cli_runs = {b["run"]["value"] for b in json.loads(listed.stdout)["results"]["bindings"]}
    from exsce_dsl import api as exsce

    with exsce.open_store(store) as opened:
        api_runs = set(exsce.query(opened, "runs", scenario="scenario_c").run)
        table = exsce.metrics(opened, "scenario_c")
    assert api_runs == cli_runs and len(api_runs) == 6
    # the API's values are the store's: one through the library query the CLI runs
    some = table[(table.metric == "distance_travelled") & (table.robot == "tiago1")].iloc[0]
    value = exscec_here(
        "query", "run_metric", "-p", f"run={some.run}", "-p", "robot=tiago1", "-p",
        "metric=distance_travelled", "-f", "json", "--store", store,
    )  # fmt: skip
    assert value.returncode == 0, value.stderr
    [binding] = json.loads(value.stdout)["results"]["bindings"]
    assert float(binding["value"]["value"]) == pytest.approx(some.value)


def test_a_library_update_is_refused() -> None:
    from exsce_dsl import api as exsce
    from exsce_dsl.store.queries.library import query, query_names

    updates = [n for n in query_names() if query(n).is_update]
    assert updates, "the library has updates"
    with exsce.open_store("memory:") as store, pytest.raises(ValueError, match="update"):
        exsce.query(store, updates[0])


def test_the_readme_example_runs_as_written(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    readme = (Path(__file__).resolve().parents[2] / "README.md").read_text(encoding="utf-8")
    [block] = _blocks(readme)
    shutil.copytree(EXAMPLES, tmp_path / "examples")
    monkeypatch.chdir(tmp_path)
    namespace: dict[str, object] = {}
    exec(compile(block, "README.md", "exec"), namespace)  # noqa: S102
    table = namespace["table"]
    import pandas as pd

    assert isinstance(table, pd.DataFrame) and table.run.nunique() == 3
    wide = namespace["wide"]  # stumble: the README's pivot dropped the mission's values
    assert isinstance(wide, pd.DataFrame)
    assert wide["mission"]["mission_duration"].notna().all().all() and len(wide) == 3
    assert len(list((tmp_path / "runs").glob("*.bag"))) == 3
