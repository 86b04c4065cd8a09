"""Drawing the rewind timeline: a thin bar above the status bar, and where the view is along it.

The numbers come from history.py (a Timeline, no pygame); this module only
draws them onto a GameWindow's surface, with its fonts and line widths, so
the bar scales with the window like everything else.
"""

from __future__ import annotations

import pygame

from airtable.app.history import Timeline
from airtable.app.panel_view import ACCENT, DIM_TEXT

TRACK_COLOR = (60, 60, 75)  # the moments after the view (dropped if the table runs on from it)
KEPT_COLOR = (130, 130, 170)  # the moments up to the view


class TimelinePainter:
    """Draws the history's timeline bar onto a GameWindow."""

    def __init__(self, window) -> None:  # a GameWindow
        self.w = window

    def bar_rect(self) -> pygame.Rect:
        """The bar: the window's width less a margin, just above the status bar."""
        w, _ = self.w.surface.get_size()
        pad = self.w.line_px(8)
        height = max(2, self.w.line_px(4))
        return pygame.Rect(pad, self.w.status_top_px - pad - height, w - 2 * pad, height)

    def timeline(self, t: Timeline) -> pygame.Rect:
        """The bar, the part behind the view filled, a mark at the view, and how far back it is."""
        surface, rect = self.w.surface, self.bar_rect()
        pygame.draw.rect(surface, TRACK_COLOR, rect)
        x = rect.x + round(t.fraction * (rect.width - 1))
        pygame.draw.rect(surface, KEPT_COLOR, pygame.Rect(rect.x, rect.y, x - rect.x + 1, rect.height))
        mark = pygame.Rect(0, 0, max(3, self.w.line_px(3)), 4 * rect.height)
        mark.center = (x, rect.centery)
        pygame.draw.rect(surface, ACCENT, mark)
        back_s = t.newest_s - t.view_s
        text = f"history {t.newest_s - t.oldest_s:.2f} s" + (f", rewound {back_s:.2f} s" if back_s > 0 else "")
        label = self.w.label_font.render(text, True, ACCENT if back_s > 0 else DIM_TEXT)
        box = label.get_rect(bottomright=(rect.right, mark.top - self.w.line_px(2)))
        surface.blit(label, box)
        self.w.label_boxes.append(box.union(mark).union(rect))
        return rect
