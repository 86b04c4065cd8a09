"""Drawing a prediction round: the students' arrows, the truth and the summary.

The same drawing serves the teacher's window (`draw_predict(app)`) and every
student's (`paint_round`, from the ROUND messages): thin arrows, one colour
per student, from where each puck stood when the round opened; the true
velocities bold in white once the collision is over; the summary lines at
the left. Pixels come from the window's AidsPainter.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING

from airtable.app.panel_view import wrap
from airtable.app.predict import ARROW_S, LOCAL_COLOR, count_text, names_shown
from airtable.net.predictions import RoundInfo

if TYPE_CHECKING:
    from airtable.app.app import App

PROMPT_COLOR = (255, 220, 90)
TRUTH_COLOR = (255, 255, 255)
PROMPT = ("PREDICT: drag an arrow from a puck,", "its velocity once the collision is over")
INDENT = "    "  # before the second and later lines of a wrapped line


def fit_lines(font, lines, width_px: int) -> list[tuple[str, tuple[int, int, int]]]:
    """`lines` of (text, colour) wrapped at word breaks to `width_px`; a line's later pieces indented."""
    indent_px = font.size(INDENT)[0]
    out = []
    for text, color in lines:
        first, *rest = wrap(font, text, width_px) or [""]
        out.append((first, color))
        if rest:
            out.extend((INDENT + piece, color) for piece in wrap(font, " ".join(rest), width_px - indent_px))
    return out


def _legend(painter, lines) -> None:
    """The painter's legend (at the left, under the HUD), every line within the window's width."""
    w = painter.w
    width = w.surface.get_width() - 4 * w.line_px(4)  # the legend starts 2 pads in; as much room on the right
    painter.legend(fit_lines(w.font, lines, width))


def paint_round(
    painter, info: RoundInfo, own: Mapping[int, Sequence[float]], own_color, count: str | None = None
) -> None:
    """Draw the round `info` with `own` guesses (puck -> velocity) onto `painter`'s window."""
    w = painter.w
    thin, bold = max(1, w.line_px(1)), w.line_px(4)
    starts = info.from_m
    if info.state == "open":
        for puck, vel in own.items():
            if puck < len(starts):
                painter.arrow(starts[puck], (vel[0] * ARROW_S, vel[1] * ARROW_S), own_color, thin)
        lines = [(text, PROMPT_COLOR) for text in PROMPT]
        if count:
            lines.append((count, PROMPT_COLOR))
        _legend(painter, lines)
        return
    if info.state != "revealed":
        return
    for a in info.arrows:
        if a.puck < len(starts):
            painter.arrow(starts[a.puck], (a.vel_mps[0] * ARROW_S, a.vel_mps[1] * ARROW_S), a.color, thin)
            if a.label:
                painter.label([(a.label, a.color)], painter._px(_tip(starts[a.puck], a.vel_mps)))
    for puck, vel in enumerate(info.truth):
        if puck < len(starts):
            painter.arrow(starts[puck], (vel[0] * ARROW_S, vel[1] * ARROW_S), TRUTH_COLOR, bold)
    if info.truth:
        _legend(painter, [("the truth in bold white", TRUTH_COLOR), *((s, PROMPT_COLOR) for s in info.summary)])
    else:
        _legend(painter, [("revealed: playing until the collision is over", PROMPT_COLOR)])


def _tip(start: Sequence[float], vel: Sequence[float]) -> tuple[float, float]:
    return (start[0] + vel[0] * ARROW_S, start[1] + vel[1] * ARROW_S)


def draw_predict(app: App) -> None:
    """The round on the teacher's window (the projector): a count while open, everything once revealed."""
    r = app.predict
    if not r.active:
        return
    info = r.info(r.predicted, r.players, names_shown(app))
    # The volunteer at the teacher's laptop sees their own arrows; the students' stay hidden until the reveal.
    paint_round(app.painter, info, r.local, LOCAL_COLOR, count_text(app))
