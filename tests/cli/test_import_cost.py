"""What ``exscec`` imports before it does anything (issue 32: the fixed cost of ``exscec ingest``).

Each check runs in a fresh interpreter and looks at ``sys.modules``, so it holds whatever the
machine's load: heavy libraries that a command does not need stay out of it.  ``exscec ingest``
is looked at the moment it first opens the bag (an audit hook, as ``bench/ingest.py`` times it):
by then it has loaded the specification (from the user's cache folder), opened the store and
added the scenario's provenance, and needs nothing for any of it but its own modules,
pyoxigraph, prov, and what reading a bag takes (numpy, rosbags).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from tests.support.paths import EXAMPLES

NEVER_FOR_INGEST = (
    "rdflib",
    "pyshacl",
    "pandas",
    "matplotlib",
    "scipy",
    "jinja2",
    "pygls",
    "mcp",
    "dask",
    "distributed",
    "http.server",
    "ssl",
    "urllib.request",
    "multiprocessing",
    "concurrent.futures.process",
)
"""Neither a specification from the cache, an embedded store, nor one bag in this process need these."""

PARSING = ("textx", "arpeggio")
"""What parsing and checking a specification take: not needed when the cache has it."""

AT_FIRST_OPEN = """
import json, sys
from pathlib import Path

bag = Path(sys.argv[1]).resolve()
seen = []


def hook(event, args):
    if event == "open" and not seen and isinstance(args[0], (str, Path)) and Path(args[0]).resolve() == bag:
        seen.append(sorted(sys.modules))


sys.addaudithook(hook)
from exsce_dsl.cli.main import main

try:
    main(["ingest", str(bag), "--scenario", sys.argv[2], "--store", sys.argv[3]], standalone_mode=False)
except SystemExit:
    pass  # the bag is not one: only what was imported before reading it counts here
print(json.dumps(seen[0] if seen else None))
"""


def _modules(code: str, *args: str, env: dict[str, str] | None = None) -> set[str]:
    done = subprocess.run(
        [sys.executable, "-c", code, *args], capture_output=True, text=True, timeout=300, env=env, check=True
    )
    found = json.loads(done.stdout.strip().splitlines()[-1])
    assert found is not None, done.stderr
    return set(found)


def test_importing_the_command_line_imports_no_library_of_any_command() -> None:
    found = _modules("import json, sys\nimport exsce_dsl.cli.main\nprint(json.dumps(sorted(sys.modules)))")
    heavy = [*NEVER_FOR_INGEST, *PARSING, "numpy", "rosbags", "prov", "pyoxigraph", "yaml"]
    assert sorted(m for m in heavy if m in found) == []
    assert not any(m.startswith("exsce_dsl.") and m.endswith("_commands") for m in found - {"exsce_dsl.cli"})


@pytest.fixture
def not_a_bag(tmp_path: Path) -> Path:
    bag = tmp_path / "run.bag"
    bag.write_bytes(b"#ROSBAG V2.0\n")  # opened (and hashed) first, refused later
    return bag


def test_ingest_imports_nothing_it_does_not_need_before_the_bag(tmp_path: Path, not_a_bag: Path) -> None:
    env = {**_environment(), "EXSCE_CACHE": str(tmp_path / "cache")}
    spec = str(EXAMPLES / "brsu_building_c" / "scenario_c.exsce")
    first = _modules(AT_FIRST_OPEN, str(not_a_bag), spec, str(tmp_path / "store"), env=env)
    assert sorted(m for m in NEVER_FOR_INGEST if m in first) == []
    assert "textx" in first  # the cache was empty: the specification was parsed
    again = _modules(AT_FIRST_OPEN, str(not_a_bag), spec, str(tmp_path / "store"), env=env)
    assert sorted(m for m in (*NEVER_FOR_INGEST, *PARSING) if m in again) == []


def _environment() -> dict[str, str]:
    return {k: v for k, v in os.environ.items() if k not in ("EXSCE_STORE", "EXSCE_MSG_PATH")}
