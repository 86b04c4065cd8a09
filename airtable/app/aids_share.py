"""The teacher's aids, shared with the students (no pygame).

`shared_aids` gathers what the teacher's window shows (the Aids, Lessons and
Rewind features, the notes) into the numbers the AIDS frame carries
(model/shared_aids.py; the bytes are net/aids_wire.py's).
A student's side keeps them in model/student_aids.py.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from airtable.model import aids
from airtable.model import shared_aids as aids_wire
from airtable.model.momenta import FEW_PUCKS
from airtable.model.shared_aids import SharedAids, SharedLessons, record_of

if TYPE_CHECKING:
    from airtable.app.aids_paint import AidsPainter
    from airtable.app.lessons import Lessons
    from airtable.app.teaching_aids import Aids
    from airtable.model.client import Client
    from airtable.model.timeline import Timeline
    from airtable.physics.table import AirTable


def shared_aids(
    shown: Aids, t: AirTable, paint: AidsPainter, clock_s: float, notes: str | None, lessons: SharedLessons | None
) -> SharedAids | None:
    """What the teacher's aids `shown` show now on table `t`, with the `notes` and `lessons` panels shown (None
    if not); None when every one is off (the students then get no AIDS bytes)."""
    panels = notes is not None or lessons is not None
    if not (shown.trails or shown.vectors or shown.show_annotations or shown.show_chart or panels):
        return None
    values, amount, vel_amount, com = None, 1.0, 1.0, (0.0, 0.0, 0.0, 0.0)
    if shown.vectors and len(t.pos_m):
        speed = np.hypot(t.vel_mps[:, 0], t.vel_mps[:, 1])
        moving = speed >= aids.MIN_ARROW_SPEED_MPS
        values = t.vel_mps if shown.vectors == 1 else t.vel_mps * t.mass_kg[:, None]
        values = np.where(moving[:, None], values, 0.0)  # resting pucks get no arrow: zeros cost nothing
        name = "velocity" if shown.vectors == 1 else "momentum"
        amount = paint.vector_scale(name).update(values[moving])[0]
        vel_amount = paint.vector_scale("velocity").update(t.vel_mps[moving])[0]
        c, cv = t.center_of_mass_m(), t.center_of_mass_vel_mps()
        com = (float(c[0]), float(c[1]), float(cv[0]), float(cv[1]))
    live = tuple(shown.collision_log.live(clock_s)) if shown.show_annotations else ()
    chart, corner, history = None, 0, None
    if shown.show_chart:
        latest = shown.chart.latest()
        chart = tuple(latest[f] for f in aids.EnergyChart.FIELDS)
        history = _chart_history(shown.chart)
        corner = (paint.chart_corner or 0) + (4 if paint.chart_small else 0)
    return SharedAids(
        trails=shown.trails,
        vectors=shown.vectors,
        values=values,
        amount=amount,
        velocity_amount=vel_amount,
        com=com,
        annotations=live,
        annotation_records=tuple(record_of(a, clock_s) for a in live),
        annotations_on=shown.show_annotations,
        chart=chart,
        chart_corner=corner,
        chart_history=history,
        chart_version=shown.chart.version,
        notes=notes,
        lessons=lessons,
    )


def shared_lessons(
    lessons: Lessons, timeline: Timeline | None, t: AirTable, clients: list[Client]
) -> SharedLessons | None:
    """The lesson panels the teacher's window shows (momenta, values, the `timeline` bar); None if none is."""
    if not (lessons.show_momenta or lessons.show_values or timeline is not None):
        return None
    corners = lessons.painter.corners if lessons.painter is not None else {}
    rows: list[int] = []
    every = len(t.pos_m) <= FEW_PUCKS
    if lessons.show_values:
        rows = list(range(len(t.pos_m))) if every else _pointed(t, clients)
    return SharedLessons(
        momenta_on=lessons.show_momenta,
        momenta_corner=corners.get("momenta") or 0,
        momenta=lessons.momenta_shown(t),
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


def _pointed(t: AirTable, clients: list[Client]) -> list[int]:
    """The pucks under the students' cursors (each student's values panel shows the one under its own)."""
    found = set()
    for client in clients[1:]:
        puck = t.puck_at(client.cursor_m) if client.active else None
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
