"""Real SPARQL servers for the store tests: ``oxigraph serve``, ``exscec serve`` and Virtuoso 7
(on Debian's default ``virtuoso.ini``, only its paths and ports changed).

Each runs as a child process on 127.0.0.1 at a free port, is waited for until
it answers, and is stopped (SIGTERM, then SIGKILL) afterwards.
"""

from __future__ import annotations

import os
import select
import signal
import socket
import subprocess
import sys
import time
import urllib.error
import urllib.request
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

BIN = Path(sys.executable).parent
STARTUP_SECONDS = 20.0


def free_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return int(s.getsockname()[1])


def wait_until_answering(url: str, process: subprocess.Popen[str], timeout: float = STARTUP_SECONDS) -> None:
    deadline = time.monotonic() + timeout
    while True:
        if process.poll() is not None:
            raise RuntimeError(f"the server stopped with status {process.returncode}")
        try:
            with urllib.request.urlopen(url, timeout=2) as answer:
                answer.read()
                return
        except urllib.error.HTTPError:
            return  # it answers
        except OSError:
            if time.monotonic() > deadline:
                raise RuntimeError(f"{url} did not answer within {timeout} s") from None
            time.sleep(0.05)


def stop(process: subprocess.Popen[str]) -> int:
    if process.poll() is None:
        process.send_signal(signal.SIGTERM)
        try:
            process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait(timeout=10)
    for stream in (process.stdout, process.stderr):
        if stream is not None:
            stream.close()
    return process.returncode


@dataclass
class Server:
    url: str
    process: subprocess.Popen[str]


@contextmanager
def oxigraph_server(location: Path) -> Iterator[Server]:
    """``oxigraph serve --location LOCATION --bind 127.0.0.1:PORT`` (three tries at a free port)."""
    last: Exception | None = None
    for _ in range(3):
        port = free_port()
        process = subprocess.Popen(
            [str(BIN / "oxigraph"), "serve", "--location", str(location), "--bind", f"127.0.0.1:{port}"],
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            text=True,
        )
        url = f"http://127.0.0.1:{port}"
        try:
            wait_until_answering(url + "/", process)
        except RuntimeError as exc:
            stop(process)
            last = exc
            continue
        try:
            yield Server(url, process)
        finally:
            stop(process)
        return
    raise RuntimeError(f"oxigraph serve did not start: {last}")


def start_exscec_serve(*args: str, cwd: Path | None = None, env: dict[str, str] | None = None) -> Server:
    """``exscec serve --bind 127.0.0.1:0 ARGS``, its URL read from the first line it prints."""
    process = subprocess.Popen(
        [str(BIN / "exscec"), "serve", "--bind", "127.0.0.1:0", *args],
        cwd=cwd,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env={**os.environ, **(env or {})},
    )
    assert process.stdout is not None
    ready, _, _ = select.select([process.stdout], [], [], STARTUP_SECONDS)
    line = process.stdout.readline().strip() if ready else ""
    if not line.startswith("http://"):
        process.kill()
        _, error = process.communicate(timeout=10)
        raise RuntimeError(f"exscec serve did not start: {line!r} {error}")
    url = line.rstrip("/")
    wait_until_answering(url + "/", process)
    return Server(url, process)


@contextmanager
def exscec_serve(*args: str, cwd: Path | None = None, env: dict[str, str] | None = None) -> Iterator[Server]:
    server = start_exscec_serve(*args, cwd=cwd, env=env)
    try:
        yield server
    finally:
        stop(server.process)


VIRTUOSO_INI = Path(__file__).parents[1] / "fixtures" / "virtuoso" / "virtuoso.ini"
"""Debian's default ``virtuoso.ini`` (``tests/fixtures/virtuoso/SOURCES.md``)."""
VIRTUOSO_STARTUP_SECONDS = 90.0
"""A new database takes ~11 s to make on this machine; more on a loaded one."""


@contextmanager
def virtuoso_server(location: Path) -> Iterator[Server]:
    """Virtuoso 7 (``virtuoso-t +foreground``) with a new database in LOCATION, its HTTP
    server at a free port (``/sparql``), the SPARQL user allowed to update (as an
    administrator would, with ``isql-vt``).

    A port found free may be taken by another test's server before Virtuoso listens on it
    ("Failed HTTP listen" in its log, and it exits): it is started again on other ports, in a
    folder of its own, up to three times."""
    for attempt in range(3):
        folder = location if attempt == 0 else location.with_name(f"{location.name}-{attempt}")
        process, url, sql_port = _start_virtuoso(folder)
        try:
            wait_until_answering(f"{url}/sparql?query=ASK%7B%7D", process, VIRTUOSO_STARTUP_SECONDS)
            break
        except RuntimeError:
            stop(process)
            log = folder / "virtuoso.log"
            said = log.read_text(errors="replace") if log.exists() else ""
            if "listen" not in said.lower() or attempt == 2:
                raise
    try:
        granted = subprocess.run(
            ["isql-vt", str(sql_port), "dba", "dba", 'exec=GRANT SPARQL_UPDATE TO "SPARQL";'],
            capture_output=True, text=True, timeout=60,
        )  # fmt: skip
        if granted.returncode != 0:
            raise RuntimeError(f"isql-vt could not grant SPARQL_UPDATE: {granted.stdout} {granted.stderr}")
        yield Server(url, process)
    finally:
        stop(process)


def debian_ini(location: Path, sql_port: int, http_port: int) -> str:
    """Debian's ``virtuoso.ini`` with only its paths and ports changed: the database in
    LOCATION, the SQL server at SQL_PORT, the HTTP server at HTTP_PORT."""
    text = VIRTUOSO_INI.read_text()
    changes = [
        ("/var/lib/virtuoso-opensource-7/db/", f"{location}/"),
        ("/var/lib/virtuoso-opensource-7/vsp", str(location)),
        ("ServerPort\t\t\t= 1111", f"ServerPort\t\t\t= {sql_port}"),
        ("ServerPort\t\t\t= 8890", f"ServerPort\t\t\t= {http_port}"),
        ("localhost:8890", f"localhost:{http_port}"),
    ]
    for old, new in changes:
        if old not in text:
            raise RuntimeError(f"Debian's virtuoso.ini no longer holds {old!r}")
        text = text.replace(old, new)
    return text


def _start_virtuoso(location: Path) -> tuple[subprocess.Popen[str], str, int]:
    """Virtuoso started on a new database in LOCATION at two free ports: the process, its HTTP
    URL and its SQL port."""
    sql_port, http_port = free_port(), free_port()
    location.mkdir(parents=True, exist_ok=True)
    ini = location / "virtuoso.ini"
    ini.write_text(debian_ini(location, sql_port, http_port))
    process = subprocess.Popen(
        ["virtuoso-t", "+foreground", "+configfile", str(ini)],
        cwd=location,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        text=True,
    )
    return process, f"http://127.0.0.1:{http_port}", sql_port
