"""Drawing pucks: small ones from cached sprites, large ones directly, clipped.

Most scenes have thousands of small pucks in a handful of sizes and colours, so
one sprite per (radius, colour) blitted with `Surface.fblits` keeps them at
full frame rate. Zooming in makes every frame's radius new and a sprite of a
puck 1000 px across weighs 16 MB, so sprites are kept only up to
`SPRITE_MAX_RADIUS_PX` and the cache is bounded by bytes, least recently used
first out. Larger pucks are drawn with `pygame.draw.circle`, which clips to the
target, and a puck that covers the whole target is a fill.
"""

from __future__ import annotations

from collections import OrderedDict

import numpy as np
import pygame

MIN_PUCK_RADIUS_PX = 2
SPRITE_MAX_RADIUS_PX = 96
SPRITE_CACHE_BYTES = 16 * 1024 * 1024
COLORKEY = (1, 2, 3)  # sprite background; no puck uses this colour


def ring_width_px(r_px: int) -> int:
    """The outline of a puck: a sixth of its radius, at least 2 px."""
    return max(2, r_px // 6)


def core_color(color: tuple[int, int, int]) -> tuple[int, int, int]:
    """The dark inside of an outlined puck."""
    return tuple(max(4, c * 3 // 10) for c in color)


def draw_puck(target: pygame.Surface, color, center, r_px: int) -> None:
    """One puck drawn directly: a ring in its colour around a dark core (a dot when tiny)."""
    if r_px <= 3:
        pygame.draw.circle(target, color, center, r_px)
        return
    clip = target.get_clip()
    cx, cy = center
    # Corners of the clip all inside the ring's inner edge: the core fills it all.
    inner = r_px - ring_width_px(r_px)
    corners = ((clip.left, clip.top), (clip.right, clip.top), (clip.left, clip.bottom), (clip.right, clip.bottom))
    if all((x - cx) ** 2 + (y - cy) ** 2 < inner * inner for x, y in corners):
        target.fill(core_color(color), clip)
        return
    pygame.draw.circle(target, core_color(color), center, r_px)
    pygame.draw.circle(target, color, center, r_px, ring_width_px(r_px))


class PuckSprites:
    """Sprites of small pucks, at most `limit_bytes` of them, least recently used dropped first."""

    def __init__(self, limit_bytes: int = SPRITE_CACHE_BYTES) -> None:
        self.limit_bytes = limit_bytes
        self.bytes = 0
        self._cache: OrderedDict[tuple, pygame.Surface] = OrderedDict()

    def __len__(self) -> int:
        return len(self._cache)

    def clear(self) -> None:
        self._cache.clear()
        self.bytes = 0

    def get(self, r_px: int, color: tuple[int, int, int]) -> pygame.Surface:
        key = (r_px, *color)
        sprite = self._cache.get(key)
        if sprite is not None:
            self._cache.move_to_end(key)
            return sprite
        size = 2 * r_px + 1
        sprite = pygame.Surface((size, size))
        sprite.fill(COLORKEY)
        sprite.set_colorkey(COLORKEY)
        draw_puck(sprite, color, (r_px, r_px), r_px)
        self._cache[key] = sprite
        self.bytes += _bytes(sprite)
        while self.bytes > self.limit_bytes and len(self._cache) > 1:
            _, old = self._cache.popitem(last=False)
            self.bytes -= _bytes(old)
        return sprite


def _bytes(surface: pygame.Surface) -> int:
    return surface.get_pitch() * surface.get_height()


def draw_pucks(target: pygame.Surface, sprites: PuckSprites, centers: np.ndarray, r_px: np.ndarray, colors) -> None:
    """Pucks at `centers` (N, 2 px floats) of radius `r_px` (N ints) in `colors` (N, 3)."""
    w, h = target.get_size()
    visible = (
        (centers[:, 0] + r_px >= 0)
        & (centers[:, 0] - r_px <= w)
        & (centers[:, 1] + r_px >= 0)
        & (centers[:, 1] - r_px <= h)
    )
    if not visible.all():
        centers, r_px, colors = centers[visible], r_px[visible], colors[visible]
    big = r_px > SPRITE_MAX_RADIUS_PX
    if big.any():  # few on screen at once: a big puck covers much of it
        for (x, y), r, c in zip(centers[big].tolist(), r_px[big].tolist(), colors[big].tolist()):
            draw_puck(target, tuple(c), (round(x), round(y)), r)
        small = ~big
        centers, r_px, colors = centers[small], r_px[small], colors[small]
    if len(r_px) == 0:
        return
    # One sprite per distinct (radius, colour); usually a handful.
    c = colors.astype(np.int64)
    keys = (r_px << 24) | (c[:, 0] << 16) | (c[:, 1] << 8) | c[:, 2]
    uniq, inverse = np.unique(keys, return_inverse=True)
    images = [sprites.get(int(k >> 24), (int(k >> 16) & 255, int(k >> 8) & 255, int(k) & 255)) for k in uniq]
    corner = np.rint(centers).astype(np.int64) - r_px[:, None]
    target.fblits(
        [(images[k], (x, y)) for k, x, y in zip(inverse.ravel().tolist(), corner[:, 0].tolist(), corner[:, 1].tolist())]
    )
