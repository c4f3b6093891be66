"""The ``--help`` examples of every ``exscec`` command, and the walk that runs them as written.

The examples are read from the click command tree itself (each command's ``Example:`` or
``Examples:`` block; a line ending in ``\\`` goes on on the next one) and run with bash, in
order, in a scratch folder holding a copy of ``examples/``, the environment's ``bin`` first on
PATH.  :data:`CHAPTERS` holds the order: each chapter is a walk through part of the tool like the
tutorial's, where an example that needs state (a store with runs, exported YAML) finds it made by
an earlier one of its chapter; chapters share nothing, so each runs in a test file of its own
(tests/cli/test_help_examples_*.py) and pytest-xdist runs them side by side.

An example exits 0 unless it says otherwise at its end (``# exits 1``).  The servers
(``serve``, ``lsp``, ``mcp``, ``stand-in``) are started, asked one question, and stopped.
"""

from __future__ import annotations

import inspect
import json
import os
import re
import selectors
import shutil
import signal
import subprocess
import sys
import time
import urllib.request
import xmlrpc.client
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import click

from exsce_dsl.cli.main import main

from tests.support.paths import EXAMPLES

BIN = Path(sys.executable).parent

CHAPTERS: dict[str, tuple[tuple[str, ...], ...]] = {
    "language": (
        (),  # exscec's own help
        ("check",),
        ("compile",),
        ("export",),
        ("import",),  # reads the YAML export wrote
        ("fmt",),  # and formats the .exsce files import wrote
        ("generate",),
        ("generate", "dispatcher-config"),
        ("generate", "monitors"),
        ("generate", "ros1-monitor"),
        ("generate", "ros2-monitor"),
    ),
    "runs": (
        ("simulate",),  # baseline runs, a faulty run, a Nav2 run
        ("bag", "info"),  # what a Nav2 bag holds
        ("bag",),
        ("init",),  # a specification drafted from a Nav2 bag, which checks
        ("ingest",),
        ("baseline",),
        ("verify",),  # the baseline runs pass, the faulty run fails; a trial of both is flaky
        ("flaky",),  # the faulty run's clauses first
        ("derive",),  # c_one, with its oracles, into the store
        ("expect",),
        ("lineage",),
        ("query",),
        ("sparql",),
        ("runs",),
        ("explain",),  # what a stored run's distance used
        ("cluster",),
        ("report",),
        ("store",),
        ("store", "info"),
        ("store", "graphs"),
        ("store", "export"),
        ("store", "check"),  # finds nothing on the store the walk wrote
        ("store", "migrate"),  # nothing to move: the walk wrote the current identities
        ("serve",),
        ("lsp",),
        ("mcp",),
        ("store", "clear"),  # last: it empties the store the others use
    ),
    "explore": (
        ("explore",),  # a campaign, and one that finds a planted deadlock, simulated and live
    ),
    "live": (
        ("execute",),  # no robot answers: exit 2, no bag
        ("stand-in",),  # scenario_c's robots on a roscore of their own, stopped with Ctrl-C
        ("demo",),
    ),
}
"""The commands whose examples are run, by chapter, in this order (each command's examples in theirs)."""

WALK: tuple[tuple[str, ...], ...] = tuple(command for chapter in CHAPTERS.values() for command in chapter)
"""Every command with examples, once."""

SERVERS = {("serve",), ("lsp",), ("mcp",), ("stand-in",)}
"""Commands that run until stopped."""

_HEADER = re.compile(r"Examples?\b[^:]*:")
_EXPECTED_EXIT = re.compile(r"#\s*exits (\d+)\b")


@dataclass(frozen=True)
class Example:
    command: tuple[str, ...]
    line: str

    @property
    def expected_exit(self) -> int:
        found = _EXPECTED_EXIT.search(self.line)
        return int(found.group(1)) if found else 0

    def __str__(self) -> str:
        return f"exscec {' '.join(self.command)} --help: {self.line}"


def examples_in(help_text: str) -> list[str]:
    """The example lines of a help text, continuations joined."""
    found: list[str] = []
    inside = False
    for line in inspect.cleandoc(help_text).splitlines():
        if _HEADER.fullmatch(line.strip()) and not line.startswith(" "):
            inside = True
        elif inside and line.startswith(" ") and line.strip() not in ("", "\b"):
            if found and found[-1].endswith("\\"):
                found[-1] = f"{found[-1][:-1].rstrip()} {line.strip()}"
            else:
                found.append(line.strip())
        else:
            inside = False
    return found


def command_tree(
    command: click.Command, path: tuple[str, ...] = ()
) -> Iterator[tuple[tuple[str, ...], click.Command]]:
    yield path, command
    if isinstance(command, click.Group):  # exscec's own group imports its commands when asked
        context = click.Context(command)
        for name in sorted(command.list_commands(context)):
            sub = command.get_command(context, name)
            assert sub is not None, name
            yield from command_tree(sub, (*path, name))


def collected() -> list[Example]:
    return [
        Example(path, line)
        for path, command in command_tree(main)
        for line in examples_in(command.help or "")
    ]


@dataclass(frozen=True)
class Walked:
    """What a chapter's walk left: its scratch folder, and how each example that is not a server
    ended (by its line), for a test to look closer at one of them."""

    scratch: Path
    ended: dict[str, subprocess.CompletedProcess[str]]


def walk(chapter: str, tmp_path: Path) -> Walked:
    """Run every example of ``chapter``'s commands as written, in order, in one scratch folder."""
    scratch = tmp_path / "walk"
    scratch.mkdir()
    shutil.copytree(EXAMPLES, scratch / "examples")
    home = tmp_path / "home"  # nothing of the walk lands in the real home (the mcp example names ~)
    home.mkdir()
    env = {
        **os.environ,
        "PATH": f"{BIN}{os.pathsep}{os.environ['PATH']}",
        "HOME": str(home),
        "COLUMNS": "120",
    }
    for variable in ("EXSCE_STORE", "EXSCE_STORE_TOKEN", "EXSCE_MSG_PATH"):
        env.pop(variable, None)
    commands = CHAPTERS[chapter]
    everything = [e for e in collected() if e.command in commands]
    ran: list[Example] = []
    ended: dict[str, subprocess.CompletedProcess[str]] = {}
    for path in commands:
        for example in (e for e in everything if e.command == path):
            if path == ("serve",):
                _serve(example, scratch, env)
            elif path == ("lsp",):
                _lsp(example, scratch, env)
            elif path == ("mcp",):
                _mcp(example, scratch, env)
            elif path == ("stand-in",):
                _stand_in(example, scratch, env)
            else:
                done = subprocess.run(
                    ["bash", "-c", example.line],
                    cwd=scratch,
                    env=env,
                    capture_output=True,
                    text=True,
                    timeout=300,
                )
                assert done.returncode == example.expected_exit, (
                    f"{example}\nexit {done.returncode}\n{done.stdout[-3000:]}\n{done.stderr[-3000:]}"
                )
                assert "Traceback" not in done.stderr and "internal error" not in done.stderr, str(example)
                ended[example.line] = done
            ran.append(example)
    assert ran == sorted(everything, key=lambda e: commands.index(e.command))  # each ran, in order
    assert {e.command for e in ran} == set(commands)
    return Walked(scratch, ended)


# -- the servers ------------------------------------------------------------------------------


def _start(line: str, cwd: Path, env: dict[str, str]) -> subprocess.Popen[bytes]:
    return subprocess.Popen(
        ["bash", "-c", f"exec {line}"],
        cwd=cwd,
        env=env,
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        start_new_session=True,
    )


class _Reader:
    """Bytes from a child's stdout, with a deadline (a server that does not answer fails the
    test instead of hanging it)."""

    def __init__(self, process: subprocess.Popen[bytes], seconds: float = 60) -> None:
        assert process.stdout is not None
        self.fd = process.stdout.fileno()
        self.buffer = b""
        self.deadline = time.monotonic() + seconds
        self.selector = selectors.DefaultSelector()
        self.selector.register(self.fd, selectors.EVENT_READ)

    def _more(self) -> None:
        left = self.deadline - time.monotonic()
        assert left > 0 and self.selector.select(left), f"no answer; so far: {self.buffer!r}"
        chunk = os.read(self.fd, 65536)
        assert chunk, f"the server closed its output; so far: {self.buffer!r}"
        self.buffer += chunk

    def until(self, marker: bytes) -> bytes:
        while marker not in self.buffer:
            self._more()
        found, self.buffer = self.buffer.split(marker, 1)
        return found

    def exactly(self, size: int) -> bytes:
        while len(self.buffer) < size:
            self._more()
        found, self.buffer = self.buffer[:size], self.buffer[size:]
        return found


def _stopped(process: subprocess.Popen[bytes], example: Example) -> None:
    try:
        process.wait(timeout=30)
    finally:
        if process.poll() is None:
            os.killpg(process.pid, signal.SIGKILL)
            process.wait()
    stderr = process.stderr.read().decode() if process.stderr else ""
    assert process.returncode == example.expected_exit, f"{example}\nexit {process.returncode}\n{stderr}"
    assert "Traceback" not in stderr, f"{example}\n{stderr}"


def _serve(example: Example, cwd: Path, env: dict[str, str]) -> None:
    # The port is the test's: a fixed one (7878, the default, or one the example names) may be taken
    # on this machine, so the example runs on a free one (--bind HOST:0), the rest as written.
    line = re.sub(r"--bind\s+(\S+):\d+", r"--bind \1:0", example.line)
    if "--bind" not in line:
        line = re.sub(r"^(exscec serve)\b", r"\1 --bind 127.0.0.1:0", line)
    process = _start(line, cwd, env)
    try:
        url = _Reader(process).until(b"\n").decode().strip()  # its first line on stdout
        with urllib.request.urlopen(  # noqa: S310 (our own server, on the loopback)
            urllib.request.Request(
                f"{url.rstrip('/')}/query?query=ASK%7B%7D",
                headers={"Accept": "application/sparql-results+json"},
            ),
            timeout=30,
        ) as answer:
            assert answer.status == 200
            assert json.loads(answer.read())["boolean"] is True
    finally:
        if process.poll() is None:
            os.killpg(process.pid, signal.SIGINT)  # Ctrl-C, as the help says
    _stopped(process, example)


def _lsp_message(payload: dict[str, object]) -> bytes:
    body = json.dumps(payload).encode()
    return b"Content-Length: %d\r\n\r\n%s" % (len(body), body)


def _lsp_answer(reader: _Reader, request_id: int) -> dict[str, object]:
    while True:
        headers = reader.until(b"\r\n\r\n").decode()
        length = re.search(r"Content-Length: (\d+)", headers, re.IGNORECASE)
        assert length is not None, headers
        size = int(length.group(1))
        message = json.loads(reader.exactly(size))
        if message.get("id") == request_id:
            return message  # type: ignore[no-any-return]


def _lsp(example: Example, cwd: Path, env: dict[str, str]) -> None:
    process = _start(example.line, cwd, env)
    assert process.stdin is not None
    try:
        reader = _Reader(process)
        initialize = {"processId": None, "rootUri": cwd.as_uri(), "capabilities": {}}
        process.stdin.write(
            _lsp_message({"jsonrpc": "2.0", "id": 1, "method": "initialize", "params": initialize})
        )
        process.stdin.flush()
        answer = _lsp_answer(reader, 1)
        assert "textDocumentSync" in answer["result"]["capabilities"]  # type: ignore[index]
        process.stdin.write(_lsp_message({"jsonrpc": "2.0", "id": 2, "method": "shutdown"}))
        process.stdin.flush()
        _lsp_answer(reader, 2)
        process.stdin.write(_lsp_message({"jsonrpc": "2.0", "method": "exit"}))
        process.stdin.close()
    finally:
        if process.poll() is None and process.stdin is not None and not process.stdin.closed:
            process.stdin.close()
    _stopped(process, example)


def _mcp(example: Example, cwd: Path, env: dict[str, str]) -> None:
    process = _start(example.line, cwd, env)
    assert process.stdin is not None
    try:
        initialize = {
            "protocolVersion": "2024-11-05",
            "capabilities": {},
            "clientInfo": {"name": "help_examples", "version": "1"},
        }
        request = {"jsonrpc": "2.0", "id": 1, "method": "initialize", "params": initialize}
        process.stdin.write(json.dumps(request).encode() + b"\n")
        process.stdin.flush()
        answer = json.loads(_Reader(process).until(b"\n"))
        assert answer["id"] == 1 and "serverInfo" in answer["result"], answer
    finally:
        process.stdin.close()  # the client goes away: the server ends
    _stopped(process, example)


def _stand_in(example: Example, cwd: Path, env: dict[str, str]) -> None:
    if "--ros2" in example.line:
        _stand_in_ros2(example, cwd, env)
        return
    process = _start(example.line, cwd, env)
    try:
        first = _Reader(process).until(b"\n").decode().strip()  # ROS_MASTER_URI=...
        assert first.startswith("ROS_MASTER_URI=http://"), first
        master = xmlrpc.client.ServerProxy(first.split("=", 1)[1])
        code, _, (publishers, _, _) = master.getSystemState("/exsce_help_examples")
        published = {topic for topic, _ in publishers}
        assert code == 1 and {"/clock", "/tiago1/move_base/result", "/tiago2/move_base/result"} <= published
    finally:
        if process.poll() is None:
            os.killpg(process.pid, signal.SIGINT)  # Ctrl-C, as the help says
    _stopped(process, example)


def _stand_in_ros2(example: Example, cwd: Path, env: dict[str, str]) -> None:
    """The ROS 2 stand-in, in a domain of its own: its first line names it, and a node of this
    process sees its clock and each robot's NavigateToPose action on the graph."""
    import rclpy

    from tests.support.ros2_graph import ros2_domain

    with ros2_domain() as domain:
        process = _start(example.line, cwd, {**env, **domain})
        context = rclpy.Context()
        try:
            first = _Reader(process).until(b"\n").decode().strip()
            assert first == f"ROS_DOMAIN_ID={domain['ROS_DOMAIN_ID']}", first
            rclpy.init(context=context, domain_id=int(domain["ROS_DOMAIN_ID"]))
            node = rclpy.create_node("exsce_help_examples", context=context)
            deadline = time.monotonic() + 20.0
            while True:  # /clock, and each of the example's two robots' Nav2 actions
                seen = {name for name, _ in node.get_topic_names_and_types()}
                actions = [t for t in seen if t.endswith("/navigate_to_pose/_action/status")]
                if ("/clock" in seen and len(actions) == 2) or time.monotonic() > deadline:
                    break
                time.sleep(0.2)
            assert "/clock" in seen and len(actions) == 2, sorted(seen)
        finally:
            context.try_shutdown()
            if process.poll() is None:
                os.killpg(process.pid, signal.SIGINT)  # Ctrl-C, as the help says
        _stopped(process, example)
