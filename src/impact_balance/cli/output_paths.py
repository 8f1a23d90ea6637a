"""Where commands write: output folders and files, checked before anything is computed.

A figure folder, a log file or a sweep's results folder is checked when the command starts,
before it loads, simulates or computes: a name the operating system cannot take, a file where
a folder is expected (or the reverse), a wrong suffix (exit status 2: bad input), and a place
where nothing can be created (a read-only or virtual file system, no permission: exit status
1), so that a long run never ends in an error about where to put its result. The check creates
nothing that stays: it makes and removes one empty temporary folder in the nearest existing
folder, which is what writing there needs.

What fails later, while the command writes (a disk that fills up, a file swapped for
``/dev/full``), is reported by :func:`writing` naming the option and the file:
``--plots = 'DIR': cannot write DIR/x_areas.png: No space left on device`` (exit status 1).
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Iterator, Sequence
from pathlib import Path

from impact_balance.exceptions import OptionError, OutputError
from impact_balance.scenario.reader import MAX_NAME_CHARS, MAX_PATH_CHARS

__all__ = ["check_output_file", "check_output_folder", "writing"]


def _text(field: str, path: str | os.PathLike[str]) -> Path:
    """An output path's text checked (not empty, no NUL, not too long) as a Path.

    Raises:
        OptionError: The name is empty, holds a NUL or is too long (naming ``field``).
    """
    text = os.fspath(path)
    if not isinstance(text, str) or not text.strip():
        raise OptionError(field, text, "an empty name")
    if "\x00" in text:
        raise OptionError(field, text, "a file name cannot contain a NUL character")
    if len(text) > MAX_PATH_CHARS:
        raise OptionError(
            field, text, f"too long for a path ({len(text)} characters, at most {MAX_PATH_CHARS})"
        )
    longest = max((len(part) for part in text.split("/")), default=0)
    if longest > MAX_NAME_CHARS:
        raise OptionError(
            field,
            text,
            f"a file or folder name has at most {MAX_NAME_CHARS} characters (this one has "
            f"{longest})",
        )
    return Path(text).expanduser()


def _probe(field: str, shown: str, folder: Path) -> None:
    """Create and remove an empty folder in ``folder`` (what writing there needs)."""
    try:
        os.rmdir(tempfile.mkdtemp(prefix=".impact-balance-check-", dir=folder))
    except OSError as exc:
        reason = exc.strerror or type(exc).__name__
        raise OutputError(field, shown, f"cannot write in {folder}: {reason}") from None


def _existing_ancestor(field: str, shown: str, path: Path, is_target: bool = True) -> Path:
    """The nearest folder of ``path`` (itself included) that exists.

    Refuses a file on the way (``is_target``: ``path`` is the output folder itself, not the
    folder of an output file).
    """
    here = path
    while True:
        try:
            if here.is_dir():
                return here
            if here.exists() or here.is_symlink():
                what = "a file" if here.is_file() else "not a folder (a broken link or a device)"
                if here == path and is_target:
                    raise OptionError(field, shown, f"exists and is {what}: give a folder")
                raise OptionError(field, shown, f"cannot be created: {here} is {what}")
        except OSError as exc:  # a name too long for the file system, a loop of links...
            raise OutputError(
                field, shown, f"cannot be examined: {exc.strerror or type(exc).__name__}"
            ) from None
        parent = here.parent
        if parent == here:  # pragma: no cover - the root always exists
            return here
        here = parent


def check_output_folder(path: str | os.PathLike[str], field: str) -> Path:
    """Check that ``path`` is, or can be made, a folder this process writes in; return it.

    Nothing is created. Raises :class:`~impact_balance.exceptions.OptionError` (bad input,
    exit 2) for a bad name or a file in the way, :class:`~impact_balance.exceptions.OutputError`
    (exit 1) when the system refuses to write there.
    """
    shown = os.fspath(path)
    folder = _text(field, path)
    _probe(field, shown, _existing_ancestor(field, shown, folder))
    return folder


def check_output_file(
    path: str | os.PathLike[str], field: str, suffixes: Sequence[str] = ()
) -> Path:
    """Check that ``path`` names a file this process can write; return it.

    Its folder is checked as by :func:`check_output_folder`, its suffix against ``suffixes``
    if given. Nothing is created.
    """
    shown = os.fspath(path)
    file = _text(field, path)
    if suffixes and file.suffix.lower() not in suffixes:
        raise OptionError(
            field,
            shown,
            f"must end with {' or '.join(suffixes)}, not {file.suffix or 'no suffix'!r}",
        )
    try:
        is_dir = file.is_dir()
    except OSError as exc:
        raise OutputError(
            field, shown, f"cannot be examined: {exc.strerror or type(exc).__name__}"
        ) from None
    if is_dir:
        raise OptionError(field, shown, "is a folder: give a file name")
    parent = file.parent if str(file.parent) else Path(".")
    _probe(field, shown, _existing_ancestor(field, shown, parent, is_target=False))
    return file


@contextlib.contextmanager
def writing(field: str, path: str | os.PathLike[str] | None) -> Iterator[None]:
    """Within the block, a failure to write is an error naming the option and the file.

    An ``OSError`` (a full disk, a read-only file system, a file that became a device) becomes
    :class:`~impact_balance.exceptions.OutputError` (exit status 1) on ``field = path``, with the
    file that failed when the system names one and the system's reason. A closed pipe stays a
    ``BrokenPipeError``.

    Args:
        field: The option (``--plots``, ``--plot``, ``--log``...).
        path: Its value, the folder or file written.
    """
    try:
        yield
    except BrokenPipeError:
        raise
    except OSError as exc:
        reason = exc.strerror or (os.strerror(exc.errno) if exc.errno else "") or str(exc)
        reason = reason or type(exc).__name__
        named = os.fsdecode(exc.filename) if exc.filename is not None else None
        shown = None if path is None else os.fspath(path)
        where = f"cannot write {named}" if named and named != shown else "cannot write"
        raise OutputError(field, shown, f"{where}: {reason}") from None
