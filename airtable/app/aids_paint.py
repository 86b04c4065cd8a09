"""The teaching aids drawn over the table: collision annotations, arrows, the energy chart.

The numbers come from aids.py (no pygame); this module only draws them, onto
a GameWindow's surface, with its fonts and line widths (which scale with the
window). Every label goes through one greedy placer: it tries a few spots
around its anchor and takes the first whose box overlaps no label drawn
before it in this frame, so labels never cover one another.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import pygame

from airtable.app import panel_view
from airtable.app.panel_view import ACCENT, DIM_TEXT, TEXT_COLOR
from airtable.app.panel_view import wrap as _wrap
from airtable.model.aids import VectorScale
from airtable.model.readout import figures, fixed, readable

ANNOTATION_NORMAL = (255, 230, 90)
ANNOTATION_TANGENT = (90, 200, 255)
IDEAL_COLOR = (0, 200, 140)  # the push a perfect contact normal would give
OVERLAP_COLOR = (255, 80, 80)
SEPARATION_COLOR = (90, 255, 120)
# Okabe and Ito's palette, which stays distinct with every common colour-vision
# deficiency; white (drawn thicker) for the total.
CHART_COLORS = {
    "kinetic_J": (230, 159, 0),  # orange
    "spring_J": (0, 158, 115),  # bluish green
    "gravity_J": (86, 180, 233),  # sky blue
    "total_J": (255, 255, 255),
    "momentum_Ns": (204, 121, 167),  # reddish purple
}
CHART_LABELS = {
    "kinetic_J": "kinetic",
    "spring_J": "spring",
    "gravity_J": "gravity",
    "total_J": "total",
    "momentum_Ns": "|momentum|",
}
SHORT_LABELS = {**CHART_LABELS, "momentum_Ns": "|p|"}  # a small chart's key: names only
CHART_CORNERS = ("top right", "bottom right", "bottom left", "top left")
MAX_AVOIDED_PUCKS = 2000
LABELLED_ANNOTATIONS = 2  # only the newest collisions get their numbers in a box: more pile up unreadably
CHART_SIZE_PX = (520, 240)  # at 720 px tall; the small chart is SMALL_CHART of it
SMALL_CHART = 0.65
# Over the table (a window without side margins) the chart takes at most these shares of the window's
# width and height, large and small (key b): at 640x480 it then covers 13 %, or 6 %, of the table.
CHART_SHARE = {False: (0.4, 0.3), True: (0.3, 0.22)}
# The axes' tops: round numbers x 10^k, a little above the largest value shown (lines at 71-95 % of the height).
CHART_STEPS = (1.0, 1.2, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0)
CHART_HEADROOM = 1.05
# Where a label may go around its anchor, in order of preference: (x side, y side).
AROUND = ((1, 1), (1, -1), (-1, 1), (-1, -1), (0, 1), (0, -1))
RINGS = 8  # how far out (in lines) a label may move from its anchor


def _faded(color: Sequence[int], alpha: float) -> tuple[int, int, int]:
    return tuple(int(c * alpha) for c in color[:3])


def box_at(anchor: tuple[float, float], size: tuple[int, int], side: tuple[int, int], gap: float) -> pygame.Rect:
    """A box of `size` beside `anchor`: side x/y of -1, 0 (centred) or 1, `gap` px away."""
    w, h = size
    ax, ay = anchor
    sx, sy = side
    left = ax + gap if sx > 0 else (ax - gap - w if sx < 0 else ax - w / 2)
    top = ay + gap if sy > 0 else ay - gap - h
    return pygame.Rect(int(round(left)), int(round(top)), w, h)


def place_box(
    size: tuple[int, int], anchor, gap: float, taken: Sequence[pygame.Rect], screen: pygame.Rect, step: int
) -> pygame.Rect | None:
    """The first box around `anchor` that stays on `screen` and overlaps none of `taken`.

    Tries the spots of AROUND, then the same spots pushed further out by `step`
    px at a time, up to RINGS times; None if all are taken (a crowded frame:
    the label is left out rather than drawn over another)."""
    for ring in range(RINGS):
        for side in AROUND:
            rect = box_at(anchor, size, side, gap + ring * step)
            if screen.contains(rect) and rect.collidelist(taken) < 0:
                return rect
    return None


class AidsPainter:
    """Draws the teaching aids onto a GameWindow (kept apart from the core frame)."""

    def __init__(self, window) -> None:  # a GameWindow
        self.w = window
        self.chart_corner: int | None = None  # index into CHART_CORNERS; None: pick one clear of pucks
        self.chart_small = False
        self.chart_text: list[pygame.Rect] = []  # the chart's lines of text as last drawn
        self.chart_plot = pygame.Rect(0, 0, 0, 0)  # and its plot's box
        self._vector_scales: dict[str, VectorScale] = {}
        self._noted: tuple[np.ndarray, np.ndarray] | None = None  # this frame's pucks (note_pucks)
        self._puck_boxes: list[pygame.Rect] | None = None  # and their boxes, once asked for

    def new_demo(self) -> None:
        """A demo (re)started: arrow scales start afresh, and the chart picks its corner again."""
        self._vector_scales.clear()
        self.chart_corner = None

    def vector_scale(self, quantity: str) -> VectorScale:
        """The round arrow scale of `quantity` ("velocity", "momentum") for the current demo."""
        return self._vector_scales.setdefault(quantity, VectorScale())

    # ------------------------------------------------------------ basics

    @property
    def _taken(self) -> list[pygame.Rect]:
        return self.w.label_boxes

    def note_pucks(self, pos_m: np.ndarray, radius_m: np.ndarray) -> None:
        """This frame's pucks: annotation boxes and the legend keep clear of them and of the walls
        (`puck_boxes`, worked out only if a label asks: most frames of a gas draw none)."""
        self._noted = (np.array(pos_m, dtype=float), np.array(radius_m, dtype=float))
        self._puck_boxes = None

    @property
    def puck_boxes(self) -> list[pygame.Rect]:
        """The walls' and the noted pucks' boxes on screen: only pucks on screen count, at most
        MAX_AVOIDED_PUCKS (a gas has no room for boxes anyway)."""
        if self._puck_boxes is not None:
            return self._puck_boxes
        boxes = self._puck_boxes = self.w.wall_rects()
        if self._noted is None or not len(self._noted[0]):
            return boxes
        pos_m, radius_m = self._noted
        centers = self.w.env.to_screen(pos_m)
        r = np.clip(self.w.env.length_to_px(radius_m), 1.0, 1e6)
        w, h = self.w.surface.get_size()
        seen = (centers[:, 0] + r > 0) & (centers[:, 0] - r < w) & (centers[:, 1] + r > 0) & (centers[:, 1] - r < h)
        for (x, y), rad in zip(centers[seen][:MAX_AVOIDED_PUCKS], r[seen][:MAX_AVOIDED_PUCKS]):
            boxes.append(pygame.Rect(int(x - rad), int(y - rad), int(2 * rad) + 1, int(2 * rad) + 1))
        return boxes

    def _px(self, point_m) -> tuple[float, float]:
        x, y = self.w.env.to_screen(np.asarray(point_m, dtype=float))
        return (float(x), float(y))

    def _text(self, text: str, pos_px, color, *, center: bool = False, font=None) -> pygame.Rect:
        """One line on a black box, at a given spot (placement is the caller's)."""
        font = font or self.w.label_font
        label = font.render(text, True, color)
        rect = label.get_rect(center=pos_px) if center else label.get_rect(topleft=pos_px)
        pygame.draw.rect(self.w.surface, (0, 0, 0), rect.inflate(4, 2))
        self.w.surface.blit(label, rect)
        return rect

    def label(
        self,
        lines: Sequence[tuple[str, Sequence[int]]],
        anchor_px,
        gap: float = 0.0,
        font=None,
        *,
        always: bool = False,
        clear_of_pucks: bool = True,
    ) -> pygame.Rect | None:
        """A block of coloured lines placed beside `anchor_px` where no other label is (nor, with
        `clear_of_pucks`, any puck noted this frame).

        Where there is no such place it is left out (None), unless `always`
        (the inspector, asked for by a held key): then it goes beside its anchor."""
        font = font or self.w.label_font
        line_h = font.get_linesize()
        size = (max(font.size(t)[0] for t, _ in lines) + 6, line_h * len(lines) + 2)
        pad = self.w.line_px(2)
        screen = self.w.surface.get_rect()
        avoid = self._taken + self.puck_boxes if clear_of_pucks else self._taken
        rect = place_box(size, anchor_px, gap + pad, avoid, screen, line_h)
        if rect is None:
            if not always:
                return None
            # Over other pucks, then, but beside its own and off the other labels and text if it can be;
            # clamped into the window only as a last resort (it would cover its puck in a corner).
            rect = place_box(size, anchor_px, gap + pad, self._taken, screen, line_h) if clear_of_pucks else None
            rect = rect or box_at(anchor_px, size, AROUND[0], gap + pad).clamp(screen)
        self._taken.append(rect)
        pygame.draw.rect(self.w.surface, (0, 0, 0), rect)
        for k, (text, color) in enumerate(lines):
            self._text(text, (rect.x + 3, rect.y + 1 + k * line_h), color, font=font)
        return rect

    def arrow(self, start_m, vector_m, color, width: int | None = None) -> None:
        """An arrow from start_m along vector_m (both in metres)."""
        self.arrows(np.asarray([start_m], dtype=float), np.asarray([vector_m], dtype=float), color, width)

    def arrows(self, starts_m: np.ndarray, vectors_m: np.ndarray, color, width: int | None = None) -> None:
        """Arrows from each of starts_m along vectors_m (metres), their ends turned into pixels at once
        (a gas has thousands)."""
        if len(starts_m) == 0:
            return
        ends = self.w.env.to_screen(np.concatenate([starts_m, starts_m + vectors_m]).astype(float)).tolist()
        width = width or self.w.line_px(2)
        surface = self.w.surface
        clip = surface.get_clip()
        surface.set_clip(clip.clip(self.w.world_area()))  # a user test: long arrows covered the status line
        try:
            for a, b in zip(ends[: len(starts_m)], ends[len(starts_m) :]):
                draw_arrow_px(surface, color, a, b, width, head_widths=5.0)
        finally:
            surface.set_clip(clip)

    def marker(self, point_m, color, label: str) -> None:
        x, y = self._px(point_m)
        lw, r = self.w.line_px(2), 4 * self.w.line_px(2)
        pygame.draw.circle(self.w.surface, color, (x, y), r, lw)
        pygame.draw.line(self.w.surface, color, (x - 1.5 * r, y), (x + 1.5 * r, y), lw)
        pygame.draw.line(self.w.surface, color, (x, y - 1.5 * r), (x, y + 1.5 * r), lw)
        self.label([(label, color)], (x, y), gap=1.5 * r)

    def legend(self, lines: Sequence[tuple[str, Sequence[int]]]) -> None:
        """Coloured lines of text in an opaque box in a corner: in a side margin where the window has
        one (wrapped to it), else the first corner clear of the pucks and other text (the top left if none is)."""
        font, pad = self.w.font, self.w.line_px(4)
        line_h = font.get_linesize()
        column = self.w.layout.side_px - 2 * pad
        if column > 0:
            lines = [(row, color) for text, color in lines for row in _wrap(font, text, column)]
        size = (max(font.size(t)[0] for t, _ in lines) + 4, line_h * len(lines))
        avoid = self._taken + self.puck_boxes
        order = (3, 2, 0, 1)  # top left first, where the eye starts
        fits_margin = 0 < size[0] <= self.w.layout.side_px - 2 * pad
        corners = [place_in_corner(self.w, pygame.Rect((0, 0), size), c) for c in order] if fits_margin else []
        inside = [table_corner(self.w, pygame.Rect((0, 0), size), c) for c in order]
        # The first corner clear of everything; else the one over the fewest pucks and walls, clear of text.
        candidates = corners + inside
        block = next((r for r in candidates if r.collidelist(avoid) < 0), None)
        if block is None:
            clear_of_text = [r for r in candidates if r.collidelist(self._taken) < 0] or candidates
            block = min(clear_of_text, key=lambda r: len(r.collidelistall(self.puck_boxes)))
        pygame.draw.rect(self.w.surface, (0, 0, 0), block.inflate(4, 2))
        for k, (text, color) in enumerate(lines):
            block.union_ip(self._text(text, (block.x + 2, block.top + k * line_h), color, font=font))
        self._taken.append(block)  # where the text really is: the layout test reads it

    def _dashed(self, color, a_px, b_px, width: int) -> None:
        length = math.hypot(b_px[0] - a_px[0], b_px[1] - a_px[1])
        dash = 4 * width
        for k in range(int(length // (2 * dash)) + 1):
            t0, t1 = min(1.0, 2 * k * dash / length), min(1.0, (2 * k + 1) * dash / length)
            p = [(a_px[0] + (b_px[0] - a_px[0]) * t, a_px[1] + (b_px[1] - a_px[1]) * t) for t in (t0, t1)]
            pygame.draw.line(self.w.surface, color, p[0], p[1], width)

    # ------------------------------------------------------------ collisions

    def annotation(self, a, now_s: float, labelled: bool = True) -> None:
        """Normal and tangent at the contact, overlap and separation, and the target's push against the ideal;
        with `labelled`, their numbers in a box clear of the pucks (left out where there is no room)."""
        alpha = a.alpha(now_s)
        surf, lw = self.w.surface, self.w.line_px(2)
        n = np.asarray(a.normal)
        c = np.asarray(a.contact_m)
        reach = 0.8 * (a.radius_i_m + a.radius_j_m)
        ends = {}
        for axis, color, name in (
            (n, ANNOTATION_NORMAL, "normal"),
            (np.array([-n[1], n[0]]), ANNOTATION_TANGENT, "tangent"),
        ):
            p0, ends[name] = self._px(c - reach * axis), self._px(c + reach * axis)
            pygame.draw.line(surf, _faded(color, alpha), p0, ends[name], lw)
        # Where the pucks were when the overlap was found, and after the correction.
        for pos, r, color in (
            (a.pos_i_before, a.radius_i_m, OVERLAP_COLOR),
            (a.pos_j_before, a.radius_j_m, OVERLAP_COLOR),
            (a.pos_i_after, a.radius_i_m, SEPARATION_COLOR),
            (a.pos_j_after, a.radius_j_m, SEPARATION_COLOR),
        ):
            r_px = max(lw + 1, int(round(float(self.w.env.length_to_px(r)))))
            pygame.draw.circle(surf, _faded(color, alpha), self._px(pos), r_px, lw)
        self._gap_bars(a, n, alpha)
        if a.target is not None:
            self._target_rays(a, alpha, reach)
        if not labelled:
            return
        # Labels, most important first: each takes the first free spot clear of the pucks.
        reach_px = float(self.w.env.length_to_px(a.radius_i_m + a.radius_j_m))
        lines = self._annotation_lines(a, alpha)
        self.label(lines, self._px(c), gap=min(reach_px, 200.0), font=self.w.font)
        for name, color in (("normal", ANNOTATION_NORMAL), ("tangent", ANNOTATION_TANGENT)):
            self.label([(name, _faded(color, alpha))], ends[name])
        if a.target is not None:
            tip = np.asarray(a.target.pos_m) + 1.6 * reach * np.asarray(a.target.ideal_dir)
            self.label([("ideal", _faded(IDEAL_COLOR, alpha))], self._px(tip))

    def _gap_bars(self, a, n: np.ndarray, alpha: float) -> None:
        """The overlap along the normal at detection, the gap after correction."""
        wide = self.w.line_px(4)
        pi, pj = np.asarray(a.pos_i_before), np.asarray(a.pos_j_before)
        ends = (self._px(pj + n * a.radius_j_m), self._px(pi - n * a.radius_i_m))
        pygame.draw.line(self.w.surface, _faded(OVERLAP_COLOR, alpha), *ends, wide)
        qi, qj = np.asarray(a.pos_i_after), np.asarray(a.pos_j_after)
        gap_n = (qi - qj) / max(float(np.hypot(*(qi - qj))), 1e-12)
        ends = (self._px(qj + gap_n * a.radius_j_m), self._px(qi - gap_n * a.radius_i_m))
        pygame.draw.line(self.w.surface, _faded(SEPARATION_COLOR, alpha), *ends, wide)

    def _target_rays(self, a, alpha: float, reach: float) -> None:
        """From the target: the way it was pushed (solid) and the way a first-contact normal pushes (dashed)."""
        start = np.asarray(a.target.pos_m)
        lw = self.w.line_px(2)
        self.arrow(start, 1.6 * reach * np.asarray(a.target.push_dir), _faded(ANNOTATION_NORMAL, alpha), lw)
        tip = self._px(start + 1.6 * reach * np.asarray(a.target.ideal_dir))
        self._dashed(_faded(IDEAL_COLOR, alpha), self._px(start), tip, lw)

    @staticmethod
    def _annotation_lines(a, alpha: float) -> list[tuple[str, tuple[int, int, int]]]:
        lines = [
            (f"overlap {fixed(a.overlap_m * 1000, 1)} mm", OVERLAP_COLOR),
            (f"separation {fixed(a.separation_m * 1000, 1)} mm", SEPARATION_COLOR),
        ]
        if a.ratio is not None:
            lines.append((f"ratio {a.ratio:.4f}", TEXT_COLOR))
        if a.target is not None:
            lines.append((f"target {a.target.actual_deg:.1f} deg vs ideal {a.target.ideal_deg:.1f} deg", IDEAL_COLOR))
        if a.angle_deg is not None:
            lines.append((f"paths {a.angle_deg:.2f} deg apart", ANNOTATION_NORMAL))
        return [(text, _faded(color, alpha)) for text, color in lines]

    # ------------------------------------------------------------ energy chart

    def cycle_chart_corner(self) -> str:
        """Move the chart to the next corner; returns the corner's name."""
        self.chart_corner = ((self.chart_corner or 0) + 1) % len(CHART_CORNERS)
        return CHART_CORNERS[self.chart_corner]

    def choose_chart_corner(self, points_px: np.ndarray) -> None:
        """Put the chart in the corner that covers the fewest of `points_px` (the pucks), once per demo."""
        if self.chart_corner is not None:
            return
        covered = []
        for corner in range(len(CHART_CORNERS)):
            rect = self.chart_rect(corner)
            inside = (
                (points_px[:, 0] >= rect.left)
                & (points_px[:, 0] < rect.right)
                & (points_px[:, 1] >= rect.top)
                & (points_px[:, 1] < rect.bottom)
            )
            covered.append(int(np.count_nonzero(inside)))
        self.chart_corner = covered.index(min(covered))

    def corner_in_sight(self) -> int:
        """The chart's corner, or the other one on its side (top and bottom swap) where the last frame's panel
        covers it and not that one: the lecture notes leave the table below them in sight, and the chart with
        it (a user test: `2 l c` showed no chart till the notes closed)."""
        corner = self.chart_corner or 0
        panel = self.w.panel_area
        if panel is None or not self.chart_rect(corner).colliderect(panel):
            return corner
        other = corner ^ 1  # CHART_CORNERS pairs each top corner with the bottom one on its side
        return other if not self.chart_rect(other).colliderect(panel) else corner

    def toggle_chart_size(self) -> None:
        self.chart_small = not self.chart_small

    def chart_rect(self, corner: int | None = None) -> pygame.Rect:
        """The chart's box: in its corner, under the HUD or above the status bar. Over the table (no side
        margins) at most CHART_SHARE of the window's width and height, but tall enough for its key."""
        w, h = self.w.surface.get_size()
        scale = max(self.w.unit * (SMALL_CHART if self.chart_small else 1.0), 0.6)
        share_w, share_h = (1.0, 0.5) if self.w.layout.side_px else CHART_SHARE[self.chart_small]
        key_h = len(CHART_COLORS) * self.w.label_font.get_linesize() + 2 * self.w.line_px(4) + 2
        size = (
            min(int(w * share_w), int(CHART_SIZE_PX[0] * scale)),
            min(h // 2, max(key_h, min(int(h * share_h), int(CHART_SIZE_PX[1] * scale)))),
        )
        return place_in_corner(
            self.w, pygame.Rect((0, 0), size), (self.chart_corner or 0) if corner is None else corner
        )

    def energy_chart(self, series: dict[str, np.ndarray], latest: dict[str, float], note: str | None) -> None:
        """Strip chart of energies (left scale, in J) and |momentum| (right scale, in N s, in its colour) in an
        opaque corner panel; the key beside the plot, or under it where the panel is narrow (a side margin),
        or beside it without the values where the panel is small (the values panel has them)."""
        box = self.chart_rect(self.corner_in_sight())
        surf, font = self.w.surface, self.w.label_font
        pygame.draw.rect(surf, (0, 0, 0), box)
        pygame.draw.rect(surf, DIM_TEXT, box, 1)
        self._taken.append(box)
        self.chart_text = []
        line_h, pad = font.get_linesize(), self.w.line_px(4)
        key, key_w, stacked = self._chart_key(box, latest)
        room = box.height - 2 * pad - (len(key) * line_h if stacked else 0)
        # The note goes under the plot (its axes' line and four lines tall at least) and under a key beside it.
        most = room // line_h - max(5, 0 if stacked else len(key))
        notes = chart_notes(font, note if not self.chart_small else None, box.width - 2 * pad, most)
        plot_w = box.width - 2 * pad if stacked else box.width - key_w - 3 * pad
        plot = pygame.Rect(box.x + pad, box.y + pad + line_h, plot_w, room - (1 + len(notes)) * line_h)
        pygame.draw.rect(surf, (60, 60, 60), plot, 1)
        self.chart_plot = plot
        if len(series["time_s"]) >= 2 and plot.width > 10 and plot.height > 10:
            self._chart_plot(series, plot, latest)
        x, y = (box.x + pad, plot.bottom) if stacked else (plot.right + pad, box.y + pad)
        spare = box.bottom - pad - len(notes) * line_h - y - len(key) * line_h
        gap = max(0, min(pad // 2, spare // max(1, len(key) - 1)))
        for text, color in key:
            mid = y + line_h // 2
            pygame.draw.line(surf, color, (x, mid), (x + 2 * pad, mid), self.w.line_px(3))
            self._chart_text(text, (x + 2 * pad + 4, y), color)
            y += line_h + gap
        for k, line in enumerate(notes):
            self._chart_text(line, (box.x + pad, box.bottom - pad - (len(notes) - k) * line_h), DIM_TEXT)

    def _chart_key(self, box: pygame.Rect, latest: dict[str, float]) -> tuple[list, int, bool]:
        """The key's lines (text, colour), its width (px) and whether it goes under the plot: with the
        values beside the plot where that leaves the plot half the box, else under it where the box is
        tall (a side margin), else only the names beside it."""
        font, pad, line_h = self.w.label_font, self.w.line_px(4), self.w.label_font.get_linesize()
        # Sized for the widest value the format gives, so the plot does not jitter.
        widest = max(font.size(key_text(k, -8.88e-88))[0] for k in CHART_COLORS)
        key_w = widest + 5 * pad
        full = [(key_text(k, latest[k]), c) for k, c in CHART_COLORS.items()]
        if box.width >= 2 * key_w:
            return full, key_w, False
        if box.height - 2 * pad - len(full) * line_h >= 4 * line_h:
            return full, key_w, True
        names = [(SHORT_LABELS[k], c) for k, c in CHART_COLORS.items()]
        return names, max(font.size(t)[0] for t, _ in names) + 5 * pad, False

    def _chart_text(self, text: str, pos_px, color) -> pygame.Rect:
        """One of the chart's lines of text, its box kept in `chart_text` (the layout tests read them)."""
        rect = self._text(text, pos_px, color)
        self.chart_text.append(rect)
        return rect

    def _chart_plot(self, series: dict[str, np.ndarray], plot: pygame.Rect, latest: dict[str, float]) -> None:
        """The lines and the plot's labels: above it, the energy axis's top (J) at the left, the momentum axis's
        (N s, in the |momentum| line's colour) at the right (inside the plot if they would meet); the span in it."""
        font, line_h = self.w.label_font, self.w.label_font.get_linesize()
        t = series["time_s"]
        # Round-off (the chart's top is 0) lies on the axis: any positive top draws it there.
        top_e = chart_top(series["total_J"], latest.get("energy_scale_J", 0.0))
        top_p = chart_top(series["momentum_Ns"], latest.get("momentum_scale_Ns", 0.0))
        self._chart_lines(series, plot, top_e or 1.0, top_p or 1.0)
        left = self._chart_text(f"{figures(top_e)} J", (plot.x, plot.y - line_h), TEXT_COLOR)
        text = f"{figures(top_p)} N s"
        right = pygame.Rect((0, 0), font.size(text))
        right.topright = (plot.right, plot.y - line_h)
        if right.inflate(8, 0).colliderect(left):
            right.topright = (plot.right - 2, plot.y + 2)
        self._chart_text(text, right.topleft, CHART_COLORS["momentum_Ns"])
        if plot.height >= 3 * line_h:
            self._chart_text(f"last {max(t[-1] - t[0], 0.0):.1f} s", (plot.x + 2, plot.bottom - line_h), DIM_TEXT)

    def _chart_lines(self, series: dict[str, np.ndarray], plot: pygame.Rect, top_e: float, top_p: float) -> None:
        """Each series as a line, energies against `top_e` (J), |momentum| against `top_p` (N s)."""
        t = series["time_s"]
        span = max(t[-1] - t[0], 1e-9)
        xs = plot.x + (t - t[0]) / span * plot.width
        # Decimate to about one point per pixel column.
        pick = np.unique(np.linspace(0, len(t) - 1, min(len(t), plot.width)).astype(int))
        thin, thick = self.w.line_px(1.5), self.w.line_px(3)
        for key, color in CHART_COLORS.items():
            top = top_p if key == "momentum_Ns" else top_e
            ys = plot.bottom - np.clip(series[key] / top, 0.0, 1.0) * plot.height
            pts = np.stack([xs[pick], ys[pick]], axis=1)
            pygame.draw.lines(self.w.surface, color, False, pts.tolist(), thick if key == "total_J" else thin)

    # ------------------------------------------------------------ inspector

    def inspector(self, point_m, radius_m: float, lines: Sequence[str]) -> None:
        """The inspected puck ringed, its `lines` beside it."""
        x, y = self._px(point_m)
        lw = self.w.line_px(2)
        r = max(round(radius_m * self.w.env.px_per_m) + 2 * lw, 3 * lw)  # just outside the puck, seen on a dot too
        pygame.draw.circle(self.w.surface, ACCENT, (x, y), r, lw)
        self.label(
            [(line, TEXT_COLOR) for line in lines],
            (x, y),
            gap=max(r, self.w.font.get_height()),
            font=self.w.font,
            always=True,
        )


def draw_annotations(paint: AidsPainter, annotations: Sequence, now_s: float) -> None:
    """The collisions' annotations, oldest first; only the newest LABELLED_ANNOTATIONS get numbers."""
    labelled_from = len(annotations) - LABELLED_ANNOTATIONS
    for k, annotation in enumerate(annotations):
        paint.annotation(annotation, now_s, labelled=k >= labelled_from)


def table_corner(window, rect: pygame.Rect, corner: int) -> pygame.Rect:
    """`rect` moved into CHART_CORNERS[corner] of the table at zoom 1, inside its walls."""
    left, top, width, height = window.env.table_rect_px
    inset = window.line_px(4) + max((min(r.width, r.height) for r in window.wall_rects()), default=0)
    inner = pygame.Rect(int(left), int(top), int(width), int(height)).inflate(-2 * inset, -2 * inset)
    name = CHART_CORNERS[corner]
    if name.startswith("top"):
        rect.top = inner.top
    else:
        rect.bottom = inner.bottom
    if name.endswith("right"):
        rect.right = inner.right
    else:
        rect.left = inner.left
    return rect


def chart_top(values: np.ndarray, scale: float) -> float:
    """The top of a chart's axis: the first round number (CHART_STEPS x 10^k) at least CHART_HEADROOM above the
    largest of `values`, or 0 if that is round-off of the scene's `scale` (readout.py).

    The axis follows what the chart shows, its window (CHART_WINDOW_S): a fling stays whole, at its true
    height, while it is in view, and the axis comes down to the calm table's numbers as it leaves. Round
    steps keep the label readable ("2.5 J") and the lines still while the window slides."""
    largest = readable(float(np.max(values)), scale) if len(values) else 0.0
    return round_up(CHART_HEADROOM * largest) if largest > 0 else 0.0


def round_up(value: float) -> float:
    """The least of CHART_STEPS x 10^k that is at least `value` (> 0)."""
    exp = math.floor(math.log10(value))
    for step in CHART_STEPS:
        top = step * 10.0**exp
        if top >= value * (1 - 1e-12):
            return top
    return 10.0 ** (exp + 1)


def chart_notes(font: pygame.font.Font, note: str | None, width_px: int, most: int) -> list[str]:
    """`note` wrapped to `width_px`, at most `most` lines (the plot keeps four lines' height): where it is
    longer, its last line ends in "..."."""
    if not note or most <= 0:
        return []  # (no room: a window shrunk to a strip leaves a negative number of lines)
    lines = _wrap(font, note, width_px)
    if len(lines) <= most:
        return lines
    return [*lines[: most - 1], panel_view.shorten(font, lines[most - 1] + " ...", width_px)]


def key_text(key: str, value: float) -> str:
    """A line of the chart's key: the quantity, its value and unit ("total 2.4 J", "|momentum| 0.5 N s")."""
    return f"{CHART_LABELS[key]} {figures(value)} {'N s' if key == 'momentum_Ns' else 'J'}"


def place_in_corner(window, rect: pygame.Rect, corner: int) -> pygame.Rect:
    """`rect` moved into CHART_CORNERS[corner]: under the HUD or above the status bar, a margin from the side;
    where the window has side margins, inside them (no wider than they are), clear of the table."""
    pad = window.line_px(4)
    name = CHART_CORNERS[corner]
    if window.layout.side_px:
        rect.width = min(rect.width, window.layout.side_px - 2 * pad)
    if name.startswith("top"):
        rect.top = window.hud_bottom_px + pad
    else:
        rect.bottom = window.status_top_px - pad
    if name.endswith("right"):
        rect.right = window.surface.get_width() - pad
    else:
        rect.left = pad
    return rect


def draw_arrow_px(surface: pygame.Surface, color, a, b, width: int, head_widths: float) -> None:
    """A line from pixel a to b with a head `head_widths` line widths long (at most 0.4 of the arrow);
    nothing for an arrow under a pixel or of no finite length."""
    length = math.hypot(b[0] - a[0], b[1] - a[1])
    if not 1.0 <= length < math.inf:
        return
    pygame.draw.line(surface, color, a, b, width)
    ux, uy = (b[0] - a[0]) / length, (b[1] - a[1]) / length
    head = min(head_widths * width, 0.4 * length)
    left = (b[0] - head * (ux - 0.5 * uy), b[1] - head * (uy + 0.5 * ux))
    right = (b[0] - head * (ux + 0.5 * uy), b[1] - head * (uy - 0.5 * ux))
    pygame.draw.polygon(surface, color, [b, left, right])
