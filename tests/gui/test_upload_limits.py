"""The cap on bytes held by unfinished uploads across every page (:mod:`.gui.uploads`).

viser's handlers are stood in for by recorders (no server, no socket): the counting handlers
decide which upload starts, the test checks what they reserve and refuse.
"""

from __future__ import annotations

from types import SimpleNamespace

import pytest

pytest.importorskip("viser", reason="needs the gui extra (viser)")

from viser import _messages

from impact_balance.gui import uploads
from impact_balance.gui.uploads import (
    MAX_PENDING_BYTES,
    MAX_UPLOAD_BYTES,
    UPLOAD_TIMEOUT_S,
    limit_uploads,
)


class FakeInterface:
    def __init__(self, start, part):
        self._incoming_handlers = {
            _messages.FileTransferStartUpload: [start],
            _messages.FileTransferPart: [part],
        }

    def unregister_handler(self, cls, handler):
        self._incoming_handlers[cls].remove(handler)

    def register_handler(self, cls, handler):
        self._incoming_handlers[cls].append(handler)


class FakeGui:
    """viser's upload bookkeeping: a state per started transfer, dropped when complete."""

    def __init__(self):
        self._current_file_upload_states: dict[str, dict] = {}
        self._websock_interface = FakeInterface(
            self._handle_file_transfer_start, self._handle_file_transfer_part
        )
        self.started: list[str] = []

    def _handle_file_transfer_start(self, client_id, message):
        self.started.append(message.transfer_uuid)
        self._current_file_upload_states[message.transfer_uuid] = {
            "total_bytes": message.size_bytes,
            "filename": message.filename,
            "received": 0,
        }

    def _handle_file_transfer_part(self, client_id, message):
        state = self._current_file_upload_states[message.transfer_uuid]
        state["received"] += len(message.content)
        if state["received"] >= state["total_bytes"]:
            del self._current_file_upload_states[message.transfer_uuid]


def _start(uuid, size=MAX_UPLOAD_BYTES):
    return SimpleNamespace(
        transfer_uuid=uuid, size_bytes=size, part_count=2, filename=f"{uuid}.yaml"
    )


@pytest.fixture()
def limit():
    refused: list[tuple[str, str]] = []
    gui = FakeGui()
    installed = limit_uploads(SimpleNamespace(gui=gui), lambda n, r: refused.append((n, r)))
    installed.refused_reasons = refused
    installed.fake = gui
    return installed


def test_unfinished_uploads_of_all_pages_share_one_cap(limit, monkeypatch):
    monkeypatch.setattr(uploads.threading, "Thread", _Inline)
    full = MAX_PENDING_BYTES // MAX_UPLOAD_BYTES
    for page in range(full):  # one unfinished upload per page, each 1 MiB declared
        limit._start(f"page{page}", _start(f"u{page}"))
    assert len(limit.fake.started) == full and limit.pending_bytes == MAX_PENDING_BYTES
    limit._start("another-page", _start("late"))
    assert limit.fake.started[-1] != "late" and limit.refused == 1
    name, reason = limit.refused_reasons[-1]
    assert name == "late.yaml" and "unfinished uploads" in reason
    # 100 pages x 2 unfinished uploads hold at most the cap, not 200 MiB.
    for page in range(100):
        for k in range(2):
            limit._start(f"p{page}", _start(f"p{page}-{k}"))
    assert limit.pending_bytes <= MAX_PENDING_BYTES
    # A finished upload returns its reservation.
    limit._part("page0", SimpleNamespace(transfer_uuid="u0", content=b"x" * MAX_UPLOAD_BYTES))
    assert limit.pending_bytes == MAX_PENDING_BYTES - MAX_UPLOAD_BYTES
    limit._start("another-page", _start("next"))
    assert limit.fake.started[-1] == "next"


def test_stale_uploads_are_dropped_and_free_the_cap(limit, monkeypatch):
    monkeypatch.setattr(uploads.threading, "Thread", _Inline)
    now = [1000.0]
    monkeypatch.setattr(uploads.time, "monotonic", lambda: now[0])
    for page in range(MAX_PENDING_BYTES // MAX_UPLOAD_BYTES):
        limit._start(f"page{page}", _start(f"u{page}"))
    limit._start("x", _start("refused"))
    assert limit.fake.started[-1] != "refused"
    now[0] += UPLOAD_TIMEOUT_S + 1
    limit._start("x", _start("after"))
    assert limit.fake.started[-1] == "after" and limit.pending_bytes == MAX_UPLOAD_BYTES
    assert list(limit.fake._current_file_upload_states) == ["after"]  # stale parts freed


def test_the_cap_is_a_byte_count():
    with pytest.raises(ValueError, match="byte counts"):
        limit_uploads(SimpleNamespace(gui=FakeGui()), lambda n, r: None, pending_cap=-1)


class _Inline:
    """threading.Thread stand-in: runs the refusal callback at once."""

    def __init__(self, target, args=(), daemon=None):
        self._target, self._args = target, args

    def start(self):
        self._target(*self._args)
