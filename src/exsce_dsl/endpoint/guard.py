"""The endpoint's doors: which requests reach it at all, and the headers every answer carries.

* ``Host`` must name the server as bound (``127.0.0.1:PORT``; for a loopback address also
  ``localhost:PORT`` and ``[::1]:PORT``; for a wildcard address any IP address with the port),
  or a name given by ``--allowed-host`` (any port: a reverse proxy's).  Anything else is
  answered 421: a web page whose own name was made to point at 127.0.0.1 (DNS rebinding)
  cannot use the browser to reach the endpoint.
* A request from a browser page of another origin is refused (403): its ``Origin`` header, when
  present, must be this server's own origin, and its ``Sec-Fetch-Site``, when present, must be
  ``same-origin`` or ``none``.  No CORS header is ever sent.
* A request framed both by ``Content-Length`` and ``Transfer-Encoding`` is refused and its
  connection closed (h11 refuses every other bad framing itself).
* Every answer says ``Cache-Control: no-store`` and ``X-Content-Type-Options: nosniff``.
"""

from __future__ import annotations

import ipaddress
import logging
from collections.abc import Callable, Collection, Mapping
from typing import Any

from starlette.responses import PlainTextResponse
from starlette.types import ASGIApp, Message, Receive, Scope, Send

from exsce_dsl import __version__
from exsce_dsl.errors import AnswerCut, Remedied
from exsce_dsl.remedies import ALLOW_THE_HOST

LOGGER = logging.getLogger("exsce_dsl.endpoint")
WILDCARDS = ("0.0.0.0", "::", "")
LOOPBACK_NAMES = ("127.0.0.1", "localhost", "::1")


def is_loopback(host: str) -> bool:
    """Whether ``host`` (a name or an address) is this machine's loopback."""
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host.strip("[]")).is_loopback
    except ValueError:
        return False


class HostRule:
    """Which ``Host`` headers name a server bound to ``host:port``, with ``allowed`` names."""

    def __init__(self, host: str, port: int, allowed: Collection[str] = ()) -> None:
        self.port = port
        self.wildcard = host in WILDCARDS
        names = {host.lower().strip("[]")}
        if is_loopback(host) or self.wildcard:
            names.update(LOOPBACK_NAMES)
        self.bound = names
        self.allowed = {name.lower().strip("[]") for name in allowed}

    def admits(self, header: str) -> bool:
        name, port = _split_host(header.strip().lower())
        if name is None:
            return False
        if name in self.allowed:
            return True
        if port != self.port and not (port is None and self.port == 80):
            return False
        if name in self.bound:
            return True
        if self.wildcard:  # an address cannot be rebound; only names can
            try:
                ipaddress.ip_address(name)
            except ValueError:
                return False
            return True
        return False


def _split_host(header: str) -> tuple[str | None, int | None]:
    """``(name, port)`` of a Host header (the name without brackets), or ``(None, None)``."""
    if header.startswith("["):
        end = header.find("]")
        if end < 0:
            return None, None
        name, rest = header[1:end], header[end + 1 :]
    else:
        name, colon, port_text = header.partition(":")
        rest = colon + port_text
    if not rest:
        return name or None, None
    if not rest.startswith(":") or not rest[1:].isdigit():
        return None, None
    return name or None, int(rest[1:])


class Guard:
    """ASGI middleware: the Host and Origin checks, the common headers, and a log line per request."""

    def __init__(
        self,
        app: ASGIApp,
        rule: HostRule,
        log: Callable[[str], None] | None = None,
        wording: Mapping[str, str] | None = None,
    ) -> None:
        self.app = app
        self.rule = rule
        self.log = log
        self.wording = wording
        """How refusals say their remedies (:meth:`~exsce_dsl.errors.Remedied.said`)."""

    async def __call__(self, scope: Scope, receive: Receive, send: Send) -> None:
        if scope["type"] != "http":
            return
        headers = {k.decode("latin-1").lower(): v.decode("latin-1") for k, v in scope["headers"]}
        status: list[int] = []

        async def sending(message: Message) -> None:
            if message["type"] == "http.response.start":
                status.append(message["status"])
                message["headers"] = [*message.get("headers", []), *_COMMON]
            await send(message)

        refusal = self._refusal(headers)
        try:
            if refusal is not None:
                await refusal(scope, receive, sending)
            else:
                await self.app(scope, receive, sending)
        except AnswerCut as cut:  # headers sent: uvicorn closes the connection before the body's end
            LOGGER.warning("an answer to %s was cut: %s", scope.get("client", ("-",))[0], cut)
        finally:
            if self.log is not None:
                client = scope.get("client") or ("-", 0)
                query = f"?{scope['query_string'].decode('latin-1')}" if scope.get("query_string") else ""
                shown = status[0] if status else "-"
                self.log(f"{client[0]} {scope['method']} {scope['path']}{query[:200]} {shown}")

    def _refusal(self, headers: dict[str, str]) -> Any:
        if "transfer-encoding" in headers and "content-length" in headers:
            # h11 reads such a body as chunked and would read what follows as the next request
            # (RFC 9112, 6.1: reject, or close the connection after the answer): both, here
            return PlainTextResponse(
                "a request framed both by Content-Length and by Transfer-Encoding is refused\n",
                status_code=400,
                headers={"Connection": "close"},
            )
        host = headers.get("host", "")
        if not self.rule.admits(host):
            refused = Remedied(f"this endpoint does not answer for the host {host[:100]!r}", ALLOW_THE_HOST)
            return PlainTextResponse(refused.said(self.wording) + "\n", status_code=421)
        origin = headers.get("origin")
        if origin is not None and origin.lower() != f"http://{host.lower()}":
            return PlainTextResponse(
                f"requests from pages of another origin ({origin[:100]}) are refused\n", status_code=403
            )
        site = headers.get("sec-fetch-site")
        if site is not None and site.lower() not in ("same-origin", "none"):
            return PlainTextResponse(
                f"requests from pages of another site ({site[:40]}) are refused\n", status_code=403
            )
        return None


_COMMON = [
    (b"cache-control", b"no-store"),
    (b"x-content-type-options", b"nosniff"),
    (b"server", f"exscec-serve/{__version__}".encode()),
]


__all__ = ["Guard", "HostRule", "is_loopback"]
