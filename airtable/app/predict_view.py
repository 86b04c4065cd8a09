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

from airtable.app.predict import ARROW_S, LOCAL_COLOR, count_text, names_shown
from airtable.net.predictions import RoundInfo

if TYPE_CHECKING:
    from airtable.app.app import App

PROMPT_COLOR = (255, 220, 90)
TRUTH_COLOR = (255, 255, 255)
PROMPT = ("PREDICT: drag an arrow from a puck,", "its velocity once the collision is over")


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
        painter.legend(lines)
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
        painter.legend([("the truth in bold white", TRUTH_COLOR), *((s, PROMPT_COLOR) for s in info.summary)])
    else:
        painter.legend([("revealed: playing until the collision is over", PROMPT_COLOR)])


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
