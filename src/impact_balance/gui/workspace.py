"""The workspace: the one folder a server-side user interface may read and write.

The web GUI takes file names typed in a browser. Whoever can reach the page must not reach the
rest of the machine through them, so every file the GUI touches goes through one rule,
:meth:`Workspace.resolve`:

- a name is relative to the workspace folder: no absolute path, no ``~``, no ``..`` part;
- no symbolic link anywhere on the way (a link inside pointing out, or a linked folder);
- the name ends with an allowed suffix (``.yaml``/``.yml`` for scenarios);
- reading: an existing regular file no larger than :data:`MAX_FILE_BYTES`;
- writing: into an existing folder of the workspace (none is created), and an existing file is
  replaced only when the caller says so (``overwrite=True``).

:meth:`Workspace.read_bytes` (and :meth:`Workspace.read_text`) and :meth:`Workspace.write_text`
apply the rule and do the I/O through descriptors: the folders are opened one by one without
following links, the file relative to its folder's descriptor with ``O_NOFOLLOW`` and
``O_NONBLOCK``, checked with ``fstat`` and read within the size limit. A link or a FIFO swapped
in after the check is refused, never followed or waited on; the bytes returned are the bytes
checked, and the GUI parses those.
Refusals raise :class:`~impact_balance.exceptions.WorkspaceError` with the field, the name (cut
short) and the reason; no message quotes a file's content.
"""

from __future__ import annotations

import os
import secrets
import stat
from collections.abc import Callable
from pathlib import Path, PurePosixPath, PureWindowsPath

from impact_balance.exceptions import ScenarioError, WorkspaceError
from impact_balance.files import read_bounded

__all__ = ["MAX_FILE_BYTES", "SCENARIO_SUFFIXES", "Workspace"]

#: Largest file the workspace reads, bytes. Scenario files are a few kB; the limit stops a
#: huge file (or a device) from filling memory before the parser sees it.
MAX_FILE_BYTES = 1 << 20
#: Suffixes of scenario files.
SCENARIO_SUFFIXES = (".yaml", ".yml")
#: Longest name accepted, characters (a longer one is refused before touching the disk).
_MAX_NAME = 1024


class Workspace:
    """One folder, the only place a server-side UI reads and writes.

    Args:
        root: The folder (must exist). Its own path may go through links (``/tmp`` on some
            systems); it is resolved once, here. Inside it, links are refused.

    Attributes:
        root: The resolved folder.
    """

    def __init__(self, root: str | os.PathLike[str] = "."):
        try:
            resolved = Path(root).expanduser().resolve(strict=True)
        except (OSError, RuntimeError):
            raise WorkspaceError("workspace", str(root), "no such folder") from None
        if not resolved.is_dir():
            raise WorkspaceError("workspace", str(root), "not a folder")
        self.root = resolved

    def __repr__(self) -> str:
        return f"Workspace({str(self.root)!r})"

    # -- the rule ---------------------------------------------------------------------------
    def parts(
        self,
        name: str | os.PathLike[str],
        *,
        field: str = "file",
        suffixes: tuple[str, ...] = SCENARIO_SUFFIXES,
    ) -> tuple[str, ...]:
        """The components of a workspace-relative ``name``, checked lexically (no disk access).

        Raises:
            WorkspaceError: Empty, too long, absolute, ``~``, a ``..`` part, a part over 255
                bytes, or a name without one of the ``suffixes``.
        """
        text = os.fspath(name) if isinstance(name, os.PathLike) else name
        if not isinstance(text, str):
            raise WorkspaceError(field, repr(text), "must be a file name")
        if not text.strip():
            raise WorkspaceError(field, text, "empty file name")
        if len(text) > _MAX_NAME or "\x00" in text:
            raise WorkspaceError(field, text, "not a valid file name")
        if text.startswith("~"):
            raise WorkspaceError(
                field, text, f"~ is not allowed: give a name relative to the workspace {self.root}"
            )
        if (
            PurePosixPath(text).is_absolute()
            or PureWindowsPath(text).is_absolute()
            or PureWindowsPath(text).drive
        ):
            raise WorkspaceError(
                field,
                text,
                f"absolute paths are not allowed: give a name relative to the "
                f"workspace {self.root}",
            )
        parts = tuple(p for p in text.replace("\\", "/").split("/") if p not in ("", "."))
        if any(p == ".." for p in parts):
            raise WorkspaceError(
                field, text, "'..' is not allowed: the file must be inside the workspace"
            )
        if not parts:
            raise WorkspaceError(field, text, "empty file name")
        if any(len(p.encode()) > 255 for p in parts):
            raise WorkspaceError(field, text, "a part of the name is longer than 255 bytes")
        if not parts[-1].lower().endswith(tuple(suffixes)):
            raise WorkspaceError(field, text, f"the name must end with {' or '.join(suffixes)}")
        return parts

    def resolve(
        self,
        name: str | os.PathLike[str],
        *,
        for_write: bool = False,
        overwrite: bool = False,
        field: str = "file",
        suffixes: tuple[str, ...] = SCENARIO_SUFFIXES,
    ) -> Path:
        """The absolute path of the workspace file ``name``, or :class:`WorkspaceError`.

        Args:
            name: Relative to the workspace, e.g. ``"stance.yaml"`` or ``"runs/a.yaml"``.
            for_write: Check for writing: the folder must exist; the file may not (or see
                ``overwrite``). Without it, the file must be a regular file within the size limit.
            overwrite: Accept replacing an existing regular file (for writing).
            field: Field named in errors ("file", "extends", "robot.urdf"...).
            suffixes: Accepted name endings (lower case).

        Raises:
            WorkspaceError: The name breaks the rule (see :meth:`parts`), a link is on the way,
                a folder is missing, the file is missing (reading) or exists (writing, without
                ``overwrite``), is not a regular file, or is over :data:`MAX_FILE_BYTES`.
        """
        parts = self.parts(name, field=field, suffixes=suffixes)
        path = self.root
        for i, part in enumerate(parts):
            path = path / part
            last = i == len(parts) - 1
            try:
                st = os.lstat(path)
            except FileNotFoundError:
                if last and for_write:
                    return path
                what = "no such file" if last else "no such folder"
                raise WorkspaceError(
                    field, str(name), f"{what} in the workspace {self.root}"
                ) from None
            except OSError as exc:
                raise WorkspaceError(
                    field, str(name), f"cannot access ({exc.strerror or 'error'})"
                ) from None
            if stat.S_ISLNK(st.st_mode):
                raise WorkspaceError(
                    field, str(name), "symbolic links are not followed in the workspace"
                )
            if not last and not stat.S_ISDIR(st.st_mode):
                raise WorkspaceError(
                    field, str(name), f"{'/'.join(parts[: i + 1])} is not a folder"
                )
            if last:
                if not stat.S_ISREG(st.st_mode):
                    raise WorkspaceError(field, str(name), "not a regular file")
                if for_write and not overwrite:
                    raise WorkspaceError(
                        field, str(name), "the file exists (confirm to overwrite it)"
                    )
                if not for_write and st.st_size > MAX_FILE_BYTES:
                    raise WorkspaceError(
                        field, str(name), f"larger than {MAX_FILE_BYTES >> 10} KiB"
                    )
        # Belt and braces: no link was on the way, so the real path is the lexical one.
        if os.path.commonpath([os.path.realpath(path), str(self.root)]) != str(self.root):
            raise WorkspaceError(field, str(name), "outside the workspace")  # pragma: no cover
        return path

    def relative(self, path: str | os.PathLike[str]) -> str | None:
        """``path`` as a workspace name if it lies inside the workspace (lexically), else None."""
        absolute = os.path.normpath(os.path.join(self.root, os.fspath(path)))
        if os.path.commonpath([absolute, str(self.root)]) != str(self.root) or absolute == str(
            self.root
        ):
            return None
        return Path(os.path.relpath(absolute, self.root)).as_posix()

    def extends_resolver(
        self, bundled: Callable[[str], Path | None]
    ) -> Callable[[str, Path], Path]:
        """A resolver for ``extends:``: a bundled scenario name, or a workspace file.

        A relative name is taken from the folder of the file that extends, when that file is in
        the workspace, else (an uploaded file) from the workspace folder.

        Args:
            bundled: Returns the path of a bundled scenario by name, None if there is none.
        """

        def resolve(name: str, referrer: Path) -> Path:
            if "/" not in name and "\\" not in name and not name.endswith(SCENARIO_SUFFIXES):
                path = bundled(name)
                if path is not None:
                    return path
            here = self.relative(referrer)
            folder = os.path.dirname(here) if here is not None else ""
            if PurePosixPath(name).is_absolute() or name.startswith("~"):
                return self.resolve(name, field="extends")  # refused, with its reason
            inside = self.relative(os.path.join(folder, name))
            if inside is None:
                raise WorkspaceError("extends", name, f"outside the workspace {self.root}")
            return self.resolve(inside, field="extends")

        return resolve

    # -- I/O without following links --------------------------------------------------------
    def _open_folder(self, parts: tuple[str, ...], field: str, name: str) -> int:
        """A descriptor of the folder ``parts`` under the root, opened part by part, no link."""
        flags = os.O_RDONLY | getattr(os, "O_DIRECTORY", 0) | getattr(os, "O_NOFOLLOW", 0)
        fd = os.open(self.root, flags)
        try:
            for part in parts:
                try:
                    child = os.open(part, flags, dir_fd=fd)
                except OSError as exc:
                    raise WorkspaceError(
                        field, name, f"cannot open its folder ({exc.strerror or 'error'})"
                    ) from None
                os.close(fd)
                fd = child
        except BaseException:
            os.close(fd)
            raise
        return fd

    @staticmethod
    def _create(folder: int, name: str, field: str, shown: str) -> tuple[int, str]:
        """A new file ``name`` in the folder descriptor (never an existing one, nor a link)."""
        flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_NOFOLLOW", 0)
        try:
            return os.open(name, flags, 0o666, dir_fd=folder), name
        except OSError as exc:
            raise WorkspaceError(
                field, shown, f"cannot write ({exc.strerror or 'error'})"
            ) from None

    def read_bytes(
        self,
        name: str | os.PathLike[str],
        *,
        field: str = "file",
        suffixes: tuple[str, ...] = SCENARIO_SUFFIXES,
        limit: int = MAX_FILE_BYTES,
    ) -> bytes:
        """The bytes of the workspace file ``name`` (at most ``limit``: :data:`MAX_FILE_BYTES`).

        The name is checked by :meth:`resolve`, then read through descriptors only: the
        workspace folder and each folder on the way are opened without following links, and
        the file is opened relative to its folder's descriptor (``openat``) with ``O_NOFOLLOW``
        and ``O_NONBLOCK``, checked with ``fstat`` (a regular file) and read within the limit
        (:func:`impact_balance.files.read_bounded`). A link or a FIFO swapped in after the
        check is refused; what is returned is what was checked.

        Raises:
            WorkspaceError: Refused by :meth:`resolve`, a link, not a regular file, too large,
                or unreadable.
        """
        parts = self.resolve(name, field=field, suffixes=suffixes).relative_to(self.root).parts
        folder = self._open_folder(parts[:-1], field, str(name))
        try:
            return read_bounded(parts[-1], limit=limit, what=field, no_follow=True, dir_fd=folder)
        except ScenarioError as exc:
            reason = exc.reason
            if "larger than" in reason:
                reason = f"larger than {limit >> 10} KiB"
            elif "symbolic link" in reason:
                reason = "symbolic links are not followed in the workspace"
            raise WorkspaceError(field, str(name), reason) from None
        finally:
            os.close(folder)

    def read_text(
        self,
        name: str | os.PathLike[str],
        *,
        field: str = "file",
        suffixes: tuple[str, ...] = SCENARIO_SUFFIXES,
    ) -> str:
        """The UTF-8 text of the workspace file ``name``, read by :meth:`read_bytes`.

        Raises:
            WorkspaceError: Refused by :meth:`read_bytes`, or not UTF-8 text.
        """
        data = self.read_bytes(name, field=field, suffixes=suffixes)
        try:
            return data.decode("utf-8")
        except UnicodeDecodeError:
            raise WorkspaceError(field, str(name), "not a UTF-8 text file") from None

    def write_text(
        self,
        name: str | os.PathLike[str],
        text: str,
        *,
        overwrite: bool = False,
        field: str = "file",
        suffixes: tuple[str, ...] = SCENARIO_SUFFIXES,
    ) -> Path:
        """Write ``text`` to the workspace file ``name``; replace a file only with ``overwrite``.

        The text goes to a temporary file in the same folder, then takes the name at once: a
        reader never sees half a file, and an existing link is replaced, never followed.

        Returns:
            The file's path.

        Raises:
            WorkspaceError: Refused by :meth:`resolve` (for writing), the file appeared
                meanwhile (without ``overwrite``), or it cannot be written.
        """
        path = self.resolve(
            name, for_write=True, overwrite=overwrite, field=field, suffixes=suffixes
        )
        parts = path.relative_to(self.root).parts
        folder = self._open_folder(parts[:-1], field, str(name))
        try:
            tmp = self._create(
                folder, f".{parts[-1]}.{os.getpid()}-{secrets.token_hex(4)}.tmp", field, str(name)
            )
            try:
                with os.fdopen(tmp[0], "w", encoding="utf-8") as f:
                    f.write(text)
                if overwrite:
                    os.replace(tmp[1], parts[-1], src_dir_fd=folder, dst_dir_fd=folder)
                else:
                    # link() fails if the name exists: no race can make it replace a file.
                    os.link(
                        tmp[1],
                        parts[-1],
                        src_dir_fd=folder,
                        dst_dir_fd=folder,
                        follow_symlinks=False,
                    )
            except FileExistsError:
                raise WorkspaceError(
                    field, str(name), "the file exists (confirm to overwrite it)"
                ) from None
            except OSError as exc:
                raise WorkspaceError(
                    field, str(name), f"cannot write ({exc.strerror or 'error'})"
                ) from None
            finally:
                try:
                    os.unlink(tmp[1], dir_fd=folder)
                except OSError:
                    pass  # already renamed
        finally:
            os.close(folder)
        return path
