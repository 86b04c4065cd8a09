"""Drawing a prediction round: the students' arrows, the truth and the summary.

The same drawing, `paint_round`, serves the teacher's window (the Predict
feature of predict.py) and every student's (from the ROUND messages): thin arrows, one colour
per student, from where each puck stood when the round opened; the true
velocities bold in white once the collision is over; the summary lines at
the top left, in the margin or inside the walls. Pixels come from the window's AidsPainter.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import pygame

from airtable.app.panel_view import wrap
from airtable.model.rounds import ARROW_S, RoundInfo

PROMPT_COLOR = (255, 220, 90)
TRUTH_COLOR = (255, 255, 255)
PROMPT = ("PREDICT: drag an arrow from a puck,", "its velocity once the collision is over")
INDENT = "    "  # before the second and later lines of a wrapped line


LEGEND_FILL = (0, 0, 0)  # behind the round's lines: opaque, a wall or an arrow beneath must not muddle them


def _clauses(font, text: str, width_px: int) -> list[str]:
    """`text` in lines of at most `width_px`, broken after its "; " where it can (a summary's parts stay
    whole), else between words."""
    parts = [p + ";" for p in text.split("; ")]
    parts[-1] = parts[-1][:-1]
    lines: list[str] = []
    for part in parts:
        trial = f"{lines[-1]} {part}" if lines else part
        if lines and font.size(trial)[0] <= width_px:
            lines[-1] = trial
        elif font.size(part)[0] <= width_px:
            lines.append(part)
        else:
            lines.extend(wrap(font, part, width_px))
    return lines or [""]


def fit_lines(font, lines, width_px: int) -> list[tuple[str, tuple[int, int, int]]]:
    """`lines` of (text, colour) wrapped to `width_px` (at "; " first, then between words); a line's
    later pieces indented."""
    indent_px = font.size(INDENT)[0]
    out = []
    for text, color in lines:
        first, *rest = _clauses(font, text, width_px)
        out.append((first, color))
        if rest:
            out.extend((INDENT + piece, color) for piece in _clauses(font, " ".join(rest), width_px - indent_px))
    return out


def _legend(painter, lines) -> list[tuple[str, pygame.Rect]]:
    """The round's lines on an opaque panel at the top left, each line wrapped to fit: in the left
    margin where the window has one, else inside the table's walls (a wall must stay seen), below
    whatever text is there and past the pucks, or over the pucks where there is no room past them (a user
    test: under the chart and past the pucks, a student's 640x480 window drew them below its bottom);
    returns each line and where it went."""
    w = painter.w
    font, pad = w.font, w.line_px(4)
    line_h = font.get_linesize()
    walls = w.wall_rects()
    if w.layout.side_px:  # the margin, a pad clear of the left wall
        room = pygame.Rect(2 * pad, w.hud_bottom_px + pad, w.layout.side_px - 5 * pad, w.surface.get_height())
        avoid = list(painter._taken)
    else:  # inside the walls: not over the pucks either (the panel is opaque)
        inset = pad + max((min(r.width, r.height) for r in walls), default=0)
        left, top, width, height = (int(v) for v in w.env.table_rect_px)
        room = pygame.Rect(left + inset + pad, max(top + inset, w.hud_bottom_px + pad), width - 2 * inset - 2 * pad, 0)
        avoid = painter._taken + [r for r in painter.puck_boxes if r not in walls]
    lines = fit_lines(font, lines, max(room.width, 1))
    width = max(font.size(t)[0] for t, _ in lines)
    first = pygame.Rect(room.left, room.top, width, line_h * len(lines)).inflate(pad, pad // 2)
    bottom = w.status_top_px
    block = _slid_past(first, avoid, bottom, pad) or _slid_past(first, painter._taken, bottom, pad) or first
    pygame.draw.rect(w.surface, LEGEND_FILL, block)
    placed = []
    for k, (text, color) in enumerate(lines):
        rect = w.surface.blit(font.render(text, True, color), (room.left, block.top + pad // 4 + k * line_h))
        placed.append((text, rect))
    painter._taken.append(block)
    return placed


def paint_round(
    painter, info: RoundInfo, own: Mapping[int, Sequence[float]], own_color, count: str | None = None
) -> list[tuple[str, pygame.Rect]]:
    """Draw the round `info` with `own` guesses (puck -> velocity) onto `painter`'s window;
    returns the lines of text it wrote and where (none for a closed round)."""
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
        return _legend(painter, lines)
    if info.state != "revealed":
        return []
    for a in info.arrows:
        if a.puck < len(starts):
            painter.arrow(starts[a.puck], (a.vel_mps[0] * ARROW_S, a.vel_mps[1] * ARROW_S), a.color, thin)
            if a.label:
                painter.label([(a.label, a.color)], painter._px(_tip(starts[a.puck], a.vel_mps)))
    for puck, vel in enumerate(info.truth):
        if puck < len(starts):
            painter.arrow(starts[puck], (vel[0] * ARROW_S, vel[1] * ARROW_S), TRUTH_COLOR, bold)
    if info.truth:
        return _legend(painter, [("the truth in bold white", TRUTH_COLOR), *((s, PROMPT_COLOR) for s in info.summary)])
    return _legend(painter, [("revealed: playing until the collision is over", PROMPT_COLOR)])


def _slid_past(block: pygame.Rect, avoid: Sequence[pygame.Rect], bottom_px: int, pad: int) -> pygame.Rect | None:
    """`block` moved down past whatever of `avoid` is in its way, or None where it then ends below `bottom_px`."""
    block = block.copy()
    for _ in range(len(avoid)):
        hit = block.collidelist(avoid)
        if hit < 0:
            break
        block.top = avoid[hit].bottom + pad
    return block if block.bottom <= bottom_px and block.collidelist(avoid) < 0 else None


def _tip(start: Sequence[float], vel: Sequence[float]) -> tuple[float, float]:
    return (start[0] + vel[0] * ARROW_S, start[1] + vel[1] * ARROW_S)
