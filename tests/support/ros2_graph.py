"""A ROS 2 graph of a test's own: a DDS domain no other test uses, discovery on loopback only.

ROS 2 nodes find each other by multicast discovery within a domain id (0-101 with Fast DDS's
default ports).  Tests running at once (pytest-xdist workers, two suites on one machine) each take
a domain of their own: :func:`ros2_domain` claims a free one with a lock file that only one process
can create, and gives it back at the end.
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

DOMAINS = range(1, 101)
LOCKS = Path(tempfile.gettempdir()) / "exsce-ros2-domains"


@contextmanager
def ros2_domain() -> Iterator[dict[str, str]]:
    """The environment of a domain of its own: ``ROS_DOMAIN_ID`` and loopback-only discovery."""
    LOCKS.mkdir(exist_ok=True)
    for domain in DOMAINS:
        lock = LOCKS / f"{domain}.lock"
        try:
            fd = os.open(lock, os.O_CREAT | os.O_EXCL | os.O_WRONLY)
        except FileExistsError:
            if _stale(lock):
                lock.unlink(missing_ok=True)
            continue
        os.write(fd, str(os.getpid()).encode())
        os.close(fd)
        try:
            yield {"ROS_DOMAIN_ID": str(domain), "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}
        finally:
            lock.unlink(missing_ok=True)
        return
    raise RuntimeError(f"no free ROS 2 domain id in {DOMAINS} (lock files in {LOCKS})")


def _stale(lock: Path) -> bool:
    """Whether the process that took ``lock`` is gone (a killed suite's)."""
    try:
        pid = int(lock.read_text())
    except (OSError, ValueError):
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return True
    except PermissionError:
        return False
    return False
