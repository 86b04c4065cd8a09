"""Drawing the teacher's view of the room: the roster panel (F2), and why students cannot join.

The roster lists each student's seat, colour, name, snapshot rate, lag and
warnings (idle, cursor far off the table, squatting), one row each, with the
selected row highlighted; it scrolls to keep the selection in view. The app
calls `draw_roster(app)` as its panel; `room_alert(app)` is the sentence that
the heads-up lines show in red when the server did not start or its thread failed.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import pygame

from airtable.app import panel_view, room

if TYPE_CHECKING:
    from airtable.app.app import App
    from airtable.net.server import Seat

ALERT_COLOR = (255, 90, 70)
SELECTED_COLOR = (60, 60, 110)
WARN_COLOR = (255, 170, 90)
HINTS = (
    "Up / Down or click: select    Delete twice: remove    F2 or Esc: close",
    "F3: hands off    F4: the floor to the next student    F5: hide names",
)
HEADINGS = ("seat", "", "rate", "lag", "warnings")
# Columns, in font heights from the left: swatch, seat, name, rate, lag, flags.
COLUMNS_EM = (0.0, 1.2, 3.0, 11.5, 15.0, 18.0)


def _row_texts(seat: Seat, label: str) -> list[str]:
    seat_id, _, name = label.partition(" ")
    return [seat_id, name, f"{seat.snapshots_per_s:.0f}/s", f"{seat.lag_s * 1000:.0f} ms", room.seat_flags(seat)]


def draw_roster(app: App) -> None:
    """The roster panel, with the selected row highlighted; notes each row's box for clicks."""
    w, r = app.window, app.room
    seats = app.server.roster() if app.server is not None else []
    rect = w.panel_rect()
    font, pad = w.font, w.font.get_height() // 2
    surf = pygame.Surface(rect.size, pygame.SRCALPHA)
    surf.fill(panel_view.PANEL_COLOR)
    pygame.draw.rect(surf, panel_view.ACCENT, surf.get_rect(), max(1, pad // 5))
    n, most = len(seats), app.server.max_clients if app.server is not None else 0
    title = f"Students: {n} of {most}" + ("  (names hidden)" if r.anonymous else "")
    surf.blit(
        w.big_font.render(panel_view.shorten(w.big_font, title, rect.w - 2 * pad), True, panel_view.ACCENT), (pad, pad)
    )
    y = pad + w.big_font.get_linesize()
    for hint in HINTS:
        surf.blit(font.render(panel_view.shorten(font, hint, rect.w - 2 * pad), True, panel_view.DIM_TEXT), (pad, y))
        y += font.get_linesize()
    y += font.get_linesize() // 2
    em = font.get_height()
    for k, heading in enumerate(HEADINGS):
        surf.blit(font.render(heading, True, panel_view.DIM_TEXT), (pad + int(COLUMNS_EM[k + 1] * em), y))
    y += font.get_linesize()
    line_h = font.get_linesize()
    fits = max(1, (rect.h - y - pad) // line_h)
    first = max(0, min(r.selected - fits + 1, n - fits))
    r.row_boxes = []
    if not seats:
        surf.blit(font.render("nobody has joined yet", True, panel_view.DIM_TEXT), (pad, y))
    for i, seat in enumerate(seats[first : first + fits], start=first):
        box = pygame.Rect(pad // 2, y, rect.w - pad, line_h)
        if i == r.selected:
            surf.fill(SELECTED_COLOR, box)
        _draw_row(surf, font, seat, r.label(seat.name), (pad, y))
        r.row_boxes.append((seat.number, box.move(rect.topleft)))
        y += line_h
    r.panel_box = rect
    w.surface.blit(surf, rect)


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


def room_alert(app: App) -> str | None:
    """Why students cannot join, if they cannot: the server did not start, or its thread failed."""
    return app.server.failure if app.server is not None else app.server_problem
