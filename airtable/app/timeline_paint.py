"""Drawing the rewind timeline: a thin bar along the top of the status bar, and where the view is along it.

The numbers come from history.py (a Timeline, no pygame); this module only
draws them onto a GameWindow's surface, with its fonts and line widths, so
the bar scales with the window like everything else.
"""

from __future__ import annotations

import pygame

from airtable.app.history import Timeline
from airtable.app.panel_view import ACCENT

TRACK_COLOR = (60, 60, 75)  # the moments after the view (dropped if the table runs on from it)
KEPT_COLOR = (130, 130, 170)  # the moments up to the view


class TimelinePainter:
    """Draws the history's timeline bar onto a GameWindow."""

    def __init__(self, window) -> None:  # a GameWindow
        self.w = window

    def bar_rect(self) -> pygame.Rect:
        """The bar: the window's width less a margin, in the strip the status bar keeps for it
        (never over the table; how far back the view is, the status line says)."""
        w, _ = self.w.surface.get_size()
        pad = self.w.line_px(8)
        return pygame.Rect(pad, self.w.status_top_px, w - 2 * pad, self.w.timeline_strip_px)

    def timeline(self, t: Timeline) -> pygame.Rect:
        """The bar, the part behind the view filled, and a mark at the view."""
        surface, rect = self.w.surface, self.bar_rect()
        pygame.draw.rect(surface, TRACK_COLOR, rect)
        x = rect.x + round(t.fraction * (rect.width - 1))
        pygame.draw.rect(surface, KEPT_COLOR, pygame.Rect(rect.x, rect.y, x - rect.x + 1, rect.height))
        mark = pygame.Rect(0, rect.y, max(3, self.w.line_px(6)), rect.height)
        mark.centerx = x
        pygame.draw.rect(surface, ACCENT, mark)
        self.w.label_boxes.append(rect)
        return rect
