"""GameWindow: the only place that draws.

It draws a `Scene` (see scene.py) through an `Environment` transform, so the
teacher's window and every student's window share this code. Pucks are blitted
from cached sprites (one per size and colour) with `Surface.fblits`, which
keeps thousands of pucks at full frame rate.
"""

from __future__ import annotations

import math
import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pygame

from airtable.app.environment import Environment
from airtable.app.scene import Scene
from airtable.assets import ASSETS_DIR

BACKGROUND = (0, 0, 0)
BACKGROUND_GRAVITY = (20, 20, 70)
BACKGROUND_NO_CORRECTION = (40, 40, 40)
WALL_COLOR = (255, 69, 0)  # orange-red
TEXT_COLOR = (230, 230, 230)
DIM_TEXT = (150, 150, 150)
PANEL_COLOR = (10, 10, 30, 225)
MIN_PUCK_RADIUS_PX = 2
_COLORKEY = (1, 2, 3)  # sprite background; no puck uses this colour
_SPRITE_CACHE_LIMIT = 4096


def background_for(scene: Scene) -> tuple[int, int, int]:
    """The course's background code: grey when puck correction is off, blue with gravity."""
    if scene.puck_correction == "off":
        return BACKGROUND_NO_CORRECTION
    if scene.gravity_on:
        return BACKGROUND_GRAVITY
    return BACKGROUND


class GameWindow:
    """Owns the display surface (or an off-screen one when headless) and draws scenes."""

    def __init__(self, env: Environment, caption: str = "Air Table", headless: bool = False) -> None:
        if headless:  # no screen needed, so none is asked for
            os.environ.setdefault("SDL_VIDEODRIVER", "dummy")
        pygame.display.init()
        pygame.font.init()
        self.env = env
        self.headless = headless
        if headless:
            self.surface = pygame.Surface(env.size_px)
        else:
            self.surface = pygame.display.set_mode(env.size_px)
            pygame.display.set_icon(pygame.image.load(str(ASSETS_DIR / "icon.png")))
        self.set_caption(caption)
        self.font = pygame.font.Font(None, 22)
        self.big_font = pygame.font.Font(None, 40)
        self.label_font = pygame.font.Font(None, 18)
        self._sprites: dict[tuple[int, int, int, int], pygame.Surface] = {}
        self._trail_layer: pygame.Surface | None = None
        self._labels: dict[tuple, pygame.Surface] = {}
        self._status_bar: pygame.Surface | None = None

    def set_caption(self, caption: str) -> None:
        self.caption = caption
        if not self.headless:
            pygame.display.set_caption(caption)

    # ------------------------------------------------------------ frame

    def draw(
        self,
        scene: Scene,
        *,
        trails: bool = False,
        hud: Sequence[str] = (),
        banner: str | None = None,
        hud_color: Sequence[int] | None = None,
    ) -> None:
        """Draw a whole frame of `scene` into `self.surface`.

        `hud` lines go under the title; `hud_color`, if given, colours the first
        (a player's "You are C3" in the player's colour).

        With `trails` on, pucks are also stamped onto a layer that is never
        erased (the course's "erase off"), while springs, cursors and text stay
        crisp on top.
        """
        surf = self.surface
        surf.fill(background_for(scene))
        if trails:
            if self._trail_layer is None:
                self._trail_layer = pygame.Surface(surf.get_size())
                self._trail_layer.fill(_COLORKEY)
                self._trail_layer.set_colorkey(_COLORKEY)
            self._draw_pucks(self._trail_layer, scene)
            surf.blit(self._trail_layer, (0, 0))
        else:
            self._trail_layer = None
        self._draw_springs(scene)
        self._draw_pucks(surf, scene)
        self._draw_cursors(scene)
        self._draw_hud(scene, hud, hud_color)
        self._draw_walls(scene)  # last, so the status bar never hides the bottom wall
        if banner:
            self.draw_banner(banner)

    def clear_trails(self) -> None:
        """Forget the trails (after a demo change or a change of view)."""
        self._trail_layer = None

    def present(self) -> None:
        if not self.headless:
            pygame.display.flip()

    def save_screenshot(self, path: str | os.PathLike) -> Path:
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        pygame.image.save(self.surface, str(path))
        return path

    # ------------------------------------------------------------ parts

    def _draw_walls(self, scene: Scene) -> None:
        # The wall line sits just inside the table's edge, so it shows even
        # when the table exactly fills the window.
        (x0, y0), (x1, y1) = self.env.to_screen(np.array([[0.0, scene.height_m], [scene.width_m, 0.0]]))
        width = max(2, int(round(self.env.length_to_px(0.03))))
        rect = pygame.Rect(int(round(x0)), int(round(y0)), int(round(x1 - x0)), int(round(y1 - y0)))
        pygame.draw.rect(self.surface, WALL_COLOR, rect, width)

    def _puck_sprite(self, r_px: int, color: tuple[int, int, int]) -> pygame.Surface:
        key = (r_px, *color)
        sprite = self._sprites.get(key)
        if sprite is None:
            if len(self._sprites) > _SPRITE_CACHE_LIMIT:
                self._sprites.clear()
            size = 2 * r_px + 1
            sprite = pygame.Surface((size, size))
            sprite.fill(_COLORKEY)
            sprite.set_colorkey(_COLORKEY)
            center = (r_px, r_px)
            if r_px <= 3:
                pygame.draw.circle(sprite, color, center, r_px)
            else:
                # An outlined puck: a ring in its colour around a dark core.
                core = tuple(max(4, c * 3 // 10) for c in color)
                pygame.draw.circle(sprite, core, center, r_px)
                pygame.draw.circle(sprite, color, center, r_px, max(2, r_px // 6))
            self._sprites[key] = sprite
        return sprite

    def _draw_pucks(self, target: pygame.Surface, scene: Scene) -> None:
        n = len(scene.pos_m)
        if n == 0:
            return
        centers = self.env.to_screen(scene.pos_m)
        r_px = np.maximum(np.rint(self.env.length_to_px(scene.radius_m)), MIN_PUCK_RADIUS_PX).astype(np.int64)
        w, h = target.get_size()
        visible = (
            (centers[:, 0] + r_px >= 0)
            & (centers[:, 0] - r_px <= w)
            & (centers[:, 1] + r_px >= 0)
            & (centers[:, 1] - r_px <= h)
        )
        if not visible.all():
            centers, r_px, colors = centers[visible], r_px[visible], scene.color_rgb[visible]
        else:
            colors = scene.color_rgb
        # One sprite per distinct (radius, colour); usually a handful.
        c = colors.astype(np.int64)
        keys = (r_px << 24) | (c[:, 0] << 16) | (c[:, 1] << 8) | c[:, 2]
        uniq, inverse = np.unique(keys, return_inverse=True)
        sprites = [self._puck_sprite(int(k >> 24), (int(k >> 16) & 255, int(k >> 8) & 255, int(k) & 255)) for k in uniq]
        corner = np.rint(centers).astype(np.int64) - r_px[:, None]
        target.fblits(
            [(sprites[k], (x, y)) for k, x, y in zip(inverse.tolist(), corner[:, 0].tolist(), corner[:, 1].tolist())]
        )

    def _draw_springs(self, scene: Scene) -> None:
        if len(scene.spring_pairs) == 0:
            return
        a = scene.pos_m[scene.spring_pairs[:, 0]]
        b = scene.pos_m[scene.spring_pairs[:, 1]]
        d = a - b
        dist = np.hypot(d[:, 0], d[:, 1])
        # Width shows the strain: fatter when compressed, thinner when
        # stretched (the area of the rectangle is roughly kept).
        rest = np.maximum(scene.spring_length_m, 1e-6)
        width_m = scene.spring_width_m * np.clip(rest / np.maximum(dist, 1e-9), 0.0, 3.0)
        normal = np.stack([-d[:, 1], d[:, 0]], axis=1) / np.maximum(dist, 1e-9)[:, None]
        half = (0.5 * width_m)[:, None] * normal
        pa, pb = self.env.to_screen(a), self.env.to_screen(b)
        qa, qb = self.env.to_screen(a + half), self.env.to_screen(b + half)
        ra, rb = self.env.to_screen(a - half), self.env.to_screen(b - half)
        width_px = self.env.length_to_px(width_m)
        for s in range(len(scene.spring_pairs)):
            color = tuple(int(v) for v in scene.spring_color_rgb[s])
            if width_px[s] < 2.0 or dist[s] == 0.0:
                pygame.draw.line(self.surface, color, pa[s], pb[s], 1)
            else:
                pygame.draw.polygon(self.surface, color, [qa[s], qb[s], rb[s], ra[s]])

    def _draw_cursors(self, scene: Scene) -> None:
        for cur in scene.cursors:
            if 0 <= cur.held < len(scene.pos_m):
                start = self.env.to_screen(np.asarray(cur.cursor_m))
                end = self.env.to_screen(scene.pos_m[cur.held])
                pygame.draw.line(self.surface, cur.color, start, end, 2)
            self.draw_cursor(cur.name, cur.color, cur.cursor_m)

    def draw_cursor(self, name: str, color: Sequence[int], cursor_m: Sequence[float]) -> None:
        """A coloured arrow with the client's name, its tip at the cursor."""
        x, y = self.env.to_screen(np.asarray(cursor_m, dtype=float))
        arrow = [(x, y), (x + 4, y + 15), (x + 7, y + 10), (x + 13, y + 12)]
        pygame.draw.polygon(self.surface, color, arrow)
        pygame.draw.polygon(self.surface, (0, 0, 0), arrow, 1)
        key = (name, tuple(color))
        label = self._labels.get(key)
        if label is None:  # rendering text is the slow part of thirty cursors
            if len(self._labels) > 256:
                self._labels.clear()
            label = self._labels[key] = self.label_font.render(name, True, color)
        self.surface.blit(label, (x + 12, y + 14))

    def _draw_hud(self, scene: Scene, hud: Sequence[str], hud_color: Sequence[int] | None = None) -> None:
        w, h = self.surface.get_size()
        # Frame-rate box, top right.
        fps = self.font.render(f"{scene.fps:5.1f} fps", True, TEXT_COLOR)
        box = fps.get_rect(topright=(w - 8, 8)).inflate(10, 6)
        pygame.draw.rect(self.surface, (0, 0, 0), box)
        pygame.draw.rect(self.surface, DIM_TEXT, box, 1)
        self.surface.blit(fps, fps.get_rect(center=box.center))
        y = 8
        if scene.title:
            self.surface.blit(self.font.render(scene.title, True, TEXT_COLOR), (10, y))
            y += 22
        for k, line in enumerate(hud):
            color = tuple(hud_color) if (k == 0 and hud_color is not None) else DIM_TEXT
            self.surface.blit(self.font.render(line, True, color), (10, y))
            y += 20
        if scene.status:
            status = self.font.render(scene.status, True, TEXT_COLOR)
            # See-through, so pucks resting on the bottom wall stay visible.
            if self._status_bar is None or self._status_bar.get_width() != w:
                self._status_bar = pygame.Surface((w, 26), pygame.SRCALPHA)
                self._status_bar.fill((0, 0, 0, 150))
            self.surface.blit(self._status_bar, (0, h - 26))
            self.surface.blit(status, (10, h - 21))

    def draw_banner(self, text: str) -> None:
        """A big message across the middle of the window."""
        w, h = self.surface.get_size()
        label = self.big_font.render(text, True, (255, 220, 120))
        box = label.get_rect(center=(w // 2, h // 2)).inflate(30, 20)
        pygame.draw.rect(self.surface, (0, 0, 0), box)
        pygame.draw.rect(self.surface, (255, 220, 120), box, 2)
        self.surface.blit(label, label.get_rect(center=box.center))

    def draw_panel(
        self,
        title: str,
        rows: Sequence[tuple[str, str] | str],
        *,
        large: bool = False,
        side_title: str = "",
        side_rows: Sequence[tuple[str, str] | str] = (),
    ) -> None:
        """A translucent panel over the table: a title, then rows of text.

        A row is either a line of text (wrapped to the panel) or a
        (key, description) pair shown in two columns, as on the help screen.
        `side_rows`, if any, fill a narrower column on the right.
        """
        w, h = self.surface.get_size()
        font = self.big_font if large else self.font
        panel = pygame.Surface((w - 80, h - 80), pygame.SRCALPHA)
        panel.fill(PANEL_COLOR)
        top = 26 + self.big_font.get_linesize()
        panel.blit(self.big_font.render(title, True, (255, 220, 120)), (20, 16))
        width = panel.get_width() - 40
        if side_rows:
            side_w = int(width * 0.34)
            width -= side_w + 20
            x_side = 20 + width + 20
            panel.blit(self.font.render(side_title, True, (255, 220, 120)), (x_side, top - 24))
            self._panel_rows(panel, self.font, side_rows, x_side, top, side_w)
        self._panel_rows(panel, font, rows, 20, top, width)
        self.surface.blit(panel, (40, 40))

    def _panel_rows(self, panel, font, rows, x: int, y: int, width: int) -> None:
        line_h = font.get_linesize() + 2
        key_w = max((font.size(r[0])[0] for r in rows if isinstance(r, tuple)), default=0) + 16
        for row in rows:
            if isinstance(row, tuple):
                key, text = row
                panel.blit(font.render(key, True, (255, 220, 120)), (x, y))
                for line in _wrap(font, text, width - key_w) or [""]:
                    panel.blit(font.render(line, True, TEXT_COLOR), (x + key_w, y))
                    y += line_h
            else:
                for line in _wrap(font, row, width) or [""]:
                    panel.blit(font.render(line, True, TEXT_COLOR), (x, y))
                    y += line_h


def _wrap(font: pygame.font.Font, text: str, width: int) -> list[str]:
    """Split text into lines that fit `width` pixels."""
    lines: list[str] = []
    current = ""
    for word in text.split():
        trial = f"{current} {word}".strip()
        if current and font.size(trial)[0] > width:
            lines.append(current)
            current = word
        else:
            current = trial
    if current:
        lines.append(current)
    return lines


# ---------------------------------------------------------------- teaching aids

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

    def __init__(self, window: GameWindow) -> None:
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
