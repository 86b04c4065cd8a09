"""The teacher's aids, shared with the students (no pygame).

`shared_aids(app)` gathers what the teacher's window shows into the numbers
the AIDS frame carries (model/shared_aids.py; the bytes are net/aids_wire.py's).
A student's side keeps them in model/student_aids.py.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from airtable.app import rewind
from airtable.model import aids
from airtable.model import shared_aids as aids_wire
from airtable.model.momenta import FEW_PUCKS
from airtable.model.shared_aids import SharedAids, SharedLessons, record_of

if TYPE_CHECKING:
    from airtable.app.app import App


def shared_aids(app: App) -> SharedAids | None:
    """What the teacher's aids show now; None when every one is off (the students then get no AIDS bytes)."""
    notes = (app.demo.notes or "(no notes)") if app.show_notes and app.demo is not None else None
    lessons = shared_lessons(app)
    if not (app.trails or app.vectors or app.show_annotations or app.show_chart or notes is not None or lessons):
        return None
    t, paint = app.table, app.painter
    values, amount, vel_amount, com = None, 1.0, 1.0, (0.0, 0.0, 0.0, 0.0)
    if app.vectors and len(t.pos_m):
        speed = np.hypot(t.vel_mps[:, 0], t.vel_mps[:, 1])
        moving = speed >= aids.MIN_ARROW_SPEED_MPS
        values = t.vel_mps if app.vectors == 1 else t.vel_mps * t.mass_kg[:, None]
        values = np.where(moving[:, None], values, 0.0)  # resting pucks get no arrow: zeros cost nothing
        name = "velocity" if app.vectors == 1 else "momentum"
        amount = paint.vector_scale(name).update(values[moving])[0]
        vel_amount = paint.vector_scale("velocity").update(t.vel_mps[moving])[0]
        c, cv = t.center_of_mass_m(), t.center_of_mass_vel_mps()
        com = (float(c[0]), float(c[1]), float(cv[0]), float(cv[1]))
    live = tuple(app.collision_log.live(app.clock_s)) if app.show_annotations else ()
    chart, corner, history = None, 0, None
    if app.show_chart:
        latest = app.chart.latest()
        chart = tuple(latest[f] for f in aids.EnergyChart.FIELDS)
        history = _chart_history(app.chart)
        corner = (paint.chart_corner or 0) + (4 if paint.chart_small else 0)
    return SharedAids(
        trails=app.trails,
        vectors=app.vectors,
        values=values,
        amount=amount,
        velocity_amount=vel_amount,
        com=com,
        annotations=live,
        annotation_records=tuple(record_of(a, app.clock_s) for a in live),
        annotations_on=app.show_annotations,
        chart=chart,
        chart_corner=corner,
        chart_history=history,
        notes=notes,
        lessons=lessons,
    )


def shared_lessons(app: App) -> SharedLessons | None:
    """The lesson panels the teacher's window shows (momenta, values, the timeline bar); None if none is."""
    lessons, t = app.lessons, app.table
    timeline = rewind.timeline_shown(app)
    if not (lessons.show_momenta or lessons.show_values or timeline is not None):
        return None
    corners = lessons.painter.corners if lessons.painter is not None else {}
    latest = lessons.momenta.latest
    rows: list[int] = []
    every = len(t.pos_m) <= FEW_PUCKS
    if lessons.show_values:
        rows = list(range(len(t.pos_m))) if every else _pointed(app)
    return SharedLessons(
        momenta_on=lessons.show_momenta,
        momenta_corner=corners.get("momenta") or 0,
        momenta=None if latest is None else latest.view,
        values_on=lessons.show_values,
        values_corner=corners.get("values") or 0,
        values_every=every,
        value_rows=tuple(rows),
        value_mass_kg=t.mass_kg[rows],
        value_vel_mps=t.vel_mps[rows],
        timeline=None
        if timeline is None
        else (timeline.oldest_s, timeline.newest_s, timeline.view_s, timeline.frames, timeline.index),
    )


def _pointed(app: App) -> list[int]:
    """The pucks under the students' cursors (each student's values panel shows the one under its own)."""
    found = set()
    for client in app.clients[1:]:
        puck = app.table.puck_at(client.cursor_m) if client.active else None
        if puck is not None:
            found.add(puck.index)
    return sorted(found)[: aids_wire.MAX_VALUE_ROWS]


def _chart_history(chart: aids.EnergyChart) -> np.ndarray:
    """The chart's window before its newest sample, thinned to at most MAX_CHART_HISTORY samples."""
    series = chart.series()
    rows = np.column_stack([series[f] for f in aids.EnergyChart.FIELDS])[:-1]
    if len(rows) > aids_wire.MAX_CHART_HISTORY:
        rows = rows[np.linspace(0, len(rows) - 1, aids_wire.MAX_CHART_HISTORY).astype(int)]
    return rows
