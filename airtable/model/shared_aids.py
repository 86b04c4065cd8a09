"""The teacher's aids as they are shared: what the app hands the server at each tick
(`SharedAids`), what a student's side decodes (`AidsFrame`), and the flags both read.
The bytes are net/aids_wire.py's business; the numbers are here, below both.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from airtable.model import aids

# Which aids are on (the AIDS frame's flags byte).
TRAILS = 1
ANNOTATIONS = 2
VELOCITY = 4
MOMENTUM = 8
CHART = 16
NOTES = 32
NOTES_TEXT = 64  # the notes' text is in this frame
VECTOR_KEY = 128  # the vector values are not a delta (no base)
# The lesson flags byte (format 2).
MOMENTA = 1  # the momenta diagram is on: its corner and the serial of the collision it shows
MOMENTA_ROWS = 2  # that collision's rows follow (this student does not hold them yet)
VALUES = 4  # the values panel is on: its corner and its pucks' masses and velocities
TIMELINE = 8  # the rewind timeline bar is on: where the view is in the history
LESSON_FLAGS = MOMENTA | MOMENTA_ROWS | VALUES | TIMELINE
MAX_CHART_HISTORY = 600  # samples of the teacher's chart sent once to a student who lacks them
MAX_VALUE_ROWS = 256  # pucks in the values panel's section: every puck when few, else one per student


@dataclass(frozen=True, eq=False)
class AnnotationRecord:
    """The numbers a collision annotation is drawn from (aids.Annotation without its clock)."""

    age_s: float  # how old it was when sent
    numbers: tuple[float, ...]  # contact 2, normal 2, overlap, separation, 4 positions x 2, radius i, radius j
    angle_deg: float | None = None
    target: tuple[float, ...] | None = None  # actual, ideal deg, pos 2, push dir 2, ideal dir 2


@dataclass(frozen=True, eq=False)
class SharedLessons:
    """The teacher's lesson panels and rewind bar at one tick, as the app hands them to the server."""

    momenta_on: bool = False
    momenta_corner: int = 0  # aids_paint.CHART_CORNERS
    momenta: object = None  # the diagram's momenta.MomentaView (a new object: a new collision); None: none yet
    values_on: bool = False
    values_corner: int = 0
    values_every: bool = True  # the rows are every puck (a few); else those under the students' cursors
    value_rows: tuple[int, ...] = ()
    value_mass_kg: np.ndarray | None = None  # (R,)
    value_vel_mps: np.ndarray | None = None  # (R, 2)
    timeline: tuple[float, float, float, int, int] | None = None  # oldest, newest, view s; frames, index

    @property
    def flags(self) -> int:
        f = MOMENTA if self.momenta_on else 0
        f |= VALUES if self.values_on else 0
        return f | (TIMELINE if self.timeline is not None else 0)


@dataclass(frozen=True)
class MomentaRecord:
    """A momenta diagram as it travels: the rows drawn, their momenta (K, 2) and the totals of all pucks."""

    t_s: float
    rows: np.ndarray
    before_Ns: np.ndarray
    after_Ns: np.ndarray
    total_before_Ns: tuple[float, float]
    total_after_Ns: tuple[float, float]


@dataclass(frozen=True, eq=False)
class SharedAids:
    """What the teacher's aids show at one tick, as the app hands it to the server."""

    trails: bool = False
    vectors: int = 0  # 0 off, 1 velocity, 2 momentum
    values: np.ndarray | None = None  # (N, 2) the drawn quantity per puck
    amount: float = 1.0  # the round value an arrow 1 m long stands for
    velocity_amount: float = 1.0  # the same for velocities (the centre of mass arrow)
    com: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)  # x, y, vx, vy
    annotations: tuple = ()  # live annotations (objects; the encoder gives each a serial), oldest first
    annotation_records: tuple[AnnotationRecord, ...] = ()
    chart: tuple[float, ...] | None = None  # the newest sample: time, kinetic, spring, gravity, total, |p|
    chart_corner: int = 0  # where the teacher's chart is (aids_paint.CHART_CORNERS), + 4 if small
    chart_history: np.ndarray | None = None  # (H, 6) the samples before `chart`, oldest first
    chart_version: int = 0  # changes when samples are taken back (a rewind, a restart): the history goes again
    notes: str | None = None  # the lecture notes, while their panel is open

    annotations_on: bool = False
    lessons: SharedLessons | None = None  # the momenta diagram, the values panel, the timeline (format 2)

    @property
    def lesson_flags(self) -> int:
        return 0 if self.lessons is None else self.lessons.flags

    @property
    def flags(self) -> int:
        f = TRAILS if self.trails else 0
        f |= {1: VELOCITY, 2: MOMENTUM}.get(self.vectors, 0)
        f |= ANNOTATIONS if self.annotations_on else 0
        f |= CHART if self.chart is not None else 0
        f |= NOTES if self.notes is not None else 0
        return f


@dataclass
class AidsFrame:
    """One decoded AIDS frame."""

    seq: int
    flags: int
    values: np.ndarray | None = None  # (N, 2) float, the drawn quantity
    amount: float = 1.0
    velocity_amount: float = 1.0
    com: tuple[float, float, float, float] = (0.0, 0.0, 0.0, 0.0)
    annotation_serial: int = 0
    live: int = 0
    new_annotations: list[AnnotationRecord] = field(default_factory=list)
    chart: tuple[float, ...] | None = None
    chart_corner: int = 0
    chart_history: np.ndarray | None = None  # (H, 6), only when it came in this frame
    notes: str | None = None  # only when its text came in this frame
    lesson_flags: int = 0
    momenta_corner: int = 0
    momenta: MomentaRecord | None = None  # the diagram's collision (held from an earlier frame, or new)
    values_corner: int = 0
    values_every: bool = True
    value_rows: np.ndarray | None = None  # (R,) int
    value_mass_kg: np.ndarray | None = None  # (R,)
    value_vel_mps: np.ndarray | None = None  # (R, 2)
    timeline: tuple[float, float, float, int, int] | None = None  # oldest, newest, view s; frames, index

    @property
    def vectors(self) -> int:
        return 1 if self.flags & VELOCITY else 2 if self.flags & MOMENTUM else 0


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
