"""The one rule for reading an input file: open once, check the open file, read a bounded count.

Every file the package reads from a user (scenarios and their ``extends``, logs, journals,
manifests, sweep files, GUI loads) goes through :func:`read_bounded` (or, for a parser that
streams, :func:`open_regular`, which applies the same checks and hands over the open file):

- the file is opened once, without blocking (``O_NONBLOCK``: a FIFO never makes the reader
  wait) and, where the caller asks it, without following a link at its last component
  (``O_NOFOLLOW``); a folder descriptor (``dir_fd``) confines the name to that folder;
- the *open descriptor* is checked (``fstat``): anything but a regular file (a FIFO, a device,
  a folder, a socket) is refused, with the file named;
- at most ``limit`` bytes are read; a larger file is refused (its size is checked before the
  read, and the read stops one byte past the limit if the file grew meanwhile);
- the caller parses the bytes returned, never the file again, so what was checked is what is
  parsed (a cache keyed on a digest of these bytes is keyed on what was parsed).

Refusals raise :class:`~impact_balance.exceptions.ScenarioError` with the field (``what``),
the file and the reason.
"""

from __future__ import annotations

import errno
import os
import stat
from typing import BinaryIO

from impact_balance.exceptions import ScenarioError

__all__ = ["describe_mode", "open_regular", "read_bounded"]

_KINDS = (
    (stat.S_ISDIR, "a folder"),
    (stat.S_ISFIFO, "a FIFO (named pipe)"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISSOCK, "a socket"),
    (stat.S_ISLNK, "a symbolic link"),
)


def describe_mode(mode: int) -> str:
    """What kind of file ``mode`` (``st_mode``) is, in words ("a FIFO (named pipe)", ...)."""
    for test, words in _KINDS:
        if test(mode):
            return words
    return "a regular file" if stat.S_ISREG(mode) else "not a regular file"


def _open(path: str | os.PathLike[str], what: str, no_follow: bool, dir_fd: int | None) -> int:
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0)
    if no_follow:
        flags |= getattr(os, "O_NOFOLLOW", 0)
    try:
        return os.open(path, flags, dir_fd=dir_fd)
    except OSError as exc:
        if no_follow and exc.errno == errno.ELOOP:
            reason = "a symbolic link: links are not followed here"
        elif exc.errno == errno.ENOENT:
            reason = "no such file"
        else:
            reason = f"cannot read: {exc.strerror or exc.__class__.__name__}"
        raise ScenarioError(what, os.fspath(path), reason) from None


def open_regular(
    path: str | os.PathLike[str],
    *,
    limit: int,
    what: str,
    no_follow: bool = False,
    dir_fd: int | None = None,
) -> BinaryIO:
    """The regular file ``path`` opened once for reading, its size checked on the descriptor.

    For a reader that streams (a Parquet or CSV parser given the file object): the same rule
    as :func:`read_bounded` but nothing is read yet; the caller reads through this object
    only, and bounds what it reads.

    Args:
        path: The file (relative to ``dir_fd`` when given).
        limit: Largest size accepted, bytes.
        what: The field or option named in errors.
        no_follow: Refuse a symbolic link at the last component (``O_NOFOLLOW``).
        dir_fd: Open ``path`` relative to this folder descriptor (``openat``).

    Returns:
        A binary file object (close it; a ``with`` block does).

    Raises:
        ScenarioError: Missing, unreadable, a link (with ``no_follow``), not a regular file,
            or larger than ``limit``.
    """
    fd = _checked(path, limit, what, no_follow, dir_fd)
    return os.fdopen(fd, "rb")


def _checked(
    path: str | os.PathLike[str], limit: int, what: str, no_follow: bool, dir_fd: int | None
) -> int:
    """An open descriptor of the regular file ``path`` of at most ``limit`` bytes."""
    shown = os.fspath(path)
    fd = _open(path, what, no_follow, dir_fd)
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise ScenarioError(
                what, shown, f"{describe_mode(st.st_mode)}, not a regular file: refused"
            )
        if st.st_size > limit:
            raise ScenarioError(
                what, shown, f"{st.st_size:,} bytes: larger than the limit of {limit:,} bytes"
            )
    except BaseException:
        os.close(fd)
        raise
    return fd


def read_bounded(
    path: str | os.PathLike[str],
    *,
    limit: int,
    what: str,
    no_follow: bool = False,
    dir_fd: int | None = None,
) -> bytes:
    """The bytes of the regular file ``path``, at most ``limit`` of them (see the module).

    Args:
        path: The file (relative to ``dir_fd`` when given).
        limit: Largest size accepted, bytes.
        what: The field or option named in errors ("scenario", "--journal", "LOG"...).
        no_follow: Refuse a symbolic link at the last component (``O_NOFOLLOW``).
        dir_fd: Open ``path`` relative to this folder descriptor (``openat``).

    Returns:
        The file's bytes, as read through the descriptor that was checked.

    Raises:
        ScenarioError: Missing, unreadable, a link (with ``no_follow``), not a regular file
            (FIFO, device, folder, socket), or larger than ``limit``.
    """
    shown = os.fspath(path)
    fd = _checked(path, limit, what, no_follow, dir_fd)
    try:
        chunks: list[bytes] = []
        count = 0
        while count <= limit:
            try:
                chunk = os.read(fd, min(1 << 20, limit + 1 - count))
            except OSError as exc:
                reason = f"cannot read: {exc.strerror or exc.__class__.__name__}"
                raise ScenarioError(what, shown, reason) from None
            if not chunk:
                break
            chunks.append(chunk)
            count += len(chunk)
        if count > limit:
            raise ScenarioError(
                what, shown, f"grew past the limit of {limit:,} bytes while it was read"
            )
        return b"".join(chunks)
    finally:
        os.close(fd)
