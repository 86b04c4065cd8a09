"""Drawing the teacher's view of the room: the roster panel (F2), and why students cannot join.

The roster lists each student's seat, colour, name, snapshot rate, lag and
warnings (idle, cursor far off the table, squatting), one row each, with the
selected row highlighted; it scrolls to keep the selection in view. The Room
feature (room.py) calls `draw_roster` while its panel is on top, and shows
in ALERT_COLOR why students cannot join.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING

import pygame

from airtable.app import panel_view

if TYPE_CHECKING:
    from airtable.model.seats import Seat

ALERT_COLOR = (255, 90, 70)
SELECTED_COLOR = (60, 60, 110)
WARN_COLOR = (255, 170, 90)
HINT_GAP = "    "
HINTS = (
    HINT_GAP.join(("Up / Down or click: select", "Delete twice: remove", "F2 or Esc: close")),
    HINT_GAP.join(("F3: hands off", "F4: the floor to the next student", "F5: hide names")),
)
HEADINGS = ("seat", "", "rate", "lag", "warnings")
# Columns, in font heights from the left: swatch, seat, name, rate, lag, flags.
COLUMNS_EM = (0.0, 1.2, 3.9, 17.6, 21.1, 26.1)  # seat: room for "C30"; name: 20 letters; lag: "1250 ms"
IDLE_FLAG_S = 60.0  # no input change for this long: "idle" in the roster


def seat_flags(seat: Seat) -> str:
    """The roster's warnings for one seat: idle long, cursor far off, or both (a squatter)."""
    idle = seat.idle_s >= IDLE_FLAG_S
    if idle and seat.far_off:
        return f"squatting? idle {seat.idle_s:.0f} s, cursor far off the table"
    if idle:
        return f"idle {seat.idle_s:.0f} s"
    return "cursor far off the table" if seat.far_off else ""


def hint_lines(font: pygame.font.Font, width: int) -> list[str]:
    """HINTS in lines that fit `width` px: each line's keys as they fit, the rest on the next line (a user
    test: at 636 px the lines ended "F2 or Es..." and "F5: hide n...")."""
    lines = []
    for hint in HINTS:
        line = ""
        for item in hint.split(HINT_GAP):
            trial = f"{line}{HINT_GAP}{item}" if line else item
            if line and font.size(trial)[0] > width:
                lines.append(line)
                trial = item
            line = trial
        lines.append(line)
    return [panel_view.shorten(font, line, width) for line in lines]  # (a key's own text wider than the panel)


def _row_texts(seat: Seat, label: str) -> list[str]:
    seat_id, _, name = label.partition(" ")
    return [seat_id, name, f"{seat.snapshots_per_s:.0f}/s", f"{seat.lag_s * 1000:.0f} ms", seat_flags(seat)]


def draw_roster(
    w,
    seats: Sequence[Seat],
    *,
    selected: int,
    label: Callable[[str], str],
    most: int,
    anonymous: bool,
    away: Sequence[tuple[str, float]] = (),
) -> tuple[list[tuple[int, pygame.Rect]], pygame.Rect]:
    """The roster panel on GameWindow `w`, the `selected` row highlighted, names as `label` gives them,
    `most` seats in all, and the students `away` (label, seconds) whose seats are held for them under the
    title; returns each row's (number, box) and the panel's box, for clicks."""
    rect = w.panel_rect()
    font, pad = w.font, w.font.get_height() // 2
    surf = panel_view.panel_surface(rect.size)
    surf.fill(panel_view.PANEL_COLOR)
    pygame.draw.rect(surf, panel_view.ACCENT, surf.get_rect(), max(1, pad // 5))
    n = len(seats)
    title = f"Students: {n} of {most}" + ("  (names hidden)" if anonymous else "")
    surf.blit(
        w.big_font.render(panel_view.shorten(w.big_font, title, rect.w - 2 * pad), True, panel_view.ACCENT), (pad, pad)
    )
    y = pad + w.big_font.get_linesize()
    for hint in hint_lines(font, rect.w - 2 * pad):
        surf.blit(font.render(hint, True, panel_view.DIM_TEXT), (pad, y))
        y += font.get_linesize()
    if away:  # dropped, seats held: they come back by themselves
        line = "away (seat kept): " + ", ".join(f"{name} {s:.0f} s" for name, s in away)
        surf.blit(font.render(panel_view.shorten(font, line, rect.w - 2 * pad), True, WARN_COLOR), (pad, y))
        y += font.get_linesize()
    y += font.get_linesize() // 2
    em = font.get_height()
    for k, heading in enumerate(HEADINGS):
        surf.blit(font.render(heading, True, panel_view.DIM_TEXT), (pad + int(COLUMNS_EM[k + 1] * em), y))
    y += font.get_linesize()
    line_h = font.get_linesize()
    fits = max(1, (rect.h - y - pad) // line_h)
    first = max(0, min(selected - fits + 1, n - fits))
    row_boxes = []
    if not seats:
        empty = "nobody plays now" if away else "nobody has joined yet"
        surf.blit(font.render(empty, True, panel_view.DIM_TEXT), (pad, y))
    for i, seat in enumerate(seats[first : first + fits], start=first):
        box = pygame.Rect(pad // 2, y, rect.w - pad, line_h)
        if i == selected:
            surf.fill(SELECTED_COLOR, box)
        _draw_row(surf, font, seat, label(seat.name), (pad, y))
        row_boxes.append((seat.number, box.move(rect.topleft)))
        y += line_h
    w.surface.blit(surf, rect)
    return row_boxes, rect


def _draw_row(surf: pygame.Surface, font: pygame.font.Font, seat: Seat, label: str, at: tuple[int, int]) -> None:
    em = font.get_height()
    x0, y = at
    size = int(em * 0.8)
    pygame.draw.rect(surf, seat.color, (x0, y + (font.get_linesize() - size) // 2, size, size))
    texts = _row_texts(seat, label)
    for k, text in enumerate(texts):
        x = x0 + int(COLUMNS_EM[k + 1] * em)
        right = x0 + int(COLUMNS_EM[k + 2] * em) - em // 2 if k + 2 < len(COLUMNS_EM) else surf.get_width() - em // 2
        color = WARN_COLOR if k == len(texts) - 1 else panel_view.TEXT_COLOR
        surf.blit(font.render(panel_view.shorten(font, text, max(0, right - x)), True, color), (x, y))
