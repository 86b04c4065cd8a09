"""The teaching aids of the teacher's window (`Aids`): trails, vectors, collision annotations, the energy
chart and the inspector, with their keys.

The numbers come from model/aids.py and the table, the drawing from
aids_view.py through the host's AidsPainter; what the students see of them is
gathered by aids_share.py.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import pygame

from airtable.app.aids_paint import draw_annotations
from airtable.app.aids_view import draw_vectors, inspector_lines
from airtable.app.feature import Binding, Feature
from airtable.app.overlays import OverlayFlag
from airtable.model import aids
from airtable.model.client import cursor_pulls

if TYPE_CHECKING:
    import numpy as np

    from airtable.app.host import Host
    from airtable.physics.table import AirTable


class Aids(Feature):
    """Which aids show, and the collision log and energy chart they draw from (`app.aids`)."""

    show_chart = OverlayFlag("chart")
    draw_order = 2  # after the lesson panels: the labels find their places around them

    def __init__(self, host: Host) -> None:
        super().__init__(host)
        self.trails = False  # the demo's setting until e changes it
        self.show_annotations = False
        self.vectors = 0  # 0 off, 1 velocity, 2 momentum
        self.inspecting = False  # i is held (set again every frame it is)
        self.inspected = None  # the puck i was pressed on, followed while i is held (in a gas the
        # puck under a still cursor changes every frame)
        self.collision_log = aids.CollisionLog()
        self.chart = aids.EnergyChart()

    def on_demo_start(self, table: AirTable) -> None:
        self.collision_log.clear()
        self.chart.clear()
        self.host.painter.new_demo()  # arrow scales are per demo
        self.chart.sample(table)

    def after_step(self, table: AirTable) -> None:
        self.chart.sample(table)
        if self.show_annotations:
            self.collision_log.add(table, self.host.clock_s)

    def forget_after(self, t_s: float) -> None:
        self.chart.drop_after(t_s)

    def chart_corner(self, points_px: np.ndarray) -> int | None:
        """The chart's corner (chosen clear of the pucks at `points_px`), None while it is hidden."""
        if not self.show_chart:
            return None
        self.host.painter.choose_chart_corner(points_px)
        return self.host.painter.corner_in_sight()

    def draw(self) -> None:
        host = self.host
        t, paint = host.table, host.painter
        paint.note_pucks(t.pos_m, t.radius_m)  # the legend and the annotations keep clear of them
        if self.show_chart:  # first: the labels below then find their places around it
            paint.choose_chart_corner(host.env.to_screen(t.pos_m))
            note = self.chart.euler_wiggle_note(t.spring_pairs.size > 0, aids.loses_energy(t))
            paint.energy_chart(self.chart.series(), self.chart.latest(), note)
        if self.vectors and len(t.pos_m):  # before the annotations: its legend has a fixed place
            held = host.local.held
            held = held if held is not None and held.alive else None
            forces = t.forces_on(held, host.dt_s, cursor_pulls(host.clients)) if held is not None else {}
            draw_vectors(paint, t, self.vectors, held, forces)
        if self.show_annotations:
            draw_annotations(paint, self.collision_log.live(host.clock_s), host.clock_s)
        if not self.inspecting:
            self.inspected = None
        else:
            if self.inspected is None or not self.inspected.alive:
                self.inspected = t.puck_at(host.env.to_world(host.mouse_px))
            if self.inspected is not None:
                puck = self.inspected
                paint.inspector(puck.pos_m, puck.radius_m, inspector_lines(t, puck, self.chart.scale))
        self.inspecting = False  # until the held key says so again

    # ------------------------------------------------------------ keys

    def toggle_trails(self) -> None:
        self.trails = not self.trails
        self.host.window.clear_trails()

    def toggle_annotations(self) -> None:
        self.show_annotations = not self.show_annotations
        self.collision_log.clear()

    def next_vectors(self) -> None:
        self.vectors = (self.vectors + 1) % 3

    def toggle_chart(self) -> None:
        self.show_chart = not self.show_chart

    def move_chart(self) -> None:
        self.show_chart = True
        self.host.say(f"energy chart: {self.host.painter.cycle_chart_corner()}")

    def resize_chart(self) -> None:
        self.show_chart = True
        self.host.painter.toggle_chart_size()

    def inspect(self) -> None:
        self.inspecting = True

    bindings = (
        Binding("e", "trails: stop erasing, so each frame's pucks stay on screen", {pygame.K_e: toggle_trails}),
        Binding("a", "collision annotations: axes, overlap, separation, angle", {pygame.K_a: toggle_annotations}),
        Binding("v", "vectors: velocity / momentum arrows, forces, centre of mass", {pygame.K_v: next_vectors}),
        Binding("c", "energy and momentum chart", {pygame.K_c: toggle_chart}),
        Binding(
            "m / b", "chart: move to the next corner / big or small", {pygame.K_m: move_chart, pygame.K_b: resize_chart}
        ),
        Binding(
            "i (hold)", "inspect the puck under the cursor (followed while held)", {pygame.K_i: inspect}, held=True
        ),
    )
