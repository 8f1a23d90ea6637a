"""Dask scheduler addresses: checked before anything is created, connected to with a time limit.

``--scheduler`` takes ``tcp://HOST:PORT`` (Dask's own protocol; ``tls://HOST:PORT`` with TLS, or
``HOST:PORT`` for tcp). A malformed address (``tcp://``, ``not-an-address``, ``http://...``, a
port out of range) is bad input, refused when the command line is read (exit status 2). A
scheduler that does not answer (a closed port, an unknown host, no route) is a failure of the
machine, refused after at most :data:`CONNECT_TIMEOUT_S` seconds (exit status 1); in both cases
before the output folder is created. A port that accepts the connection but says nothing (a
scheduler greets its client at once) is refused within the same time, as is a scheduler that
does not answer the client's requests (:func:`bounded`).
"""

from __future__ import annotations

import ipaddress
import re
import socket
import threading
import time
from collections.abc import Callable
from typing import Any, TypeVar

from impact_balance.exceptions import EnvironmentFailure, OptionError

__all__ = ["CONNECT_TIMEOUT_S", "SCHEMES", "bounded", "check_scheduler_address", "connect"]

_T = TypeVar("_T")

#: Longest wait for a scheduler to answer, s.
CONNECT_TIMEOUT_S = 10.0
#: Protocols accepted (Dask's tcp, and tcp with TLS).
SCHEMES = ("tcp", "tls")
_HOSTNAME = re.compile(
    r"^(?=.{1,253}$)[A-Za-z0-9_](?:[A-Za-z0-9_-]{0,61}[A-Za-z0-9_])?"
    r"(?:\.[A-Za-z0-9_](?:[A-Za-z0-9_-]{0,61}[A-Za-z0-9_])?)*\.?$"
)
_FORM = "expected tcp://HOST:PORT, e.g. tcp://10.0.0.5:8786"


def _split(address: str) -> tuple[str, str, int]:
    """(scheme, host, port) of a checked address (see :func:`check_scheduler_address`)."""
    text = address.strip()
    if not text:
        raise OptionError("--scheduler", address, f"an empty address: {_FORM}")
    scheme = "tcp"
    if "://" in text:
        scheme, text = text.split("://", 1)
        scheme = scheme.lower()
        if scheme in ("http", "https", "ws", "wss"):
            raise OptionError(
                "--scheduler",
                address,
                f"{scheme}:// is not Dask's protocol (the dashboard is http; the "
                f"scheduler listens on tcp://HOST:8786): {_FORM}",
            )
        if scheme not in SCHEMES:
            raise OptionError(
                "--scheduler", address, f"unknown protocol {scheme!r} (tcp or tls): {_FORM}"
            )
    if not text:
        raise OptionError("--scheduler", address, f"no host: {_FORM}")
    if "/" in text or "@" in text or "?" in text or "#" in text:
        raise OptionError("--scheduler", address, f"an address has no path, user or query: {_FORM}")
    if text.startswith("["):
        end = text.find("]")
        host, rest = (text[1:end], text[end + 1 :]) if end > 0 else ("", "")
        try:
            ipaddress.IPv6Address(host)
        except ValueError:
            raise OptionError(
                "--scheduler", address, f"not an IPv6 address in brackets: {_FORM}"
            ) from None
    else:
        host, sep, port_text = text.rpartition(":")
        if not sep:
            raise OptionError("--scheduler", address, f"no port: {_FORM}")
        rest = ":" + port_text
        if not _HOSTNAME.match(host):
            raise OptionError("--scheduler", address, f"not a host name or address: {_FORM}")
    if not (rest.startswith(":") and rest[1:].isdigit() and 1 <= int(rest[1:]) <= 65535):
        raise OptionError("--scheduler", address, f"no port, or a port outside 1..65535: {_FORM}")
    return scheme, host, int(rest[1:])


def check_scheduler_address(address: str) -> str:
    """The address in Dask's form (``tcp://HOST:PORT``); :class:`OptionError` if malformed."""
    scheme, host, port = _split(address)
    shown = f"[{host}]" if ":" in host else host
    return f"{scheme}://{shown}:{port}"


def bounded(call: Callable[[], _T], timeout: float, field: str, value: Any, what: str) -> _T:
    """``call()``, waited for at most ``timeout`` seconds (in a daemon thread).

    Raises:
        EnvironmentFailure: ``call`` did not return in time (``field = value: what ...``).
        BaseException: What ``call`` raised.
    """
    result: list[Any] = []

    def target() -> None:
        try:
            result.append((True, call()))
        except BaseException as exc:
            result.append((False, exc))

    worker = threading.Thread(target=target, name="impact-balance-bounded", daemon=True)
    worker.start()
    worker.join(timeout)
    if not result:
        raise EnvironmentFailure(field, value, f"{what}: no answer within {timeout:g} s")
    ok, value_or_error = result[0]
    if not ok:
        raise value_or_error
    returned: _T = value_or_error
    return returned


def _greeting(sock: socket.socket, canonical: str, deadline: float, timeout: float) -> None:
    """Wait for a Dask scheduler's first bytes (it writes its handshake at once over tcp)."""
    sock.settimeout(max(0.01, deadline - time.monotonic()))
    try:
        data = sock.recv(1)
    except TimeoutError:
        raise EnvironmentFailure(
            "--scheduler",
            canonical,
            f"accepts connections but says nothing within {timeout:g} s (not a Dask scheduler?)",
        ) from None
    except OSError as exc:
        raise EnvironmentFailure(
            "--scheduler", canonical, f"cannot connect: {exc.strerror or type(exc).__name__}"
        ) from None
    if not data:
        raise EnvironmentFailure(
            "--scheduler", canonical, "closed the connection at once (not a Dask scheduler?)"
        )


def connect(address: str, timeout: float = CONNECT_TIMEOUT_S) -> Any:
    """A :class:`distributed.Client` of the scheduler at ``address``.

    Args:
        address: The scheduler's address (``tcp://host:8786``).
        timeout: How long to wait for it, s.

    Returns:
        The client.

    Raises:
        EnvironmentFailure: (exit status 1) naming ``--scheduler`` and what the network said.
    """
    scheme, host, port = _split(address)
    canonical = check_scheduler_address(address)
    deadline = time.monotonic() + timeout
    try:  # a closed port answers at once; Dask itself would retry for its whole timeout
        with socket.create_connection((host, port), timeout=timeout) as sock:
            if scheme == "tcp":
                _greeting(sock, canonical, deadline, timeout)
    except EnvironmentFailure:
        raise
    except socket.gaierror as exc:
        raise EnvironmentFailure(
            "--scheduler", canonical, f"unknown host ({exc.strerror or exc})"
        ) from None
    except TimeoutError:
        raise EnvironmentFailure(
            "--scheduler", canonical, f"no answer within {timeout:g} s"
        ) from None
    except OSError as exc:
        raise EnvironmentFailure(
            "--scheduler", canonical, f"cannot connect: {exc.strerror or type(exc).__name__}"
        ) from None
    from distributed import Client

    left = max(1.0, deadline - time.monotonic())
    try:
        return bounded(
            lambda: Client(canonical, timeout=left),  # type: ignore[no-untyped-call]
            left,
            "--scheduler",
            canonical,
            "the scheduler did not take the client",
        )
    except EnvironmentFailure:
        raise
    except Exception as exc:
        text = " ".join(str(exc).split())[:160] or type(exc).__name__
        raise EnvironmentFailure(
            "--scheduler", canonical, f"not a Dask scheduler, or it refused the client ({text})"
        ) from None
