"""GameWindow: the only place that draws.

It draws a `Scene` (see scene.py) through an `Environment` transform, so the
teacher's window and every student's window share this code. The window is
resizable and can go fullscreen (F11); the table is fitted to it with its
aspect kept, and text and lines scale with the window's height, so a
projector at 1280x720 and a 4K screen both show all of it, readably.
Pucks are drawn by pucks_view.py, text panels by panel_view.py and the
teaching aids by aids_paint.py. On X11 the programs' entry points call
`prefer_plain_framebuffer` before a window opens: with 10000 pucks at
1920x1080 a frame then costs about 4 ms of CPU (draw 2.5, physics 0.5, flip
0.1) instead of 20 with SDL's OpenGL framebuffer in software.
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pygame

from airtable.app import panel_view
from airtable.app.aids_paint import AidsPainter  # noqa: F401  (imported from here by the app)
from airtable.app.environment import Environment, fitting_size_px
from airtable.app.hud_view import HudLine, HudStyle, TextLayout, draw_hud, fit_parts, fitting_parts, text_layout
from airtable.app.lessons_paint import LessonsPainter  # noqa: F401  (imported from here by the student's window)
from airtable.app.pucks_view import COLORKEY, PuckSprites, draw_pucks, radii_px
from airtable.app.timeline_paint import TimelinePainter  # noqa: F401  (imported from here by the student's window)
from airtable.assets import ASSETS_DIR
from airtable.model.scene import STATUS_SEPARATOR, CursorView, Scene

BANNER_LINES = 3  # a banner's sentence wraps over at most this many lines; the last is cut to fit

BACKGROUND = (0, 0, 0)
BACKGROUND_GRAVITY = (20, 20, 70)
BACKGROUND_NO_CORRECTION = (40, 40, 40)
MARGIN_COLOR = (12, 12, 12)  # outside the table, where the window is wider than it
WALL_COLOR = (255, 69, 0)  # orange-red
TEXT_COLOR = panel_view.TEXT_COLOR
DIM_TEXT = panel_view.DIM_TEXT
ACCENT = panel_view.ACCENT
PAUSED_COLOR = (255, 210, 60)
REFERENCE_HEIGHT_PX = 720  # type sizes below are for a window this tall, and scale with it
# Font sizes (pygame's default font) at the reference height, and their floor:
# the smallest, 22, is 15 px tall, so no text is under 14 px at 720p.
FONT_SIZES = {"label": (24, 22), "text": (28, 22), "big": (44, 30)}

PAUSED = "PAUSED"
IDLE = "idle"  # the frame rate's corner while the loop idles (loop.py's IdlingLoop)
FRAMEBUFFER_HINT = "SDL_FRAMEBUFFER_ACCELERATION"


def prefer_plain_framebuffer() -> bool:
    """On X11, ask SDL to keep the window's pixels in its plain shared-memory framebuffer.

    For the entry points (the app's and the student client's main), before
    their window opens; never on import. Otherwise SDL 2 puts an OpenGL
    texture behind the window surface, and where OpenGL runs in software (no
    GPU driver, a virtual machine, Xvfb) each flip of a 1920x1080 window takes
    11-35 ms against 1-3 ms: the difference between 30 and 60 fps. Only X11
    has both ways, so other drivers are left alone (on Wayland or macOS the
    hint would leave the window without pixels). A value already set, by the
    user or a test, is kept. True if the hint is set now.
    """
    try:
        pygame.display.init()  # picks the driver; opens no window
    except pygame.error:
        return False  # opening the window will say why
    if pygame.display.get_driver() == "x11":
        os.environ.setdefault(FRAMEBUFFER_HINT, "0")  # SDL reads it when the window's surface is made
    return os.environ.get(FRAMEBUFFER_HINT) == "0"


def background_for(scene: Scene) -> tuple[int, int, int]:
    """The course's background code: grey when puck correction is off, blue with gravity."""
    if scene.puck_correction == "off":
        return BACKGROUND_NO_CORRECTION
    if scene.gravity_on:
        return BACKGROUND_GRAVITY
    return BACKGROUND


def margins_around(screen: pygame.Rect, inner: pygame.Rect) -> list[pygame.Rect]:
    """The parts of `screen` outside `inner`: up to four rectangles (above, below, left, right)."""
    inner = inner.clip(screen)
    if not inner.width or not inner.height:
        return [screen]
    parts = [
        pygame.Rect(screen.left, screen.top, screen.width, inner.top - screen.top),
        pygame.Rect(screen.left, inner.bottom, screen.width, screen.bottom - inner.bottom),
        pygame.Rect(screen.left, inner.top, inner.left - screen.left, inner.height),
        pygame.Rect(inner.right, inner.top, screen.right - inner.right, inner.height),
    ]
    return [r for r in parts if r.width > 0 and r.height > 0]


class GameWindow:
    """Owns the display surface (or an off-screen one when headless) and draws scenes.

    `size_px` is the window's size (default: the table's shape in 90 % of the
    desktop; headless: the Environment's size); `fullscreen` starts on the whole
    desktop. Pass every event to `handle_event`: it follows resizes and F11.
    """

    def __init__(
        self,
        env: Environment,
        caption: str = "Air Table",
        headless: bool = False,
        *,
        size_px: Sequence[int] | None = None,
        fullscreen: bool = False,
    ) -> None:
        # A headless window draws on a plain Surface; its entry point chose the
        # dummy video driver (cli.main, the player's main, tests/conftest.py).
        pygame.display.init()
        pygame.font.init()
        self.env = env
        self.headless = headless
        self.fullscreen = False
        self.sprites = PuckSprites()
        self._fonts: dict[int, pygame.font.Font] = {}
        self._trail_layer: pygame.Surface | None = None
        self._labels: dict[tuple, pygame.Surface] = {}
        self._panels: dict[tuple, tuple[pygame.Surface, int]] = {}
        # Where the last frame's panel lay (None: no panel), so what is drawn before the panels can keep clear of
        # one that leaves room (the lecture notes, only as tall as their text): the chart does.
        self.panel_area: pygame.Rect | None = None
        self._panel_drawn: pygame.Rect | None = None
        self._status_bar: pygame.Surface | None = None
        self.hud_bottom_px = 0  # below the title and HUD lines: panels start under it
        self.corner_bottom_px = 0  # below the frame rate and PAUSED in the top right corner (margins layout)
        self.layout = TextLayout(0, 0)  # where the text goes (hud_view.py)
        self.show_fps = False  # the frame rate in a corner (--stats): not for the room
        self.idle = False  # the loop idles (a still table): the corner says IDLE instead of the frame rate
        self.label_boxes: list[pygame.Rect] = []  # text drawn this frame; the aids place labels around it
        self.hud_boxes: list[pygame.Rect] = []  # the window's own text this frame: cursors' names keep off it
        self.status_top_px = 0
        self.status_boxes: list[tuple[str, pygame.Rect]] = []  # each part of the status line drawn, and where
        self.cursor_boxes: list[pygame.Rect] = []  # the cursors' names drawn this frame
        self._windowed_at: tuple[int, int] | None = None  # where the window was before fullscreen (F11)
        if headless:
            self.windowed_size_px = tuple(int(v) for v in (size_px or env.size_px))
            self.surface = pygame.Surface(self.windowed_size_px)
        else:
            self.windowed_size_px = tuple(int(v) for v in (size_px or self.default_size_px()))
            self._open(fullscreen)
            icon = ASSETS_DIR / "icon.png"
            if icon.is_file():
                pygame.display.set_icon(pygame.image.load(str(icon)))
        self._sized()
        self.set_caption(caption)

    # ------------------------------------------------------------ the window itself

    def default_size_px(self) -> tuple[int, int]:
        """The table's shape in at most 90 % of the (first) desktop."""
        try:
            desktop = pygame.display.get_desktop_sizes()[0]
        except (pygame.error, IndexError):
            desktop = (1280, 720)
        return fitting_size_px(desktop, self.env.width_m / self.env.height_m)

    def _open(self, fullscreen: bool) -> None:
        if fullscreen:
            # Size (0, 0) with FULLSCREEN: the desktop's own mode, no mode switch.
            self.surface = pygame.display.set_mode((0, 0), pygame.FULLSCREEN)
        else:
            with warnings.catch_warnings():  # a window manager may keep the fullscreen size at first
                warnings.simplefilter("ignore", RuntimeWarning)
                self.surface = pygame.display.set_mode(self.windowed_size_px, pygame.RESIZABLE)
                if self.surface.get_size() != self.windowed_size_px:
                    # Leaving fullscreen, SDL restores the size it had set for fullscreen (the
                    # desktop's); once windowed, the window takes the size asked for again.
                    self.surface = pygame.display.set_mode(self.windowed_size_px, pygame.RESIZABLE)
        self.fullscreen = fullscreen

    def put_pointer_on(self, point_m) -> tuple[int, int]:
        """Move the pointer (a real window's) over the table's point_m, or as near as the window reaches;
        returns where (px)."""
        x, y = self.env.to_screen(point_m)
        w, h = self.surface.get_size()
        at = (min(max(round(x), 0), w - 1), min(max(round(y), 0), h - 1))
        if not self.headless:
            pygame.mouse.set_pos(at)
        return at

    def toggle_fullscreen(self) -> None:
        """Desktop fullscreen on or off (F11); the windowed size comes back after."""
        if self.headless:
            return
        if not self.fullscreen:
            self.windowed_size_px = self.surface.get_size()
            self._windowed_at = pygame.display.get_window_position()
        self._open(not self.fullscreen)
        if not self.fullscreen and self._windowed_at is not None:
            # Where it was: left to itself, the window came back a title bar lower each time.
            pygame.display.set_window_position(self._windowed_at)
        self._sized()

    def resize(self, size_px: Sequence[int]) -> None:
        """Make the window (headless: the off-screen surface) `size_px` big; leaves fullscreen."""
        size = (max(1, int(size_px[0])), max(1, int(size_px[1])))
        if self.headless:
            self.surface = pygame.Surface(size)
        else:
            self.windowed_size_px = size
            self._open(False)
        self._sized()

    def set_env(self, env: Environment) -> None:
        """Show another table (a student's window, when the teacher restarts with another size)."""
        self.env = env
        self._sized()

    def _sized(self) -> None:
        """After any change of size: the type, the transform and the layers follow."""
        self.unit = self.surface.get_height() / REFERENCE_HEIGHT_PX
        self.label_font = self._font("label")
        self.font = self._font("text")
        self.big_font = self._font("big")
        size = self.surface.get_size()
        aspect = self.env.width_m / self.env.height_m
        self.layout = text_layout(size, aspect, self.font.get_linesize(), self.status_bar_px)
        self.env.resize(size, bottom_px=self.status_bar_px, top_px=self.layout.top_px)
        self._trail_layer = None
        self._status_bar = None
        self._labels.clear()
        self._panels.clear()

    @property
    def timeline_strip_px(self) -> int:
        """The strip along the top of the status bar kept for the rewind timeline."""
        return max(2, self.line_px(4))

    @property
    def status_bar_px(self) -> int:
        """The status bar's height, with the timeline's strip: the table is fitted above it (Environment.resize)."""
        return self.font.get_linesize() + self.font.get_height() // 2 + self.timeline_strip_px

    def _size_px(self, role: str) -> int:
        size, floor = FONT_SIZES[role]
        return max(floor, round(size * self.unit))

    def _font(self, role: str) -> pygame.font.Font:
        return self._font_px(self._size_px(role))

    def _font_px(self, px: int) -> pygame.font.Font:
        font = self._fonts.get(px)
        if font is None:
            if len(self._fonts) > 32:  # many resizes: keep the cache small
                self._fonts.clear()
            font = self._fonts[px] = pygame.font.Font(None, px)
        return font

    def _panel_font(self, sections, rect: pygame.Rect, largest: str = "text") -> pygame.font.Font:
        """The largest type from the size of `largest` (a FONT_SIZES role) down to the smallest readable
        size that fits the panel on one page."""
        best = None
        for px in range(self._size_px(largest), FONT_SIZES["label"][1] - 1, -2):
            font = self._font_px(px)
            pages = len(
                panel_view.layout(font, sections, panel_view.body_rect(rect.size, font, self.big_font, font).size)
            )
            if pages == 1:
                return font
            best = best if best is not None and best[0] <= pages else (pages, font)
        return best[1]

    def line_px(self, width_at_720: float = 2.0) -> int:
        """A line width that scales with the window: `width_at_720` px at 720 px tall, never under 2."""
        return max(2, round(width_at_720 * self.unit))

    def follow_display(self) -> None:
        """Catch up with a size the window manager gave the display without an event we saw,
        or with a new Environment handed to `self.env` (a player's, on reconnecting)."""
        if self.env.size_px != self.surface.get_size():
            self._sized()
        if not self.headless:
            display = pygame.display.get_surface()
            if display is not None and (display is not self.surface or display.get_size() != self.env.size_px):
                self.surface = display
                if not self.fullscreen:
                    self.windowed_size_px = display.get_size()
                self._sized()

    def handle_event(self, event: pygame.event.Event) -> bool:
        """Resizes and F11 (fullscreen); True when the event was one of those."""
        if event.type in (pygame.VIDEORESIZE, pygame.WINDOWSIZECHANGED):
            if self.headless:  # posted by a test: there is no display to follow
                self.resize(event.size if event.type == pygame.VIDEORESIZE else (event.x, event.y))
            else:  # the display surface already has the new size
                self.follow_display()
            return True
        if event.type == pygame.KEYDOWN and event.key == pygame.K_F11:
            self.toggle_fullscreen()
            return True
        return False

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
        (a player's "You are C3" in the player's colour). Of the status line's
        parts (most important first) those that do not fit the width are
        dropped from the end, and a "PAUSED" part is shown large.

        With `trails` on, pucks are also stamped onto a layer that is never
        erased (the course's "erase off"), while springs, cursors and text stay
        crisp on top.
        """
        self.follow_display()
        self.label_boxes = []
        self.panel_area, self._panel_drawn = self._panel_drawn, None
        surf = self.surface
        table = self._table_rect(scene)
        for margin in margins_around(surf.get_rect(), table):  # not the whole screen: each fill costs its pixels
            surf.fill(MARGIN_COLOR, margin)
        surf.fill(background_for(scene), table)
        if trails:
            if self._trail_layer is None:
                self._trail_layer = pygame.Surface(surf.get_size())
                self._trail_layer.fill(COLORKEY)
                self._trail_layer.set_colorkey(COLORKEY)
            self._draw_pucks(self._trail_layer, scene)
            surf.blit(self._trail_layer, (0, 0))
        else:
            self._trail_layer = None
        self._draw_springs(scene)
        self._draw_pucks(surf, scene)
        self._draw_walls(scene)
        if hud_color is not None and hud:
            hud = [(hud[0], hud_color), *hud[1:]]
        self._draw_hud(scene, hud)  # on opaque ground: a zoomed view passes under it
        self._draw_cursors(scene)  # the pointers over everything
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

    def _table_rect(self, scene: Scene) -> pygame.Rect:
        """The table on screen, clipped to the window (no huge rectangles when zoomed in)."""
        (x0, y0), (x1, y1) = self.env.to_screen(np.array([[0.0, scene.height_m], [scene.width_m, 0.0]]))
        w, h = self.surface.get_size()
        left, top = int(round(np.clip(x0, -2, w + 2))), int(round(np.clip(y0, -2, h + 2)))
        right, bottom = int(round(np.clip(x1, -2, w + 2))), int(round(np.clip(y1, -2, h + 2)))
        return pygame.Rect(left, top, max(0, right - left), max(0, bottom - top))

    def wall_rects(self, size_m: Sequence[float] | None = None) -> list[pygame.Rect]:
        """The four walls' lines on screen for a table of `size_m` (default: the view's), clipped near
        the window (none when the table is out of view).

        The wall line sits just inside the table's edge, so it shows even when the table
        exactly fills the window."""
        width_m, height_m = size_m if size_m is not None else (self.env.width_m, self.env.height_m)
        width = max(self.line_px(2), int(round(self.env.length_to_px(0.03))))
        width = min(width, 4 * self.line_px(2))
        (x0, y0), (x1, y1) = self.env.to_screen(np.array([[0.0, height_m], [width_m, 0.0]]))
        w, h = self.surface.get_size()
        if not (x0 < w and x1 > 0 and y0 < h and y1 > 0):
            return []
        top, bottom = max(y0, -width), min(y1, h + width)
        left, right = max(x0, -width), min(x1, w + width)
        return [
            pygame.Rect(*(int(round(v)) for v in rect))
            for rect in (
                (left, y0, right - left, width),
                (left, y1 - width, right - left, width),
                (x0, top, width, bottom - top),
                (x1 - width, top, width, bottom - top),
            )
        ]

    def _draw_walls(self, scene: Scene) -> None:
        for rect in self.wall_rects((scene.width_m, scene.height_m)):
            self.surface.fill(WALL_COLOR, rect)

    def _draw_pucks(self, target: pygame.Surface, scene: Scene) -> None:
        if len(scene.pos_m) == 0:
            return
        centers = self.env.to_screen(scene.pos_m)
        r_px = radii_px(self.env.length_to_px(scene.radius_m), scene.color_rgb, target.get_size())
        draw_pucks(target, self.sprites, centers, r_px, scene.color_rgb)

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
        thin = self.line_px(1)
        for s in range(len(scene.spring_pairs)):
            color = tuple(int(v) for v in scene.spring_color_rgb[s])
            if width_px[s] < 2.0 * thin or dist[s] == 0.0:
                pygame.draw.line(self.surface, color, pa[s], pb[s], thin)
            else:
                pygame.draw.polygon(self.surface, color, [qa[s], qb[s], rb[s], ra[s]])

    def _draw_cursors(self, scene: Scene) -> None:
        self.cursor_boxes = []
        for cur in scene.cursors:
            self.draw_cursor_view(scene, cur)

    def draw_cursor_view(self, scene: Scene, cur: CursorView) -> None:
        """One cursor of `scene`: its string to the puck it holds, its arrow, its name (kept in `cursor_boxes`)."""
        if 0 <= cur.held < len(scene.pos_m):
            start = self.env.to_screen(np.asarray(cur.cursor_m))
            end = self.env.to_screen(scene.pos_m[cur.held])
            pygame.draw.line(self.surface, cur.color, start, end, self.line_px(2))
        self.cursor_boxes.append(self.draw_cursor(cur.name, cur.color, cur.cursor_m))

    def draw_cursor(self, name: str, color: Sequence[int], cursor_m: Sequence[float]) -> pygame.Rect:
        """A coloured arrow with the client's name on dark ground, its tip at the cursor; returns the name's box."""
        x, y = self.env.to_screen(np.asarray(cursor_m, dtype=float))
        u = max(1.0, self.unit)
        arrow = [(x, y), (x + 4 * u, y + 15 * u), (x + 7 * u, y + 10 * u), (x + 13 * u, y + 12 * u)]
        pygame.draw.polygon(self.surface, color, arrow)
        pygame.draw.polygon(self.surface, (0, 0, 0), arrow, 1)
        key = (name, tuple(color))
        label = self._labels.get(key)
        if label is None:  # rendering text is the slow part of thirty cursors
            if len(self._labels) > 256:
                self._labels.clear()
            label = self._labels[key] = self.label_font.render(name, True, color, (0, 0, 0))  # on dark ground
        return self.surface.blit(label, self._cursor_label_box(label.get_size(), x, y, u))

    def world_area(self) -> pygame.Rect:
        """The window between the top band of text and the status bar: where drawings on the table may go
        (an arrow running off the table stops there, not over the status line)."""
        return pygame.Rect(
            0, self.layout.top_px, self.surface.get_width(), max(0, self.status_top_px - self.layout.top_px)
        )

    def _cursor_label_box(self, size: tuple[int, int], x: float, y: float, u: float) -> pygame.Rect:
        """Where a cursor's name goes: beside its arrow (below right; at the right edge left of it; at the
        bottom above it), on screen and off the window's own text (the heads-up lines, the status line)
        and off the names drawn before it (a user test: two cursors at one spot wrote over each other: the
        later one goes a line further down or up); where no such spot is, between the top band and the
        status bar. A cursor out of the view (zoomed in) has its name at the edge nearest to it, on the first
        free line along that edge (a user test: after a zoom the idle students' names piled up on the title)."""
        below, above = y + 14 * u, y - 2 * u - size[1]
        free = self.world_area()
        right_of, left_of = int(x + 12 * u), int(x - 2 * u) - size[0]
        tops = [top + k * size[1] * way for k in range(8) for top, way in ((below, 1), (above, -1))]
        spots = [pygame.Rect((left, int(top)), size) for top in tops for left in (right_of, left_of)]
        taken = self.hud_boxes + self.cursor_boxes
        clear = [b for b in spots if free.contains(b) and b.collidelist(taken) < 0]
        if clear:
            return clear[0]
        edge = spots[0].clamp(free if free.height >= size[1] else self.surface.get_rect())
        lines = max(1, free.height // max(1, size[1]))
        along = (edge.move(0, k * size[1] * way) for k in range(1, lines + 1) for way in (1, -1))
        return next((b for b in along if free.contains(b) and b.collidelist(taken) < 0), edge)

    def _draw_hud(self, scene: Scene, hud: Sequence[HudLine]) -> None:
        """The title, heads-up lines, frame rate and PAUSED in their places (hud_view.py), then the
        status line along the bottom (_draw_status)."""
        parts = [p.strip() for p in scene.status_parts]
        paused = PAUSED in parts
        parts = [p for p in parts if p != PAUSED]
        style = HudStyle(self.font, self.big_font, TEXT_COLOR, DIM_TEXT, PAUSED_COLOR, self.line_px(3))
        fps = (IDLE if self.idle else f"{scene.fps:5.1f} fps") if self.show_fps else None
        drawn = draw_hud(self.surface, self.layout, style, scene.title, hud, fps, paused)
        boxes, self.hud_bottom_px, self.corner_bottom_px = drawn
        self.label_boxes.extend(boxes)
        self.hud_boxes = list(boxes)
        self._draw_status(parts)

    def _draw_status(self, parts: Sequence[str]) -> None:
        """The status line in a bar along the bottom: its parts (most important first) as fit the width,
        the least important shortened, then left out, each whole (hud_view.fitting_parts); `status_boxes`
        says where each went."""
        w, h = self.surface.get_size()
        pad, bar_h = self.font.get_height() // 2, self.status_bar_px
        self.status_top_px = h - bar_h if parts else h
        self.status_boxes = []
        if not parts:
            return
        bar = pygame.Rect(0, h - bar_h, w, bar_h)
        self.surface.fill((0, 0, 0), bar)
        self.label_boxes.append(bar)
        self.hud_boxes.append(bar)
        x, top = pad, h - bar_h + self.timeline_strip_px + pad // 2
        gap = self.font.size(STATUS_SEPARATOR)[0]
        for part in fitting_parts(self.font, parts, w - 2 * pad):
            box = self.surface.blit(self.font.render(part, True, TEXT_COLOR), (x, top))
            self.status_boxes.append((part, box))
            x = box.right + gap

    def draw_banner(self, text: str) -> None:
        """A big message across the middle of the window, over up to BANNER_LINES lines (a user test: one
        line cut "...: the network..." before the advice)."""
        w, h = self.surface.get_size()
        lines = panel_view.wrap(self.big_font, text, w - 40)
        if not lines:
            return
        if len(lines) > BANNER_LINES:
            lines = [
                *lines[: BANNER_LINES - 1],
                fit_parts(self.big_font, [" ".join(lines[BANNER_LINES - 1 :])], w - 40),
            ]
        labels = [self.big_font.render(line, True, ACCENT) for line in lines]
        pad, step = self.font.get_height(), self.big_font.get_linesize()
        inner = pygame.Rect(0, 0, max(label.get_width() for label in labels), step * len(labels))
        inner.center = (w // 2, h // 2)
        box = inner.inflate(pad, pad // 2)
        pygame.draw.rect(self.surface, (0, 0, 0), box)
        pygame.draw.rect(self.surface, ACCENT, box, self.line_px(2))
        for k, label in enumerate(labels):
            self.surface.blit(label, label.get_rect(midtop=(w // 2, inner.top + k * step)))

    def panel_rect(self) -> pygame.Rect:
        """Where panels go: under the top band, or right of the left margin (the join line stays
        visible either way), and under the frame rate and PAUSED in the top right corner, above the
        status bar. Sideways a panel reaches the window's edges: the chart, the values and the momenta
        in the right margin or at the table's edges are covered whole, none peeks out from under it
        (a user test saw the chart's edge beside the roster in fullscreen, and the values' at 640x480)."""
        pad = self.font.get_height() // 2
        top = max(pad, self.layout.top_px + pad // 2, self.corner_bottom_px + pad // 2)
        left = self.layout.side_px  # (0: no margins)
        height = max(4 * self.font.get_linesize(), self.status_top_px - top)
        return pygame.Rect(left, top, self.surface.get_width() - left, height)

    def draw_question(self, title: str, lines: Sequence[str]) -> pygame.Rect:
        """A short question in an opaque box just big enough for it, in the middle of the window."""
        font, title_font = self.font, self.big_font
        pad = font.get_height()
        width = min(self.surface.get_width() - 2 * pad, max(font.size(t)[0] for t in [title, *lines]) + 2 * pad)
        wrapped = [row for line in lines for row in panel_view.wrap(font, line, width - 2 * pad)]
        height = title_font.get_linesize() + len(wrapped) * font.get_linesize() + 2 * pad
        box = pygame.Rect(0, 0, width, height)
        box.center = self.surface.get_rect().center
        pygame.draw.rect(self.surface, panel_view.PANEL_COLOR[:3], box)
        pygame.draw.rect(self.surface, ACCENT, box, self.line_px(2))
        title_text = panel_view.shorten(title_font, title, width - 2 * pad)
        self.surface.blit(title_font.render(title_text, True, ACCENT), (box.x + pad, box.y + pad // 2))
        y = box.y + pad // 2 + title_font.get_linesize() + pad // 2
        for row in wrapped:
            self.surface.blit(font.render(row, True, TEXT_COLOR), (box.x + pad, y))
            y += font.get_linesize()
        self.label_boxes.append(box)
        return box

    def panel_rows(self) -> int:
        """How many one-line rows a panel holds on one page at the smallest readable type."""
        font = self._font_px(FONT_SIZES["label"][1])
        body = panel_view.body_rect(self.panel_rect().size, font, self.big_font, self.label_font)
        return max(3, body.height // font.get_linesize())

    def draw_panel(
        self,
        title: str,
        rows: Sequence[panel_view.Row],
        *,
        large: bool = False,
        side_title: str = "",
        side_rows: Sequence[panel_view.Row] = (),
        page: int = 0,
        page_key: str | None = None,
    ) -> int:
        """A translucent panel over the table: a title, then rows of text; returns its number of pages.

        A row is either a line of text (wrapped to the panel) or a (key,
        description) pair shown in two columns, as on the help screen.
        `side_rows`, if any, follow under their own `side_title`. Rows flow
        into columns and, if they still do not fit, onto pages: `page` picks one, `page_key` turns them
        (None: no key does; the note under the page says a larger window shows the rest).
        `large`: in the large type where the text fits on one page, the panel no taller than the text.
        """
        sections = [("", tuple(rows))]
        if side_rows:
            sections.append((side_title, tuple(side_rows)))
        rect = self.panel_rect()
        key = (title, tuple(sections), large, rect.size, page, page_key)
        cached = self._panels.get(key)
        if cached is None:  # laying out and rendering text is slow: once per content and size
            font = self._panel_font(sections, rect, "big" if large else "text")
            cached = panel_view.render_panel(
                rect.size,
                title,
                sections,
                font=font,
                title_font=self.big_font,
                small_font=self.label_font,
                page=page,
                page_key=page_key,
                fit=large,
            )
            if len(self._panels) >= 8:
                self._panels.clear()
            self._panels[key] = cached
        self._panel_drawn = self.surface.blit(cached[0], rect)
        return cached[1]
