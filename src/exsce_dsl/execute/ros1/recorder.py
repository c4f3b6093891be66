"""``rosbag record`` on exactly a run's topics, started before the first goal and closed cleanly.

:class:`Recorder` runs ROS 1's ``record`` program directly (not the ``rosbag`` script: on SIGINT
that script forwards the signal and then raises at once, while ``record`` is still closing the
bag) in a process group of its own, so that Ctrl-C in the terminal reaches exsce, which stops
the recording in order.  :meth:`Recorder.start` returns once ``record`` receives every listed
topic that is published now: its node is registered, it subscribes to each topic, each
publisher of a published one lists a connection to it (the publisher's own ``getBusInfo``: a
message published after that is recorded), and it has opened the bag (on simulated time it waits
for the first ``/clock`` to do so, dropping what comes before).  :meth:`Recorder.stop` sends
SIGINT and waits for ``record`` to write the bag's index and rename ``<bag>.active`` to ``<bag>``;
after a timeout it kills ``record``, removes the unfinished ``.active`` file and raises, saying
the bag may be incomplete.  No ``.active`` file is ever left behind.  It records into the path
the caller gives (a run's hidden folder, :mod:`exsce_dsl.execute.run_files`).
"""

from __future__ import annotations

import http.client
import itertools
import os
import re
import signal
import subprocess
import time
import xmlrpc.client
from collections.abc import Sequence
from pathlib import Path
from types import TracebackType
from typing import Any

from exsce_dsl.errors import RosGraphError
from exsce_dsl.execute.ros1.graph import CALLER, INSTALL_HINT, Master, node_environment
from exsce_dsl.runs import ROS1_BAG

RECORD_PROGRAMS = (Path("/usr/lib/rosbag/record"), Path("/opt/ros/noetic/lib/rosbag/record"))
"""Where ``record`` is: Debian's ``rosbag`` package, ROS Noetic's."""
ROS_NAME = re.compile(r"(/[A-Za-z_][A-Za-z0-9_]*)+")
"""An absolute ROS 1 graph name, as ``record`` subscribes to it."""
POLL = 0.05
NODE_TIMEOUT = 1.0
"""Seconds a publisher node has to answer ``getBusInfo``."""
_numbers = itertools.count(1)


def record_program() -> Path:
    """ROS 1's ``record`` program; :class:`RosGraphError` naming what to install if it is missing."""
    found = next((p for p in RECORD_PROGRAMS if p.is_file() and os.access(p, os.X_OK)), None)
    if found is None:
        listed = " or ".join(str(p) for p in RECORD_PROGRAMS)
        raise RosGraphError(f"rosbag's record program is missing ({listed}); {INSTALL_HINT}")
    return found


class Recorder:
    """``record -O bag_path topics...`` on the graph of ``master_uri``, its output to ``log``."""

    def __init__(
        self,
        master_uri: str,
        topics: Sequence[str],
        bag_path: Path,
        log: Path,
        ros_home: Path | None = None,
    ) -> None:
        wrong = [t for t in topics if not ROS_NAME.fullmatch(t)]
        if wrong:
            raise RosGraphError(
                f"rosbag record cannot subscribe to {', '.join(repr(t) for t in wrong)}: a topic it records "
                "is an absolute ROS name (/ns/name: letters, digits and '_')"
            )
        if bag_path.suffix != ROS1_BAG.suffix or ":=" in str(bag_path):
            raise RosGraphError(f"rosbag record writes a file named *.bag without ':=', not {bag_path}")
        if not topics:
            raise RosGraphError("rosbag record was given no topic to record")
        self.master_uri = master_uri
        self.topics = tuple(dict.fromkeys(topics))
        self.bag_path = bag_path.absolute()
        self.log = log
        self.ros_home = ros_home
        self.node = f"/exsce_record_{os.getpid()}_{next(_numbers)}"
        """The record node's name on the graph."""
        self.process: subprocess.Popen[bytes] | None = None

    @property
    def active(self) -> Path:
        """The file ``record`` writes while it runs, renamed to :attr:`bag_path` when closed."""
        return self.bag_path.with_name(self.bag_path.name + ".active")

    def __enter__(self) -> Recorder:
        return self

    def __exit__(
        self, kind: type[BaseException] | None, error: BaseException | None, tb: TracebackType | None
    ) -> None:
        try:
            self.stop()
        except RosGraphError:
            if kind is None:
                raise  # else the error that ended the block is the one to tell

    def running(self) -> bool:
        return self.process is not None and self.process.poll() is None

    def start(self, timeout: float = 30.0) -> None:
        """Start recording; return once every listed topic published now reaches ``record``
        (:class:`RosGraphError` if ``record`` ends or that takes over ``timeout`` seconds)."""
        if self.process is not None:
            raise RosGraphError(f"the recorder of {self.bag_path.name} was started already")
        program = record_program()
        self.bag_path.parent.mkdir(parents=True, exist_ok=True)
        self.log.parent.mkdir(parents=True, exist_ok=True)
        self._removed_active()  # an earlier try's: its presence says when this record has opened the bag
        argv = [str(program), "-O", str(self.bag_path), *self.topics, f"__name:={self.node.lstrip('/')}"]
        with self.log.open("wb") as out:
            self.process = subprocess.Popen(
                argv,
                stdin=subprocess.DEVNULL,
                stdout=out,
                stderr=subprocess.STDOUT,
                env=node_environment(self.master_uri, self.ros_home),
                cwd=self.bag_path.parent,
                start_new_session=True,  # Ctrl-C reaches exsce, which stops the recording in order
            )
        try:
            self._wait_until_receiving(timeout)
        except BaseException:
            self._kill()
            raise

    def _wait_until_receiving(self, timeout: float) -> None:
        master = Master(self.master_uri)
        deadline = time.monotonic() + timeout
        while True:
            if not self.running():
                raise self._ended("while starting")
            lacking = self._not_receiving(master)
            if not lacking:
                return
            if time.monotonic() > deadline:
                listed = ", ".join(lacking)
                raise RosGraphError(
                    f"rosbag record did not receive {listed} within {timeout:g} s{_no_clock(master)}:\n"
                    f"{self._log_tail()}"
                )
            time.sleep(POLL)

    def _not_receiving(self, master: Master) -> list[str]:
        """What ``record`` does not receive yet: every listed topic until its node is registered;
        those it does not subscribe to; those a publisher has no connection to it for; and
        anything until it has opened the bag (it waits for a valid time first: on simulated time,
        for the first ``/clock``, and drops what comes before)."""
        if master.lookup_node(self.node) is None:
            return list(self.topics)
        subscribed = master.subscribers()
        lacking = [t for t in self.topics if self.node not in subscribed.get(t, set())]
        if not self.active.exists():
            lacking.append("anything (it has not opened the bag)")
        publishers = master.publishers()
        connected: dict[str, set[str] | None] = {}
        for topic in self.topics:
            for node in sorted(publishers.get(topic, set())):
                if node not in connected:
                    connected[node] = _outbound(master, node, self.node)
                to_record = connected[node]
                if to_record is not None and topic not in to_record:
                    lacking.append(f"{topic} (from {node})")
        return lacking

    def stop(self, timeout: float = 30.0) -> Path:
        """Stop recording as Ctrl-C does (SIGINT) and wait until ``record`` has closed the bag;
        returns the bag's path.  After ``timeout`` seconds ``record`` is killed, its unfinished
        ``.active`` file removed and :class:`RosGraphError` raised: the bag may be incomplete."""
        process = self.process
        if process is None:
            return self.bag_path
        if process.poll() is not None:
            self._kill()
            if process.returncode != 0 or not self.bag_path.exists():
                raise self._ended("before it was stopped")
            return self.bag_path
        _signal_group(process, signal.SIGINT)
        try:
            process.wait(timeout)
        except subprocess.TimeoutExpired:
            self._kill()
            raise RosGraphError(
                f"rosbag record did not close {self.bag_path.name} within {timeout:g} s after SIGINT and was "
                f"killed: the recording is incomplete{self._removed_active()}"
            ) from None
        self._kill()
        if process.returncode != 0 or not self.bag_path.exists():
            raise self._ended("while closing the bag")
        return self.bag_path

    def _kill(self) -> None:
        """SIGKILL what is left of ``record``'s group; remove an ``.active`` file it left."""
        if self.process is None:
            return
        _signal_group(self.process, signal.SIGKILL)
        try:
            self.process.wait(5.0)
        except subprocess.TimeoutExpired:
            pass
        self._removed_active()

    def _removed_active(self) -> str:
        if self.active.exists():
            self.active.unlink()
            return f" ({self.active.name} was removed)"
        return ""

    def _ended(self, when: str) -> RosGraphError:
        assert self.process is not None
        code = self.process.poll()
        removed = self._removed_active()
        return RosGraphError(f"rosbag record ended {when} (exit status {code}){removed}:\n{self._log_tail()}")

    def _log_tail(self, lines: int = 15) -> str:
        text = self.log.read_text(errors="replace") if self.log.exists() else ""
        return "\n".join(text.splitlines()[-lines:])


def _outbound(master: Master, publisher: str, subscriber: str) -> set[str] | None:
    """The topics ``publisher`` has a connection to ``subscriber`` for, from its ``getBusInfo``;
    None when it cannot be asked (not registered any more, not answering): not waited for."""
    uri = master.lookup_node(publisher)
    if uri is None:
        return None
    try:
        answer: Any = xmlrpc.client.ServerProxy(uri, transport=_Patient()).getBusInfo(CALLER)
    except (OSError, xmlrpc.client.Error):
        return None
    code, _, connections = answer
    if code != 1:
        return None
    return {str(c[4]) for c in connections if len(c) > 4 and c[2] == "o" and c[1] == subscriber}


def _no_clock(master: Master) -> str:
    """Why ``record`` may wait for ever: the graph runs on simulated time and has no clock."""
    try:
        simulated = master.has_param("/use_sim_time") and bool(master.get_param("/use_sim_time"))
        clockless = simulated and "/clock" not in master.publishers()
    except RosGraphError:
        return ""
    return " (/use_sim_time is set and nothing publishes /clock)" if clockless else ""


class _Patient(xmlrpc.client.Transport):
    """An XML-RPC transport that gives up on a node that does not answer within a second."""

    def make_connection(self, host: tuple[str, dict[str, str]] | str) -> http.client.HTTPConnection:
        connection = super().make_connection(host)
        connection.timeout = NODE_TIMEOUT
        return connection


def _signal_group(process: subprocess.Popen[bytes], sig: int) -> None:
    try:
        os.killpg(process.pid, sig)
    except (ProcessLookupError, PermissionError):
        pass
