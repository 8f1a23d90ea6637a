"""Who may talk to the GUI server: the ``Host`` and ``Origin`` checks.

The GUI server listens on this machine, but the user's browser visits other sites. Without
checks, any page could open a WebSocket to ``ws://127.0.0.1:8080`` and drive the GUI (browsers
do not apply the same-origin policy to WebSockets), or reach it under its own name by DNS
rebinding. So every request is checked before viser sees it:

- ``Host`` must name this server: its bound address, or a localhost name (``localhost``,
  ``127.0.0.1``, ``[::1]``) for a localhost bind, with the bound port;
- a WebSocket must come with an ``Origin`` that is the page's own (``http://`` + such a host
  and port); a plain HTTP request with an ``Origin`` is held to the same rule;
- ``--allow-origin ORIGIN`` adds an origin (and its host name) on purpose, e.g. a reverse proxy.

A refused request gets ``403 Forbidden`` and never reaches viser. The same wrapper bounds what
a connection may buffer: a message of at most :data:`~.uploads.MAX_MESSAGE_BYTES` (viser asks
for 50 MiB) and :data:`~.uploads.MAX_QUEUED_MESSAGES` messages read ahead (see :mod:`.uploads`).

Why a patch: viser (1.1) starts its websockets server inside ``ViserServer.__init__`` with its
own ``process_request`` (the static file server) and passes no ``origins``; it offers no hook to
check a request. websockets' supported hook is that same ``process_request``. So
:func:`guarded_start` replaces ``websockets.asyncio.server.serve`` *only while viser starts*
(under a lock) with a wrapper that puts the check in front of viser's ``process_request``, and
reports whether it was used: if a viser release starts its server differently, the GUI refuses
to run rather than run unguarded.
"""

from __future__ import annotations

import contextlib
import http
import inspect
import ipaddress
import socket
import threading
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass
from typing import Any
from urllib.parse import urlsplit

from impact_balance.exceptions import ImpactBalanceError

__all__ = ["LOCAL_NAMES", "AccessPolicy", "OriginError", "guarded_start", "normalize_origin"]

#: Host names of this machine as they appear in ``Host`` and ``Origin`` headers.
LOCAL_NAMES = ("localhost", "127.0.0.1", "[::1]")
_WILDCARD = ("", "0.0.0.0", "::")
_DEFAULT_PORTS = {"http": 80, "https": 443}


class OriginError(ImpactBalanceError, ValueError):
    """An ``--allow-origin`` value that is not ``scheme://host[:port]``.

    Attributes:
        value: The value (cut to 80 characters).
    """

    def __init__(self, value: str, reason: str):
        self.value = value if len(value) <= 80 else value[:77] + "..."
        super().__init__(f"--allow-origin = {self.value!r}: {reason}")


def _host_name(host: str) -> str:
    """A host as written in a URL: lower case, IPv6 addresses in brackets."""
    host = host.strip().lower()
    try:
        if ipaddress.ip_address(host.strip("[]")).version == 6:
            return f"[{host.strip('[]')}]"
    except ValueError:
        pass
    return host


def _split_host(value: str) -> tuple[str, int | None] | None:
    """``host[:port]`` (a ``Host`` header or a URL's netloc) -> (host name, port or None).

    None if it is malformed.
    """
    value = value.strip()
    if value.startswith("["):
        end = value.find("]")
        if end < 0:
            return None
        host, rest = value[: end + 1], value[end + 1 :]
    else:
        host, sep, port = value.partition(":")
        rest = sep + port
    if rest and not (
        rest.startswith(":") and rest[1:].isdigit() and len(rest) <= 6 and int(rest[1:]) <= 65535
    ):
        return None
    if not host:
        return None
    return _host_name(host), int(rest[1:]) if rest else None


def normalize_origin(origin: str) -> str:
    """``origin`` as ``scheme://host[:port]`` in canonical form.

    Lower case, IPv6 addresses in brackets, the scheme's default port dropped.

    Raises:
        OriginError: Not an ``http://`` or ``https://`` origin (a path, a query, user
            information, a bad host or port).
    """
    try:
        parts = urlsplit(origin.strip())
    except ValueError:
        raise OriginError(origin, "not a URL") from None
    if parts.scheme not in _DEFAULT_PORTS:
        raise OriginError(origin, "must start with http:// or https://")
    if (
        parts.path not in ("", "/")
        or parts.query
        or parts.fragment
        or parts.username
        or parts.password
    ):
        raise OriginError(origin, "an origin is scheme://host[:port], without a path")
    split = _split_host(parts.netloc)
    if split is None:
        raise OriginError(origin, "bad host or port")
    host, port = split
    if port is None or port == _DEFAULT_PORTS[parts.scheme]:
        return f"{parts.scheme}://{host}"
    return f"{parts.scheme}://{host}:{port}"


@dataclass(frozen=True)
class AccessPolicy:
    """The hosts and origins the GUI server answers.

    Attributes:
        hosts: Host names of this server (lower case, IPv6 in brackets); the port must be the
            bound one.
        origins: Origins allowed on purpose (canonical, see :func:`normalize_origin`).
        extra_hosts: Host names of those origins (any port: a proxy may forward its own).
    """

    hosts: frozenset[str]
    origins: frozenset[str] = frozenset()
    extra_hosts: frozenset[str] = frozenset()

    @classmethod
    def for_bind(cls, host: str, allow_origins: Iterable[str] = ()) -> AccessPolicy:
        """The policy of a server bound to ``host``, plus the ``allow_origins``.

        A localhost bind answers the localhost names too; a bind to every interface also the
        machine's own names and addresses.

        Raises:
            OriginError: An allowed origin is not ``scheme://host[:port]``.
        """
        name = _host_name(host)
        hosts = {name}
        if name in _WILDCARD or name in LOCAL_NAMES or name.startswith("127.") or name == "[::1]":
            hosts.update(LOCAL_NAMES)
        if name in _WILDCARD:
            # Every interface: also the machine's own names and addresses (others: --allow-origin).
            for own in {socket.gethostname(), socket.getfqdn()}:
                hosts.add(_host_name(own))
                with contextlib.suppress(OSError, UnicodeError):
                    hosts.update(
                        _host_name(str(info[4][0])) for info in socket.getaddrinfo(own, None)
                    )
            hosts -= {"", "0.0.0.0", "[::]"}
        origins = {normalize_origin(o) for o in allow_origins}
        extra = set()
        for origin in origins:  # canonical: each has a host
            split = _split_host(urlsplit(origin).netloc)
            if split is not None:
                extra.add(split[0])
        return cls(frozenset(hosts), frozenset(origins), frozenset(extra))

    def _own(self, host: str, port: int | None, bound_port: int, default: int) -> bool:
        return host in self.extra_hosts or (host in self.hosts and (port or default) == bound_port)

    def refusal(
        self, bound_port: int, host: list[str], origin: list[str], websocket: bool
    ) -> str | None:
        """Why a request is refused, or None to serve it.

        Args:
            bound_port: The server's port.
            host: The request's ``Host`` header values (one expected).
            origin: Its ``Origin`` header values (zero or one).
            websocket: Whether it asks for a WebSocket upgrade (an ``Origin`` is required).
        """
        if len(host) != 1:
            return "one Host header expected"
        split = _split_host(host[0])
        if split is None or not self._own(split[0], split[1], bound_port, 80):
            return "unknown Host (this server answers its own address only; see --allow-origin)"
        if len(origin) > 1:
            return "one Origin header expected"
        if not origin:
            return "a WebSocket needs the Origin header of the GUI's page" if websocket else None
        value = origin[0].strip()
        try:
            canonical = normalize_origin(value)
        except OriginError:
            return "foreign Origin"
        if canonical in self.origins:
            return None
        parts = urlsplit(canonical)
        split = _split_host(parts.netloc)
        if (
            parts.scheme == "http"
            and split is not None
            and split[0] in self.hosts
            and (split[1] or 80) == bound_port
        ):
            return None
        return "foreign Origin (only the GUI's own page may connect; see --allow-origin)"


def _checker(policy: AccessPolicy, inner: Callable[..., Any] | None) -> Callable[..., Any]:
    """A websockets ``process_request`` that checks ``policy`` first, then calls ``inner``."""

    def process_request(connection: Any, request: Any) -> Any:
        headers = request.headers
        websocket = "websocket" in ",".join(headers.get_all("Upgrade")).lower()
        reason = policy.refusal(
            int(connection.local_address[1]),
            headers.get_all("Host"),
            headers.get_all("Origin"),
            websocket,
        )
        if reason is not None:
            return connection.respond(
                http.HTTPStatus.FORBIDDEN, f"impact-balance gui: refused: {reason}\n"
            )
        return inner(connection, request) if inner is not None else None

    return process_request


_PATCH_LOCK = threading.Lock()


@contextlib.contextmanager
def guarded_start(policy: AccessPolicy) -> Iterator[list[int]]:
    """Within the block, websockets servers that start are guarded by ``policy``.

    Yields a list that gets one item per server started: empty after the block means the
    server was not started through websockets' ``serve`` and is NOT guarded.
    """
    import websockets.asyncio.server as ws_server

    original = ws_server.serve
    started: list[int] = []

    def serve(handler: Any, *args: Any, process_request: Any = None, **kwargs: Any) -> Any:
        if inspect.iscoroutinefunction(process_request):  # pragma: no cover - viser's is a function
            raise RuntimeError("impact-balance's GUI guard expects a synchronous process_request")
        from impact_balance.gui.uploads import MAX_MESSAGE_BYTES, MAX_QUEUED_MESSAGES

        started.append(1)
        kwargs["max_size"] = min(kwargs.get("max_size") or MAX_MESSAGE_BYTES, MAX_MESSAGE_BYTES)
        kwargs["max_queue"] = MAX_QUEUED_MESSAGES
        return original(handler, *args, process_request=_checker(policy, process_request), **kwargs)

    with _PATCH_LOCK:
        # A patch of the module's attribute, undone on leaving: `serve` is a class there, so
        # the wrapper function is set with setattr (an assignment would not type-check).
        setattr(ws_server, "serve", serve)  # noqa: B010
        try:
            yield started
        finally:
            setattr(ws_server, "serve", original)  # noqa: B010
