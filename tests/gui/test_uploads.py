"""GUI uploads are counted as they arrive and cut at the 1 MiB limit; the server's
memory stays bounded during a 200 MB upload.

The server runs in its own process (its resident memory is measured alone, sampled every 5 ms);
a WebSocket client speaks viser's protocol as the page does (msgpack messages, 512 KiB parts).
The figures are printed (``pytest -s``): resident memory before and at its peak.
"""

from __future__ import annotations

import os
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

pytest.importorskip("viser", reason="needs the gui extra (viser)")
pytest.importorskip("msgspec", reason="needs msgspec (installed with the gui extra's viser)")
pytest.importorskip("psutil", reason="needs psutil (installed with the sweep extra's Dask)")

import msgspec
import psutil

#: A server process and 200 MB through a WebSocket: seconds each.
pytestmark = pytest.mark.slow

SRC = str(Path(__file__).parents[2] / "src")
PART = 512 << 10  # what viser's page sends
#: Allowed growth of the server's resident memory while 200 MB arrive.
BOUND_MB = 20.0

SERVER = r"""
import sys
from impact_balance.gui.app import GuiApp
app = GuiApp(port=0, workspace=sys.argv[1])
handles = app.server.gui._gui_input_handle_from_uuid.items()
uuid = next(u for u, h in handles if "Upload" in type(h).__name__)
print("READY", app.server.get_port(), uuid, flush=True)
while True:
    line = sys.stdin.readline()
    if not line.strip():
        break
    state = (app.uploads.refused, app.uploads.peak_bytes, app.session.revision)
    print("STATE", *state, repr(app.session.message), flush=True)
app.stop()
"""


class Server:
    def __init__(self, workspace: Path):
        self.proc = subprocess.Popen(
            [sys.executable, "-c", SERVER, str(workspace)],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            text=True,
            env={**os.environ, "PYTHONPATH": SRC},
        )
        line = ""
        deadline = time.time() + 240
        while not line.startswith("READY") and time.time() < deadline:
            line = self.proc.stdout.readline()
            assert line or self.proc.poll() is None, "the GUI server did not start"
        _, port, self.uuid = line.split()
        self.port = int(port)
        self.process = psutil.Process(self.proc.pid)

    def state(self) -> tuple[int, int, str, int]:
        """Uploads refused, most bytes held for one, the GUI's message, its accepted edits."""
        self.proc.stdin.write("state\n")
        self.proc.stdin.flush()
        _, refused, peak, revision, message = self.proc.stdout.readline().rstrip("\n").split(" ", 4)
        return int(refused), int(peak), message, int(revision)

    def close(self) -> None:
        if self.proc.poll() is None:
            self.proc.stdin.write("\n")
            self.proc.stdin.flush()
            try:
                self.proc.wait(30)
            except subprocess.TimeoutExpired:
                self.proc.kill()


@pytest.fixture(scope="module")
def server(tmp_path_factory):
    s = Server(tmp_path_factory.mktemp("ws"))
    yield s
    s.close()


def _send(server: Server, messages, until=lambda: True) -> tuple[float, float]:
    """Send ``messages`` (viser message objects) on one page connection, stay connected until
    ``until()`` (at most a minute); the server's peak resident memory growth meanwhile and its
    resident memory before, MB."""
    import viser
    from viser import _messages as m
    from websockets.sync.client import connect

    with connect(
        f"ws://127.0.0.1:{server.port}",
        subprotocols=[f"viser-v{viser.__version__}"],
        origin=f"http://127.0.0.1:{server.port}",
        max_size=None,
        open_timeout=30,
    ) as ws:
        # viser counts a page as a client once it reports its camera (upload callbacks need one).
        camera = m.ViewerCameraMessage(
            (1.0, 0.0, 0.0, 0.0),
            (3.0, 0.0, 1.0),
            1.0,
            0.01,
            100.0,
            480,
            640,
            (0.0, 0.0, 1.0),
            (0.0, 0.0, 1.0),
        )
        ws.send(msgspec.msgpack.encode(camera.as_serializable_dict()))
        time.sleep(1.0)  # the scene and the panels arrive
        base = peak = server.process.memory_info().rss
        stop = threading.Event()

        def sample():
            nonlocal peak
            while not stop.is_set():
                peak = max(peak, server.process.memory_info().rss)
                time.sleep(0.005)

        sampler = threading.Thread(target=sample)
        sampler.start()
        try:
            for message in messages:
                ws.send(msgspec.msgpack.encode(message.as_serializable_dict()))
            time.sleep(1.0)  # the server handles what is queued
            deadline = time.time() + 60
            while not until() and time.time() < deadline:
                time.sleep(0.5)
        finally:
            stop.set()
            sampler.join()
    return (peak - base) / 2**20, base / 2**20


def _upload(server: Server, transfer: str, name: str, declared: int, parts: int, sizes):
    from viser import _messages as m

    yield m.FileTransferStartUpload(server.uuid, transfer, name, "text/yaml", parts, declared)
    for i, size in enumerate(sizes):
        yield m.FileTransferPart(server.uuid, transfer, i % max(parts, 1), b"#" * size)


def test_a_200_mb_upload_is_refused_before_a_byte_is_kept(server):
    total = 200 << 20
    grew, base = _send(
        server, _upload(server, "t1", "big.yaml", total, total // PART, [PART] * (total // PART))
    )
    _refused, peak, message, _ = server.state()
    print(
        f"\n200 MB declared: server RSS {base:.0f} MB, +{grew:.1f} MB at its peak;"
        f" load {open('/proc/loadavg').read().split()[0]}"
    )
    assert "larger than 1024 KiB" in message and "big.yaml" in message
    assert peak == 0 and grew < BOUND_MB


def test_a_lying_upload_is_cut_at_the_limit_as_it_arrives(server):
    """Declares 1 MiB in 2 parts, sends 200 MB: cut once it passes what it declared."""
    total = 200 << 20
    before = server.state()[0]
    grew, base = _send(
        server,
        _upload(server, "t2", "liar.yaml", 1 << 20, 2, [PART + 1] + [PART] * (total // PART - 1)),
    )
    refused, peak, message, _ = server.state()
    print(f"\n1 MiB declared, 200 MB sent: server RSS {base:.0f} MB, +{grew:.1f} MB at its peak")
    assert refused == before + 1 and "cut at" in message and peak <= 1 << 20
    assert grew < BOUND_MB


def test_a_40_gb_declaration_and_too_many_parts_are_refused(server):
    before = server.state()[0]
    grew, _ = _send(
        server,
        [
            *_upload(server, "t3", "huge.yaml", 40 << 30, 80_000, [PART] * 4),
            *_upload(server, "t4", "many.yaml", 1 << 20, 1 << 20, [1] * 1000),
        ],
    )
    refused, _, message, _ = server.state()
    assert refused == before + 2 and "not a valid upload" in message and grew < BOUND_MB


def test_an_upload_within_the_limit_is_loaded(server):
    from viser import _messages as m

    text = b"extends: kick_one_foot\nplane_height: 0.01\n"
    revision = server.state()[3]
    _send(
        server,
        [
            m.FileTransferStartUpload(server.uuid, "t5", "ok.yaml", "text/yaml", 1, len(text)),
            m.FileTransferPart(server.uuid, "t5", 0, text),
        ],
        until=lambda: server.state()[3] > revision,
    )
    _, _, message, after = server.state()
    assert after == revision + 1 and message == "None"  # accepted: the refusal shown before is gone
