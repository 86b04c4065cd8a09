"""Where the window's own text goes, so that it never lies over the table or its walls.

The title, the heads-up lines (the join line, the student count, messages),
the frame rate, PAUSED and the status line each have a place of their own:

- the status line in a band along the bottom (the table is fitted above it);
- where the window is much wider than the table (a 16:9 screen), the rest in
  the side margins: title and heads-up lines down the left, frame rate and
  PAUSED at the top of the right;
- elsewhere, in a band of `BAND_LINES` lines along the top.

`text_layout` decides which, from the window's size alone, so the table does
not jump when a message comes or goes. `draw_hud` draws into those places on
opaque ground, so a zoomed or panned view passes under the text, never over it.
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass

import pygame

from airtable.app import panel_view
from airtable.model.scene import STATUS_SEPARATOR

BAND_LINES = 3  # the top band: the title (with the frame rate and PAUSED), then two heads-up lines
# Side margins at least this share of the window's height hold the text instead of a top band.
SIDE_MIN_SHARE = 0.18
GROUND = (0, 0, 0)  # under the text: opaque
HudLine = str | tuple[str, Sequence[int]]  # a line, or a line and its colour
HINT = re.compile(r"\s*\([^()]*\)$")  # a closing remark in brackets: what a narrow window leaves out first


@dataclass(frozen=True)
class TextLayout:
    """Bands kept clear of the table, in pixels: along the top, and down each side (0: none)."""

    top_px: int
    side_px: int


def text_layout(size_px: Sequence[int], aspect: float, line_px: int, bar_px: int) -> TextLayout:
    """The text's places for a window of `size_px` showing a table `aspect` (width / height) wide."""
    w, h = (int(v) for v in size_px)
    room = max(1, h - bar_px)
    margin = (w - min(w, room * aspect)) / 2
    if margin >= SIDE_MIN_SHARE * h:
        return TextLayout(top_px=0, side_px=int(margin))
    return TextLayout(top_px=BAND_LINES * line_px + line_px // 2, side_px=0)


def fold_lines(lines: Sequence[HudLine], count: int, font: pygame.font.Font, width_px: int) -> list[HudLine]:
    """`lines` into at most `count`: the last (the newest message) keeps a line of its own, the
    first ones share a line, the least important (later) parts dropped if they do not fit."""
    lines = list(lines)
    if len(lines) <= count:
        return lines
    head, tail = lines[: len(lines) - count + 1], lines[len(lines) - count + 1 :]
    joined = fit_parts(font, [_text(line) for line in head], width_px)
    return [joined if isinstance(head[0], str) else (joined, head[0][1]), *tail]


def fit_parts(font: pygame.font.Font, parts: Sequence[str], width_px: int, separator: str = STATUS_SEPARATOR) -> str:
    """`parts` (most important first) joined by `separator`, made to fit `width_px` (fitting_parts)."""
    return separator.join(fitting_parts(font, parts, width_px, separator))


def fitting_parts(
    font: pygame.font.Font, parts: Sequence[str], width_px: int, separator: str = STATUS_SEPARATOR
) -> list[str]:
    """`parts` (most important first), made to fit `width_px` once joined by `separator`: first they lose
    their hints, the least important first ("PREDICT: 2 of 5 predicted (F6 reveals)" reads "PREDICT: 2 of 5
    predicted"), then the least important go whole. Only a first part too wide alone is cut, with "..."."""
    parts = [p for p in parts if p]

    def fits(shown: list[str]) -> bool:
        return font.size(separator.join(shown))[0] <= width_px

    for k in reversed(range(len(parts))):
        if fits(parts):
            return parts
        parts[k] = without_hint(parts[k])
    while len(parts) > 1 and not fits(parts):
        parts.pop()
    if parts and not fits(parts):
        return [panel_view.shorten(font, parts[0], width_px)]
    return parts


def without_hint(part: str) -> str:
    """`part` without a closing remark in brackets ("0 students (F2: roster)" -> "0 students")."""
    short = HINT.sub("", part)
    return short or part


def _text(line: HudLine) -> str:
    return line if isinstance(line, str) else line[0]


def _color(line: HudLine, default):
    return default if isinstance(line, str) else tuple(line[1])


@dataclass
class HudStyle:
    """The fonts and colours the heads-up text is drawn with."""

    font: pygame.font.Font
    big_font: pygame.font.Font
    text: Sequence[int]
    dim: Sequence[int]
    paused: Sequence[int]
    line_px: int  # a frame's line width


def draw_hud(
    surface: pygame.Surface,
    layout: TextLayout,
    style: HudStyle,
    title: str,
    lines: Sequence[HudLine],
    fps: str | None,
    paused: bool,
) -> tuple[list[pygame.Rect], int, int]:
    """The title, heads-up lines, frame rate's text (None: not shown) and PAUSED in their places; returns
    the boxes drawn (for the aids to keep clear of), how far down the window the text goes, and how
    far the top right corner's boxes (frame rate, PAUSED) go beside the table (0: none there)."""
    if layout.side_px:
        return _draw_in_margins(surface, layout, style, title, lines, fps, paused)
    return _draw_in_band(surface, layout, style, title, lines, fps, paused)


def _fps_box(surface, style: HudStyle, fps: str | None, topright) -> pygame.Rect:
    """The frame rate's text ("60.0 fps", "idle") in a box at `topright`; with none, an empty box of no width."""
    font = style.font
    pad = font.get_height() // 2
    if fps is None:
        return pygame.Rect(topright[0], topright[1], 0, font.get_linesize())
    label = font.render(fps, True, style.text)
    box = label.get_rect(topright=topright).inflate(pad, pad // 4)
    box.topright = topright
    pygame.draw.rect(surface, GROUND, box)
    pygame.draw.rect(surface, style.dim, box, 1)
    surface.blit(label, label.get_rect(center=box.center))
    return box


def _paused_box(surface, style: HudStyle, font, topright, width_px: int) -> pygame.Rect:
    label = font.render(panel_view.shorten(font, "PAUSED", width_px), True, style.paused)
    pad = style.font.get_height() // 2
    box = label.get_rect().inflate(pad, 0)
    box.topright = topright
    pygame.draw.rect(surface, GROUND, box)
    pygame.draw.rect(surface, style.paused, box, style.line_px)
    surface.blit(label, label.get_rect(center=box.center))
    return box


def _draw_in_band(surface, layout, style, title, lines, fps, paused) -> tuple[list[pygame.Rect], int, int]:
    w = surface.get_width()
    font = style.font
    pad, line_h = font.get_height() // 2, font.get_linesize()
    band = pygame.Rect(0, 0, w, layout.top_px)
    surface.fill(GROUND, band)
    y = pad // 2
    fps_box = _fps_box(surface, style, fps, (w - pad, y))
    surface.blit(font.render(fit_parts(font, [title], fps_box.left - 2 * pad), True, style.text), (pad, y))
    right = w - pad  # the heads-up lines end here: left of PAUSED, which takes the band's right under the fps
    if paused:
        box = _paused_box(surface, style, style.big_font, (w - pad, fps_box.bottom + 1), w // 3)
        box.bottom = min(box.bottom, band.bottom)
        right = box.left - pad
    for line in fold_lines(lines, BAND_LINES - 1, font, right - pad):
        y += line_h
        surface.blit(font.render(fit_parts(font, [_text(line)], right - pad), True, _color(line, style.dim)), (pad, y))
    return [band], layout.top_px, 0


def _draw_in_margins(surface, layout, style, title, lines, fps, paused) -> tuple[list[pygame.Rect], int, int]:
    w, _ = surface.get_size()
    font = style.font
    pad, line_h = font.get_height() // 2, font.get_linesize()
    column = layout.side_px - 2 * pad
    y = pad // 2
    boxes = []
    for k, line in enumerate([title, *lines]):
        color = style.text if k == 0 else _color(line, style.dim)
        for text in panel_view.wrap(font, _text(line), column):
            boxes.append(surface.blit(font.render(text, True, color), (pad, y)))
            y += line_h
        y += pad // 2
    right = [] if fps is None else [_fps_box(surface, style, fps, (w - pad, pad // 2))]
    if paused:
        top = (right[-1].bottom if right else pad // 2) + pad
        right.append(_paused_box(surface, style, style.big_font, (w - pad, top), column))
    corner = max((box.bottom for box in right), default=0)
    return boxes + right, max(y, corner), corner
