"""The teacher's aids, shared with the students (no pygame).

`shared_aids(app)` gathers what the teacher's window shows into the
numbers the AIDS frame carries (airtable/net/aids_wire.py); `StudentAids`
keeps, on a student's side, what those frames said, plus the student's own
toggles, and hands the drawing code the same objects the teacher's window
draws from (aids.Annotation, aids.EnergyChart).
"""

from __future__ import annotations

import threading
from typing import TYPE_CHECKING

import numpy as np

from airtable.app import aids, rewind
from airtable.app.history import Timeline
from airtable.app.momenta import FEW_PUCKS, MomentaView, PuckValues, every_puck_values, puck_values
from airtable.net import aids_wire
from airtable.net.aids_wire import AidsFrame, AnnotationRecord, SharedAids, SharedLessons

if TYPE_CHECKING:
    from airtable.app.app import App

LOCAL_KEYS = ("v", "c", "i", "e")  # the aids a student may turn on or off on their own window


def record_of(a: aids.Annotation, now_s: float) -> AnnotationRecord:
    numbers = (
        *a.contact_m,
        *a.normal,
        a.overlap_m,
        a.separation_m,
        *a.pos_i_before,
        *a.pos_j_before,
        *a.pos_i_after,
        *a.pos_j_after,
        a.radius_i_m,
        a.radius_j_m,
    )
    t = a.target
    target = None if t is None else (t.actual_deg, t.ideal_deg, *t.pos_m, *t.push_dir, *t.ideal_dir)
    return AnnotationRecord(max(0.0, now_s - a.born_s), numbers, a.angle_deg, target)


def annotation_of(r: AnnotationRecord, born_s: float) -> aids.Annotation:
    n = r.numbers
    target = None
    if r.target is not None:
        t = r.target
        target = aids.TargetPush(t[0], t[1], (t[2], t[3]), (t[4], t[5]), (t[6], t[7]))
    return aids.Annotation(
        born_s=born_s,
        contact_m=(n[0], n[1]),
        normal=(n[2], n[3]),
        overlap_m=n[4],
        separation_m=n[5],
        pos_i_before=(n[6], n[7]),
        pos_j_before=(n[8], n[9]),
        pos_i_after=(n[10], n[11]),
        pos_j_after=(n[12], n[13]),
        radius_i_m=n[14],
        radius_j_m=n[15],
        angle_deg=r.angle_deg,
        target=target,
    )


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


class StudentAids:
    """A student's view of the teacher's aids, and the student's own toggles.

    `take(frame, now_s)` (network thread) and `snapshot()` (each SNAPSHOT)
    update it; the drawing thread reads the properties. `local` maps a key of
    LOCAL_KEYS to True/False where the student overrode the teacher."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self.teacher = 0  # the teacher's aids flags (aids_wire)
        self.frame: AidsFrame | None = None
        self.annotations: list[tuple[int, aids.Annotation]] = []  # (serial, annotation)
        self.chart = aids.EnergyChart(capacity=2048)
        self.notes: str | None = None
        self.local: dict[str, bool] = {}
        self.inspecting = False
        self._got = False
        self._seen: tuple[float, np.ndarray] | None = None  # the previous snapshot's time and positions
        self._derived: np.ndarray | None = None
        self.restarts = 0  # counts demo starts and restarts (time going back, pucks coming or going)

    def snapshot(self, scene) -> None:
        """A SNAPSHOT came in: if the one before had no AIDS after it, the teacher's aids are off."""
        pos = np.asarray(scene.pos_m, dtype=float)
        with self._lock:
            if not self._got:
                self.teacher, self.frame = 0, None
            self._got = False
            seen, self._seen = self._seen, (float(scene.time_s), pos)
            if seen is not None and seen[1].shape == pos.shape and scene.time_s > seen[0]:
                self._derived = (pos - seen[1]) / (scene.time_s - seen[0])
            elif seen is not None and scene.time_s != seen[0]:
                self._derived = None
            if seen is not None and (seen[1].shape != pos.shape or scene.time_s < seen[0]):
                self.restarts += 1  # a restart or another demo: trails and arrow scales start afresh

    def velocities(self, n: int) -> np.ndarray | None:
        """(n, 2) puck velocities: the teacher's when it sends them, else from the last two snapshots."""
        frame = self.frame
        if frame is not None and frame.vectors == 1 and frame.values is not None and len(frame.values) == n:
            return frame.values
        derived = self._derived
        return derived if derived is not None and len(derived) == n else None

    def take(self, frame: AidsFrame, now_s: float) -> None:
        with self._lock:
            self._got = True
            self.teacher, self.frame = frame.flags, frame
            if frame.flags & aids_wire.ANNOTATIONS:
                serial = frame.annotation_serial - len(frame.new_annotations)
                for k, r in enumerate(frame.new_annotations):
                    self.annotations.append((serial + k + 1, annotation_of(r, now_s - r.age_s)))
                first = frame.annotation_serial - frame.live
                self.annotations = [(s, a) for s, a in self.annotations if first < s <= frame.annotation_serial]
            if frame.chart_history is not None:  # the teacher's last seconds, once
                self.chart.clear()
                for row in frame.chart_history:
                    self.chart.append(row)
            if frame.chart is not None:
                self.chart.append(frame.chart)
            if frame.notes is not None:
                self.notes = frame.notes

    def toggle(self, key: str) -> bool:
        """The student pressed `key` (one of LOCAL_KEYS): flip what their window shows; returns it."""
        shown = not self.shows(key)
        self.local[key] = shown
        return shown

    def shows(self, key: str) -> bool:
        flag = {"v": aids_wire.VELOCITY | aids_wire.MOMENTUM, "c": aids_wire.CHART, "e": aids_wire.TRAILS}.get(key, 0)
        return self.local.get(key, bool(self.teacher & flag))

    def chart_view(self, scene) -> tuple[dict, dict, str | None]:
        """(series, latest, note) of the chart, read while the network thread is not appending."""
        with self._lock:
            return self.chart.series(), self.chart.latest(), self.chart.euler_wiggle_note(scene)

    def momenta_view(self, colors: np.ndarray) -> tuple[int, MomentaView | None] | None:
        """(corner, diagram) while the teacher shows the momenta diagram, else None; the rows drawn in
        `colors` (the snapshot's puck colours), as the teacher's window draws them."""
        frame = self.frame
        if frame is None or not frame.lesson_flags & aids_wire.MOMENTA:
            return None
        m = frame.momenta
        if m is None:
            return frame.momenta_corner, None
        colors = np.asarray(colors, dtype=np.uint8).reshape(-1, 3)
        known = m.rows < len(colors)
        shown = np.full((len(m.rows), 3), 200, np.uint8)
        shown[known] = colors[m.rows[known]]
        view = MomentaView(
            m.t_s, m.rows, m.before_Ns, m.after_Ns, np.array(m.total_before_Ns), np.array(m.total_after_Ns), shown
        )
        return frame.momenta_corner, view

    def values_rows(self, pointed: int | None) -> tuple[int, list[PuckValues]] | None:
        """(corner, rows) while the teacher shows the values panel, else None: every puck and the total
        when there are few, else the puck `pointed` at (under this student's cursor) if the frame has it."""
        frame = self.frame
        if frame is None or not frame.lesson_flags & aids_wire.VALUES:
            return None
        mass, vel, rows = frame.value_mass_kg, frame.value_vel_mps, frame.value_rows
        scale = self.chart.scale if self.chart.scale.energy_J > 0 else None  # the scene's, while the chart came
        if frame.values_every:
            return frame.values_corner, every_puck_values(mass, vel, scale)
        at = np.flatnonzero(rows == pointed) if pointed is not None else ()
        if not len(at):
            return frame.values_corner, []
        k = int(at[0])
        return frame.values_corner, puck_values(mass[k : k + 1], vel[k : k + 1], [pointed], scale)

    def timeline(self) -> Timeline | None:
        """Where the teacher's view is in the history while the teacher's window shows the bar, else None."""
        frame = self.frame
        if frame is None or frame.timeline is None:
            return None
        return Timeline(*frame.timeline)

    def live_annotations(self, now_s: float) -> list[aids.Annotation]:
        with self._lock:
            if not self.teacher & aids_wire.ANNOTATIONS:
                return []
            return [a for _, a in self.annotations if a.alpha(now_s) > 0.0]
