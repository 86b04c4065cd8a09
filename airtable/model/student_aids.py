"""A student's view of the teacher's aids: what the AIDS frames said, and the student's own toggles.

The network thread feeds it (`take`, `snapshot`); the student's window reads it
and draws the same objects the teacher's window draws from (aids.Annotation,
aids.EnergyChart)."""

from __future__ import annotations

import dataclasses
import threading

import numpy as np

from airtable.model import aids
from airtable.model import shared_aids as aids_wire
from airtable.model.momenta import MomentaView, PuckValues, every_puck_values, puck_values
from airtable.model.shared_aids import AidsFrame, annotation_of
from airtable.model.timeline import Timeline

LOCAL_KEYS = ("v", "c", "i", "e", "k")  # the aids a student may turn on or off on their own window


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
            springs = len(scene.spring_pairs) > 0
            return self.chart.series(), self.chart.latest(), self.chart.euler_wiggle_note(springs, lossy=False)

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
        scale = None
        if self.chart.scale.energy_J > 0:  # the scene's, while the chart comes; its momentum scale needs the masses
            scale = dataclasses.replace(self.chart.scale)
            scale.observe((), 0.0, float(np.sum(mass)) if mass is not None else 0.0)
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
