"""Text helpers shared by the report's renderers: table cells, escaping, badges."""

from __future__ import annotations

import html
import math

from .types import (BASES, BY_CONSTRUCTION, BY_CONSTRUCTION_HOLDS, CALIBRATED, CHOSEN, CONFIRMED, DEPENDS, INDEPENDENT,
                    NOT_CHECKABLE, NOT_CONFIRMED, NOT_REPRODUCED, REPRODUCED, SAME_ORDERING)

BADGE = {CONFIRMED: ("#1a7f37", "#ffffff"), NOT_CONFIRMED: ("#cf222e", "#ffffff"), DEPENDS: ("#bf8700", "#ffffff"),
         BY_CONSTRUCTION_HOLDS: ("#57606a", "#ffffff")}
BADGE.update({REPRODUCED: ("#1a7f37", "#ffffff"), SAME_ORDERING: ("#bf8700", "#ffffff"),
              NOT_REPRODUCED: ("#cf222e", "#ffffff"), NOT_CHECKABLE: ("#57606a", "#ffffff")})
BADGE.update({INDEPENDENT: ("#1a7f37", "#ffffff"), CALIBRATED: ("#8250df", "#ffffff"),
              BY_CONSTRUCTION: ("#8250df", "#ffffff"), CHOSEN: ("#8250df", "#ffffff")})
assert all(b in BADGE for b in BASES)
MD_MARK = {CONFIRMED: "✅ confirmed", NOT_CONFIRMED: "❌ not confirmed", DEPENDS: "⚠️ depends on a reading",
           BY_CONSTRUCTION_HOLDS: "⚙️ holds by construction"}


def md_verdict(claim) -> str:
    """A claim's verdict in Markdown: the mark, and the chosen readings when they are its only support."""
    mark = MD_MARK.get(claim.verdict, claim.verdict)
    return mark + claim.verdict_text[len(claim.verdict):]


def fmt_cell(v, digits: int = 4) -> str:
    """Plain text of one table cell: floats with ``digits`` significant digits, NaN as "–"."""
    if isinstance(v, bool):
        return "yes" if v else "no"
    if isinstance(v, float):
        if math.isnan(v):
            return "–"
        if math.isinf(v):
            return "∞" if v > 0 else "−∞"
        return f"{v:.{digits}g}"
    if v is None:
        return "–"
    return str(v)


def _is_num(v) -> bool:
    return isinstance(v, (int, float)) and not isinstance(v, bool)


def _e(text) -> str:
    return html.escape(str(text), quote=True)


def _md(text) -> str:
    """Markdown table cell: one line, pipes escaped."""
    return str(text).replace("\\", "\\\\").replace("|", "\\|").replace("\r", " ").replace("\n", " ")


def badge(verdict: str) -> str:
    bg, fg = BADGE.get(verdict, ("#57606a", "#ffffff"))
    return f'<span class="badge" style="background:{bg};color:{fg}">{_e(verdict)}</span>'


def _paras(text: str) -> str:
    parts = [p.strip() for p in str(text).split("\n\n") if p.strip()]
    return "".join(f"<p>{_e(p)}</p>" for p in parts)

