"""Drawing the lesson panels: the momenta diagram and the values panel, each in a corner of the window.

The numbers come from momenta.py (no pygame); this module only draws them
onto a GameWindow's surface with its fonts and line widths, which scale with
the window. Each panel takes a corner once per demo: not the energy chart's,
and of the others the one over the fewest pucks. Their boxes join the
window's label boxes, so the labels drawn after them stay clear of them.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import pygame

from airtable.app.aids_paint import CHART_COLORS, CHART_CORNERS, draw_arrow_px, place_in_corner
from airtable.app.panel_view import ACCENT, DIM_TEXT, TEXT_COLOR, panel_surface, shorten, wrap
from airtable.model.momenta import FEW_PUCKS, VALUE_HEADINGS, MomentaView, PuckValues, fit_chains, tip_to_tail
from airtable.model.readout import figures, readable


def values_hint(pucks: int) -> str:
    """What the values panel says when it lists no puck (a user test: an empty table said "more than 6")."""
    return f"values: more than {FEW_PUCKS} pucks, so point at one" if pucks else "values: no pucks on the table"


TOTAL_COLOR = CHART_COLORS["momentum_Ns"]  # the chart's |momentum| colour
PANEL_FILL = (0, 0, 0, 255)  # opaque: nothing shows through the numbers
MOMENTA_SIZE_PX = (480, 250)  # at 720 px tall, like the chart


def momenta_scale(m: MomentaView) -> float:
    """The size of the largest momentum in the diagram (N s): the round-off scale of its totals (readout.py)."""
    sizes = [np.abs(np.asarray(a, dtype=float)).max(initial=0.0) for a in (m.before_Ns, m.after_Ns)]
    sizes += [np.abs(np.asarray(t, dtype=float)).max() for t in (m.total_before_Ns, m.total_after_Ns)]
    return float(max(sizes))


def total_texts(total, scale: float) -> tuple[tuple[str, ...], tuple[str, ...]]:
    """The two lines under a chain, each longest first: the total's components, and its size.
    A component that is round-off of `scale` (1.39e-17 after a hit along x) shows as 0 (readout.readable)."""
    x, y = (readable(v, scale) for v in total)
    size = math.hypot(x, y)
    return (
        (
            f"total ({figures(x)}, {figures(y)}) N s",
            f"({figures(x)}, {figures(y)}) N s",
            f"({figures(x)}, {figures(y)})",
        ),
        (f"|total| {figures(size, 4)} N s", f"|p| {figures(size, 4)} N s", f"{figures(size, 4)}"),
    )


def momenta_titles(m: MomentaView) -> tuple[str, ...]:
    """The diagram's title, longest first. When the totals differ (a wall acted between two collisions of
    a puck, or through a puck resting on it: one dropped on a puck on the floor bounces off the floor
    through it), what came from outside, so a class does not read it as momentum lost or made."""
    t = f"t = {m.t_s:.2f} s"
    plain = (f"momenta, collision at {t}", f"collision at {t}", t)
    scale = momenta_scale(m)
    x, y = (readable(a - b, scale) for a, b in zip(m.total_after_Ns, m.total_before_Ns, strict=True))
    if not (x or y):
        return plain
    outside = f"from outside ({figures(x)}, {figures(y)}) N s"
    return (f"momenta at {t}; {outside}", f"{t}; {outside}", *plain)


def fitting(font: pygame.font.Font, texts: Sequence[str], width: int) -> str:
    """The first of `texts` (longest first) that fits `width` pixels; else the last, cut to fit."""
    for text in texts:
        if font.size(text)[0] <= width:
            return text
    return shorten(font, texts[-1], width)


# Where the values panel is too narrow for every column, the first to go: mass, then speed. Momentum and
# kinetic energy are what the lessons compare (a user test: fullscreen's margin kept m and |v|, lost KE).
COLUMN_PRIORITY = (0, 3, 4, 2, 1)  # puck, |p|, KE, |v|, m (VALUE_HEADINGS' columns)


def shown_columns(widths: Sequence[int], room: int) -> list[int]:
    """The columns (in their order) that fit `room` px, taken by COLUMN_PRIORITY."""
    shown, used = [], 0
    for c in COLUMN_PRIORITY:
        if used + widths[c] <= room:
            shown.append(c)
            used += widths[c]
    return sorted(shown)


class LessonsPainter:
    """Draws the momenta diagram and the values panel onto a GameWindow."""

    def __init__(self, window) -> None:  # a GameWindow
        self.w = window
        self.corners: dict[str, int] = {}  # panel name -> index into CHART_CORNERS, chosen once per demo

    def new_demo(self) -> None:
        self.corners.clear()

    # ------------------------------------------------------------ corners

    def choose_corner(self, panel: str, points_px: np.ndarray, avoid: Sequence[int]) -> int:
        """The corner of `panel`: kept once chosen, unless in `avoid`; else the free corner over the fewest points.
        Corners under the last frame's panel (the lecture notes leave room below them) are avoided too, while
        others are free."""
        under = [k for k in range(len(CHART_CORNERS)) if k not in avoid and self._under_panel(k)]
        if len(avoid) + len(under) < len(CHART_CORNERS):
            avoid = [*avoid, *under]
        if self.corners.get(panel) is None or self.corners[panel] in avoid:
            free = [k for k in range(len(CHART_CORNERS)) if k not in avoid] or [0]
            w, h = self.w.surface.get_size()
            mid = np.array([w / 2, h / 2])
            pts = np.asarray(points_px, dtype=float).reshape(-1, 2)
            counts = []
            for k in free:
                name = CHART_CORNERS[k]
                dx = pts[:, 0] > mid[0] if name.endswith("right") else pts[:, 0] <= mid[0]
                dy = pts[:, 1] <= mid[1] if name.startswith("top") else pts[:, 1] > mid[1]
                counts.append(int(np.count_nonzero(dx & dy)))
            self.corners[panel] = free[counts.index(min(counts))]
        return self.corners[panel]

    def _under_panel(self, corner: int) -> bool:
        """Whether the last frame's panel covers the corner's first few lines."""
        panel = self.w.panel_area
        if panel is None:
            return False
        line = self.w.label_font.get_linesize()
        return place_in_corner(self.w, pygame.Rect(0, 0, 8 * line, 3 * line), corner).colliderect(panel)

    def corner_rect(self, size: tuple[int, int], corner: int) -> pygame.Rect:
        """A box of `size` in `corner`: under the HUD or above the status bar, at most half the window,
        moved down (a top corner) or up (a bottom one) past the text already drawn there (PAUSED, the
        timeline bar and its label, another panel)."""
        w, h = self.w.surface.get_size()
        pad = self.w.line_px(4)
        rect = pygame.Rect(0, 0, min(size[0], w // 2 - 2 * pad), min(size[1], h // 2 - 2 * pad))
        rect = place_in_corner(self.w, rect, corner)
        top, boxes = CHART_CORNERS[corner].startswith("top"), self.w.label_boxes
        for _ in range(len(boxes)):
            hit = rect.collidelist(boxes)
            if hit < 0:
                break
            if top:
                rect.top = boxes[hit].bottom + pad
            else:
                rect.bottom = boxes[hit].top - pad
        return rect

    def _panel(self, rect: pygame.Rect) -> None:
        back = panel_surface(rect.size)
        back.fill(PANEL_FILL)
        self.w.surface.blit(back, rect)
        pygame.draw.rect(self.w.surface, DIM_TEXT, rect, 1)
        self.w.label_boxes.append(rect)

    def _text(self, text: str, pos, color, font=None) -> pygame.Rect:
        font = font or self.w.label_font
        rect = self.w.surface.blit(font.render(text, True, color), pos)
        self.w.label_boxes.append(rect)  # where the text really is: the layout test reads it
        return rect

    def text_width_px(self) -> int:
        """The widest line a panel holds: half the window, or a side margin where there is one
        (corner_rect and place_in_corner cut a panel to that)."""
        w, pad = self.w.surface.get_width(), self.w.line_px(4)
        widest = w // 2 - 2 * pad
        if self.w.layout.side_px:
            widest = min(widest, self.w.layout.side_px - 2 * pad)
        return widest - 2 * pad

    def _arrow_px(self, a, b, color, width: int) -> None:
        draw_arrow_px(self.w.surface, color, a, b, width, head_widths=4.0)

    # ------------------------------------------------------------ momenta diagram

    def momenta_size(self) -> tuple[int, int]:
        u = max(self.w.unit, 0.6)
        return (int(MOMENTA_SIZE_PX[0] * u), int(MOMENTA_SIZE_PX[1] * u))

    def momenta_diagram(self, m: MomentaView | None, corner: int) -> pygame.Rect:
        """Before and after the latest collision: each puck's momentum tip to tail (its colour), and the total."""
        font, pad = self.w.label_font, self.w.line_px(4)
        line_h = font.get_linesize()
        if m is None:
            text = "momenta: no collision yet"
            rect = self.corner_rect((font.size(text)[0] + 2 * pad, line_h + 2 * pad), corner)
            self._panel(rect)
            self._text(text, (rect.x + pad, rect.y + pad), TEXT_COLOR)
            return rect
        rect = self.corner_rect(self.momenta_size(), corner)
        self._panel(rect)
        self._text(fitting(font, momenta_titles(m), rect.width - 2 * pad), (rect.x + pad, rect.y + pad), TEXT_COLOR)
        half = pygame.Rect(0, 0, (rect.width - 3 * pad) // 2, rect.height - 2 * pad - 3 * line_h)
        chains = []
        for momenta, total in ((m.before_Ns, m.total_before_Ns), (m.after_Ns, m.total_after_Ns)):
            tails, tips = tip_to_tail(momenta)
            chains.append((tails, tips, np.asarray(total, dtype=float)))
        fit = fit_chains([np.vstack([t, p, tot[None]]) for t, p, tot in chains], half.size)
        for side, (name, (tails, tips, total)) in enumerate(zip(("before", "after"), chains)):
            box = half.move(rect.x + pad + side * (half.width + pad), rect.y + pad + line_h)
            pygame.draw.rect(self.w.surface, (60, 60, 60), box, 1)
            self._text(name, (box.x + pad, box.y + pad // 2), DIM_TEXT)
            self._chain(fit, side, box, tails, tips, total, m.colors)
            for k, texts in enumerate(total_texts(total, momenta_scale(m))):
                self._text(fitting(font, texts, box.width), (box.x, box.bottom + pad // 2 + k * line_h), TOTAL_COLOR)
        return rect

    def _chain(self, fit, side: int, box: pygame.Rect, tails, tips, total, colors) -> None:
        size = box.size
        a, b = fit.to_px(side, tails, size), fit.to_px(side, tips, size)
        width = self.w.line_px(2)
        origin = np.array([box.x, box.y])
        for k in range(len(tails)):
            self._arrow_px(origin + a[k], origin + b[k], tuple(int(c) for c in colors[k]), width)
        ends = fit.to_px(side, np.array([[0.0, 0.0], total]), size) + origin
        # Beside the chain, not on it: when every arrow lies on one line the total would hide them.
        d = ends[1] - ends[0]
        n = np.array([-d[1], d[0]]) / max(float(np.hypot(*d)), 1e-9)
        shift = n * 3 * self.w.line_px(2)
        self._arrow_px(ends[0] + shift, ends[1] + shift, TOTAL_COLOR, self.w.line_px(3))

    # ------------------------------------------------------------ values panel

    def values_size(
        self, rows: Sequence[PuckValues], hint: str, spaces: int = 2
    ) -> tuple[tuple[int, ...], tuple[int, int]]:
        """Column widths and the panel's size for `rows` (or the one-line `hint` if there are none);
        `spaces`: as wide a gap between columns (at least the padding: where room is short)."""
        font, pad = self.w.label_font, self.w.line_px(4)
        if not rows:  # the hint wrapped to the panel's room: a margin is narrower than the line
            lines = wrap(font, hint, self.text_width_px())
            return (), (max(font.size(t)[0] for t in lines) + 2 * pad, font.get_linesize() * len(lines) + 2 * pad)
        swatch = font.get_height()
        table = [VALUE_HEADINGS, *(r.cells() for r in rows)]
        gap = max(2 * pad, font.size(" " * spaces)[0])  # (the padding alone: "m kg |v| m/s" ran together)
        widths = tuple(max(font.size(row[c])[0] for row in table) + gap for c in range(len(VALUE_HEADINGS)))
        widths = (widths[0] + swatch, *widths[1:])
        return widths, (sum(widths) + 2 * pad, font.get_linesize() * len(table) + 2 * pad)

    def values_panel(self, rows: Sequence[PuckValues], colors: Sequence, hint: str, corner: int) -> pygame.Rect:
        """A small table: each puck's mass, speed, momentum and kinetic energy; its colour beside its number."""
        for spaces in (2, 1, 0):  # too wide for its room: closer columns before dropping one (mass, first)
            widths, size = self.values_size(rows, hint, spaces)
            rect = self.corner_rect(size, corner)
            if rect.width >= size[0]:
                break
        self._panel(rect)
        font, pad = self.w.label_font, self.w.line_px(4)
        line_h = font.get_linesize()
        if not rows:
            for k, text in enumerate(wrap(font, hint, self.text_width_px())):
                self._text(text, (rect.x + pad, rect.y + pad + k * line_h), DIM_TEXT)
            return rect
        swatch = font.get_height()
        table = [(VALUE_HEADINGS, DIM_TEXT, None)]
        table += [(r.cells(), ACCENT if r.speed_mps is None else TEXT_COLOR, c) for r, c in zip(rows, colors)]
        shown = shown_columns(widths, rect.width + pad)  # (a column's width holds its share of the padding)
        for k, (cells, color, puck_color) in enumerate(table):
            y = rect.y + pad + k * line_h
            if y + line_h > rect.bottom:
                break  # a window too small for the whole table: cut, never spill
            x = rect.x + pad
            if puck_color is not None:
                r = swatch // 3
                pygame.draw.circle(self.w.surface, tuple(int(v) for v in puck_color), (x + r, y + line_h // 2), r)
            for c in shown:
                self._text(cells[c], (x + (swatch if c == 0 else 0), y), color, font)
                x += widths[c]
        return rect
