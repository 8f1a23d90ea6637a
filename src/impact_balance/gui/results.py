"""The numbers panel: the session's verdict and figures as HTML.

Every text from the scenario or a message is escaped, and lengths are capped (a warning at 300
characters, ten warnings, a message at 400 characters); no file content is shown. The elements
a test or a user script reads carry ids (``ib-verdict``, ``ib-vmax-com``, ``ib-vmax-zmp``,
``ib-vmax-reach`` (after the "CoM reach" button), ``ib-vmax-held`` (after the "Held
stance" button), ``ib-reference``, ``ib-governor-*``,
``ib-update-ms``, ``ib-warnings``, ``ib-message``).
"""

from __future__ import annotations

import html

from impact_balance.gui.session import Governed, Session, Summary, format_speed

__all__ = ["results_html"]

#: A table cell aligned right, for the numbers.
_RIGHT = 'style="text-align:right"'
#: A table row spanning both columns, in grey: the heading of the rows below it.
_HEADING = '<tr><td colspan="2" style="color:#555">{}</td></tr>'


def _speed_rows(s: Summary) -> list[str]:
    """The maximum contact velocities (m/s) and the reference approach speed, table rows."""
    rows = [
        _HEADING.format("maximum contact velocity"),
        f'<tr><td>&nbsp;&nbsp;by the CoM criterion</td><td {_RIGHT}><b id="ib-vmax-com">'
        f"{html.escape(format_speed(s.max_contact_velocity))}</b></td></tr>",
        f'<tr><td>&nbsp;&nbsp;by the ZMP criterion</td><td {_RIGHT}><b id="ib-vmax-zmp">'
        f"{html.escape(format_speed(s.zmp_max_contact_velocity))}</b></td></tr>",
    ]
    if s.reference_speed is not None:
        verdict = "falls" if s.falls_at_reference else "holds"
        rows.append(
            f'<tr><td>reference approach speed</td><td {_RIGHT} id="ib-reference">'
            f"{s.reference_speed:.3f} m/s ({verdict})</td></tr>"
        )
    return rows


def _governor_rows(g: Governed) -> list[str]:
    """The governor's answer: the speed allowed, the capped reference (m/s), its tick (µs)."""
    rows = [
        _HEADING.format("governor, live (from this posture and CoM velocity)"),
        f'<tr><td>&nbsp;&nbsp;speed allowed</td><td {_RIGHT}><b id="ib-governor-cap">'
        f"{html.escape(format_speed(g.ceiling))}</b></td></tr>",
    ]
    if g.reference is not None:
        rows.append(
            f'<tr><td>&nbsp;&nbsp;reference, capped</td><td {_RIGHT} id="ib-governor-capped">'
            f"{g.reference:.3f} &rarr; {g.capped:.3f} m/s</td></tr>"
        )
    rows.append(
        f'<tr><td>&nbsp;&nbsp;governor tick</td><td {_RIGHT} id="ib-governor-us">'
        f"{g.tick_us:.0f} &micro;s</td></tr>"
    )
    return rows


def _warnings_list(warnings: tuple[str, ...]) -> str:
    """The first ten warnings as a list (each cut at 300 characters), and how many more."""
    items = "".join(
        f"<li>{html.escape(w if len(w) <= 300 else w[:297] + '...')}</li>" for w in warnings[:10]
    )
    more = f"<li>... {len(warnings) - 10} more</li>" if len(warnings) > 10 else ""
    return (
        '<ul id="ib-warnings" class="ib-warning" style="color:#b36b00;font-size:0.85em;'
        f'margin:4px 0;padding-left:1.2em;overflow-wrap:anywhere">{items}{more}</ul>'
    )


def _message(message: str, refused: bool) -> str:
    """The last edit's message (red and "refused: " when refused), cut at 400 characters."""
    color = "#d62728" if refused else "#555"
    prefix = "refused: " if refused else ""
    text = message if len(message) <= 400 else message[:400] + "..."
    return (
        f'<div id="ib-message" style="color:{color};font-size:0.85em;margin-top:4px;'
        f'overflow-wrap:anywhere">{html.escape(prefix + text)}</div>'
    )


def results_html(session: Session, last_update_ms: float) -> str:
    """The results panel for ``session``'s summary, governor answer and last message.

    Args:
        session: The session shown.
        last_update_ms: The last update's time (edit, analysis and redraw), ms.

    Returns:
        An HTML ``<div>``.
    """
    s = session.summary
    ok = s.headline == "balanced"
    color = "#2ca02c" if ok else "#d62728"
    rows = [
        f'<div id="ib-verdict" style="font-weight:bold;font-size:1.15em;color:{color}">'
        f"{html.escape(s.headline.upper())}</div>",
    ]
    if not ok:
        rows.append(f'<div style="color:{color};font-size:0.85em">{html.escape(s.verdict)}</div>')
    rows.append('<table style="font-size:0.9em;margin-top:4px;width:100%">')
    rows += _speed_rows(s)
    if session.reach is not None and session.reach.max_contact_velocity is not None:
        rows.append(
            f"<tr><td>&nbsp;&nbsp;within the CoM's reach</td><td {_RIGHT}>"
            f'<b id="ib-vmax-reach">'
            f"{html.escape(format_speed(session.reach.max_contact_velocity))}</b></td></tr>"
        )
    held = session.held_stance
    if held is not None:
        note = " (paper's: not converged)" if held.fell_back else ""
        rows.append(
            f"<tr><td>&nbsp;&nbsp;held stance{note}</td><td {_RIGHT}>"
            f'<b id="ib-vmax-held">'
            f"{html.escape(format_speed(held.max_contact_velocity))}</b></td></tr>"
        )
    if session.governed is not None:
        rows += _governor_rows(session.governed)
    rows.append(
        f'<tr><td>update (analysis + redraw)</td><td {_RIGHT} id="ib-update-ms">'
        f"{last_update_ms:.1f} ms</td></tr>"
    )
    rows.append("</table>")
    if s.warnings:
        rows.append(_warnings_list(s.warnings))
    if session.message:
        rows.append(_message(session.message, session.refused))
    return '<div style="padding:0 0.75em">' + "".join(rows) + "</div>"
