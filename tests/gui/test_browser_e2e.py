"""End to end: the GUI in a real headless Chromium (Debian's), driven by playwright.

The test starts the GUI server on a free port, opens the page, edits the impact friction
field and waits for the displayed maximum contact velocity to change; then types a bad value
and checks that it is refused with a message, cleared by the next good edit. In the Contacts
tab it switches a sole to its world normal and types a new normal. It saves screenshots
under pytest's tmp path.
Last, a page of another local site, in the same browser, tries to open the GUI's WebSocket:
the server refuses it (its Origin is not the GUI's page).

It needs ``/usr/bin/chromium`` (``apt-get install chromium``; ``.ci/run`` installs it) and
playwright (the ``[test]`` extra). No browser is downloaded: playwright launches that binary.
Without Chromium the test is skipped, unless ``IMPACT_BALANCE_E2E=1`` (CI), where a missing
browser is a failure.
"""

from __future__ import annotations

import http.server
import os
import shutil
import threading
from pathlib import Path

import pytest

CHROMIUM = Path(os.environ.get("IMPACT_BALANCE_CHROMIUM", "/usr/bin/chromium"))
REQUIRED = os.environ.get("IMPACT_BALANCE_E2E", "") not in ("", "0")
#: Flags for a closed network and no GPU: no background connections (they would be refused
#: and slow the start), software WebGL for the 3D view.
FLAGS = [
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
]
TIMEOUT_MS = 120_000

#: A browser start and page loads: seconds each.
pytestmark = [pytest.mark.e2e, pytest.mark.slow]

if not REQUIRED:  # CI (IMPACT_BALANCE_E2E=1): a missing browser, playwright or viser fails
    if not CHROMIUM.exists():
        pytest.skip(
            f"{CHROMIUM} not found (apt-get install chromium); "
            "set IMPACT_BALANCE_E2E=1 to make this a failure",
            allow_module_level=True,
        )
    pytest.importorskip("playwright", reason="needs the test extra (playwright)")
    pytest.importorskip("viser", reason="needs the gui extra (viser)")


@pytest.fixture(scope="module")
def app():
    from impact_balance.gui.app import GuiApp

    app = GuiApp("palm_push_two_feet", host="127.0.0.1", port=0)
    yield app
    app.stop()


@pytest.fixture(scope="module")
def page(app, tmp_path_factory):
    assert CHROMIUM.exists(), (
        f"IMPACT_BALANCE_E2E is set but {CHROMIUM} is missing: apt-get install chromium"
    )
    from playwright.sync_api import sync_playwright

    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=str(CHROMIUM), headless=True, args=FLAGS)
        try:
            page = browser.new_page(viewport={"width": 1500, "height": 950})
            page.set_default_timeout(TIMEOUT_MS)
            page.goto(app.url)
            page.locator("#ib-vmax-com").wait_for()
            yield page
        finally:
            browser.close()


def expect(locator):
    from playwright.sync_api import expect as _expect

    return _expect(locator)


def vmax_text(page) -> str:
    return page.locator("#ib-vmax-com").inner_text().strip()


def test_page_shows_the_maximum_contact_velocity(page, app):
    assert vmax_text(page) == "0.481 m/s"
    assert page.locator("#ib-vmax-zmp").inner_text().strip() == "0.007 m/s"
    assert page.locator("#ib-verdict").inner_text().strip() == "BALANCED"
    assert page.locator("svg").filter(has_text="CoM velocity area").count() >= 1  # the 2D view


def test_2d_view_fits_its_panel(page, app):
    """At 1500 x 950 px the 2D view is whole: inside the window and clear of the panel's
    scroll bar, its texts (maxima, axis labels) within the drawing."""
    svg = page.locator("svg").filter(has_text="CoM velocity area").first
    box = svg.bounding_box()
    width = page.viewport_size["width"]
    assert box["x"] >= 0 and box["x"] + box["width"] <= width - 12, box  # the scroll bar: ~10 px
    overflow = svg.evaluate("""(svg) => {
        const r = svg.getBoundingClientRect();
        return Array.from(svg.querySelectorAll('text')).map((t) => t.getBoundingClientRect())
            .filter((b) => b.left < r.left - 1 || b.right > r.right + 1).length;
    }""")
    assert overflow == 0
    assert svg.locator("text", has_text="CoM velocity y (m/s)").count() == 1


def test_editing_a_field_recomputes_and_redraws(page, app, tmp_path):
    before = vmax_text(page)
    page.screenshot(path=str(tmp_path / "gui_before.png"))
    field = page.get_by_label("impact friction")
    field.fill("0.4", force=True)  # force: no wait for animation frames (slow without a GPU)
    page.wait_for_function(
        "before => document.querySelector('#ib-vmax-com').textContent.trim() !== before",
        arg=before,
        polling=100,  # the default polls each animation frame: slow under software WebGL
    )
    after = vmax_text(page)
    assert after != before
    assert after == f"{app.session.summary.max_contact_velocity:.3f} m/s" == "0.373 m/s"
    assert app.session.state.scenario.impact.friction == pytest.approx(0.4)
    # The 2D view was redrawn with the new maximum.
    page.locator("svg").filter(has_text="post-impact set at the maximum 0.373 m/s").wait_for()
    close = page.locator(".mantine-Notification-closeButton")  # "software WebGL" notice: not ours
    if close.count():
        close.first.click(force=True)
    page.wait_for_timeout(1500)  # let the software renderer finish the 3D frame
    shot = tmp_path / "gui.png"
    page.screenshot(path=str(shot))
    assert shot.stat().st_size > 20_000
    out = os.environ.get("IMPACT_BALANCE_E2E_SCREENSHOT")
    if out:  # keep one screenshot (e.g. for docs/gui.png)
        shutil.copy(shot, out)


def test_a_bad_value_is_refused_and_the_page_lives_on(page, app):
    before = vmax_text(page)
    field = page.get_by_label("impact friction")
    field.fill("-1", force=True)
    message = page.locator("#ib-message")
    message.wait_for()
    assert "impact.friction" in message.inner_text() and "refused" in message.inner_text()
    assert vmax_text(page) == before
    # The field shows the good value again, and the next edit works.
    expect(field).to_have_value("0.4")
    field.fill("0.1", force=True)
    page.wait_for_function(
        "before => document.querySelector('#ib-vmax-com').textContent.trim() !== before",
        arg=before,
        polling=100,  # the default polls each animation frame: slow under software WebGL
    )
    assert vmax_text(page) == f"{app.session.summary.max_contact_velocity:.3f} m/s"
    assert page.locator("#ib-message").count() == 0


def _wait_until(condition, what: str, seconds: float = 60.0) -> None:
    """Poll the server's side until ``condition()`` holds (the page's edits arrive async)."""
    import time

    end = time.monotonic() + seconds
    while not condition():
        assert time.monotonic() < end, f"timed out waiting for {what}"
        time.sleep(0.1)


def _choose(page, label: str, option: str) -> None:
    """Pick ``option`` in the dropdown labelled ``label``."""
    page.get_by_label(label, exact=True).click(force=True)
    page.get_by_role("option", name=option, exact=True).click(force=True)


def _vector_inputs(page, label: str):
    """The inputs of the vector field labelled ``label`` (the label names the first)."""
    first = page.get_by_label(label, exact=True)
    return first.locator("xpath=ancestor::div[count(.//input) >= 3][1]").locator("input")


def test_a_contact_is_edited_by_its_world_normal(page, app, tmp_path):
    """In the Contacts tab: the right sole shows its world normal, switches to the normal
    form, and a typed normal tilts it (analysed, shown); the offset rpy field is disabled."""
    import math

    page.get_by_role("tab", name="Contacts").click(force=True)
    _choose(page, "contact", "1: right_sole_link")
    _wait_until(lambda: app._contact_index == 1, "contact 1 selected")
    normal = _vector_inputs(page, "world normal")
    expect(normal.nth(2)).to_have_value("1")  # the flat sole's world normal, shown
    _choose(page, "orientation", "world normal and angle")
    _wait_until(
        lambda: app.session.state.get(("contacts", 1, "normal")) is not None, "the normal form"
    )
    expect(_vector_inputs(page, "offset rpy (rad)").first).to_be_disabled()
    expect(normal.nth(1)).to_be_enabled()
    normal.nth(1).fill("0.2", force=True)
    normal.nth(1).press("Enter")
    _wait_until(
        lambda: app.session.state.get(("contacts", 1, "normal")) == [0.0, 0.2, 1.0],
        "the typed normal",
    )
    tilted = app.session.analysis.stance.contacts[1].normal
    assert tilted == pytest.approx([0.0, 0.2 / math.hypot(0.2, 1.0), 1.0 / math.hypot(0.2, 1.0)])
    expect(page.locator("#ib-vmax-com")).to_have_text(
        f"{app.session.summary.max_contact_velocity:.3f} m/s"
    )
    assert page.locator("#ib-message").count() == 0
    page.screenshot(path=str(tmp_path / "gui_world_normal.png"))


#: Opens a WebSocket to the GUI as viser's client does; resolves to "open" or "refused".
OPEN_WEBSOCKET = """([url, protocol]) => new Promise((resolve) => {
    const ws = new WebSocket(url, [protocol]);
    ws.onopen = () => { ws.close(); resolve("open"); };
    ws.onerror = () => resolve("refused");
})"""


class _OtherSite(http.server.BaseHTTPRequestHandler):
    """Another web site on this machine (any local server the user's browser visits)."""

    def do_GET(self):
        body = b"<html><body>another site</body></html>"
        self.send_response(200)
        self.send_header("Content-Type", "text/html")
        self.send_header("Content-Length", str(len(body)))
        self.end_headers()
        self.wfile.write(body)

    def log_message(self, *args):
        pass


def test_another_site_cannot_drive_the_gui(page, app):
    """A page of another origin, in the same browser, cannot open the GUI's WebSocket.

    The other site is local (another port): a public site's request to 127.0.0.1 may also be
    stopped by Chromium's local-network rules, which would hide whether the GUI refuses it.
    """
    import viser

    url, protocol = f"ws://127.0.0.1:{app.server.get_port()}", f"viser-v{viser.__version__}"
    site = http.server.ThreadingHTTPServer(("127.0.0.1", 0), _OtherSite)
    threading.Thread(target=site.serve_forever, daemon=True).start()
    other = page.context.browser.new_page()
    try:
        other.goto(f"http://localhost:{site.server_address[1]}/")
        assert other.evaluate(OPEN_WEBSOCKET, [url, protocol]) == "refused"
        # The GUI's own page may (the same script, the page's origin).
        assert page.evaluate(OPEN_WEBSOCKET, [url, protocol]) == "open"
    finally:
        other.close()
        site.shutdown()


def _changed_pixels(a: bytes, b: bytes) -> float:
    """Share of pixels that differ between two PNG screenshots (of the same size)."""
    import io

    import numpy as np
    from PIL import Image

    x = np.asarray(Image.open(io.BytesIO(a)).convert("RGB"), dtype=int)
    y = np.asarray(Image.open(io.BytesIO(b)).convert("RGB"), dtype=int)
    return float((np.abs(x - y).sum(axis=2) > 30).mean())


def test_romeo_is_drawn_from_its_collada_meshes(page, tmp_path):
    """Romeo's meshes are .dae files: the 3D view shows the robot (the pixels it covers change
    when its meshes are removed), and every one of its 44 visual meshes was read."""
    from impact_balance.gui.app import GuiApp

    romeo = GuiApp("romeo_two_feet", host="127.0.0.1", port=0)
    other = page.context.browser.new_page(
        viewport={"width": 1100, "height": 700}
    )  # smaller: software WebGL
    other.set_default_timeout(TIMEOUT_MS)
    try:
        assert len(romeo._meshes.meshes) == len(romeo._meshes.geometry_model.geometryObjects) == 44
        romeo._meshes.set_opacity(1.0)
        other.goto(romeo.url)
        other.locator("#ib-vmax-com").wait_for()
        box = other.locator("canvas").first.bounding_box()
        clip = {"x": box["x"], "y": box["y"], "width": box["width"], "height": box["height"]}
        other.wait_for_timeout(2000)  # the software renderer draws the meshes
        with_robot = other.screenshot(path=str(tmp_path / "romeo.png"), clip=clip)
        with romeo.session.lock:
            romeo._meshes.remove()
        other.wait_for_timeout(2000)
        without = other.screenshot(path=str(tmp_path / "romeo_without_meshes.png"), clip=clip)
        out = os.environ.get("IMPACT_BALANCE_E2E_ROMEO")
        if out:
            shutil.copy(tmp_path / "romeo.png", out)
        # Romeo covers a few percent of the view at the initial camera (1.7 m away).
        assert _changed_pixels(with_robot, without) > 0.01
    finally:
        other.close()
        romeo.stop()
