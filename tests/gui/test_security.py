"""The GUI's confinement: who may talk to the server, and which files it may touch.

- Host and Origin: a non-browser client (websockets, plain HTTP) forging the headers is refused
  with 403; the page's own origin is accepted.
- Files: every load, save, upload, ``extends`` and robot file goes through the workspace rule;
  traversal, absolute paths, ``~``, symbolic links and silent overwrites are refused; messages
  never quote a file's content.
- SIGTERM ends the server.
"""

from __future__ import annotations

import http.client
import os
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import yaml

pytest.importorskip("viser", reason="needs the gui extra (viser)")

from impact_balance import cli
from impact_balance.exceptions import WorkspaceError
from impact_balance.gui import DEFAULT_SCENARIO, GuiState, Session
from impact_balance.gui.files import GuiFiles, describe
from impact_balance.gui.guard import AccessPolicy, OriginError, guarded_start, normalize_origin
from impact_balance.gui.workspace import MAX_FILE_BYTES, Workspace
from impact_balance.robot.robot import example_robot_data_root
from impact_balance.scenario import load_scenario

SECRET = "hunter2-very-secret-token"


@pytest.fixture()
def ws(tmp_path) -> Path:
    """A workspace folder with one scenario, a subfolder, and a secret file next to it (outside)."""
    root = tmp_path / "ws"
    (root / "sub").mkdir(parents=True)
    GuiState.from_file(DEFAULT_SCENARIO).save(root / "a.yaml")
    (tmp_path / "outside.yaml").write_text(f"password: {SECRET}\n")
    return root


@pytest.fixture()
def session(ws) -> Session:
    return Session(DEFAULT_SCENARIO, workspace=ws)


# -- the workspace rule ------------------------------------------------------------------------
def test_workspace_names_resolve_inside(ws):
    w = Workspace(ws)
    assert w.resolve("a.yaml") == ws / "a.yaml"
    assert w.resolve("sub/new.yml", for_write=True) == ws / "sub" / "new.yml"
    assert (
        w.relative(ws / "sub" / "x.yaml") == "sub/x.yaml"
        and w.relative(ws.parent / "x.yaml") is None
    )


@pytest.mark.parametrize(
    ("name", "needle"),
    [
        ("../outside.yaml", "'..' is not allowed"),
        ("sub/../../outside.yaml", "'..' is not allowed"),
        ("sub\\..\\..\\outside.yaml", "'..' is not allowed"),
        ("/etc/passwd.yaml", "absolute paths are not allowed"),
        ("C:\\x.yaml", "absolute paths are not allowed"),
        ("~/x.yaml", "~ is not allowed"),
        ("~root/x.yaml", "~ is not allowed"),
        ("a.txt", "must end with .yaml or .yml"),
        ("a.yaml.txt", "must end with"),
        ("", "empty file name"),
        ("a\x00.yaml", "not a valid file name"),
        ("x" * 300 + ".yaml", "longer than 255 bytes"),
        ("missing.yaml", "no such file"),
        ("nofolder/a.yaml", "no such folder"),
    ],
)
def test_workspace_refuses_escapes_and_bad_names(ws, name, needle):
    w = Workspace(ws)
    with pytest.raises(WorkspaceError, match=needle) as info:
        w.resolve(name)
    assert info.value.field == "file" and len(str(info.value.value)) <= 80


def test_workspace_refuses_symlinks_anywhere(ws):
    w = Workspace(ws)
    (ws / "link.yaml").symlink_to(ws.parent / "outside.yaml")  # inside, pointing out
    (ws / "inner.yaml").symlink_to(ws / "a.yaml")  # inside, pointing inside: refused too
    (ws / "linked").symlink_to(ws.parent)  # a linked folder
    for name in ("link.yaml", "inner.yaml", "linked/outside.yaml"):
        with pytest.raises(WorkspaceError, match="symbolic links"):
            w.resolve(name)
        with pytest.raises(WorkspaceError, match="symbolic links"):
            w.read_text(name)
        with pytest.raises(WorkspaceError, match="symbolic links"):
            w.write_text(name, "x: 1\n", overwrite=True)
    with pytest.raises(WorkspaceError, match="symbolic links"):
        w.write_text("linked/new.yaml", "x: 1\n")
    assert (ws.parent / "outside.yaml").read_text() == f"password: {SECRET}\n"  # untouched
    assert not (ws.parent / "new.yaml").exists()


def test_workspace_write_never_overwrites_silently_nor_creates_folders(ws):
    w = Workspace(ws)
    before = (ws / "a.yaml").read_text()
    with pytest.raises(WorkspaceError, match="exists"):
        w.write_text("a.yaml", "x: 1\n")
    assert (ws / "a.yaml").read_text() == before
    assert w.write_text("a.yaml", "x: 1\n", overwrite=True) == ws / "a.yaml"
    assert (ws / "a.yaml").read_text() == "x: 1\n"
    with pytest.raises(WorkspaceError, match="no such folder"):
        w.write_text("new/b.yaml", "x: 1\n")
    assert not (ws / "new").exists()
    (ws / "dir.yaml").mkdir()
    with pytest.raises(WorkspaceError, match="not a regular file"):
        w.write_text("dir.yaml", "x: 1\n", overwrite=True)
    assert sorted(p.name for p in ws.iterdir()) == [
        "a.yaml",
        "dir.yaml",
        "sub",
    ]  # no temporary left


def test_workspace_read_limits(ws):
    w = Workspace(ws)
    (ws / "big.yaml").write_bytes(b"#" * (MAX_FILE_BYTES + 1))
    with pytest.raises(WorkspaceError, match="larger than"):
        w.read_text("big.yaml")
    (ws / "bin.yaml").write_bytes(b"\xff\xfe\x00")
    with pytest.raises(WorkspaceError, match="UTF-8"):
        w.read_text("bin.yaml")
    with pytest.raises(WorkspaceError, match="no such folder"):
        Workspace(ws / "missing")


# -- GUI loads, saves and uploads --------------------------------------------------------------
def test_load_save_round_trip_in_the_workspace(session, ws):
    assert session.set(("impact", "friction"), 0.3)
    edited = session.state
    assert session.save("sub/tuned.yaml") == ws / "sub" / "tuned.yaml"
    assert session.message == "saved sub/tuned.yaml"
    assert session.load("g1_two_feet") and session.analysis.stance.robot.name == "g1"
    assert session.load("sub/tuned.yaml") and session.state == edited.saved_as("tuned.yaml")
    assert session.state.scenario.name == "tuned"  # named after its file
    assert (
        load_scenario(ws / "sub" / "tuned.yaml").impact.friction == 0.3
    )  # an ordinary scenario file


def test_overwrite_needs_the_confirmation(session, ws):
    before = (ws / "a.yaml").read_text()
    assert session.set(("impact", "friction"), 0.3)
    assert session.save("a.yaml") is None and session.refused and "exists" in session.message
    assert (ws / "a.yaml").read_text() == before
    assert session.save("a.yaml", overwrite=True) == ws / "a.yaml"
    assert yaml.safe_load((ws / "a.yaml").read_text())["impact"]["friction"] == 0.3


@pytest.mark.parametrize(
    "name", ["../outside.yaml", str(Path("/tmp") / "x.yaml"), "~/x.yaml", "/etc/passwd"]
)
def test_session_load_and_save_refuse_outside_names(session, ws, name):
    state = session.state
    assert not session.load(name) and session.refused and session.state is state
    assert SECRET not in session.message
    assert session.save(name) is None and session.refused


def test_extends_is_confined(session, ws):
    outside = ws.parent / "base.yaml"
    outside.write_text((ws / "a.yaml").read_text())
    cases = {
        "up.yaml": "../base.yaml",
        "abs.yaml": str(outside),
        "home.yaml": "~/base.yaml",
        "secret.yaml": "../outside.yaml",
    }
    for name, target in cases.items():
        (ws / name).write_text(f"extends: {target}\nplane_height: 0.01\n")
        assert not session.load(name), name
        assert session.message.startswith(f"{name}: extends") and SECRET not in session.message
    (ws / "linked.yaml").symlink_to(outside)
    (ws / "via_link.yaml").write_text("extends: linked.yaml\n")
    assert not session.load("via_link.yaml") and "symbolic links" in session.message
    # Allowed: a bundled name, a workspace file (relative to the extending file's folder).
    (ws / "bundled.yaml").write_text("extends: palm_push_mu040\nplane_height: 0.01\n")
    assert session.load("bundled.yaml") and session.state.scenario.impact.friction == 0.4
    (ws / "sub" / "child.yaml").write_text("extends: ../a.yaml\nplane_height: 0.02\n")
    assert session.load("sub/child.yaml") and session.state.scenario.plane_height == 0.02


def test_upload_is_confined_and_bounded(session, ws):
    outside = (ws.parent / "outside.yaml").resolve()
    for target in ("../outside.yaml", str(outside)):
        assert not session.upload("up.yaml", f"extends: {target}\n".encode())
        assert session.message.startswith("up.yaml: extends") and SECRET not in session.message
    # extends from an upload: workspace files (from the workspace folder) and bundled names.
    assert session.upload("up.yaml", b"extends: a.yaml\nplane_height: 0.03\n")
    assert session.state.scenario.plane_height == 0.03 and session.state.source == "up.yaml"
    assert session.upload("../../evil/up.yaml", b"extends: kick_one_foot\n")
    assert session.state.source == "up.yaml"
    assert (
        not session.upload("big.yaml", b"#" * (MAX_FILE_BYTES + 1))
        and "larger than" in session.message
    )
    assert not session.upload("bin.yaml", b"\xff\xfe") and "UTF-8" in session.message


ALIAS_BOMB = "\n".join(
    [f"a0: &a0 [{', '.join(['lol'] * 9)}]"]
    + [f"a{i}: &a{i} [{', '.join([f'*a{i - 1}'] * 9)}]" for i in range(1, 9)]
    + ["contacts: *a8", ""]
).encode()  # 370 bytes that expand to 9^9 items


@pytest.mark.parametrize(
    "content",
    [ALIAS_BOMB, b"contacts: " + b"[" * 600 + b"]" * 600 + b"\n"],
    ids=["alias-bomb", "deep-nesting"],
)
def test_hostile_uploads_are_refused_without_hanging(session, content):
    import threading

    state = session.state
    done = threading.Event()

    def upload():
        session.upload("hostile.yaml", content)
        done.set()

    threading.Thread(target=upload, daemon=True).start()
    assert done.wait(60), "the upload hangs"  # a hang guard, not a speed test
    assert session.refused and session.state is state
    assert (
        session.message.startswith("hostile.yaml")
        and len(session.message) <= 300
        and "lol" not in session.message
    )


def test_robot_files_must_be_in_the_workspace(session, ws):
    erd = example_robot_data_root()
    urdf, srdf = erd / "talos_data/robots/talos_reduced.urdf", erd / "talos_data/srdf/talos.srdf"
    raw = yaml.safe_load((ws / "a.yaml").read_text())
    raw["robot"] = {"urdf": str(urdf), "srdf": str(srdf)}
    (ws / "out.yaml").write_text(yaml.safe_dump(raw))
    assert (
        not session.load("out.yaml")
        and "robot.urdf" in session.message
        and "outside" in session.message
    )
    raw["robot"] = {"urdf": "/etc/passwd"}
    (ws / "passwd.yaml").write_text(yaml.safe_dump(raw))
    assert not session.load("passwd.yaml") and "robot.urdf" in session.message
    assert (
        not session.upload("passwd.yaml", yaml.safe_dump(raw).encode())
        and "robot.urdf" in session.message
    )
    # Copied into the workspace, the same files load (relative to the scenario's folder).
    shutil.copy(urdf, ws / "sub" / "talos.urdf")
    shutil.copy(srdf, ws / "sub" / "talos.srdf")
    raw["robot"] = {"urdf": "talos.urdf", "srdf": "talos.srdf", "standing": "half_sitting"}
    (ws / "sub" / "files.yaml").write_text(yaml.safe_dump(raw))
    assert session.load("sub/files.yaml"), session.message
    assert session.summary.max_contact_velocity == pytest.approx(0.481, abs=5e-4)


def test_bundled_names_only_from_the_bundled_list(session):
    # A forged dropdown value is a name like any other: no path gets through.
    for name in ("/etc/passwd", "../scenarios/palm_push_two_feet", "palm_push_two_feet/"):
        assert not session.load(name) and "unknown scenario" in session.message
    assert session.load("kick_one_foot")


def test_messages_never_quote_file_content(session, ws):
    (ws / "secret.yaml").write_text(f"password: {SECRET}\ntoken: {'x' * 5000}\n")
    assert not session.load("secret.yaml")
    assert SECRET not in session.message and "xxxxx" not in session.message
    assert session.message.startswith(
        ("secret.yaml: password: unknown key", "secret.yaml: token: unknown key")
    )
    (ws / "broken.yaml").write_text(f"contacts: [\n  {SECRET}: [\n")
    assert not session.load("broken.yaml")
    assert SECRET not in session.message and "not valid YAML" in session.message
    raw = yaml.safe_load((ws / "a.yaml").read_text())
    raw["contacts"][0]["friction"] = "y" * 5000
    (ws / "long.yaml").write_text(yaml.safe_dump(raw))
    assert not session.load("long.yaml")
    assert "contacts[0].friction" in session.message and len(session.message) < 200
    assert len(describe(WorkspaceError("file", "z" * 5000, "refused"))) < 120


def test_upload_rename_does_not_leak_the_temporary_path(session):
    assert not session.upload("x.yaml", b"contacts: [\n")
    assert session.message.startswith("x.yaml: ") and "/tmp" not in session.message


# -- Host and Origin -----------------------------------------------------------------------------
def test_policy_for_a_localhost_bind():
    policy = AccessPolicy.for_bind("127.0.0.1")
    ok = {
        "bound_port": 8080,
        "host": ["127.0.0.1:8080"],
        "origin": ["http://127.0.0.1:8080"],
        "websocket": True,
    }
    assert policy.refusal(**ok) is None
    for origin in ("http://localhost:8080", "http://[::1]:8080"):
        assert policy.refusal(**{**ok, "origin": [origin]}) is None
    assert policy.refusal(**{**ok, "host": ["localhost:8080"]}) is None
    refused = [
        {"origin": ["http://evil.example:8080"]},  # a foreign page
        {"origin": ["http://localhost:3000"]},  # another local server's page
        {"origin": ["https://127.0.0.1:8080"]},  # not this server's scheme
        {"origin": ["null"]},
        {"origin": []},  # a WebSocket needs an Origin
        {"origin": ["http://127.0.0.1:8080", "http://127.0.0.1:8080"]},
        {"host": ["evil.example:8080"]},  # DNS rebinding
        {"host": ["127.0.0.1:8081"]},
        {"host": []},
        {"host": ["127.0.0.1:8080", "evil.example"]},
    ]
    for change in refused:
        assert policy.refusal(**{**ok, **change}) is not None, change
    # A plain HTTP request needs no Origin, but a foreign one is refused.
    assert policy.refusal(8080, ["127.0.0.1:8080"], [], websocket=False) is None
    assert (
        policy.refusal(8080, ["127.0.0.1:8080"], ["http://evil.example"], websocket=False)
        is not None
    )


def test_policy_allow_origin():
    policy = AccessPolicy.for_bind(
        "127.0.0.1", ["HTTPS://GUI.Example.org:443/", "http://10.0.0.5:9000"]
    )
    assert policy.origins == {"https://gui.example.org", "http://10.0.0.5:9000"}
    assert policy.refusal(8080, ["gui.example.org"], ["https://gui.example.org"], True) is None
    assert policy.refusal(8080, ["10.0.0.5:9000"], ["http://10.0.0.5:9000"], True) is None
    assert policy.refusal(8080, ["gui.example.org"], ["https://evil.example"], True) is not None
    for bad in ("gui.example.org", "ftp://x", "http://x/path", "http://x:99999", "http://user@x"):
        with pytest.raises(OriginError):
            normalize_origin(bad)


def test_the_guard_fails_closed(monkeypatch):
    from contextlib import contextmanager

    from impact_balance.gui import app as app_module

    with guarded_start(AccessPolicy.for_bind("127.0.0.1")) as started:
        pass
    assert started == []  # nothing started: the caller can tell

    @contextmanager
    def unused(policy):
        yield []

    monkeypatch.setattr(app_module, "guarded_start", unused)
    with pytest.raises(app_module.GuiError, match="Host/Origin check"):
        app_module.GuiApp(DEFAULT_SCENARIO, port=0)


@pytest.fixture(scope="module")
def app(tmp_path_factory):
    from impact_balance.gui.app import GuiApp

    app = GuiApp(DEFAULT_SCENARIO, port=0, workspace=tmp_path_factory.mktemp("ws"))
    yield app
    app.stop()


def _http(app, host: str, origin: str | None = None) -> tuple[int, bytes]:
    port = app.server.get_port()
    conn = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
    headers = {"Host": host} | ({"Origin": origin} if origin else {})
    conn.request("GET", "/", headers=headers)
    response = conn.getresponse()
    try:
        return response.status, response.read()
    finally:
        conn.close()


def _websocket(app, origin: str | None, host: str | None = None):
    """Open a WebSocket as viser's client does; the first message, or the refusal's status."""
    import viser
    from websockets.exceptions import InvalidStatus
    from websockets.sync.client import connect

    port = app.server.get_port()
    extra = {"origin": origin} if origin else {}
    headers = {"Host": host} if host else None
    try:
        with connect(
            f"ws://127.0.0.1:{port}",
            subprotocols=[f"viser-v{viser.__version__}"],
            max_size=None,
            open_timeout=10,
            additional_headers=headers,
            **extra,
        ) as ws:
            return ws.recv(timeout=20)
    except InvalidStatus as exc:
        return exc.response.status_code


def test_http_with_a_foreign_host_is_refused(app):
    port = app.server.get_port()
    for host in (f"127.0.0.1:{port}", f"localhost:{port}"):
        status, body = _http(app, host)
        assert status == 200 and b"<html" in body[:2000].lower()
    for host in (f"evil.example:{port}", "evil.example", f"127.0.0.1:{port + 1}"):
        status, body = _http(app, host)
        assert status == 403 and b"unknown Host" in body
    assert _http(app, f"127.0.0.1:{port}", "http://evil.example")[0] == 403


def test_websocket_with_a_foreign_origin_is_refused(app):
    port = app.server.get_port()
    assert _websocket(app, "http://evil.example") == 403
    assert (
        _websocket(app, f"http://evil.example:{port}", host=f"evil.example:{port}") == 403
    )  # DNS rebinding
    assert _websocket(app, f"http://localhost:{port + 1}") == 403  # another local page
    assert _websocket(app, None) == 403  # no Origin: not the GUI's page
    for origin in (f"http://127.0.0.1:{port}", f"http://localhost:{port}"):
        message = _websocket(app, origin)
        assert isinstance(message, bytes) and len(message) > 1000  # the scene and the panels


def test_warnings_are_shown_in_the_numbers_panel(app):
    real = app.session.analysis

    class WithWarnings:  # an analysis that carries warnings (see Analysis.warnings)
        warnings = ("impact.normal points away from the reference <b>", "second")

        def __getattr__(self, name):
            return getattr(real, name)

    try:
        app.session.analysis = WithWarnings()
        html = app._results_html()
        assert (
            'id="ib-warnings"' in html
            and "reference &lt;b&gt;" in html
            and "<li>second</li>" in html
        )
    finally:
        app.session.analysis = real
    if not getattr(real, "warnings", ()):
        assert 'id="ib-warnings"' not in app._results_html()


def test_gui_file_widgets_use_the_workspace(app):
    app.w_file.value = "../escape.yaml"
    app._save()
    assert app.session.refused and "'..' is not allowed" in app.session.message
    assert not (app.workspace.root.parent / "escape.yaml").exists()
    app.w_file.value = "mine.yaml"
    app._save()
    assert (app.workspace.root / "mine.yaml").is_file()
    app._save()
    assert app.session.refused and "exists" in app.session.message
    app.w_overwrite.value = True
    app._save()
    assert not app.session.refused and app.w_overwrite.value is False  # one confirmation, one save


# -- command line --------------------------------------------------------------------------------
def test_cli_refuses_bad_flags(capsys, tmp_path):
    assert cli.main(["gui", "--workspace", str(tmp_path / "missing"), "--port", "0"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "workspace" in err and "no such folder" in err
    assert cli.main(["gui", "--allow-origin", "evil.example", "--port", "0"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--allow-origin" in err


@pytest.mark.slow
def test_cli_prints_the_workspace_and_stops_on_sigterm(tmp_path):
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).parents[2] / "src")}
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "impact_balance",
            "gui",
            "--port",
            "0",
            "--workspace",
            str(tmp_path),
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        env=env,
    )
    try:
        lines = []
        deadline = time.time() + 240
        while time.time() < deadline and not any("workspace:" in line for line in lines):
            line = proc.stdout.readline()
            if not line:
                break
            lines.append(line)
        assert any(f"workspace: {tmp_path.resolve()}" in line for line in lines), (
            lines,
            proc.poll(),
        )
        proc.send_signal(signal.SIGTERM)
        assert proc.wait(timeout=10) == -signal.SIGTERM
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()


def test_state_of_a_file_in_the_workspace_names_it_relatively(ws):
    files = GuiFiles(ws)
    state = files.load("a.yaml")
    assert (
        Path(state.source) == ws / "a.yaml" and files.workspace.relative(state.source) == "a.yaml"
    )


# -- the GUI reads only what it checked --------------------------------------------------------
def _swap_after_check(monkeypatch, ws, name: str, swap) -> None:
    """Swap ``ws/name`` right after the workspace checked it, before it is opened (the race)."""
    original = Workspace._open_folder

    def open_folder(self, parts, field, shown):
        target = ws / name
        if target.exists() and not target.is_symlink() and target.is_file():
            target.unlink()
            swap(target)
        return original(self, parts, field, shown)

    monkeypatch.setattr(Workspace, "_open_folder", open_folder)


def test_a_link_swapped_in_after_the_check_is_refused(session, ws, monkeypatch):
    state = session.state
    (ws / "race.yaml").write_text((ws / "a.yaml").read_text())
    outside = ws.parent / "outside.yaml"
    _swap_after_check(monkeypatch, ws, "race.yaml", lambda p: p.symlink_to(outside))
    assert not session.load("race.yaml")
    assert "symbolic links" in session.message and SECRET not in session.message
    assert session.state is state
    # The same through an extends: the extended file is read through the checked folder too.
    monkeypatch.undo()
    (ws / "base.yaml").write_text((ws / "a.yaml").read_text())
    (ws / "child.yaml").write_text("extends: base.yaml\nplane_height: 0.01\n")
    _swap_after_check(monkeypatch, ws, "base.yaml", lambda p: p.symlink_to(outside))
    assert not session.load("child.yaml")
    assert "symbolic links" in session.message and SECRET not in session.message
    assert session.state is state


def test_an_inside_file_never_serves_content_read_elsewhere(session, ws):
    """The cache poisoning of issue 30: after a refused race, the inside file loads its own."""
    (ws / "race.yaml").write_text("extends: palm_push_two_feet\nimpact: {friction: 0.3}\n")
    assert session.load("race.yaml") and session.state.scenario.impact.friction == 0.3
    (ws / "race.yaml").write_text("extends: palm_push_two_feet\nimpact: {friction: 0.2}\n")
    assert session.load("race.yaml") and session.state.scenario.impact.friction == 0.2


def test_a_fifo_swapped_in_during_a_load_neither_blocks_nor_holds_the_lock(
    session, ws, monkeypatch
):
    import threading

    (ws / "race.yaml").write_text((ws / "a.yaml").read_text())
    _swap_after_check(monkeypatch, ws, "race.yaml", lambda p: os.mkfifo(p))
    done = threading.Event()

    def load():
        session.load("race.yaml")
        done.set()

    threading.Thread(target=load, daemon=True).start()
    assert done.wait(10), "the load waits on the FIFO"
    assert session.refused and "FIFO" in session.message
    assert session.lock.acquire(timeout=1)  # nobody holds it
    session.lock.release()


def test_uploads_are_parsed_outside_the_session_lock(session, monkeypatch):
    import threading

    parsed = threading.Event()
    original = session.files.upload

    def upload(filename, content):
        state = original(filename, content)
        parsed.set()
        return state

    monkeypatch.setattr(session.files, "upload", upload)
    holding, release = threading.Event(), threading.Event()

    def hold():  # another page redrawing, for as long as the test says
        with session.lock:
            holding.set()
            release.wait(30)

    threading.Thread(target=hold, daemon=True).start()
    assert holding.wait(5)
    finished = threading.Event()

    def do_upload():
        session.upload("up.yaml", b"extends: kick_one_foot\n")
        finished.set()

    threading.Thread(target=do_upload, daemon=True).start()
    try:
        assert parsed.wait(30), "the upload was not parsed while another page held the lock"
        assert not finished.is_set()  # its commit waits for the lock, as it must
    finally:
        release.set()
    assert finished.wait(30) and session.state.source == "up.yaml"


def test_an_upload_of_too_many_keys_is_refused_quickly(session):
    import time

    from impact_balance.scenario.reader import MAX_KEYS

    content = "".join(f"k{i}: 1\n" for i in range(60_000)).encode()
    assert len(content) <= MAX_FILE_BYTES
    state = session.state
    t0 = time.perf_counter()
    assert not session.upload("many.yaml", content)
    assert time.perf_counter() - t0 < 5.0
    assert f"more than {MAX_KEYS} keys" in session.message and session.state is state


def test_the_apps_upload_and_load_parse_before_taking_the_lock(app, monkeypatch):
    """The upload button's callback: the YAML is parsed while another page holds the lock."""
    import threading
    from types import SimpleNamespace

    session = app.session
    parsed = threading.Event()
    original = session.files.upload

    def upload(filename, content):
        state = original(filename, content)
        parsed.set()
        return state

    monkeypatch.setattr(session.files, "upload", upload)
    release = threading.Event()
    holding = threading.Event()

    def hold():
        with session.lock:
            holding.set()
            release.wait(30)

    threading.Thread(target=hold, daemon=True).start()
    assert holding.wait(5)
    event = SimpleNamespace(
        target=SimpleNamespace(
            value=SimpleNamespace(name="up.yaml", content=b"extends: kick_one_foot\n")
        )
    )
    done = threading.Event()
    threading.Thread(target=lambda: (app._on_upload(event), done.set()), daemon=True).start()
    try:
        assert parsed.wait(30), "the upload waited for the lock before it was parsed"
        assert not done.is_set()
    finally:
        release.set()
    assert done.wait(30) and session.state.source == "up.yaml"


def test_a_robot_file_swapped_for_a_link_after_the_load_is_never_read(session, ws, tmp_path):
    """Every analysis reads the robot files through the workspace (no link followed): a URDF
    replaced by a link to a file outside the workspace after the load is refused, not loaded."""
    erd = example_robot_data_root()
    urdf, srdf = erd / "talos_data/robots/talos_reduced.urdf", erd / "talos_data/srdf/talos.srdf"
    shutil.copy(urdf, ws / "sub" / "talos.urdf")
    shutil.copy(srdf, ws / "sub" / "talos.srdf")
    raw = yaml.safe_load((ws / "a.yaml").read_text())
    raw["robot"] = {"urdf": "talos.urdf", "srdf": "talos.srdf", "standing": "half_sitting"}
    (ws / "sub" / "robot.yaml").write_text(yaml.safe_dump(raw))
    assert session.load("sub/robot.yaml"), session.message
    # Outside the workspace, a URDF with other content (so that a read of it would show).
    outside = tmp_path / "outside.urdf"
    outside.write_text(urdf.read_text() + "\n<!-- outside -->\n")
    (ws / "sub" / "talos.urdf").unlink()
    (ws / "sub" / "talos.urdf").symlink_to(outside)
    assert not session.set(("com_velocity",), [0.01, 0.0])
    assert "link" in session.message and "robot file" in session.message
    assert str(outside) not in session.message
