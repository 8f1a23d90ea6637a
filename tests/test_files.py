"""The one file-reading rule (:mod:`impact_balance.files`): one open, a regular file, a bound.

A FIFO, a device, a folder or a socket is refused at once (never waited on), a file over the
limit is refused, a link is refused where the caller asks it, and the bytes returned are the
file's whole content.
"""

from __future__ import annotations

import os
import socket
import threading
import time

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from impact_balance.exceptions import ScenarioError
from impact_balance.files import describe_mode, open_regular, read_bounded


def _quickly(call, seconds: float = 5.0):
    """Run ``call`` in a thread; fail (instead of hanging the suite) if it blocks."""
    out: dict[str, object] = {}

    def run():
        try:
            out["value"] = call()
        except BaseException as exc:
            out["error"] = exc

    thread = threading.Thread(target=run, daemon=True)
    t0 = time.monotonic()
    thread.start()
    thread.join(seconds)
    assert not thread.is_alive(), "the read blocked"
    return out, time.monotonic() - t0


@settings(max_examples=40, deadline=None)
@given(data=st.binary(max_size=4096), limit=st.integers(0, 4096))
def test_read_bounded_returns_the_bytes_or_refuses_beyond_the_limit(tmp_path_factory, data, limit):
    path = tmp_path_factory.mktemp("r") / "f.bin"
    path.write_bytes(data)
    if len(data) <= limit:
        assert read_bounded(path, limit=limit, what="scenario") == data
    else:
        with pytest.raises(ScenarioError, match="larger than the limit") as info:
            read_bounded(path, limit=limit, what="scenario")
        assert info.value.field == "scenario" and info.value.value == str(path)


def test_a_fifo_is_refused_without_waiting(tmp_path):
    fifo = tmp_path / "pipe.yaml"
    os.mkfifo(fifo)
    for call in (
        lambda: read_bounded(fifo, limit=100, what="--journal"),
        lambda: open_regular(fifo, limit=100, what="LOG"),
    ):
        out, seconds = _quickly(call)
        error = out.get("error")
        assert isinstance(error, ScenarioError) and seconds < 2.0
        assert "FIFO" in error.reason and "not a regular file" in error.reason
        assert str(fifo) in str(error)


@pytest.mark.parametrize(
    ("make", "kind"),
    [
        (lambda p: p.mkdir(), "a folder"),
        (lambda p: p.symlink_to("/dev/zero"), "a character device"),
    ],
    ids=["folder", "dev-zero"],
)
def test_folders_and_devices_are_refused(tmp_path, make, kind):
    path = tmp_path / "x.yaml"
    make(path)
    with pytest.raises(ScenarioError) as info:
        read_bounded(path, limit=1 << 20, what="scenario")
    assert kind in info.value.reason or "cannot read" in info.value.reason


def test_a_socket_is_refused(tmp_path):
    path = tmp_path / "s.yaml"
    sock = socket.socket(socket.AF_UNIX)
    try:
        sock.bind(str(path))
        with pytest.raises(ScenarioError):  # ENXIO at open, or a socket after fstat
            read_bounded(path, limit=100, what="scenario")
    finally:
        sock.close()


def test_links_are_refused_only_when_asked(tmp_path):
    (tmp_path / "real.yaml").write_text("a: 1\n")
    (tmp_path / "link.yaml").symlink_to(tmp_path / "real.yaml")
    assert read_bounded(tmp_path / "link.yaml", limit=100, what="scenario") == b"a: 1\n"
    with pytest.raises(ScenarioError, match="symbolic link"):
        read_bounded(tmp_path / "link.yaml", limit=100, what="scenario", no_follow=True)


def test_dir_fd_reads_relative_to_the_folder_descriptor(tmp_path):
    (tmp_path / "a.yaml").write_text("x: 2\n")
    folder = os.open(tmp_path, os.O_RDONLY)
    try:
        assert read_bounded("a.yaml", limit=10, what="file", dir_fd=folder) == b"x: 2\n"
        with pytest.raises(ScenarioError, match="no such file"):
            read_bounded("b.yaml", limit=10, what="file", dir_fd=folder)
    finally:
        os.close(folder)


def test_describe_mode_names_each_kind():
    import stat

    assert describe_mode(stat.S_IFIFO) == "a FIFO (named pipe)"
    assert describe_mode(stat.S_IFREG) == "a regular file"
    assert describe_mode(stat.S_IFSOCK) == "a socket"


def test_read_regular_raises_the_operating_systems_errors(tmp_path):
    """The rule behind read_bounded, for readers that word their own errors."""
    from impact_balance.files import FileTooLargeError, NotRegularFileError, read_regular

    good = tmp_path / "good.txt"
    good.write_bytes(b"x" * 10)
    assert read_regular(good, limit=10) == b"x" * 10
    with pytest.raises(FileTooLargeError) as big:
        read_regular(good, limit=9)
    assert (big.value.size, big.value.limit) == (10, 9) and isinstance(big.value, OSError)
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    with pytest.raises(NotRegularFileError) as pipe:
        read_regular(fifo, limit=10)  # never waits for a writer
    assert "FIFO" in pipe.value.kind
    with pytest.raises(NotRegularFileError):
        read_regular(tmp_path, limit=10)
    with pytest.raises(FileNotFoundError):
        read_regular(tmp_path / "missing", limit=10)
