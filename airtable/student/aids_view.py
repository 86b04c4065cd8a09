"""Drawing the teacher's aids on a student's window, with the student's own toggles.

The numbers come from StudentAids (aids_share.py), filled from the AIDS
frames; the pixels from the same AidsPainter and panel code the teacher's
window uses, so both windows show the same arrows, annotations and chart.
"""

from __future__ import annotations

import numpy as np

from airtable.app.aids_paint import AidsPainter, draw_annotations
from airtable.app.aids_view import COM_COLOR
from airtable.app.lessons_paint import values_hint
from airtable.model import aids
from airtable.model import shared_aids as aids_wire
from airtable.model.momenta import FEW_PUCKS, puck_number
from airtable.model.scene import Scene
from airtable.model.student_aids import StudentAids

VELOCITY_COLOR = (120, 220, 255)
MOMENTUM_COLOR = (230, 120, 230)
# The keys of a student's window, as its F1 panel lists them.
STUDENT_KEYS = (
    ("mouse buttons 1 / 2 / 3", "grab a puck with the medium / soft / stiff cursor string"),
    ("v", "arrows on your window: the teacher's, or velocities from the snapshots when the teacher has none"),
    ("c", "hide or show the teacher's energy and momentum chart on your window"),
    ("i", "inspect the puck under your cursor, on or off"),
    ("e", "trails on your window, on or off"),
    ("k", "puck numbers on your window (as the teacher's summaries count them), on or off"),
    ("L", "the teacher's notes, while shown: their next page; after the last, hidden here (L shows them again)"),
    ("F1", "this help (again: its next page, then close it)"),
    ("F11", "fullscreen on / off"),
    ("Esc", "close this help or the notes; else leave the table (Esc twice)"),
)


def draw_student_aids(paint: AidsPainter, scene: Scene, state: StudentAids, now_s: float, mouse_m) -> None:
    """The aids over a student's frame: chart, vectors, annotations, inspector (in the teacher's order)."""
    env = paint.w.env
    paint.note_pucks(scene.pos_m, scene.radius_m)  # the legend and the annotations keep clear of them
    # The chart needs the teacher's samples: the student can hide it, not make it up.
    chart = state.chart_view(scene) if state.shows("c") and state.teacher & aids_wire.CHART else None
    series = chart[0] if chart else None
    if series is not None and len(series["time_s"]):
        frame = state.frame
        if frame is not None and frame.chart is not None:  # where the teacher has it
            paint.chart_corner, paint.chart_small = frame.chart_corner % 4, frame.chart_corner >= 4
        elif len(scene.pos_m):
            paint.choose_chart_corner(env.to_screen(scene.pos_m))
        paint.energy_chart(*chart)
    if state.shows("v") and len(scene.pos_m):
        _vectors(paint, scene, state)
    draw_annotations(paint, state.live_annotations(now_s), now_s)
    if state.shows("i"):
        _inspect(paint, scene, state, mouse_m)


def draw_student_lessons(paint, timeline_paint, scene: Scene, state: StudentAids, mouse_m) -> None:
    """The teacher's lesson panels on a student's frame, where the teacher has them: the momenta diagram,
    the values panel (of the puck under this student's cursor when there are many) and the timeline bar.
    `paint` is the window's LessonsPainter, `timeline_paint` its TimelinePainter. The bar first, as
    on the teacher's window: the panels stand clear of it."""
    timeline = state.timeline()
    if timeline is not None:
        timeline_paint.timeline(timeline)
    momenta = state.momenta_view(scene.color_rgb)
    if momenta is not None:
        corner, view = momenta
        paint.momenta_diagram(view, corner)
    pointed = puck_under(scene, mouse_m) if len(scene.pos_m) > FEW_PUCKS else None
    values = state.values_rows(pointed)
    if values is not None:
        corner, rows = values
        n = len(scene.color_rgb)
        colors = [scene.color_rgb[r.row] if r.row is not None and r.row < n else None for r in rows]
        paint.values_panel(rows, colors, values_hint(n), corner)


def puck_under(scene: Scene, point_m) -> int | None:
    """The row of the puck under `point_m` (the last drawn, on top, as the teacher's table picks), or None."""
    pos = np.asarray(scene.pos_m, dtype=float).reshape(-1, 2)
    d2 = (pos[:, 0] - point_m[0]) ** 2 + (pos[:, 1] - point_m[1]) ** 2
    inside = np.flatnonzero(d2 <= np.asarray(scene.radius_m, dtype=float) ** 2)
    return int(inside[-1]) if len(inside) else None


def _vectors(paint: AidsPainter, scene: Scene, state: StudentAids) -> None:
    """The teacher's arrows at the teacher's round scale; without them, velocities from the snapshots."""
    frame = state.frame
    n = len(scene.pos_m)
    if frame is not None and frame.values is not None and len(frame.values) == n:
        values, amount = frame.values, frame.amount
        name, unit, color = (
            ("velocity", "m/s", VELOCITY_COLOR) if frame.vectors == 1 else ("momentum", "N s", MOMENTUM_COLOR)
        )
        com = np.asarray(frame.com[:2]), np.asarray(frame.com[2:])
        m_per_mps = 1.0 / frame.velocity_amount
    else:
        values = state.velocities(n)
        if values is None:
            return
        name, unit, color = "velocity (from the snapshots)", "m/s", VELOCITY_COLOR
        amount = paint.vector_scale("student velocity").update(values)[0]
        com, m_per_mps = None, 0.0
    moving = np.hypot(values[:, 0], values[:, 1]) > 0
    paint.arrows(scene.pos_m[moving], values[moving] / amount, color)
    paint.legend([(f"{name}: an arrow 1 m long is {amount:g} {unit}", color)])
    if com is not None:
        if np.hypot(*com[1]) >= aids.MIN_ARROW_SPEED_MPS:
            paint.arrow(com[0], com[1] * m_per_mps, COM_COLOR, width=paint.w.line_px(3))
        paint.marker(com[0], COM_COLOR, f"centre of mass, {np.hypot(*com[1]):.2f} m/s")


def _inspect(paint: AidsPainter, scene: Scene, state: StudentAids, mouse_m) -> None:
    pos = np.asarray(scene.pos_m, dtype=float).reshape(-1, 2)
    if not len(pos):
        return
    d = np.hypot(pos[:, 0] - mouse_m[0], pos[:, 1] - mouse_m[1])
    k = int(np.argmin(d))
    if d[k] > scene.radius_m[k]:
        return
    lines = [f"puck {puck_number(k)}   radius {scene.radius_m[k]:.4g} m", f"at ({pos[k, 0]:.3f}, {pos[k, 1]:.3f}) m"]
    v = state.velocities(len(pos))
    if v is not None:
        lines.append(f"speed {np.hypot(*v[k]):.3g} m/s (from the snapshots)")
    paint.inspector(pos[k], float(scene.radius_m[k]), lines)
