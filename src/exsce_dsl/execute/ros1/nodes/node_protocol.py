"""The node side of exsce's JSON-lines channel (see ``exsce_dsl.execute.ros1.channel``).

Imported by the nodes beside it, which run in rospy's Python (Debian's 3.11 or ROS Noetic's 3.8):
the standard library only, and spellings Python 3.8 accepts.  Events go to standard output, one
JSON object per line, from any thread; commands come from standard input, one per line, to a
handler called on a thread of their own; the end of input calls ``on_close``.
"""

import json
import sys
import threading
from typing import Any, Callable, Dict, Optional

_write_lock = threading.Lock()


def emit(event: str, **fields: Any) -> None:
    """Write one event line."""
    fields["event"] = event
    line = json.dumps(fields, separators=(",", ":"))
    with _write_lock:
        sys.stdout.write(line + "\n")
        sys.stdout.flush()


def fail(message: str) -> None:
    """Say what went wrong, then end the process with status 2."""
    emit("error", message=message)
    sys.exit(2)


def serve_commands(
    handle: Callable[[Dict[str, Any]], None], on_close: Optional[Callable[[], None]] = None
) -> None:
    """Read commands on a daemon thread: ``handle`` each, ``on_close`` at the end of input."""

    def read() -> None:
        for raw in sys.stdin:
            raw = raw.strip()
            if not raw:
                continue
            try:
                command = json.loads(raw)
            except ValueError:
                emit("warning", message="not a JSON command: " + raw[:80])
                continue
            try:
                handle(command)
            except Exception as e:  # a command that fails says so; the node goes on
                emit("warning", message="%s failed: %s" % (command.get("command"), e))
        if on_close is not None:
            on_close()

    threading.Thread(target=read, name="commands", daemon=True).start()
