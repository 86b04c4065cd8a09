"""Environment: the world <-> screen transform (no pygame).

World coordinates are metres with y up; screen coordinates are pixels with y
down and the origin at the top-left of the window. One transform serves both
directions and stays in floats; only the drawing code rounds to pixels.

    screen_x = (x_m - origin_x) * scale
    screen_y = height_px - (y_m - origin_y) * scale

where `origin_m` is the world point at the bottom-left corner of the window
and `scale` (px per m) is the base scale times the zoom.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

DEFAULT_SIZE_PX = (900, 788)
DEFAULT_WIDTH_M = 10.0
MIN_ZOOM = 0.05
MAX_ZOOM = 200.0


class Environment:
    """Maps world metres to window pixels, with zoom about a point and pan."""

    def __init__(self, size_px: Sequence[int] = DEFAULT_SIZE_PX, width_m: float = DEFAULT_WIDTH_M) -> None:
        w, h = (int(v) for v in size_px)
        if w <= 0 or h <= 0 or not width_m > 0:
            raise ValueError("window size and world width must be positive")
        self.size_px = (w, h)
        self.base_px_per_m = w / float(width_m)
        self.reset()

    def reset(self) -> None:
        """Back to the default view: no zoom, bottom-left of the table at bottom-left."""
        self.zoom = 1.0
        self.origin_m = np.zeros(2)

    @property
    def px_per_m(self) -> float:
        return self.base_px_per_m * self.zoom

    @property
    def view_height_m(self) -> float:
        """World height visible at zoom 1 (8.7556 m for the default window)."""
        return self.size_px[1] / self.base_px_per_m

    def to_screen(self, points_m) -> np.ndarray:
        """World metres -> screen pixels (floats). Accepts (2,) or (N, 2)."""
        p = np.asarray(points_m, dtype=float)
        s = self.px_per_m
        out = np.empty_like(p)
        out[..., 0] = (p[..., 0] - self.origin_m[0]) * s
        out[..., 1] = self.size_px[1] - (p[..., 1] - self.origin_m[1]) * s
        return out

    def to_world(self, points_px) -> np.ndarray:
        """Screen pixels -> world metres; the exact inverse of `to_screen`."""
        p = np.asarray(points_px, dtype=float)
        s = self.px_per_m
        out = np.empty_like(p)
        out[..., 0] = p[..., 0] / s + self.origin_m[0]
        out[..., 1] = (self.size_px[1] - p[..., 1]) / s + self.origin_m[1]
        return out

    def length_to_px(self, length_m):
        """A world length in pixels at the current zoom."""
        return np.asarray(length_m, dtype=float) * self.px_per_m

    def zoom_about(self, point_px: Sequence[float], factor: float) -> None:
        """Multiply the zoom by `factor`, keeping the world point under point_px fixed."""
        anchor = self.to_world(point_px)
        self.zoom = float(np.clip(self.zoom * factor, MIN_ZOOM, MAX_ZOOM))
        s = self.px_per_m
        px = np.asarray(point_px, dtype=float)
        self.origin_m = np.array([anchor[0] - px[0] / s, anchor[1] - (self.size_px[1] - px[1]) / s])

    def pan(self, delta_px: Sequence[float]) -> None:
        """Move the view with the mouse: the world follows a drag of delta_px pixels."""
        dx, dy = (float(v) for v in delta_px)
        s = self.px_per_m
        self.origin_m = self.origin_m + np.array([-dx / s, dy / s])
