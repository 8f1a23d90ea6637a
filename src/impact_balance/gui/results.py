"""The numbers panel: the session's verdict and figures as escaped HTML (no file content, capped lengths)."""

from __future__ import annotations

import html

from impact_balance.gui.session import Session, format_speed

__all__ = ["results_html"]


def results_html(session: Session, last_update_ms: float) -> str:
    """The results panel for ``session``'s summary and message; ``last_update_ms`` is the last update's time (ms)."""
    s = session.summary
    ok = s.headline == "balanced"
    color = "#2ca02c" if ok else "#d62728"
    rows = [
        f'<div id="ib-verdict" style="font-weight:bold;font-size:1.15em;color:{color}">{html.escape(s.headline.upper())}</div>',
    ]
    if not ok:
        rows.append(f'<div style="color:{color};font-size:0.85em">{html.escape(s.verdict)}</div>')
    rows.append('<table style="font-size:0.9em;margin-top:4px;width:100%">')
    rows.append('<tr><td colspan="2" style="color:#555">maximum contact velocity</td></tr>')
    rows.append(
        f'<tr><td>&nbsp;&nbsp;by the CoM criterion</td><td style="text-align:right"><b id="ib-vmax-com">'
        f"{html.escape(format_speed(s.max_contact_velocity))}</b></td></tr>"
    )
    rows.append(
        f'<tr><td>&nbsp;&nbsp;by the ZMP criterion</td><td style="text-align:right"><b id="ib-vmax-zmp">'
        f"{html.escape(format_speed(s.zmp_max_contact_velocity))}</b></td></tr>"
    )
    if s.reference_speed is not None:
        verdict = "falls" if s.falls_at_reference else "holds"
        rows.append(
            f'<tr><td>reference approach speed</td><td style="text-align:right" id="ib-reference">'
            f"{s.reference_speed:.3f} m/s ({verdict})</td></tr>"
        )
    g = session.governed
    if g is not None:
        rows.append(
            '<tr><td colspan="2" style="color:#555">governor, live (from this posture and CoM velocity)</td></tr>'
        )
        rows.append(
            f'<tr><td>&nbsp;&nbsp;speed allowed</td><td style="text-align:right"><b id="ib-governor-cap">'
            f"{html.escape(format_speed(g.ceiling))}</b></td></tr>"
        )
        if g.reference is not None:
            rows.append(
                f'<tr><td>&nbsp;&nbsp;reference, capped</td><td style="text-align:right" id="ib-governor-capped">'
                f"{g.reference:.3f} &rarr; {g.capped:.3f} m/s</td></tr>"
            )
        rows.append(
            f'<tr><td>&nbsp;&nbsp;governor tick</td><td style="text-align:right" id="ib-governor-us">'
            f"{g.tick_us:.0f} &micro;s</td></tr>"
        )
    rows.append(
        f'<tr><td>update (analysis + redraw)</td><td style="text-align:right" id="ib-update-ms">'
        f"{last_update_ms:.1f} ms</td></tr>"
    )
    rows.append("</table>")
    if s.warnings:
        items = "".join(
            f"<li>{html.escape(w if len(w) <= 300 else w[:297] + '...')}</li>"
            for w in s.warnings[:10]
        )
        more = f"<li>... {len(s.warnings) - 10} more</li>" if len(s.warnings) > 10 else ""
        rows.append(
            f'<ul id="ib-warnings" class="ib-warning" style="color:#b36b00;font-size:0.85em;margin:4px 0;'
            f'padding-left:1.2em;overflow-wrap:anywhere">{items}{more}</ul>'
        )
    msg = session.message
    if msg:
        mcolor = "#d62728" if session.refused else "#555"
        prefix = "refused: " if session.refused else ""
        text = msg if len(msg) <= 400 else msg[:400] + "..."
        rows.append(
            f'<div id="ib-message" style="color:{mcolor};font-size:0.85em;margin-top:4px;'
            f'overflow-wrap:anywhere">{html.escape(prefix + text)}</div>'
        )
    return '<div style="padding:0 0.75em">' + "".join(rows) + "</div>"
