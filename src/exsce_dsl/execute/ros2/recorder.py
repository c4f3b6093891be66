"""Recording a run on ROS 2: ``ros2 bag record`` to MCAP, its command line and its process.

The command line (:func:`record_command`), for the topics the caller gives (the run's topics:
what the spec's metrics and the robots' conventions read, plus ``/tf``, ``/tf_static`` and
``/clock``)::

    ros2 bag record -s mcap -o DIR [--use-sim-time] [--include-hidden-topics]
        [--qos-profile-overrides-path FILE] (--topics TOPIC... | TOPIC...)

- Humble (and Iron) take the topics as positional arguments only; Jazzy takes ``--topics``
  (its positional form is deprecated) and later distros only ``--topics``: the distro is
  ``$ROS_DISTRO``, which sourcing a ROS 2 setup sets.
- ``-s mcap``: Jazzy's default storage; Humble needs ``ros-humble-rosbag2-storage-mcap``.
- ``--include-hidden-topics`` when a topic has a hidden level (``_action``: Nav2's
  ``navigate_to_pose/_action/status`` and ``feedback``), which the recorder skips otherwise.
- ``/tf_static`` (any topic named ``tf_static``) is latched: its publishers offer transient
  local durability and publish once, before the recorder starts.  The overrides file asks for it
  with transient local durability, reliable, keeping the last :data:`LATCHED_DEPTH`, so that
  the recorder is handed what was published before it joined.
- ``--use-sim-time`` (when the graph has ``/clock``, e.g. Gazebo): the bag's log times are the
  simulated clock; nothing is written until the first ``/clock`` message.

:class:`Ros2Recorder` runs it in a session of its own and stops it with SIGINT, as Ctrl-C would,
then waits for the bag's ``metadata.yaml``, which rosbag2 writes when it closes the bag.
"""

from __future__ import annotations

import os
import re
import shutil
import signal
import subprocess
import time
from collections.abc import Sequence
from pathlib import Path
from types import TracebackType

import yaml

from exsce_dsl.errors import ExsceError, RosGraphError
from exsce_dsl.runs import ROS2_METADATA

STORAGE = "mcap"
POSITIONAL_TOPICS = frozenset({"foxy", "galactic", "humble", "iron"})
"""The distros whose ``ros2 bag record`` takes its topics as positional arguments only."""
LATCHED = "tf_static"
"""The last level of the topics recorded as latched (transient local)."""
LATCHED_DEPTH = 100
"""How many messages of a latched topic the recorder asks for (one per publisher is sent)."""
SOURCE_HINT = "source a ROS 2 distro's setup first (e.g. . /opt/ros/jazzy/setup.bash)"
STOP_WAIT = 30.0
"""Seconds the recorder may take to close its bag after SIGINT."""

_TOPIC = re.compile(r"(/[A-Za-z_][A-Za-z0-9_]*)+")


def check_topics(topics: Sequence[str]) -> None:
    """Raise :class:`ExsceError` unless ``topics`` are absolute ROS 2 topic names, at least one."""
    if not topics:
        raise ExsceError("no topics to record")
    bad = [t for t in topics if not _TOPIC.fullmatch(t)]
    if bad:
        raise ExsceError(f"not ROS 2 topic names (absolute, of letters, digits and '_'): {bad}")


def qos_overrides(topics: Sequence[str]) -> dict[str, dict[str, str | int]]:
    """The QoS each latched topic of ``topics`` is recorded with (the overrides file's content)."""
    return {
        t: {
            "history": "keep_last",
            "depth": LATCHED_DEPTH,
            "reliability": "reliable",
            "durability": "transient_local",
        }
        for t in topics
        if t.rsplit("/", 1)[-1] == LATCHED
    }


def record_command(
    output: Path,
    topics: Sequence[str],
    distro: str,
    use_sim_time: bool = False,
    overrides: Path | None = None,
) -> tuple[str, ...]:
    """``ros2 bag record`` writing ``topics`` to the MCAP bag ``output`` (a folder that must not
    exist yet), as ``distro``'s recorder takes them; ``overrides``: the QoS overrides file."""
    check_topics(topics)
    command = ["ros2", "bag", "record", "-s", STORAGE, "-o", str(output)]
    if use_sim_time:
        command.append("--use-sim-time")
    if any(level.startswith("_") for t in topics for level in t.split("/")):
        command.append("--include-hidden-topics")
    if overrides is not None:
        command += ["--qos-profile-overrides-path", str(overrides)]
    if distro.lower() in POSITIONAL_TOPICS:
        command += list(topics)
    else:
        command += ["--topics", *topics]
    return tuple(command)


class Ros2Recorder:
    """``ros2 bag record`` of ``topics`` into the bag folder ``output``, from :meth:`start` to
    :meth:`stop` (a context manager: leaving it stops the recorder, also on an error).  The QoS
    overrides file is written beside the bag, as ``<output>.qos.yaml``."""

    def __init__(self, output: Path, topics: Sequence[str], use_sim_time: bool = False) -> None:
        check_topics(topics)
        self.output, self.topics, self.use_sim_time = output, tuple(topics), use_sim_time
        self.process: subprocess.Popen[bytes] | None = None
        self.log = output.with_name(output.name + ".record.log")
        """What the recorder printed."""

    def start(self) -> None:
        distro = os.environ.get("ROS_DISTRO", "")
        if shutil.which("ros2") is None or not distro:
            raise RosGraphError(f"no ROS 2 here ('ros2' not on PATH or ROS_DISTRO not set): {SOURCE_HINT}")
        if self.output.exists():
            raise RosGraphError(f"{self.output} exists: ros2 bag record writes a new folder")
        self.output.parent.mkdir(parents=True, exist_ok=True)
        overrides = None
        latched = qos_overrides(self.topics)
        if latched:
            overrides = self.output.with_name(self.output.name + ".qos.yaml")
            overrides.write_text(yaml.safe_dump(latched, sort_keys=True), encoding="utf-8")
        command = record_command(self.output, self.topics, distro, self.use_sim_time, overrides)
        with self.log.open("wb") as log:
            self.process = subprocess.Popen(
                command, stdout=log, stderr=subprocess.STDOUT, start_new_session=True
            )

    def check_running(self) -> None:
        """Raise :class:`RosGraphError` if the recorder is not running (it failed to start:
        an unknown storage, a folder it cannot write...)."""
        if self.process is None or self.process.poll() is not None:
            code = None if self.process is None else self.process.returncode
            raise RosGraphError(f"ros2 bag record is not running (exit {code}): see {self.log}")

    def stop(self) -> Path:
        """Stop the recorder as Ctrl-C does and wait for the bag to be closed; the bag folder."""
        process, self.process = self.process, None
        if process is None:
            raise RosGraphError("the ROS 2 recorder was not started")
        if process.poll() is not None:
            raise RosGraphError(f"ros2 bag record ended early (exit {process.returncode}): see {self.log}")
        process.send_signal(signal.SIGINT)
        try:
            process.wait(STOP_WAIT)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()
            raise RosGraphError(
                f"ros2 bag record did not close {self.output} within {STOP_WAIT:g} s"
            ) from None
        deadline = time.monotonic() + STOP_WAIT
        while not (self.output / ROS2_METADATA).exists():
            if time.monotonic() > deadline:
                raise RosGraphError(
                    f"ros2 bag record left no metadata.yaml in {self.output}: the bag is not closed"
                )
            time.sleep(0.1)
        return self.output

    def __enter__(self) -> Ros2Recorder:
        self.start()
        return self

    def __exit__(
        self, kind: type[BaseException] | None, error: BaseException | None, trace: TracebackType | None
    ) -> None:
        if self.process is not None:
            if error is None:
                self.stop()
                return
            try:
                self.stop()
            except RosGraphError:
                pass  # the error that left the block is the one to report
