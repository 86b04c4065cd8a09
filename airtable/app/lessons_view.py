"""Drawing the lesson panels of a frame: the momenta diagram (d) and the values panel (t).

The numbers come from momenta.py and the table; the pixels from the
window's LessonsPainter. The app calls `draw_lessons(app)` before the
teaching aids, so their labels place themselves around these panels.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from airtable.app.pucks_view import draw_numbers
from airtable.app.window import LessonsPainter
from airtable.model.momenta import FEW_PUCKS, puck_number, values_for

if TYPE_CHECKING:
    from airtable.app.app import App

VALUES_HINT = f"values: more than {FEW_PUCKS} pucks, so point at one"


def draw_lessons(app: App) -> None:
    lessons = app.lessons
    if lessons.show_numbers and len(app.table.pos_m):
        t = app.table
        numbers = [puck_number(row) for row in range(len(t.pos_m))]
        draw_numbers(app.window.surface, app.window.label_font, app.env.to_screen(t.pos_m), numbers)
    if not (lessons.show_momenta or lessons.show_values):
        return
    if lessons.painter is None:
        lessons.painter = LessonsPainter(app.window)
    paint, t = lessons.painter, app.table
    points = app.env.to_screen(t.pos_m) if len(t.pos_m) else t.pos_m
    taken = []
    if app.show_chart:  # the chart keeps its corner; the panels take others
        app.painter.choose_chart_corner(points)
        taken.append(app.painter.chart_corner)
    if lessons.show_momenta:
        corner = paint.choose_corner("momenta", points, taken)
        taken.append(corner)
        latest = lessons.momenta.latest
        paint.momenta_diagram(None if latest is None else latest.view, corner)
    if lessons.show_values:
        puck = t.puck_at(app.env.to_world(app.mouse_px)) if len(t.pos_m) > FEW_PUCKS else None
        rows = values_for(t, None if puck is None else puck.index, app.chart.scale)
        colors = [t.color_rgb[r.row] if r.row is not None else None for r in rows]
        paint.values_panel(rows, colors, VALUES_HINT, paint.choose_corner("values", points, taken))
