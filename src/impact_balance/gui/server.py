"""Where the GUI may listen: the address check made before viser starts, and its error."""

from __future__ import annotations

from impact_balance.exceptions import ImpactBalanceError

__all__ = ["GuiError", "check_listen_address"]


class GuiError(ImpactBalanceError):
    """The GUI server cannot start (a host it cannot listen on, a bad port).

    Attributes:
        host: Where it was asked to listen.
        port: The port asked for.
        reason: Why it cannot.
    """

    def __init__(self, host: str, port: int, reason: str):
        self.host, self.port, self.reason = host, port, reason
        super().__init__(f"cannot serve on {host}:{port}: {reason}")


def check_listen_address(host: str, port: int) -> None:
    """Check that ``host`` is an address of this machine and ``port`` a valid port.

    viser retries the next port on any bind error, so an address that can never be bound
    would make it loop for ever: check it first.

    Raises:
        GuiError: The port is not in 0..65535, the host is unknown, or it is not an address
            of this machine.
    """
    import socket

    if not 0 <= int(port) <= 65535:
        raise GuiError(host, port, "the port must be in 0..65535")
    try:
        infos = socket.getaddrinfo(host, None, type=socket.SOCK_STREAM)
    except (socket.gaierror, UnicodeError) as exc:
        raise GuiError(
            host, port, f"unknown host ({getattr(exc, 'strerror', None) or exc})"
        ) from None
    family, _, _, _, address = infos[0]
    with socket.socket(family, socket.SOCK_STREAM) as sock:
        try:
            sock.bind((address[0], 0))
        except OSError as exc:
            raise GuiError(
                host, port, f"not an address of this machine ({exc.strerror or exc})"
            ) from None
