"""The teaching aids drawn over the table: collision annotations, arrows, the energy chart.

The numbers come from aids.py (no pygame); this module only draws them, onto
a GameWindow's surface, with its fonts and line widths.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
import pygame

from airtable.app.panel_view import DIM_TEXT, TEXT_COLOR
from airtable.app.panel_view import wrap as _wrap

ANNOTATION_NORMAL = (255, 230, 90)
ANNOTATION_TANGENT = (90, 200, 255)
OVERLAP_COLOR = (255, 80, 80)
SEPARATION_COLOR = (90, 255, 120)
CHART_COLORS = {
    "kinetic_J": (255, 165, 0),
    "spring_J": (255, 215, 0),
    "gravity_J": (90, 160, 255),
    "total_J": (255, 255, 255),
    "momentum_Ns": (230, 100, 230),
}
CHART_LABELS = {
    "kinetic_J": "kinetic",
    "spring_J": "spring",
    "gravity_J": "gravity",
    "total_J": "total",
    "momentum_Ns": "|momentum|",
}


def _faded(color: Sequence[int], alpha: float) -> tuple[int, int, int]:
    return tuple(int(c * alpha) for c in color[:3])


class AidsPainter:
    """Draws the teaching aids onto a GameWindow (kept apart from the core frame)."""

    def __init__(self, window) -> None:  # a GameWindow
        self.w = window

    def _px(self, point_m) -> tuple[float, float]:
        x, y = self.w.env.to_screen(np.asarray(point_m, dtype=float))
        return (float(x), float(y))

    def _text(self, text: str, pos_px, color, *, center: bool = False, font=None) -> None:
        font = font or self.w.label_font
        label = font.render(text, True, color)
        rect = label.get_rect(center=pos_px) if center else label.get_rect(topleft=pos_px)
        back = rect.inflate(4, 2)
        pygame.draw.rect(self.w.surface, (0, 0, 0), back)
        self.w.surface.blit(label, rect)

    def arrow(self, start_m, vector_m, color, width: int = 2) -> None:
        """An arrow from start_m along vector_m (both in metres)."""
        start = np.asarray(start_m, dtype=float)
        a, b = self._px(start), self._px(start + np.asarray(vector_m, dtype=float))
        length = math.hypot(b[0] - a[0], b[1] - a[1])
        if length < 1.0:
            return
        pygame.draw.line(self.w.surface, color, a, b, width)
        ux, uy = (b[0] - a[0]) / length, (b[1] - a[1]) / length
        head = min(10.0, 0.4 * length)
        left = (b[0] - head * (ux - 0.5 * uy), b[1] - head * (uy + 0.5 * ux))
        right = (b[0] - head * (ux + 0.5 * uy), b[1] - head * (uy - 0.5 * ux))
        pygame.draw.polygon(self.w.surface, color, [b, left, right])

    def arrows(self, starts_m: np.ndarray, vectors_m: np.ndarray, color) -> None:
        for s, v in zip(starts_m, vectors_m):
            self.arrow(s, v, color)

    def marker(self, point_m, color, label: str) -> None:
        x, y = self._px(point_m)
        pygame.draw.circle(self.w.surface, color, (x, y), 7, 2)
        pygame.draw.line(self.w.surface, color, (x - 11, y), (x + 11, y), 2)
        pygame.draw.line(self.w.surface, color, (x, y - 11), (x, y + 11), 2)
        self._text(label, (x + 12, y + 6), color)

    def legend(self, lines: Sequence[tuple[str, Sequence[int]]]) -> None:
        """Coloured lines of text in the top-left corner, under the HUD."""
        y = 100
        for text, color in lines:
            self._text(text, (10, y), color, font=self.w.font)
            y += 22

    def annotation(self, a, now_s: float) -> None:
        """Normal and tangent axes at the contact, overlap and separation with lengths and ratio."""
        alpha = a.alpha(now_s)
        n = np.asarray(a.normal)
        t = np.array([-n[1], n[0]])
        c = np.asarray(a.contact_m)
        reach = 0.8 * (a.radius_i_m + a.radius_j_m)
        for axis, color, name in ((n, ANNOTATION_NORMAL, "normal"), (t, ANNOTATION_TANGENT, "tangent")):
            p0, p1 = self._px(c - reach * axis), self._px(c + reach * axis)
            pygame.draw.line(self.w.surface, _faded(color, alpha), p0, p1, 2)
            self._text(name, p1, _faded(color, alpha))
        # Where the pucks were when the overlap was found, and after the correction.
        for pos, r, color in (
            (a.pos_i_before, a.radius_i_m, OVERLAP_COLOR),
            (a.pos_j_before, a.radius_j_m, OVERLAP_COLOR),
            (a.pos_i_after, a.radius_i_m, SEPARATION_COLOR),
            (a.pos_j_after, a.radius_j_m, SEPARATION_COLOR),
        ):
            r_px = max(2, int(round(float(self.w.env.length_to_px(r)))))
            pygame.draw.circle(self.w.surface, _faded(color, alpha), self._px(pos), r_px, 1)
        # The overlap along the normal at detection, the gap after correction.
        pi, pj = np.asarray(a.pos_i_before), np.asarray(a.pos_j_before)
        pygame.draw.line(
            self.w.surface,
            _faded(OVERLAP_COLOR, alpha),
            self._px(pj + n * a.radius_j_m),
            self._px(pi - n * a.radius_i_m),
            4,
        )
        qi, qj = np.asarray(a.pos_i_after), np.asarray(a.pos_j_after)
        gap_n = (qi - qj) / max(float(np.hypot(*(qi - qj))), 1e-12)
        pygame.draw.line(
            self.w.surface,
            _faded(SEPARATION_COLOR, alpha),
            self._px(qj + gap_n * a.radius_j_m),
            self._px(qi - gap_n * a.radius_i_m),
            4,
        )
        x, y = self._px(c)
        lines = [
            (f"overlap {a.overlap_m * 1000:.1f} mm", OVERLAP_COLOR),
            (f"separation {a.separation_m * 1000:.1f} mm", SEPARATION_COLOR),
        ]
        if a.ratio is not None:
            lines.append((f"ratio {a.ratio:.4f}", TEXT_COLOR))
        if a.angle_deg is not None:
            lines.append((f"paths {a.angle_deg:.2f} deg apart", ANNOTATION_NORMAL))
        for k, (text, color) in enumerate(lines):
            self._text(text, (x + 24, y + 24 + 20 * k), _faded(color, alpha), font=self.w.font)

    def energy_chart(self, series: dict[str, np.ndarray], latest: dict[str, float], note: str | None) -> None:
        """Strip chart of energies (left scale) and |momentum| (right scale), bottom right."""
        w, h = self.w.surface.get_size()
        box = pygame.Rect(w - 430, h - 266, 420, 231)
        panel = pygame.Surface(box.size, pygame.SRCALPHA)
        panel.fill((0, 0, 0, 200))
        self.w.surface.blit(panel, box)
        pygame.draw.rect(self.w.surface, DIM_TEXT, box, 1)
        plot = pygame.Rect(box.x + 10, box.y + 10, box.width - 150, box.height - 66)
        pygame.draw.rect(self.w.surface, (60, 60, 60), plot, 1)
        t = series["time_s"]
        if len(t) >= 2:
            span = max(t[-1] - t[0], 1e-9)
            xs = plot.x + (t - t[0]) / span * plot.width
            top_e = max(float(np.max(series["total_J"])), 1e-12) * 1.1
            top_p = max(float(np.max(series["momentum_Ns"])), 1e-12) * 1.1
            # Decimate to about one point per pixel column.
            pick = np.unique(np.linspace(0, len(t) - 1, min(len(t), plot.width)).astype(int))
            for key, color in CHART_COLORS.items():
                top = top_p if key == "momentum_Ns" else top_e
                ys = plot.bottom - np.clip(series[key] / top, 0.0, 1.0) * plot.height
                pts = np.stack([xs[pick], ys[pick]], axis=1)
                pygame.draw.lines(self.w.surface, color, False, pts.tolist(), 2 if key == "total_J" else 1)
            self._text(f"{top_e:.3g} J", (plot.x + 2, plot.y + 2), DIM_TEXT)
            self._text(f"last {span:.1f} s", (plot.x + 2, plot.bottom - 16), DIM_TEXT)
        y = box.y + 10
        for key, color in CHART_COLORS.items():
            value = f"{latest[key]:.4f} N s" if key == "momentum_Ns" else f"{latest[key]:.5g} J"
            self._text(f"{CHART_LABELS[key]}", (plot.right + 10, y), color)
            self._text(value, (plot.right + 10, y + 14), color)
            y += 34
        if note:
            for k, line in enumerate(_wrap(self.w.label_font, note, box.width - 20)[:3]):
                self._text(line, (box.x + 10, plot.bottom + 6 + 16 * k), DIM_TEXT)

    def inspector(self, point_m, lines: Sequence[str]) -> None:
        x, y = self._px(point_m)
        width = max(self.w.font.size(line)[0] for line in lines) + 16
        box = pygame.Rect(int(x) + 20, int(y) - 10, width, 22 * len(lines) + 10)
        box.clamp_ip(self.w.surface.get_rect())
        pygame.draw.rect(self.w.surface, (0, 0, 0), box)
        pygame.draw.rect(self.w.surface, (255, 220, 120), box, 1)
        for k, line in enumerate(lines):
            self.w.surface.blit(self.w.font.render(line, True, TEXT_COLOR), (box.x + 8, box.y + 6 + 22 * k))
