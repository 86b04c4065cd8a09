"""Environment: the world <-> screen transform (no pygame).

World coordinates are metres with y up; screen coordinates are pixels with y
down and the origin at the top-left of the window. One transform serves both
directions and stays in floats; only the drawing code rounds to pixels.

The table (width_m x height_m) is fitted into the window with its aspect
ratio kept and centred, above a band kept for the status line (`resize`'s
bottom_px): that box, the "viewport", is `fit_px_per_m` pixels per metre;
`offset_px` is how far its left edge is from the window's and its bottom edge
from the window's (margins, and the band).
The view inside it is a zoom and `origin_m`, the world point at the
viewport's bottom-left corner:

    screen_x = offset_x + (x_m - origin_x) * scale
    screen_y = size_y - offset_y - (y_m - origin_y) * scale

with `scale` (px per m) = fit_px_per_m * zoom. Zoom and origin do not depend
on the window's size, so a resize keeps the view, and a student's window of
another shape shows what the teacher's shows.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

DEFAULT_SIZE_PX = (900, 788)
DEFAULT_WIDTH_M = 10.0
MIN_ZOOM = 0.05
MAX_ZOOM = 200.0
DESKTOP_SHARE = 0.9  # a default window takes at most this much of the desktop
MIN_WINDOW_PX = (320, 240)


class Environment:
    """Maps world metres to window pixels, with zoom about a point and pan."""

    def __init__(
        self,
        size_px: Sequence[int] = DEFAULT_SIZE_PX,
        width_m: float = DEFAULT_WIDTH_M,
        height_m: float | None = None,
    ) -> None:
        """`height_m` defaults to the height that fills `size_px` at `width_m` across."""
        w, h = _checked_size(size_px)
        if height_m is None:
            height_m = h * float(width_m) / w
        if not (width_m > 0 and height_m > 0 and math.isfinite(width_m) and math.isfinite(height_m)):
            raise ValueError("the table's width and height must be positive numbers of metres")
        self.width_m = float(width_m)
        self.height_m = float(height_m)
        self._zoom = 1.0
        self.resize((w, h))
        self.reset()

    # ------------------------------------------------------------ view

    def reset(self) -> None:
        """Back to the default view: the whole table, centred, no zoom."""
        self.zoom = 1.0
        self.origin_m = np.zeros(2)

    def resize(self, size_px: Sequence[int], bottom_px: float = 0.0, top_px: float = 0.0) -> None:
        """A new window size: the table is fitted again; zoom and pan are kept.

        `bottom_px` and `top_px`: bands along the bottom and the top of the window kept
        clear of the table (the status bar's, the title's and the heads-up lines'), so
        that no text lies over the table and nothing resting on the floor is hidden.
        """
        w, h = _checked_size(size_px)
        self.size_px = (w, h)
        band = min(max(0.0, float(bottom_px)), 0.5 * h)
        top = min(max(0.0, float(top_px)), 0.5 * (h - band))
        room = h - band - top
        # A window within 0.01 % of the table's shape counts as that shape, so 900 x 788
        # is 90 px per metre across the 10 x 8.7556 m table (8.7556 being 788 / 90 rounded).
        if w / self.width_m <= room / self.height_m * (1 + 1e-4):  # the width fits: margins above and below
            self.fit_px_per_m = w / self.width_m
            self.offset_px = (0.0, band + 0.5 * max(0.0, room - self.height_m * self.fit_px_per_m))
        else:
            self.fit_px_per_m = room / self.height_m
            self.offset_px = (0.5 * max(0.0, w - self.width_m * self.fit_px_per_m), band)

    @property
    def zoom(self) -> float:
        return self._zoom

    @zoom.setter
    def zoom(self, value: float) -> None:
        # Clamped whatever sets it (keys, wheel, a snapshot), so drawing cost stays bounded.
        value = float(value)
        self._zoom = float(np.clip(value, MIN_ZOOM, MAX_ZOOM)) if math.isfinite(value) else 1.0

    @property
    def base_px_per_m(self) -> float:
        """Pixels per metre at zoom 1 (the table fitted to the window)."""
        return self.fit_px_per_m

    @property
    def px_per_m(self) -> float:
        return self.fit_px_per_m * self._zoom

    @property
    def view_height_m(self) -> float:
        """The height of the table the view is fitted to (8.7556 m for the default window)."""
        return self.height_m

    @property
    def table_rect_px(self) -> tuple[float, float, float, float]:
        """(left, top, width, height) of the viewport: where the whole table shows at zoom 1."""
        width, height = self.width_m * self.fit_px_per_m, self.height_m * self.fit_px_per_m
        return (self.offset_px[0], self.size_px[1] - self.offset_px[1] - height, width, height)

    def view_note(self, pos_m: np.ndarray | None = None, radius_m: np.ndarray | None = None) -> tuple[str, bool]:
        """(What the status line says of the view, whether the window shows nothing): "" for the whole table;
        else how far it is zoomed, and whether the table, or (given the pucks) every puck, is out of sight:
        zoomed in on empty space the window is plain black, and a teacher at x200 saw nothing to tell where
        the pucks had gone."""
        if self.zoom == 1.0 and not self.origin_m.any():
            return "", False
        zoom = f"zoom x{self.zoom:.3g}"
        corners = self.to_screen(np.array([[0.0, 0.0], [self.width_m, self.height_m]]))
        (x0, y1), (x1, y0) = corners
        w, h = self.size_px
        if x1 < 0 or x0 > w or y1 < 0 or y0 > h:
            return f"{zoom}, the table is out of sight", True
        if pos_m is not None and radius_m is not None and not self.any_in_sight(pos_m, radius_m):
            return f"{zoom}, no puck in sight", True
        return zoom, False

    def any_in_sight(self, pos_m: np.ndarray, radius_m: np.ndarray) -> bool:
        """Whether any puck (centres pos_m, radii radius_m) shows in the window, at least in part."""
        (left, top), (right, bottom) = self.to_world(np.array([[0.0, 0.0], [*self.size_px]], dtype=float))
        x, y = pos_m[:, 0], pos_m[:, 1]
        near = (x + radius_m >= left) & (x - radius_m <= right) & (y + radius_m >= bottom) & (y - radius_m <= top)
        return bool(near.any())

    # ------------------------------------------------------------ transform

    def to_screen(self, points_m) -> np.ndarray:
        """World metres -> screen pixels (floats). Accepts (2,) or (N, 2)."""
        p = np.asarray(points_m, dtype=float)
        s = self.px_per_m
        out = np.empty_like(p)
        out[..., 0] = self.offset_px[0] + (p[..., 0] - self.origin_m[0]) * s
        out[..., 1] = (self.size_px[1] - self.offset_px[1]) - (p[..., 1] - self.origin_m[1]) * s
        return out

    def to_world(self, points_px) -> np.ndarray:
        """Screen pixels -> world metres; the exact inverse of `to_screen`."""
        p = np.asarray(points_px, dtype=float)
        s = self.px_per_m
        out = np.empty_like(p)
        out[..., 0] = (p[..., 0] - self.offset_px[0]) / s + self.origin_m[0]
        out[..., 1] = ((self.size_px[1] - self.offset_px[1]) - p[..., 1]) / s + self.origin_m[1]
        return out

    def length_to_px(self, length_m):
        """A world length in pixels at the current zoom."""
        return np.asarray(length_m, dtype=float) * self.px_per_m

    def zoom_about(self, point_px: Sequence[float], factor: float) -> None:
        """Multiply the zoom by `factor`, keeping the world point under point_px fixed."""
        anchor = self.to_world(point_px)
        self.zoom = self._zoom * factor
        s = self.px_per_m
        px = np.asarray(point_px, dtype=float)
        self.origin_m = np.array(
            [
                anchor[0] - (px[0] - self.offset_px[0]) / s,
                anchor[1] - ((self.size_px[1] - self.offset_px[1]) - px[1]) / s,
            ]
        )

    def pan(self, delta_px: Sequence[float]) -> None:
        """Move the view with the mouse: the world follows a drag of delta_px pixels."""
        dx, dy = (float(v) for v in delta_px)
        s = self.px_per_m
        self.origin_m = self.origin_m + np.array([-dx / s, dy / s])


def _checked_size(size_px: Sequence[int]) -> tuple[int, int]:
    w, h = (int(v) for v in size_px)
    if w <= 0 or h <= 0:
        raise ValueError("window size must be positive")
    return w, h


def fitting_size_px(desktop_px: Sequence[int], aspect: float, share: float = DESKTOP_SHARE) -> tuple[int, int]:
    """The largest window of `aspect` (width / height) within `share` of the desktop."""
    dw, dh = (max(1, int(v)) for v in desktop_px)
    w, h = share * dw, share * dh
    if w / h > aspect:
        w = h * aspect
    else:
        h = w / aspect
    return max(MIN_WINDOW_PX[0], int(w)), max(MIN_WINDOW_PX[1], int(h))


def parse_size(text: str) -> tuple[int, int]:
    """'1280x720' -> (1280, 720); a ValueError with a sentence a person can act on otherwise."""
    parts = text.lower().replace(" ", "").split("x")
    try:
        w, h = (int(p) for p in parts)
    except ValueError:
        raise ValueError(f"window size {text!r} should look like 1280x720 (width x height in pixels)") from None
    if w < MIN_WINDOW_PX[0] or h < MIN_WINDOW_PX[1] or w > 16384 or h > 16384:
        raise ValueError(
            f"window size {text!r} is out of range: use at least {MIN_WINDOW_PX[0]}x{MIN_WINDOW_PX[1]}"
            " and at most 16384 on a side"
        )
    return w, h
