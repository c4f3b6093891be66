"""``<store>.serve.json``: the record a running ``exscec serve`` keeps beside the store it holds.

Only one process may open an embedded store folder, so while the endpoint (:mod:`exsce_dsl.endpoint`)
runs it holds the store, and says so in this file (URL, pid, whether updates are allowed; never the
token).  :func:`exsce_dsl.store.open.open_store` reads it: other exscec commands on the same store go
through the endpoint.  The file is removed when the server stops.
"""

from __future__ import annotations

import json
import os
from dataclasses import asdict, dataclass
from pathlib import Path


@dataclass(frozen=True)
class ServeInfo:
    """What ``<store>.serve.json`` says about a running ``exscec serve``."""

    url: str
    """The base URL, for clients on this machine (``http://127.0.0.1:7878``)."""
    pid: int
    store: str
    updates: bool

    @property
    def query_url(self) -> str:
        return f"{self.url}/query"

    @property
    def update_url(self) -> str:
        return f"{self.url}/update"

    def is_alive(self) -> bool:
        """True while the process that wrote the file runs."""
        try:
            os.kill(self.pid, 0)
        except ProcessLookupError:
            return False
        except PermissionError:  # someone else's process: alive
            return True
        except OSError:
            return False
        return True


def serve_info_path(store_path: Path) -> Path:
    """``<store folder>.serve.json``, beside the folder (``.exsce/store.serve.json``)."""
    return store_path.with_name(store_path.name + ".serve.json")


def read_serve_info(store_path: Path) -> ServeInfo | None:
    """The running server's record for this store folder, or None (no file, unreadable)."""
    try:
        data = json.loads(serve_info_path(store_path).read_text(encoding="utf-8"))
        return ServeInfo(str(data["url"]), int(data["pid"]), str(data["store"]), bool(data["updates"]))
    except (OSError, ValueError, KeyError, TypeError):
        return None


def write_serve_info(path: Path, info: ServeInfo) -> None:
    """Write ``info`` to ``path`` (whole or not at all: through a temporary file beside it)."""
    temporary = path.with_name(path.name + f".{os.getpid()}.tmp")
    temporary.write_text(json.dumps(asdict(info), indent=2) + "\n", encoding="utf-8")
    os.replace(temporary, path)


__all__ = ["ServeInfo", "read_serve_info", "serve_info_path", "write_serve_info"]
