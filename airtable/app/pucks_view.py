"""Drawing pucks: small ones from cached sprites, large ones directly, clipped.

Most scenes have thousands of small pucks in a handful of sizes and colours, so
there is one sprite per (radius, colour), and the pucks are drawn in groups,
one group per sprite:

- A few pucks: `Surface.fblits`, which clips.
- Many pucks of a small sprite (the burst's 10000 pucks of 6 px): the
  sprite's pixels are stamped straight into the target with numpy, a
  thousand pucks per array assignment. Handing fblits 10000 (sprite,
  position) pairs made 10000 Python tuples a frame, which cost more than the
  blitting itself (8.4 ms against 4.0 ms a frame at 1920x1080). Stamped
  pucks overlap in their own order, as blitted ones do; blitted pucks are on
  top of stamped ones, and pucks cut by the clip's edge are blitted. A puck
  at the same corner as the next of its group is not stamped: the next
  covers it exactly (a burst's pucks start piled up).

Zooming in makes every frame's radius new and a sprite of a puck 1000 px
across weighs 16 MB, so sprites are kept only up to `SPRITE_MAX_RADIUS_PX`
and the cache is bounded by bytes, least recently used first out. Larger
pucks are drawn with `pygame.draw.circle`, which clips to the target, and a
puck that covers the whole target is a fill.
"""

from __future__ import annotations

from collections import OrderedDict

import numpy as np
import pygame

from airtable.model.momenta import puck_number

MIN_PUCK_RADIUS_PX = 2  # a small puck shows on a projector ...
CROWD_SHARE = 0.1  # ... unless that many so enlarged would cover this share of the window
SPRITE_MAX_RADIUS_PX = 96
SPRITE_CACHE_BYTES = 16 * 1024 * 1024
COLORKEY = (1, 2, 3)  # sprite background; no puck uses this colour
# A group of one sprite is stamped with numpy when it has this many pucks and
# the sprite at most this many pixels. Measured (CPU ms for N pucks, stamped
# against fblits): radius 6 (104 pixels) 0.23/0.26 at 1000, 2.1/4.8 at 10000;
# radius 10 (308 pixels) 1.9/1.4 at 3000, 5.4/5.9 at 10000.
STAMP_MIN_PUCKS = 1000
STAMP_MAX_PIXELS = 200
STAMP_CHUNK_PIXELS = 65536  # pixels written per numpy call: a few pucks' worth, 256 kB of values


def ring_width_px(r_px: int) -> int:
    """The outline of a puck: a sixth of its radius, at least 2 px."""
    return max(2, r_px // 6)


def core_color(color: tuple[int, int, int]) -> tuple[int, int, int]:
    """The dark inside of an outlined puck."""
    return tuple(max(4, c * 3 // 10) for c in color)


def radii_px(r_px: np.ndarray, colors: np.ndarray, window_px: tuple[int, int]) -> np.ndarray:
    """Whole-pixel radii to draw pucks of radii `r_px` (floats) and `colors` (N, 3) with: at least
    MIN_PUCK_RADIUS_PX, so a small puck shows on a projector, unless the pucks of its colour so enlarged
    would cover CROWD_SHARE of the window; then as they are, and a puck of under 1.5 square pixels one
    pixel (radius 0). A user test: a gas of 10000 white pucks covering 30 % of a small window drew white
    all over (96 % of its pixels at 320x240), each puck of radius 0.5 px drawn 2 px; its orange puck, one
    of its colour, stays enlarged."""
    whole = np.rint(np.minimum(r_px, 1 << 20))  # (before the cast: a zoom of any size stays a sane integer)
    r = np.maximum(whole, MIN_PUCK_RADIUS_PX)
    most = CROWD_SHARE * window_px[0] * window_px[1] / (np.pi * MIN_PUCK_RADIUS_PX**2)
    if len(r_px) > most:  # (else no colour can crowd: the usual case)
        shade = (colors[:, 0] >> 5).astype(np.intp) << 6 | (colors[:, 1] >> 5) << 3 | colors[:, 2] >> 5  # 512
        crowded = np.bincount(shade, minlength=512).take(shade) > most
        r = np.where(crowded, np.where(np.pi * r_px * r_px < 1.5, 0.0, whole), r)
    return r.astype(np.int64)


def draw_puck(target: pygame.Surface, color, center, r_px: int) -> None:
    """One puck drawn directly: a ring in its colour around a dark core (a dot when tiny, a pixel at radius 0)."""
    if r_px <= 0:
        target.fill(color, (*center, 1, 1))
        return
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
        self._stamps: dict[tuple, tuple[np.ndarray, np.ndarray]] = {}  # 256 kB each at most

    def __len__(self) -> int:
        return len(self._cache)

    def clear(self) -> None:
        self._cache.clear()
        self._stamps.clear()
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

    def stamp(self, r_px: int, color: tuple[int, int, int], target: pygame.Surface) -> tuple[np.ndarray, np.ndarray]:
        """The sprite's opaque pixels for a 32-bit `target`: their offsets from its
        corner in the target's pixels, row after row, and the values to write there
        in the target's pixel format, repeated for as many pucks as one numpy call
        takes (`STAMP_CHUNK_PIXELS`)."""
        pitch = target.get_pitch() // 4
        key = (r_px, *color, pitch, target.get_masks())
        stamp = self._stamps.get(key)
        if stamp is None:
            rgb = pygame.surfarray.array3d(self.get(r_px, color)).transpose(1, 0, 2)
            ys, xs = np.nonzero(np.any(rgb != COLORKEY, axis=2))
            mapped = {c: target.map_rgb(c) for c in set(map(tuple, rgb[ys, xs].tolist()))}
            values = np.array([mapped[tuple(c)] for c in rgb[ys, xs].tolist()], dtype=np.uint32)
            if len(self._stamps) >= 16:
                self._stamps.clear()
            per_call = max(1, STAMP_CHUNK_PIXELS // len(values))
            stamp = self._stamps[key] = (ys.astype(np.int64) * pitch + xs, np.tile(values, per_call))
        return stamp


def _bytes(surface: pygame.Surface) -> int:
    return surface.get_pitch() * surface.get_height()


def draw_pucks(target: pygame.Surface, sprites: PuckSprites, centers: np.ndarray, r_px: np.ndarray, colors) -> None:
    """Pucks at `centers` (N, 2 px floats) of radius `r_px` (N ints) in `colors` (N, 3)."""
    # Rows are picked with take and columns used one at a time: numpy's boolean or fancy indexing of
    # (N, 2) arrays costs about ten times as much, 0.1-0.3 ms for 10000 rows.
    w, h = target.get_size()
    cx, cy = centers[:, 0], centers[:, 1]
    visible = (cx + r_px >= 0) & (cx - r_px <= w) & (cy + r_px >= 0) & (cy - r_px <= h)
    if not visible.all():
        centers, r_px, colors = _rows(visible, centers, r_px, colors)
    big = r_px > SPRITE_MAX_RADIUS_PX
    if big.any():  # few on screen at once: a big puck covers much of it
        at, r_big, c_big = np.rint(centers[big]).astype(np.int64), r_px[big], colors[big]
        shown = _big_ones_shown(at, r_big, target.get_clip())
        for (x, y), r, c in zip(at[shown].tolist(), r_big[shown].tolist(), c_big[shown].tolist()):
            draw_puck(target, tuple(c), (x, y), r)
        centers, r_px, colors = _rows(~big, centers, r_px, colors)
    if len(r_px) == 0:
        return
    # One sprite per distinct (radius, colour); usually a handful.
    keys = r_px.astype(np.int64) << 24
    for shift, channel in ((16, 0), (8, 1), (0, 2)):
        keys |= colors[:, channel].astype(np.int64) << shift
    uniq, inverse, counts = _groups(keys)
    sprite_of = [(k >> 24, ((k >> 16) & 255, (k >> 8) & 255, k & 255)) for k in uniq.tolist()]
    corner = (np.rint(centers[:, 0]).astype(np.int64) - r_px, np.rint(centers[:, 1]).astype(np.int64) - r_px)
    if _stampable(target) and counts.max() >= STAMP_MIN_PUCKS:
        left = _stamp_groups(target, sprites, sprite_of, inverse, counts, corner)
        if not left.all():
            *corner, inverse = _rows(left, *corner, inverse)
    if len(inverse):  # the rest in their own order, so overlaps look as they always did
        images = [sprites.get(r, color) for r, color in sprite_of]
        sources = map(images.__getitem__, inverse.tolist())
        target.fblits(list(zip(sources, zip(corner[0].tolist(), corner[1].tolist()))))


def _rows(keep: np.ndarray, *arrays: np.ndarray) -> tuple[np.ndarray, ...]:
    """The rows of each array where `keep` is true."""
    at = np.flatnonzero(keep)
    return tuple(np.take(a, at, axis=0) for a in arrays)


def _groups(keys: np.ndarray, most: int = 8) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """np.unique(keys, return_inverse=True, return_counts=True), without its sort when there are at most
    `most` distinct keys (a scene has a handful of sprites; the sort of 10000 costs 0.3 ms)."""
    found, rest = [], keys
    while len(rest) and len(found) < most:
        found.append(rest[0])
        rest = rest[rest != rest[0]]
    if len(rest):
        uniq, inverse, counts = np.unique(keys, return_inverse=True, return_counts=True)
        return uniq, inverse.ravel(), counts
    uniq = np.sort(np.array(found, dtype=keys.dtype))
    inverse = np.searchsorted(uniq, keys)
    return uniq, inverse, np.bincount(inverse, minlength=len(uniq))


def _big_ones_shown(at: np.ndarray, r_px: np.ndarray, clip: pygame.Rect) -> np.ndarray:
    """Which big pucks can be seen, in drawing order: none under a later one whose core fills the whole
    clip, and of pucks on the very same disc only the last. Each big puck costs its area in pixels, so a
    snapshot of thousands of them (a table zoomed in on a crowd) would take seconds a frame if all were drawn."""
    inner = r_px - np.maximum(2, r_px // 6)  # ring_width_px, for every puck at once
    far_x = np.maximum(np.abs(at[:, 0] - clip.left), np.abs(at[:, 0] - clip.right))
    far_y = np.maximum(np.abs(at[:, 1] - clip.top), np.abs(at[:, 1] - clip.bottom))
    fills = np.flatnonzero(far_x**2 + far_y**2 < inner**2)  # as draw_puck tests it: fills the clip
    keep = np.arange(fills[-1] if len(fills) else 0, len(r_px))
    discs = np.column_stack((at[keep], r_px[keep]))
    _, last_from_end = np.unique(discs[::-1], axis=0, return_index=True)
    return keep[np.sort(len(keep) - 1 - last_from_end)]


def _stampable(target: pygame.Surface) -> bool:
    """Pixels written straight into `target` look as blitted: 32 bits, no alpha, not a view of another surface."""
    return target.get_bytesize() == 4 and not target.get_flags() & pygame.SRCALPHA and target.get_parent() is None


def _stamp_groups(
    target: pygame.Surface, sprites: PuckSprites, sprite_of, inverse: np.ndarray, counts, corner: tuple
) -> np.ndarray:
    """Stamp every group big enough for it, of a sprite small enough; returns which pucks are left to blit.
    `corner`: the pucks' top left corners, (x, y) arrays of px."""
    left = np.ones(len(inverse), dtype=bool)
    for i, ((r, color), count) in enumerate(zip(sprite_of, counts.tolist())):
        if count < STAMP_MIN_PUCKS or (r + 1) ** 2 > STAMP_MAX_PIXELS:  # too big, as a disc has more pixels
            continue
        stamp = sprites.stamp(r, color, target)
        if len(stamp[0]) <= STAMP_MAX_PIXELS:
            members = np.flatnonzero(inverse == i)
            x, y = (c[members] for c in corner)
            left[members[_stamp(target, stamp, x, y, 2 * r + 1)]] = False
    return left


def _stamp(
    target: pygame.Surface, stamp: tuple[np.ndarray, np.ndarray], x: np.ndarray, y: np.ndarray, size: int
) -> np.ndarray:
    """Write the stamp at each corner (`x`, `y` px) whose sprite lies wholly inside the
    target's clip (the others are left for fblits, which clips); returns which it wrote."""
    clip = target.get_clip()
    inside = (x >= clip.left) & (y >= clip.top) & (x + size <= clip.right) & (y + size <= clip.bottom)
    at = np.flatnonzero(inside)
    base = y[at] * (target.get_pitch() // 4) + x[at]  # one address a corner, as x < pitch
    # A puck at the same corner as the next is all covered by it, pixel for pixel: left out. A burst's
    # pucks start on top of each other and spread slowly: 1-10 a corner, 2.5x faster drawn this way.
    last = np.ones(len(base), dtype=bool)
    last[:-1] = base[1:] != base[:-1]
    base = base[last]
    offsets, values = stamp
    per_call = len(values) // len(offsets)
    pixels = np.frombuffer(target.get_buffer(), dtype=np.uint32)  # row after row; locks the target
    # Pixels written two at a time as 64-bit words (pairs at even addresses, single pixels after) were
    # measured no faster, even without the overlap check that keeps the order: 10000 pucks of radius 3-6
    # at 1920x1080 took 2.6-5.4 ms either way. The time goes to the cache lines touched, the same for
    # both, and the words need two index arrays a puck where pixels need one.
    for start in range(0, len(base), per_call):
        # Puck after puck, so a later puck covers an earlier one, as when blitted.
        where = (base[start : start + per_call, None] + offsets).ravel()
        pixels[where] = values[: len(where)]
    del pixels  # unlocks it
    return inside


MAX_NUMBERED_PUCKS = 120  # more pucks on screen than this: their numbers would be a blur; none drawn
NUMBER_FILL = (0, 0, 0)


def draw_numbers(target: pygame.Surface, font: pygame.font.Font, centers_px: np.ndarray) -> int:
    """Each puck's number (`puck_number` of its row, as the values panel, the momenta diagram, predict
    and the CSV name it), in white
    on a small dark box at its centre, for the pucks whose centre is on `target`; returns how many were
    drawn (none when more than MAX_NUMBERED_PUCKS would be)."""
    w, h = target.get_size()
    centers_px = np.asarray(centers_px, dtype=float).reshape(-1, 2)
    on = np.flatnonzero(
        (centers_px[:, 0] >= 0) & (centers_px[:, 0] < w) & (centers_px[:, 1] >= 0) & (centers_px[:, 1] < h)
    )
    if len(on) > MAX_NUMBERED_PUCKS:
        return 0
    for k in on.tolist():
        text = font.render(str(puck_number(k)), True, (255, 255, 255))
        box = text.get_rect(center=(round(centers_px[k, 0]), round(centers_px[k, 1])))
        target.fill(NUMBER_FILL, box.inflate(4, 0))
        target.blit(text, box)
    return len(on)
