"""GameWindow: the only place that draws.

It draws a `Scene` (see scene.py) through an `Environment` transform, so the
teacher's window and every student's window share this code. Pucks are blitted
from cached sprites (one per size and colour) with `Surface.fblits`, which
keeps thousands of pucks at full frame rate.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pygame

from airtable.environment import Environment
from airtable.scene import Scene

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
            icon = Path(__file__).resolve().parent / "assets" / "icon.png"
            if icon.exists():
                pygame.display.set_icon(pygame.image.load(str(icon)))
        self.set_caption(caption)
        self.font = pygame.font.Font(None, 22)
        self.big_font = pygame.font.Font(None, 40)
        self.label_font = pygame.font.Font(None, 18)
        self._sprites: dict[tuple[int, int, int, int], pygame.Surface] = {}
        self._trail_layer: pygame.Surface | None = None

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
    ) -> None:
        """Draw a whole frame of `scene` into `self.surface`.

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
        self._draw_hud(scene, hud)
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
        if path.parent and not path.parent.exists():
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
        label = self.label_font.render(name, True, color)
        self.surface.blit(label, (x + 12, y + 14))

    def _draw_hud(self, scene: Scene, hud: Sequence[str]) -> None:
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
        for line in hud:
            self.surface.blit(self.font.render(line, True, DIM_TEXT), (10, y))
            y += 20
        if scene.status:
            status = self.font.render(scene.status, True, TEXT_COLOR)
            bar = pygame.Rect(0, h - 26, w, 26)
            pygame.draw.rect(self.surface, (0, 0, 0), bar)
            self.surface.blit(status, (10, h - 21))

    def draw_banner(self, text: str) -> None:
        """A big message across the middle of the window."""
        w, h = self.surface.get_size()
        label = self.big_font.render(text, True, (255, 220, 120))
        box = label.get_rect(center=(w // 2, h // 2)).inflate(30, 20)
        pygame.draw.rect(self.surface, (0, 0, 0), box)
        pygame.draw.rect(self.surface, (255, 220, 120), box, 2)
        self.surface.blit(label, label.get_rect(center=box.center))

    def draw_panel(self, title: str, rows: Sequence[tuple[str, str] | str], *, large: bool = False) -> None:
        """A translucent panel over the table: a title, then rows of text.

        A row is either a line of text (wrapped to the panel) or a
        (key, description) pair shown in two columns, as on the help screen.
        """
        w, h = self.surface.get_size()
        font = self.big_font if large else self.font
        line_h = font.get_linesize() + 2
        panel = pygame.Surface((w - 80, h - 80), pygame.SRCALPHA)
        panel.fill(PANEL_COLOR)
        inner_w = panel.get_width() - 40
        y = 16
        panel.blit(self.big_font.render(title, True, (255, 220, 120)), (20, y))
        y += self.big_font.get_linesize() + 10
        key_w = max((font.size(r[0])[0] for r in rows if isinstance(r, tuple)), default=0) + 24
        for row in rows:
            if isinstance(row, tuple):
                key, text = row
                panel.blit(font.render(key, True, (255, 220, 120)), (20, y))
                for line in _wrap(font, text, inner_w - key_w):
                    panel.blit(font.render(line, True, TEXT_COLOR), (20 + key_w, y))
                    y += line_h
            else:
                for line in _wrap(font, row, inner_w) or [""]:
                    panel.blit(font.render(line, True, TEXT_COLOR), (20, y))
                    y += line_h
        self.surface.blit(panel, (40, 40))


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
