"""Rewind in the teacher's app (`Rewind`): the table's history, the keys that move through it, its timeline
bar, and running on from the past.

The history itself (history.py) keeps the moments; after every frame whose
physics stepped, the table as it is joins it. Once the table runs again from a
moment in the past, the moments after it are dropped, and every feature
forgets what it saw later (`Host.forget_after`: the recording's samples and
the chart's points), so the recording, the chart and the history tell one story.

`,` goes back a frame (and pauses, if the table was running); `.` goes
forward through the history while the view is in the past and, at the
newest moment, steps the physics once as it always did. With Shift they jump
a second of simulated time. A prediction round that holds the table turns
these keys off.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import pygame

from airtable.app.feature import Binding, Feature
from airtable.app.history import History
from airtable.app.timeline_paint import TimelinePainter

if TYPE_CHECKING:
    from airtable.app.host import Host
    from airtable.app.predict import Predict
    from airtable.model.timeline import Timeline
    from airtable.physics.table import AirTable

JUMP_S = 1.0  # Shift+, / Shift+. : this much simulated time


class Rewind(Feature):
    """The table's recent moments and the way back through them (`app.rewind`)."""

    draw_order = 0  # first: the lesson panels then stand clear of the bar

    def __init__(self, host: Host, predict: Predict) -> None:
        super().__init__(host)
        self.predict = predict  # a round under way holds the table
        self.history = History()
        self.painter = TimelinePainter(host.window)
        self._steps = 0  # the table's step count before the frame's physics

    def on_demo_start(self, table: AirTable) -> None:
        self.history.clear()
        self.history.record(table)

    def before_physics(self) -> None:
        """Running again from a moment in the past: its future is dropped, everywhere."""
        host = self.host
        self._steps = host.table.steps
        if host.paused or not self.history.in_past:
            return
        t_s = host.table.time_s
        gone = self.history.drop_future()
        host.forget_after(t_s)
        host.say(f"running on from t = {t_s:.2f} s: the {gone} later frame{'' if gone == 1 else 's'} dropped")

    def after_physics(self) -> None:
        """The table as the frame's steps left it joins the history."""
        if self.host.table.steps != self._steps:
            self.history.record(self.host.table)

    def timeline_shown(self) -> Timeline | None:
        """The timeline the bar shows: while paused (or in the past) with more than one moment kept, and no
        prediction round holding the table (its keys are off then), else None. The teacher's window draws
        it, and the students' windows get it in the AIDS frames."""
        if self.predict.holds():
            return None
        timeline = self.history.timeline()
        if (self.host.paused or self.history.in_past) and timeline is not None and timeline.frames > 1:
            return timeline
        return None

    def status_parts(self, for_students: bool) -> list[str]:
        timeline = self.history.timeline() if self.history.in_past else None
        return [] if timeline is None else [f"rewound {timeline.newest_s - timeline.view_s:.2f} s"]

    def draw(self) -> None:
        """While paused (or in the past), where the view is in the history."""
        timeline = self.timeline_shown()
        if timeline is not None:
            self.painter.timeline(timeline)

    # ------------------------------------------------------------ keys

    def _back(self, frames: int = 0, seconds: float = 0.0) -> None:
        if self.predict.holds_the_table():
            return
        host, h = self.host, self.history
        host.paused = True
        moved = h.back_seconds(host.table, seconds) if seconds else h.back(host.table, frames)
        if moved:
            host.window.clear_trails()  # the trails drawn so far belong to another moment
        elif len(h):
            host.say(f"this is the oldest moment kept (t = {host.table.time_s:.2f} s; {h.span_s:.1f} s of history)")
        else:
            host.say("no history to go back through: the table is too big to keep a moment in memory")

    def _forward(self, frames: int = 0, seconds: float = 0.0) -> bool:
        """Forward through the history; False if the view was already the newest moment."""
        h, table = self.history, self.host.table
        moved = h.forward_seconds(table, seconds) if seconds else h.forward(table, frames)
        if moved:
            self.host.window.clear_trails()
        return moved

    def step_back(self) -> None:
        self._back(frames=1)

    def jump_back(self) -> None:
        self._back(seconds=JUMP_S)

    def step_forward(self) -> None:
        """Forward one frame through the history; at the newest moment, one new physics step (while paused)."""
        if self.predict.holds_the_table():
            return
        if not self.host.paused:
            self.host.say("'.' steps once while paused (Space pauses)")
        elif not self._forward(frames=1):
            if self.host.physics_step():
                self.history.record(self.host.table)

    def jump_forward(self) -> None:
        if self.predict.holds_the_table():
            return
        if not self.host.paused:
            self.host.say("Shift+. jumps forward through the history while paused (Space pauses)")
        elif not self._forward(seconds=JUMP_S):
            self.host.say("this is the newest moment: '.' steps on from here")

    bindings = (
        Binding(
            ", / .",
            "rewind / on a step (Shift: 1 s)",
            {
                pygame.K_COMMA: step_back,
                pygame.K_PERIOD: step_forward,
                (pygame.KMOD_SHIFT, pygame.K_COMMA): jump_back,
                (pygame.KMOD_SHIFT, pygame.K_PERIOD): jump_forward,
            },
        ),
    )
