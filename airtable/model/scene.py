"""Scene: everything a window needs to draw one frame of the table (no pygame).

The server app builds a Scene from its AirTable and clients; the network
snapshot carries a Scene to the players; `GameWindow.draw` draws a Scene. So
the teacher's window and every student's window use the same drawing code.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

# Between the parts of `Scene.status` ("PAUSED", "t = 1.25 s", ...), most important first.
STATUS_SEPARATOR = "   "


@dataclass(frozen=True)
class CursorView:
    """One client's cursor as drawn: name, colour, position, button, held puck row (-1: none)."""

    name: str
    color: tuple[int, int, int]
    cursor_m: tuple[float, float]
    button: int = 0
    held: int = -1


@dataclass
class Scene:
    width_m: float
    height_m: float
    pos_m: np.ndarray  # (N, 2) float
    radius_m: np.ndarray  # (N,) float
    color_rgb: np.ndarray  # (N, 3) uint8
    spring_pairs: np.ndarray = field(default_factory=lambda: np.zeros((0, 2), np.intp))  # (S, 2) puck rows
    spring_length_m: np.ndarray = field(default_factory=lambda: np.zeros(0))
    spring_width_m: np.ndarray = field(default_factory=lambda: np.zeros(0))
    spring_color_rgb: np.ndarray = field(default_factory=lambda: np.zeros((0, 3), np.uint8))
    cursors: tuple[CursorView, ...] = ()
    title: str = ""
    status: str = ""
    gravity_on: bool = False
    puck_correction: str = "two-step"
    time_s: float = 0.0
    fps: float = 0.0
    zoom: float = 1.0
    origin_m: tuple[float, float] = (0.0, 0.0)
    aids: object = None  # the teacher's aids for the students (aids_wire.SharedAids), set while serving

    @property
    def status_parts(self) -> list[str]:
        """The status line's parts, most important first: a narrow window drops from the end."""
        return [part for part in self.status.split(STATUS_SEPARATOR) if part]

    @classmethod
    def from_table(cls, table, clients=(), **extra) -> Scene:
        """Copy what is drawn out of an AirTable and its clients."""
        cursors = tuple(
            CursorView(
                name=c.name,
                color=tuple(int(v) for v in c.color),
                cursor_m=(float(c.cursor_m[0]), float(c.cursor_m[1])),
                button=int(c.button),
                held=c.held.index if c.held is not None and c.held.alive else -1,
            )
            for c in clients
            if c.active
        )
        return cls(
            width_m=table.width_m,
            height_m=table.height_m,
            pos_m=table.pos_m.copy(),
            radius_m=table.radius_m.copy(),
            color_rgb=table.color_rgb.copy(),
            spring_pairs=table.spring_pairs.copy(),
            spring_length_m=table.spring_length_m.copy(),
            spring_width_m=table.spring_width_m.copy(),
            spring_color_rgb=table.spring_color_rgb.copy(),
            cursors=cursors,
            gravity_on=table.gravity_on,
            puck_correction=table.puck_correction,
            time_s=table.time_s,
            **extra,
        )
