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

__all__ = [
    "FileTooLargeError",
    "NotRegularFileError",
    "describe_mode",
    "open_regular",
    "read_bounded",
    "read_regular",
]

_KINDS = (
    (stat.S_ISDIR, "a folder"),
    (stat.S_ISFIFO, "a FIFO (named pipe)"),
    (stat.S_ISCHR, "a character device"),
    (stat.S_ISBLK, "a block device"),
    (stat.S_ISSOCK, "a socket"),
    (stat.S_ISLNK, "a symbolic link"),
)


class NotRegularFileError(OSError):
    """The path names something other than a regular file (a FIFO, a device, a folder...).

    Attributes:
        kind: What it is, in words (:func:`describe_mode`).
    """

    def __init__(self, path: str, kind: str) -> None:
        super().__init__(errno.EINVAL, f"{kind}, not a regular file", path)
        self.kind = kind


class FileTooLargeError(OSError):
    """The file is larger than the reader's limit.

    Attributes:
        size: Its size when it was checked, or None when it grew past the limit while read.
        limit: The limit, bytes.
    """

    def __init__(self, path: str, size: int | None, limit: int) -> None:
        super().__init__(errno.EFBIG, f"larger than {limit} bytes", path)
        self.size = size
        self.limit = limit


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
        raise ScenarioError(what, os.fspath(path), _open_reason(exc, no_follow)) from None


def _open_reason(exc: OSError, no_follow: bool) -> str:
    """Why a file could not be opened or read, in words."""
    if no_follow and exc.errno == errno.ELOOP:
        return "a symbolic link: links are not followed here"
    if exc.errno == errno.ENOENT:
        return "no such file"
    return f"cannot read: {exc.strerror or exc.__class__.__name__}"


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
    try:
        return read_regular(path, limit=limit, no_follow=no_follow, dir_fd=dir_fd)
    except NotRegularFileError as exc:
        raise ScenarioError(what, shown, f"{exc.kind}, not a regular file: refused") from None
    except FileTooLargeError as exc:
        if exc.size is None:
            reason = f"grew past the limit of {limit:,} bytes while it was read"
        else:
            reason = f"{exc.size:,} bytes: larger than the limit of {limit:,} bytes"
        raise ScenarioError(what, shown, reason) from None
    except OSError as exc:
        raise ScenarioError(what, shown, _open_reason(exc, no_follow)) from None


def read_regular(
    path: str | os.PathLike[str],
    *,
    limit: int,
    no_follow: bool = False,
    dir_fd: int | None = None,
) -> bytes:
    """The rule of :func:`read_bounded`, raising the operating system's errors.

    For a reader that words its own errors (a journal, a sweep folder, a robot file): the
    same open, check and bounded read, with an :class:`OSError` to translate.

    Args:
        path: The file (relative to ``dir_fd`` when given).
        limit: Largest size accepted, bytes.
        no_follow: Refuse a symbolic link at the last component (``O_NOFOLLOW``: ``ELOOP``).
        dir_fd: Open ``path`` relative to this folder descriptor (``openat``).

    Returns:
        The file's bytes, as read through the descriptor that was checked.

    Raises:
        NotRegularFileError: A FIFO, a device, a folder or a socket (never waited on).
        FileTooLargeError: Larger than ``limit`` (checked before the read, and while reading).
        OSError: The file cannot be opened or read (``FileNotFoundError``...).
    """
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0)
    if no_follow:
        flags |= getattr(os, "O_NOFOLLOW", 0)
    shown = os.fspath(path)
    fd = os.open(path, flags, dir_fd=dir_fd)
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise NotRegularFileError(shown, describe_mode(st.st_mode))
        if st.st_size > limit:
            raise FileTooLargeError(shown, st.st_size, limit)
        chunks: list[bytes] = []
        count = 0
        while count <= limit:
            chunk = os.read(fd, min(1 << 20, limit + 1 - count))
            if not chunk:
                break
            chunks.append(chunk)
            count += len(chunk)
        if count > limit:
            raise FileTooLargeError(shown, None, limit)
        return b"".join(chunks)
    finally:
        os.close(fd)
