"""GUI uploads counted as they arrive: cut at the limit, never held whole.

viser buffers an upload's parts in memory until the last one arrives, so the size check of
:meth:`~impact_balance.gui.files.GuiFiles.upload` alone would run only once the whole upload is
held. So the server counts an upload while it arrives:

- the declared size must be at most :data:`MAX_UPLOAD_BYTES`, and the declared number of parts
  at most :data:`MAX_UPLOAD_PARTS` (viser's page sends 512 KiB parts), else the transfer is
  refused before one byte is kept;
- each part is counted on arrival; the transfer is dropped (its buffered parts freed) as soon as
  the bytes received pass the declared size or the limit;
- a client has at most :data:`MAX_TRANSFERS_PER_CLIENT` uploads in flight;
- all pages together hold at most :data:`MAX_PENDING_BYTES` in unfinished uploads: an upload's
  declared size is reserved when it starts, and refused if the reservations of the uploads in
  flight would pass the cap; an upload unfinished after :data:`UPLOAD_TIMEOUT_S` is dropped
  (its parts freed, its reservation returned), so idle pages cannot hold the cap forever;
- a WebSocket message is at most :data:`MAX_MESSAGE_BYTES` and at most :data:`MAX_QUEUED_MESSAGES`
  wait to be handled (:mod:`.guard` passes both to websockets), so a huge message or a flood of
  them is not buffered either.

A refused upload is shown in the GUI as one line, like any refused edit.

Why a patch: viser registers its own handlers for the two upload messages and offers no hook;
:func:`limit_uploads` puts a counting handler in front of each (the replaced handlers must be
found, or the GUI refuses to start, as for the Host/Origin check).
"""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Callable
from typing import Any

from impact_balance.gui.workspace import MAX_FILE_BYTES

__all__ = [
    "MAX_MESSAGE_BYTES",
    "MAX_PENDING_BYTES",
    "MAX_QUEUED_MESSAGES",
    "MAX_TRANSFERS_PER_CLIENT",
    "MAX_UPLOAD_BYTES",
    "MAX_UPLOAD_PARTS",
    "UPLOAD_TIMEOUT_S",
    "UploadLimit",
    "limit_uploads",
]

#: Largest upload, bytes (the workspace's file limit, 1 MiB).
MAX_UPLOAD_BYTES = MAX_FILE_BYTES
#: Most parts an upload may declare (the page sends 512 KiB parts: 2 for 1 MiB).
MAX_UPLOAD_PARTS = 64
#: Uploads one client may have in flight.
MAX_TRANSFERS_PER_CLIENT = 2
#: Bytes all unfinished uploads together may hold (declared sizes), across every page.
MAX_PENDING_BYTES = 4 * MAX_UPLOAD_BYTES
#: An upload still unfinished this long after it started is dropped, seconds.
UPLOAD_TIMEOUT_S = 60.0
#: Largest WebSocket message from a browser, bytes (a 512 KiB upload part and its envelope).
MAX_MESSAGE_BYTES = MAX_UPLOAD_BYTES + (64 << 10)
#: Messages read ahead of the handlers, per connection.
MAX_QUEUED_MESSAGES = 4


class UploadLimit:
    """The counting handlers installed by :func:`limit_uploads`.

    Attributes:
        refused: Number of uploads refused so far.
        peak_bytes: Largest number of bytes held for one upload.
        pending_cap: Bytes all unfinished uploads may reserve together.
    """

    def __init__(
        self,
        server: Any,
        on_refused: Callable[[str, str], None],
        limit: int = MAX_UPLOAD_BYTES,
        pending_cap: int = MAX_PENDING_BYTES,
    ):
        from viser import _messages

        gui = server.gui
        self._gui = gui
        self._iface = gui._websock_interface
        self._states: dict[str, Any] = gui._current_file_upload_states
        self._start_original = gui._handle_file_transfer_start
        self._part_original = gui._handle_file_transfer_part
        self._messages = _messages
        self._limit = int(limit)
        self._on_refused = on_refused
        self._received: dict[str, int] = {}
        self._owner: dict[str, Any] = {}
        self._reserved: dict[str, tuple[int, float]] = {}  # uuid -> (declared bytes, start)
        self.pending_cap = int(pending_cap)
        self.refused = 0
        self.peak_bytes = 0
        handlers = self._iface._incoming_handlers
        for cls, original, mine in (
            (_messages.FileTransferStartUpload, self._start_original, self._start),
            (_messages.FileTransferPart, self._part_original, self._part),
        ):
            if original not in handlers.get(cls, []):
                raise RuntimeError(f"viser's {cls.__name__} handler not found")
            self._iface.unregister_handler(cls, original)
            self._iface.register_handler(cls, mine)

    def _refuse(self, client_id: Any, filename: Any, reason: str) -> None:
        self.refused += 1
        name = str(filename).replace("\\", "/").rsplit("/", 1)[-1][:80] or "upload"
        # The GUI redraws under its lock: not in viser's event loop, which must keep serving.
        threading.Thread(target=self._on_refused, args=(name, reason), daemon=True).start()

    def _drop(self, uuid: str) -> None:
        self._received.pop(uuid, None)
        self._owner.pop(uuid, None)
        self._reserved.pop(uuid, None)

    def _forget_finished(self) -> None:
        now = time.monotonic()
        for uuid in list(self._received):
            if uuid not in self._states:
                self._drop(uuid)
            elif now - self._reserved.get(uuid, (0, now))[1] > UPLOAD_TIMEOUT_S:
                self._states.pop(uuid, None)  # frees the parts buffered so far
                self._drop(uuid)

    @property
    def pending_bytes(self) -> int:
        """Bytes reserved by the uploads in flight (their declared sizes)."""
        return sum(size for size, _ in self._reserved.values())

    def _start(self, client_id: Any, message: Any) -> None:
        self._forget_finished()
        size, parts = message.size_bytes, message.part_count
        kib = self._limit >> 10
        reason = None
        if not isinstance(size, int) or not isinstance(parts, int) or size < 0 or parts < 0:
            reason = "not a valid upload"
        elif size > self._limit:
            reason = (
                f"larger than {kib} KiB ({size:,} bytes declared): refused before any byte was kept"
            )
        elif parts > MAX_UPLOAD_PARTS or (size > 0 and parts == 0) or parts > max(1, size):
            reason = f"{parts} parts declared for {size:,} bytes: not a valid upload"
        elif sum(owner == client_id for owner in self._owner.values()) >= MAX_TRANSFERS_PER_CLIENT:
            reason = f"more than {MAX_TRANSFERS_PER_CLIENT} uploads at once"
        elif self.pending_bytes + size > self.pending_cap:
            reason = (
                f"the server already holds {self.pending_bytes:,} bytes of unfinished uploads "
                f"(at most {self.pending_cap:,} for all pages): try again in a minute"
            )
        if reason is not None:
            self._refuse(client_id, message.filename, reason)
            return
        self._received[message.transfer_uuid] = 0
        self._owner[message.transfer_uuid] = client_id
        self._reserved[message.transfer_uuid] = (size, time.monotonic())
        self._start_original(client_id, message)

    def _part(self, client_id: Any, message: Any) -> None:
        uuid = message.transfer_uuid
        state = self._states.get(uuid)
        if state is None or uuid not in self._received:
            return  # unknown, refused or finished: nothing is kept
        count = self._received[uuid] + len(message.content)
        if count > self._limit or count > state["total_bytes"]:
            self._states.pop(uuid, None)  # frees the parts buffered so far
            self._drop(uuid)
            self._refuse(
                client_id,
                state.get("filename"),
                f"larger than {self._limit >> 10} KiB or than it declared: cut at {count:,} bytes",
            )
            return
        self._received[uuid] = count
        self.peak_bytes = max(self.peak_bytes, count)
        self._part_original(client_id, message)
        if uuid not in self._states:  # complete
            self._drop(uuid)


def limit_uploads(
    server: Any,
    on_refused: Callable[[str, str], None],
    limit: int = MAX_UPLOAD_BYTES,
    pending_cap: int = MAX_PENDING_BYTES,
) -> UploadLimit:
    """Count the uploads of ``server`` as they arrive (see the module docstring).

    ``on_refused(filename, reason)`` is called (in a thread of its own) for each refused upload.

    Args:
        server: The :class:`viser.ViserServer`.
        on_refused: Called with (file name, reason) for each refused upload.
        limit: The largest upload, bytes.
        pending_cap: Bytes all unfinished uploads together may reserve.

    Returns:
        The installed counting handlers.

    Raises:
        ValueError: ``limit`` is not a byte count.
        RuntimeError: viser's upload handlers are not where this viser version should have them.
    """
    for value in (limit, pending_cap):
        if not math.isfinite(value) or value < 0:
            raise ValueError("limit and pending_cap must be byte counts")
    return UploadLimit(server, on_refused, int(limit), int(pending_cap))
