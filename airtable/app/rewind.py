"""Rewind in the teacher's app: the keys that move through the table's history, and running on from the past.

The history itself (history.py) keeps the moments; these are the actions the
key table binds (`action(app)`), and `run_on`, which the frame calls once the
table runs again from a moment in the past: the moments after it are
dropped, and so are the recording's samples and the chart's points after it,
so the recording, the chart and the history tell one story.

`,` goes back a frame (and pauses, if the table was running); `.` goes
forward through the history while the view is in the past and, at the
newest moment, steps the physics once as it always did. With Shift they jump
a second of simulated time.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from airtable.app.predict import holds_the_table, round_holds

if TYPE_CHECKING:
    from airtable.app.app import App
    from airtable.model.timeline import Timeline

JUMP_S = 1.0  # Shift+, / Shift+. : this much simulated time


def _moved(app: App) -> None:
    """After the view moved: the trails drawn so far belong to another moment."""
    app.window.clear_trails()


def _back(app: App, frames: int = 0, seconds: float = 0.0) -> None:
    if holds_the_table(app):
        return
    app.paused = True
    h = app.history
    moved = h.back_seconds(app.table, seconds) if seconds else h.back(app.table, frames)
    if moved:
        _moved(app)
    elif len(h):
        app.say(f"this is the oldest moment kept (t = {app.table.time_s:.2f} s; {h.span_s:.1f} s of history)")
    else:
        app.say("no history to go back through: the table is too big to keep a moment in memory")


def _forward(app: App, frames: int = 0, seconds: float = 0.0) -> bool:
    """Forward through the history; False if the view was already the newest moment."""
    h = app.history
    moved = h.forward_seconds(app.table, seconds) if seconds else h.forward(app.table, frames)
    if moved:
        _moved(app)
    return moved


def timeline_shown(app: App) -> Timeline | None:
    """The timeline the bar shows: while paused (or in the past) with more than one moment kept, and no
    prediction round holding the table (its keys are off then), else None. The teacher's window draws
    it, and the students' windows get it in the AIDS frames."""
    if round_holds(app):
        return None
    timeline = app.history.timeline()
    if (app.paused or app.history.in_past) and timeline is not None and timeline.frames > 1:
        return timeline
    return None


def step_back(app: App) -> None:
    _back(app, frames=1)


def jump_back(app: App) -> None:
    _back(app, seconds=JUMP_S)


def step_forward(app: App) -> None:
    """Forward one frame through the history; at the newest moment, one new physics step (while paused)."""
    if holds_the_table(app):
        return
    if not app.paused:
        app.say("'.' steps once while paused (Space pauses)")
    elif not _forward(app, frames=1):
        if app.physics_step():
            app.history.record(app.table)


def jump_forward(app: App) -> None:
    if holds_the_table(app):
        return
    if not app.paused:
        app.say("Shift+. jumps forward through the history while paused (Space pauses)")
    elif not _forward(app, seconds=JUMP_S):
        app.say("this is the newest moment: '.' steps on from here")


def run_on(app: App) -> None:
    """The table runs again from the moment on view: forget what came after it, everywhere."""
    t_s = app.table.time_s
    gone = app.history.drop_future()
    app.lessons.drop_after(t_s)
    app.chart.drop_after(t_s)
    app.say(f"running on from t = {t_s:.2f} s: the {gone} later frame{'' if gone == 1 else 's'} dropped")
