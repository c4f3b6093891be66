"""Benchmark: the language server on a 2,000-line specification, over stdio.

Writes a specification into a temporary folder: an environment of 40 areas of 20
poses (880 lines), 200 tasks of two waypoints (1,000 lines), a scenario of 4
robots allocating all of them (220 lines).  Starts ``exscec lsp`` (SHACL on, as
editors get it), opens the three files, then measures with a real client:

  (a) didChange → publishDiagnostics of that version, 50 edits of a waypoint in
      the tasks file (debounce included; the tasks file and the scenario that
      reads it are analysed again);
  (b) the same, 50 edits of a pose's coordinates in the environment file (all
      three files are analysed again);
  (c) the same, 50 edits of the scenario's mission (the scenario only);
  (d) completion of a pose id after `visit` in the tasks file, 50 requests.

Each edit waits for its diagnostics before the next one (no bursts).  Targets:
diagnostics p50 < 300 ms; completion p95 < 100 ms.

    python bench/lsp.py [--edits 50] [--no-shacl]
"""

from __future__ import annotations

import argparse
import asyncio
import statistics
import sys
import tempfile
import time
from pathlib import Path

from lsprotocol import types
from pygls.lsp.client import LanguageClient
from pygls.uris import from_fs_path

EXSCEC = str(Path(sys.executable).with_name("exscec"))


def write_spec(folder: Path, areas: int = 40, poses: int = 20, tasks: int = 200) -> list[Path]:
    env = ["environment big_env {"]
    ids = []
    for a in range(areas):
        env.append(f"  area room_{a:03d} {{")
        for p in range(poses):
            pose = f"room_{a:03d}-w{p:03d}"
            ids.append(pose)
            env.append(f"    pose {pose} at ({a * 1.5 + p * 0.1:.2f}, {p * 0.7:.2f}) facing 0.5")
        env += ["  }", ""]
    env.append("}")
    lines = ['import "environment.exsce"', ""]
    for t in range(tasks):
        lines += [
            f"task task_{t:03d} {{",
            f"  visit {ids[t % len(ids)]}",
            f"  visit {ids[(t * 7 + 3) % len(ids)]}",
        ]
        lines += ["}", ""]
    scenario = ['import "environment.exsce"', 'import "tasks.exsce"', "", "robot type tiago {", "  base pmb2"]
    scenario += ["  torso yes", "}", "", "scenario big in big_env {", "  robots {"]
    scenario += [f"    r{r}: tiago starts at {ids[r]}" for r in range(4)]
    scenario += ["  }", "  mission big_mission parallel {"]
    scenario += [f"    r{t % 4} does task_{t:03d}" for t in range(tasks)]
    scenario += ["  }", "}"]
    files = {"environment.exsce": env, "tasks.exsce": lines, "scenario.exsce": scenario}
    for name, text in files.items():
        (folder / name).write_text("\n".join(text) + "\n")
    return [folder / name for name in files]


class Client:
    """A real LSP client that notes when each version's diagnostics arrive."""

    def __init__(self) -> None:
        self.lsp = LanguageClient("exsce-bench", "1")
        self.arrived: dict[tuple[str, int | None], float] = {}
        self.count: dict[str, int] = {}

        @self.lsp.feature(types.TEXT_DOCUMENT_PUBLISH_DIAGNOSTICS)
        def published(params: types.PublishDiagnosticsParams) -> None:
            self.arrived.setdefault((params.uri, params.version), time.perf_counter())
            self.count[params.uri] = len(params.diagnostics)

    async def diagnostics(self, uri: str, version: int, timeout: float = 30.0) -> float:
        deadline = time.perf_counter() + timeout
        while (uri, version) not in self.arrived:
            if time.perf_counter() > deadline:
                raise SystemExit(f"no diagnostics for version {version} of {uri}")
            await asyncio.sleep(0.001)
        return self.arrived[(uri, version)]


def percentile(values: list[float], p: float) -> float:
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, round(p / 100 * (len(ordered) - 1)))]


async def edits(client: Client, path: Path, versions: dict[str, int], n: int, edit: str) -> list[float]:
    """Time n edits of ``path`` from didChange to its diagnostics; ``edit`` says what changes."""
    uri = from_fs_path(str(path)) or ""
    text = path.read_text()
    times = []
    for i in range(n):
        if edit == "waypoint":  # a valid pose id in place of another, in the middle of the file
            at = text.index("  visit ", len(text) // 2)
            end = text.index("\n", at)
            new = text[:at] + f"  visit room_{i % 40:03d}-w{i % 20:03d}" + text[end:]
        elif edit == "coordinates":
            needle = "pose room_020-w010 at ("
            at = text.index(needle) + len(needle)
            new = text[:at] + f"{30 + i * 0.01:.2f}" + text[text.index(",", at) :]
        else:  # the mission: another task for r1
            at = text.index("    r1 does task_")
            end = text.index("\n", at)
            new = text[:at] + f"    r1 does task_{i % 200:03d}" + text[end:]
        text = new
        versions[uri] += 1
        start = time.perf_counter()
        client.lsp.text_document_did_change(
            types.DidChangeTextDocumentParams(
                types.VersionedTextDocumentIdentifier(version=versions[uri], uri=uri),
                [types.TextDocumentContentChangeWholeDocument(text)],
            )
        )
        times.append(await client.diagnostics(uri, versions[uri]) - start)
        if client.count.get(uri):
            raise SystemExit(f"edit {i} of {path.name} has diagnostics; the bench wants valid edits")
    return times


async def completions(client: Client, tasks: Path, n: int) -> list[float]:
    uri = from_fs_path(str(tasks)) or ""
    lines = tasks.read_text().split("\n")
    rows = [i for i, line in enumerate(lines) if line.startswith("  visit room_")]
    times = []
    for i in range(n):
        row = rows[(i * 37) % len(rows)]
        where = types.Position(row, len("  visit room_0"))
        start = time.perf_counter()
        result = await client.lsp.text_document_completion_async(
            types.CompletionParams(types.TextDocumentIdentifier(uri), where)
        )
        times.append(time.perf_counter() - start)
        assert isinstance(result, types.CompletionList) and result.items, result
    return times


def report(name: str, times: list[float], target: str) -> None:
    ms = [t * 1000 for t in times]
    print(
        f"{name:44s} p50 {percentile(ms, 50):6.1f} ms  p95 {percentile(ms, 95):6.1f} ms  "
        f"max {max(ms):6.1f} ms  mean {statistics.mean(ms):6.1f} ms   ({target})"
    )


async def run(folder: Path, n: int, shacl: bool) -> None:
    env, tasks, scenario = write_spec(folder)
    total = sum(len(p.read_text().splitlines()) for p in (env, tasks, scenario))
    print(
        f"spec: {total} lines in 3 files ({', '.join(p.name for p in (env, tasks, scenario))}); SHACL {shacl}"
    )
    client = Client()
    await client.lsp.start_io(EXSCEC, "lsp")
    root = from_fs_path(str(folder)) or ""
    await client.lsp.initialize_async(
        types.InitializeParams(
            capabilities=types.ClientCapabilities(),
            root_uri=root,
            workspace_folders=[types.WorkspaceFolder(root, "bench")],
            initialization_options={"shacl": shacl},
        )
    )
    client.lsp.initialized(types.InitializedParams())
    versions = {}
    start = time.perf_counter()
    for path in (env, tasks, scenario):
        uri = from_fs_path(str(path)) or ""
        versions[uri] = 1
        client.lsp.text_document_did_open(
            types.DidOpenTextDocumentParams(types.TextDocumentItem(uri, "exsce", 1, path.read_text()))
        )
    for uri in versions:
        await client.diagnostics(uri, 1)
    print(f"first diagnostics of the three files after {time.perf_counter() - start:.2f} s (cold parse)")
    await asyncio.sleep(1.0)
    report(
        "(a) edit a waypoint (tasks.exsce)",
        await edits(client, tasks, versions, n, "waypoint"),
        "target p50 < 300",
    )
    report(
        "(b) edit a pose (environment.exsce)",
        await edits(client, env, versions, n, "coordinates"),
        "target p50 < 300",
    )
    report(
        "(c) edit the mission (scenario.exsce)",
        await edits(client, scenario, versions, n, "mission"),
        "target p50 < 300",
    )
    report("(d) complete a pose id after 'visit'", await completions(client, tasks, n), "target p95 < 100")
    await client.lsp.shutdown_async(None)
    client.lsp.exit(None)
    await asyncio.sleep(0.2)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--edits", type=int, default=50)
    parser.add_argument("--no-shacl", action="store_true", help="Turn the server's SHACL checks off.")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        asyncio.run(run(Path(tmp), args.edits, not args.no_shacl))


if __name__ == "__main__":
    main()
