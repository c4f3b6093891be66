"""Talk to one of exsce's ROS-side nodes: a program run by rospy's Python, JSON lines both ways.

The nodes (``nodes/*.py``) import only the standard library and ROS 1's Python packages, never
exsce: they run in Debian's Python (or ROS Noetic's 3.8), not in this venv.  Each reads one JSON
object per line on its standard input (commands) and writes one per line on its standard output
(events); its log goes to a file.  A node says ``{"event": "ready"}`` once it is up, or
``{"event": "error", "message": ...}`` and exits.  Closing its input asks it to shut down.
"""

from __future__ import annotations

import json
import os
import queue
import signal
import subprocess
import threading
import time
from importlib import resources
from pathlib import Path
from types import TracebackType
from typing import Any

from exsce_dsl.errors import RosGraphError
from exsce_dsl.execute.ros1.graph import node_environment, ros_python

Message = dict[str, Any]


def node_script(name: str) -> Path:
    """The file of node ``name`` (``dispatcher``, ``stand_in``): ``nodes/<name>_node.py``."""
    path = Path(str(resources.files("exsce_dsl.execute.ros1") / "nodes" / f"{name}_node.py"))
    if not path.is_file():
        raise RosGraphError(f"exsce's ROS 1 node '{name}' is not installed ({path} is missing)")
    return path


class NodeChannel:
    """A running node and the lines it wrote that were not read yet."""

    def __init__(self, name: str, args: list[str], master_uri: str, log: Path, ros_home: Path | None = None):
        self.name = name
        self.log = log
        log.parent.mkdir(parents=True, exist_ok=True)
        self._log_file = log.open("wb")
        self.process = subprocess.Popen(
            [str(ros_python()), "-u", str(node_script(name)), *args],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=self._log_file,
            env=node_environment(master_uri, ros_home),
            start_new_session=True,  # Ctrl-C reaches us, not the node: we stop it in order
        )
        self._lines: queue.Queue[Message | None] = queue.Queue()
        self._reader = threading.Thread(target=self._read, name=f"{name}-events", daemon=True)
        self._reader.start()

    def __enter__(self) -> NodeChannel:
        return self

    def __exit__(
        self, kind: type[BaseException] | None, error: BaseException | None, tb: TracebackType | None
    ) -> None:
        self.close()

    def _read(self) -> None:
        assert self.process.stdout is not None
        for raw in self.process.stdout:
            try:
                message = json.loads(raw)
            except ValueError:
                continue  # not ours (a library printing to stdout); the log has the rest
            if isinstance(message, dict):
                self._lines.put(message)
        self._lines.put(None)  # the node closed its output: it has ended

    def send(self, message: Message) -> None:
        """Write one command; :class:`RosGraphError` if the node has ended."""
        line = (json.dumps(message, separators=(",", ":")) + "\n").encode()
        try:
            assert self.process.stdin is not None
            self.process.stdin.write(line)
            self.process.stdin.flush()
        except (BrokenPipeError, ValueError) as e:
            raise self._ended() from e

    def receive(self, timeout: float | None) -> Message | None:
        """The next event, waiting at most ``timeout`` seconds (None: until one comes); None if none
        came.  An ``error`` event and a node that ended raise :class:`RosGraphError`."""
        try:
            message = self._lines.get(timeout=timeout)
        except queue.Empty:
            return None
        if message is None:
            self._lines.put(None)  # every later receive says so too
            raise self._ended()
        if message.get("event") == "error":
            raise RosGraphError(f"{self.name} node: {message.get('message', 'failed')}")
        return message

    def expect(self, event: str, timeout: float) -> Message:
        """Wait for the event named ``event`` (other events before it are dropped)."""
        deadline = time.monotonic() + timeout
        while True:
            left = deadline - time.monotonic()
            message = self.receive(max(0.0, left))
            if message is not None and message.get("event") == event:
                return message
            if message is None and left <= 0:
                raise RosGraphError(f"the {self.name} node did not say '{event}' within {timeout:g} s")

    def _ended(self) -> RosGraphError:
        code = self.process.wait(5.0)
        return RosGraphError(f"the {self.name} node ended (exit status {code}):\n{self.log_tail()}")

    def log_tail(self, lines: int = 15) -> str:
        self._log_file.flush()
        text = self.log.read_text(errors="replace") if self.log.exists() else ""
        return "\n".join(text.splitlines()[-lines:])

    def close(self, timeout: float = 10.0) -> int | None:
        """Ask the node to end (its input closed, then SIGINT, then SIGKILL); its exit status."""
        if self.process.poll() is None:
            try:
                assert self.process.stdin is not None
                self.process.stdin.close()
            except (BrokenPipeError, OSError):
                pass
            for sig, wait in ((None, timeout / 2), (signal.SIGINT, timeout / 2), (signal.SIGKILL, 5.0)):
                if sig is not None:
                    try:
                        os.killpg(self.process.pid, sig)
                    except (ProcessLookupError, PermissionError):
                        pass
                try:
                    self.process.wait(wait)
                    break
                except subprocess.TimeoutExpired:
                    continue
        self._reader.join(timeout=2.0)
        self._log_file.close()
        return self.process.poll()
