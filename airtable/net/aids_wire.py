"""The teacher's teaching aids on the wire: the AIDS frame (type 10, server -> client). No pygame, no sockets.

When the teacher turns an aid on (trails, collision annotations, vectors,
the energy chart, the lecture notes), each SNAPSHOT is followed by one AIDS
frame for the same tick. With every aid off nothing is sent: not one byte.
What it carries, and how compactly:

- which aids are on (one flag byte);
- vectors: the arrows' round scale (the teacher's, fixed per demo), the centre
  of mass and its velocity, and per puck the drawn quantity (velocity or
  momentum) in steps of a thousandth of that scale (an arrow 1 m long is
  1000 steps: arrows are exact to a millimetre of table, and 1 mm/s for a
  1 m/s scale), coded against the values the same student got last (they
  change little between ticks), zigzag byte planes, deflated when shorter;
- annotations: the serial of the newest collision and how many are live; the
  full record (16-26 float32) only of those this student has not had yet;
- the chart: the newest sample (5 float32; its time is the snapshot's); the student keeps the
  history, and gets the teacher's last seconds (at most MAX_CHART_HISTORY samples) once, when
  the chart first reaches it;
- the notes: their text only when this student does not hold it yet;
- the lesson panels (format 2, only while one is on; format 1 frames are
  unchanged): which of the momenta diagram, the values panel and the rewind
  timeline the teacher shows, in which corner; the diagram's rows (16 bytes
  each, at most MAX_MOMENTA_ROWS, with the totals of all pucks) only when
  this student does not hold that collision yet; the values panel's pucks
  (mass and velocity, 16 bytes each: every puck when there are few, else
  the pucks under the students' cursors); the timeline's times and frames.

`AidsEncoder` (server) caches one encoding per (tick, what the student
holds), so students on the same footing share it. `AidsDecoder` (player)
checks every count, index and value before use and raises ProtocolError.
"""

from __future__ import annotations

import math
import struct
import threading
from dataclasses import dataclass

import numpy as np

from airtable.model.shared_aids import (  # noqa: F401  (the numbers these bytes carry, importable from here)
    ANNOTATIONS,
    CHART,
    LESSON_FLAGS,
    MAX_CHART_HISTORY,
    MAX_VALUE_ROWS,
    MOMENTA,
    MOMENTA_ROWS,
    MOMENTUM,
    NOTES,
    NOTES_TEXT,
    TIMELINE,
    TRAILS,
    VALUES,
    VECTOR_KEY,
    VELOCITY,
    AidsFrame,
    AnnotationRecord,
    MomentaRecord,
    SharedAids,
    SharedLessons,
)
from airtable.net.protocol import AIDS, MAX_DRAWN_PUCKS, ProtocolError, encode_frame
from airtable.net.wire import Reader, bad, deflate, inflate, pack_residuals, unpack_residuals, wire_text

AIDS_MAGIC = b"ATAD"
AIDS_VERSION = 1  # no lesson panel on: the frame as it always was
LESSONS_VERSION = 2  # a lesson flags byte follows the header, then the panels' sections at the end


ARROW_STEPS = 1000  # vector values travel in thousandths of the arrow scale
MAX_VALUE = 1 << 20  # steps: an arrow of at most a kilometre (the scale keeps real ones under 1 m)
MAX_ANNOTATIONS = 8
MAX_AGE_MS = 60_000
MAX_NOTES_BYTES = 16_384
MAX_VECTOR_HISTORY = 8  # ticks of vector values kept as bases
MAX_COORD_M = 1e6  # a position or length beyond this is not a picture of a table
MAX_MOMENTA_ROWS = 64  # arrows in a momenta diagram (momenta.MAX_DIAGRAM_PUCKS draws at most 40)
MAX_HISTORY_FRAMES = 1 << 31
MAX_NUMBER = 1e30  # any momentum, mass, velocity or time beyond this is not physics

_HEAD = struct.Struct("<4sBBI")  # magic, version, flags, tick seq
_VEC = struct.Struct("<H6fBBI")  # N, amount, velocity amount, com x, y, vx, vy, width, deflated, block size
_ANN_HEAD = struct.Struct("<IBB")  # newest serial, live count, new count
_ANN = struct.Struct("<HB16f")  # age ms, has (1 angle, 2 target), 16 numbers
_ANGLE = struct.Struct("<f")
_TARGET = struct.Struct("<8f")
# The sample without its time (the snapshot's), then the teacher's corner (0-3) + 4 if the chart is small
# + 128 if the history follows: u16 H, then H samples of 6 f4 (time first), oldest first.
_CHART = struct.Struct("<5fB")
HISTORY_FOLLOWS = 128
_NOTES = struct.Struct("<HH")  # notes version, text size (then deflated text)
_LESSONS = struct.Struct("<B")  # the lesson flags, right after the header (format 2)
_MOMENTA = struct.Struct("<BI")  # corner, serial of the collision shown (0: none yet)
_MOMENTA_ROWS = struct.Struct("<d4fH")  # time, total before x y, total after x y, K; K u32 rows; K x 4 f4
_VALUES = struct.Struct("<BBH")  # corner, every puck (1) or the pointed ones (0), R; R u32 rows; R x 3 f4
_TIMELINE = struct.Struct("<3dII")  # oldest, newest, view s; frames kept, the one on view


@dataclass
class AidsViewer:
    """What one student holds of the aids: vector values of a tick, annotations up to a serial, notes."""

    vector_seq: int = 0
    annotation_serial: int = 0
    notes_version: int = -1
    # The version of the teacher's chart whose history (and every sample since) it has; None: none (a rewind or
    # a restart takes samples back and changes the version: the history goes again).
    chart_version: int | None = None
    momenta_serial: int = 0  # the collision whose momenta it holds


@dataclass
class _Prepared:
    seq: int
    flags: int
    aids: SharedAids
    values: np.ndarray | None  # int64 (2N,): x of N then y of N
    serials: tuple[int, ...]  # of the live annotations, oldest first
    notes_version: int
    momenta_serial: int = 0  # of the collision the diagram shows (0: none yet)

    @property
    def base_key(self) -> tuple:
        """Values are deltas only on values of the same quantity at the same scale."""
        return (self.flags & (VELOCITY | MOMENTUM), _scale32(self.aids.amount), self.values)


class AidsEncoder:
    """Server side: `add(aids, seq)` per tick (game loop), `frame_for(viewer)` per student (network thread)."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._newest: _Prepared | None = None
        # seq -> (flags, scale, values); rebuilt on each publish: readers keep their copy
        self._history: dict[int, tuple] = {}
        self._serials: dict[int, tuple[object, int]] = {}  # id(annotation) -> (annotation, serial)
        self._next_serial = 1
        self._notes: str | None = None
        self._notes_version = 0
        self._cache: dict[tuple, bytes] = {}
        self._momenta: tuple[object, int] = (None, 0)  # the diagram's momenta and their serial

    def prepare(self, aids: SharedAids | None, seq: int) -> _Prepared | None:
        """The aids of tick `seq`, made ready (O(N), outside any lock); None, or every aid off: nothing to send."""
        return None if aids is None or not (aids.flags or aids.lesson_flags) else self._prepare(aids, seq)

    def publish(self, prepared: _Prepared | None) -> None:
        """Make `prepared` the newest (the snapshot encoder calls this with its tick, under its lock)."""
        with self._lock:
            self._newest = prepared
            self._cache = {}
            if prepared is not None and prepared.values is not None:
                kept = sorted(self._history)[-(MAX_VECTOR_HISTORY - 1) :]
                self._history = {**{s: self._history[s] for s in kept}, prepared.seq: prepared.base_key}

    def state(self) -> tuple:
        """What frame_for needs, read at one moment (with the snapshot tick it goes with)."""
        with self._lock:
            return self._newest, self._history, self._cache, self._notes

    def _prepare(self, aids: SharedAids, seq: int) -> _Prepared:
        values = None
        if aids.vectors and aids.values is not None:
            v = np.nan_to_num(np.asarray(aids.values, dtype=float).reshape(-1, 2), posinf=0.0, neginf=0.0)
            q = np.rint(v * (ARROW_STEPS / _scale32(aids.amount)))
            q = np.clip(np.nan_to_num(q), -MAX_VALUE, MAX_VALUE).astype(np.int64)
            values = np.concatenate([q[:, 0], q[:, 1]])
        serials = []
        known = {}
        for a in aids.annotations[-MAX_ANNOTATIONS:]:
            old = self._serials.get(id(a))
            if old is None or old[0] is not a:
                old = (a, self._next_serial)
                self._next_serial += 1
            known[id(a)] = old
            serials.append(old[1])
        self._serials = known  # forget the faded ones (and ids that could be reused)
        if aids.notes is not None and aids.notes != self._notes:
            self._notes, self._notes_version = aids.notes, (self._notes_version + 1) & 0xFFFF
        return _Prepared(seq, aids.flags, aids, values, tuple(serials), self._notes_version, self._momenta_serial(aids))

    def _momenta_serial(self, aids: SharedAids) -> int:
        """A serial per collision the diagram shows (a new MomentaView object is a new one); 0 for none."""
        momenta = aids.lessons.momenta if aids.lesson_flags & MOMENTA else None
        if momenta is None:
            return 0
        held, serial = self._momenta
        if held is not momenta:
            serial = serial % 0xFFFFFFFF + 1  # wraps past 0, which means "none"
            self._momenta = (momenta, serial)
        return serial

    def frame_for(self, viewer: AidsViewer, state: tuple | None = None) -> bytes:
        """The AIDS frame for `viewer` at the tick of `state` (default: the newest); b"" with every aid off.
        Updates `viewer`."""
        p, history, cache, notes = self.state() if state is None else state
        if p is None:
            viewer.chart_version = None
            return b""
        held = history.get(viewer.vector_seq) if p.values is not None else None
        base = held[2] if held is not None and held[:2] == p.base_key[:2] and held[2].shape == p.values.shape else None
        fresh = [s for s in p.serials if s > viewer.annotation_serial]
        send_notes = bool(p.flags & NOTES) and viewer.notes_version != p.notes_version
        behind = viewer.chart_version != p.aids.chart_version
        sync = bool(p.flags & CHART) and behind and p.aids.chart_history is not None
        rows = p.momenta_serial != 0 and viewer.momenta_serial != p.momenta_serial
        key = (p.seq, viewer.vector_seq if base is not None else 0, len(fresh), send_notes, sync, rows)
        data = cache.get(key)
        if data is None:
            data = cache[key] = encode_frame(AIDS, encode_aids(p, base, len(fresh), send_notes, notes, sync, rows))
        viewer.chart_version = p.aids.chart_version if p.flags & CHART else None
        if p.aids.lesson_flags & MOMENTA:
            viewer.momenta_serial = p.momenta_serial
        if p.values is not None:
            viewer.vector_seq = p.seq
        if p.serials:
            viewer.annotation_serial = max(viewer.annotation_serial, p.serials[-1])
        if send_notes:
            viewer.notes_version = p.notes_version
        return data


def _scale32(amount: float) -> float:
    """The arrow scale as it travels (float32), never 0 or beyond."""
    a = float(amount)
    return float(np.float32(min(max(a, 1e-29), 1e29))) if math.isfinite(a) else 1.0


def _f32(values) -> list[float]:
    out = []
    for v in values:
        v = float(v)
        out.append(min(max(v, -3e38), 3e38) if math.isfinite(v) else 0.0)
    return out


def encode_aids(
    p: _Prepared,
    base: np.ndarray | None,
    fresh: int,
    send_notes: bool,
    notes: str | None,
    history: bool = False,
    momenta_rows: bool = False,
) -> bytes:
    """The AIDS payload for one tick and one footing (see the module's docstring)."""
    flags = p.flags | (NOTES_TEXT if send_notes else 0)
    parts = []
    if p.values is not None:
        if base is None:
            flags |= VECTOR_KEY
        residuals = p.values - (0 if base is None else base)
        width, block, deflated = pack_residuals(residuals)
        a = p.aids
        parts.append(
            _VEC.pack(
                len(p.values) // 2,
                _scale32(a.amount),
                _scale32(a.velocity_amount),
                *_f32(a.com),
                width,
                int(deflated),
                len(block),
            )
        )
        parts.append(block)
    if flags & ANNOTATIONS:
        records = p.aids.annotation_records[-len(p.serials) :] if p.serials else ()
        newest = p.serials[-1] if p.serials else 0
        new = records[len(records) - fresh :] if fresh else ()
        parts.append(_ANN_HEAD.pack(newest & 0xFFFFFFFF, len(p.serials), len(new)))
        parts.extend(_annotation_bytes(r) for r in new)
    if flags & CHART:
        parts.append(_chart_bytes(p.aids, history))
    if send_notes:
        raw = (notes or "").encode("utf-8")[:MAX_NOTES_BYTES]
        parts.append(_NOTES.pack(p.notes_version, len(raw)))
        packed = deflate(raw)
        parts.append(len(packed).to_bytes(2, "little") + packed)
    lessons = p.aids.lessons
    if lessons is None or not lessons.flags:
        return _HEAD.pack(AIDS_MAGIC, AIDS_VERSION, flags, p.seq & 0xFFFFFFFF) + b"".join(parts)
    lesson_flags = lessons.flags | (MOMENTA_ROWS if momenta_rows else 0)
    head = _HEAD.pack(AIDS_MAGIC, LESSONS_VERSION, flags, p.seq & 0xFFFFFFFF) + _LESSONS.pack(lesson_flags)
    return head + b"".join(parts) + _lessons_bytes(lessons, lesson_flags, p.momenta_serial)


def _lessons_bytes(a: SharedLessons, flags: int, serial: int) -> bytes:
    """The lesson panels' sections, in flag order."""
    out = b""
    if flags & MOMENTA:
        out += _MOMENTA.pack(a.momenta_corner & 3, serial)
    if flags & MOMENTA_ROWS:
        m = a.momenta
        rows = np.asarray(m.rows, dtype=np.int64)[:MAX_MOMENTA_ROWS]
        k = len(rows)
        numbers = np.hstack([np.asarray(m.before_Ns, dtype=float)[:k], np.asarray(m.after_Ns, dtype=float)[:k]])
        totals = _f32((*m.total_before_Ns, *m.total_after_Ns))
        out += _MOMENTA_ROWS.pack(_f32((m.t_s,))[0], *totals, k)
        out += rows.astype("<u4").tobytes() + _f32_block(numbers)
    if flags & VALUES:
        rows = np.asarray(a.value_rows, dtype=np.int64)[:MAX_VALUE_ROWS]
        k = len(rows)
        numbers = np.column_stack(
            [np.asarray(a.value_mass_kg, dtype=float)[:k], np.asarray(a.value_vel_mps, dtype=float).reshape(-1, 2)[:k]]
        )
        out += _VALUES.pack(a.values_corner & 3, int(a.values_every), k)
        out += rows.astype("<u4").tobytes() + _f32_block(numbers)
    if flags & TIMELINE:
        oldest, newest, view, frames, index = a.timeline
        out += _TIMELINE.pack(*_f32((oldest, newest, view)), min(int(frames), MAX_HISTORY_FRAMES), int(index))
    return out


def _f32_block(numbers: np.ndarray) -> bytes:
    """Finite float32s, row by row (non-finite become 0, the huge are cut)."""
    clean = np.clip(np.nan_to_num(numbers, nan=0.0, posinf=0.0, neginf=0.0), -MAX_NUMBER, MAX_NUMBER)
    return clean.astype("<f4").tobytes()


def _chart_bytes(a: SharedAids, history: bool) -> bytes:
    out = _CHART.pack(*_f32(a.chart[1:]), (a.chart_corner & 7) | (HISTORY_FOLLOWS if history else 0))
    if not history:
        return out
    rows = np.asarray(a.chart_history, dtype=float).reshape(-1, 6)[-MAX_CHART_HISTORY:]
    rows = np.clip(np.nan_to_num(rows, posinf=0.0, neginf=0.0), -1e30, 1e30)
    return out + len(rows).to_bytes(2, "little") + rows.astype("<f4").tobytes()


def _annotation_bytes(r: AnnotationRecord) -> bytes:
    has = (1 if r.angle_deg is not None else 0) | (2 if r.target is not None else 0)
    age = min(max(int(round(r.age_s * 1000)), 0), MAX_AGE_MS)
    out = _ANN.pack(age, has, *_f32(r.numbers))
    if r.angle_deg is not None:
        out += _ANGLE.pack(*_f32((r.angle_deg,)))
    if r.target is not None:
        out += _TARGET.pack(*_f32(r.target))
    return out


# ---------------------------------------------------------------- the player side


@dataclass
class AidsDecoder:
    """Feed it AIDS payloads in order, each right after the SNAPSHOT of the same tick."""

    values: np.ndarray | None = None  # int64, the last vector values (the next delta's base)
    values_key: tuple = ()  # their quantity flag and scale
    values_seq: int = 0
    notes: str | None = None
    momenta_serial: int = 0  # the collision whose momenta this client holds (0: none)
    momenta: MomentaRecord | None = None

    def feed(self, payload: bytes, seq: int, pucks: int, time_s: float = 0.0) -> AidsFrame:
        """Check and decode; `seq`, `pucks` and `time_s` are those of the snapshot just decoded."""
        r, out = _header(bytes(payload), seq)
        flags = out.flags
        if flags & (VELOCITY | MOMENTUM):
            self._vectors(r, out, pucks)
        if flags & ANNOTATIONS:
            _annotations(r, out)
        if flags & CHART:
            _chart(r, out, time_s)
        if flags & NOTES_TEXT:
            if not flags & NOTES:
                raise bad("notes text while the notes are off")
            out.notes = self.notes = _notes(r)
        if out.lesson_flags & MOMENTA:
            self._momenta(r, out, pucks)
        if out.lesson_flags & VALUES:
            _values(r, out, pucks)
        if out.lesson_flags & TIMELINE:
            out.timeline = _timeline(r)
        r.done()
        return out

    def _momenta(self, r: Reader, out: AidsFrame, pucks: int) -> None:
        corner, serial = _MOMENTA.unpack(r.take(_MOMENTA.size))
        if corner > 3:
            raise bad(f"a momenta diagram in corner {corner}")
        out.momenta_corner = corner
        if out.lesson_flags & MOMENTA_ROWS:
            if serial == 0:
                raise bad("momenta rows for no collision")
            self.momenta = _momenta_rows(r, pucks)
        elif serial == 0:
            self.momenta = None
        elif serial != self.momenta_serial:
            raise bad(f"momenta of collision {serial}, which this client was never sent")
        self.momenta_serial = serial
        out.momenta = self.momenta

    def _vectors(self, r: Reader, out: AidsFrame, pucks: int) -> None:
        n, amount, vel_amount, cx, cy, cvx, cvy, width, deflated, size = _VEC.unpack(r.take(_VEC.size))
        kind = out.flags & (VELOCITY | MOMENTUM)
        if n != pucks or n > MAX_DRAWN_PUCKS:
            raise bad(f"arrows for {n} pucks on a table of {pucks}")
        for value in (amount, vel_amount):
            if not (math.isfinite(value) and 1e-30 < value < 1e30):
                raise bad("an arrow scale that is not a positive number")
        if deflated > 1:
            raise bad("a vector block with a bad flag")
        out.com = _finite((cx, cy, cvx, cvy), "centre of mass")
        residuals = unpack_residuals(r.take(size), width, 2 * n, bool(deflated))
        if out.flags & VECTOR_KEY:
            values = residuals
        elif self.values is None or len(self.values) != 2 * n or self.values_key != (kind, amount):
            raise bad("vector values coded against values this client does not hold")
        else:
            values = self.values + residuals
        if len(values) and np.abs(values).max() > MAX_VALUE:
            raise bad("an arrow longer than any table")
        self.values, self.values_seq, self.values_key = values, out.seq, (kind, amount)
        out.values = np.column_stack([values[:n], values[n:]]) * (amount / ARROW_STEPS)
        out.amount, out.velocity_amount = amount, vel_amount


def _header(payload: bytes, seq: int) -> tuple[Reader, AidsFrame]:
    """The header checked (and format 2's lesson flags): a reader past it, and the frame to fill."""
    if len(payload) < _HEAD.size:
        raise ProtocolError(f"the aids frame is only {len(payload)} bytes, less than its {_HEAD.size} byte header")
    magic, version, flags, aseq = _HEAD.unpack_from(payload)
    if magic != AIDS_MAGIC or version not in (AIDS_VERSION, LESSONS_VERSION):
        raise bad("an aids frame of another version")
    if aseq != seq & 0xFFFFFFFF:
        raise bad(f"aids for tick {aseq} right after tick {seq}")
    if flags & VELOCITY and flags & MOMENTUM:
        raise bad("aids asking for velocity and momentum arrows at once")
    r = Reader(payload, "aids frame")
    r.take(_HEAD.size)
    out = AidsFrame(seq=aseq, flags=flags)
    if version == LESSONS_VERSION:
        (lf,) = _LESSONS.unpack(r.take(_LESSONS.size))
        if not lf or lf & ~LESSON_FLAGS or (lf & MOMENTA_ROWS and not lf & MOMENTA):
            raise bad(f"lesson panels flagged {lf}")
        out.lesson_flags = lf
    return r, out


def _rows(r: Reader, count: int, pucks: int, what: str) -> np.ndarray:
    """`count` u32 puck rows, strictly increasing and on the table."""
    rows = r.array("<u4", (count,)).astype(np.int64)
    if count and (rows[-1] >= pucks or (np.diff(rows) <= 0).any()):
        raise bad(f"{what} rows that are not distinct pucks of the table's {pucks}, in order")
    return rows


def _numbers(r: Reader, shape: tuple[int, int], what: str) -> np.ndarray:
    with np.errstate(invalid="ignore"):  # a signalling NaN among the bytes: refused below, not warned about
        numbers = r.array("<f4", shape).astype(float)
    if not (np.isfinite(numbers).all() and (np.abs(numbers) <= MAX_NUMBER).all()):
        raise bad(f"{what} that are not finite numbers")
    return numbers


def _momenta_rows(r: Reader, pucks: int) -> MomentaRecord:
    t_s, bx, by, ax, ay, count = _MOMENTA_ROWS.unpack(r.take(_MOMENTA_ROWS.size))
    if count > min(MAX_MOMENTA_ROWS, pucks):
        raise bad(f"a momenta diagram of {count} pucks on a table of {pucks} (at most {MAX_MOMENTA_ROWS})")
    t_s, *totals = _finite((t_s, bx, by, ax, ay), "momenta total")
    rows = _rows(r, count, pucks, "momenta")
    numbers = _numbers(r, (count, 4), "momenta")
    return MomentaRecord(t_s, rows, numbers[:, :2], numbers[:, 2:], tuple(totals[:2]), tuple(totals[2:]))


def _values(r: Reader, out: AidsFrame, pucks: int) -> None:
    corner, every, count = _VALUES.unpack(r.take(_VALUES.size))
    if corner > 3 or every > 1:
        raise bad(f"a values panel in corner {corner} with flag {every}")
    if count > min(MAX_VALUE_ROWS, pucks) or (every and count != pucks):
        raise bad(f"values of {count} pucks on a table of {pucks}")
    rows = _rows(r, count, pucks, "values")
    numbers = _numbers(r, (count, 3), "values")
    if count and (numbers[:, 0] <= 0).any():
        raise bad("a puck of no mass in the values panel")
    out.values_corner, out.values_every = corner, bool(every)
    out.value_rows, out.value_mass_kg, out.value_vel_mps = rows, numbers[:, 0], numbers[:, 1:]


def _timeline(r: Reader) -> tuple[float, float, float, int, int]:
    oldest, newest, view, frames, index = _TIMELINE.unpack(r.take(_TIMELINE.size))
    oldest, newest, view = _finite((oldest, newest, view), "timeline time")
    if not (oldest <= view <= newest and 2 <= frames <= MAX_HISTORY_FRAMES and index < frames):
        raise bad(f"a timeline at {view} s of {oldest} to {newest} s, frame {index} of {frames}")
    return (oldest, newest, view, frames, index)


def _finite(values, what: str) -> tuple[float, ...]:
    if not all(math.isfinite(v) and abs(v) <= 1e30 for v in values):
        raise bad(f"a {what} that is not a finite number")
    return tuple(float(v) for v in values)


def _chart(r: Reader, out: AidsFrame, time_s: float) -> None:
    *sample, corner = _CHART.unpack(r.take(_CHART.size))
    if corner & ~HISTORY_FOLLOWS > 7:
        raise bad(f"a chart in corner {corner}")
    out.chart, out.chart_corner = (float(time_s), *_finite(sample, "chart sample")), corner & 7
    if corner & HISTORY_FOLLOWS:
        count = int.from_bytes(r.take(2), "little")
        if count > MAX_CHART_HISTORY:
            raise bad(f"a chart history of {count} samples (at most {MAX_CHART_HISTORY})")
        out.chart_history = _numbers(r, (count, 6), "chart history samples")


def _annotations(r: Reader, out: AidsFrame) -> None:
    newest, live, new = _ANN_HEAD.unpack(r.take(_ANN_HEAD.size))
    if live > MAX_ANNOTATIONS or new > live or live > newest:
        raise bad(f"{new} new of {live} live collision annotations (at most {MAX_ANNOTATIONS})")
    out.annotation_serial, out.live = newest, live
    for _ in range(new):
        age_ms, has, *numbers = _ANN.unpack(r.take(_ANN.size))
        if has > 3 or age_ms > MAX_AGE_MS:
            raise bad("a collision annotation with bad flags or age")
        numbers = _finite(numbers, "collision annotation")
        if any(abs(v) > MAX_COORD_M for v in numbers) or numbers[4] < 0 or min(numbers[14:16]) <= 0:
            raise bad("a collision annotation with impossible sizes")
        angle = _finite(_ANGLE.unpack(r.take(_ANGLE.size)), "collision angle")[0] if has & 1 else None
        target = _finite(_TARGET.unpack(r.take(_TARGET.size)), "collision target") if has & 2 else None
        if target is not None and any(abs(v) > MAX_COORD_M for v in target):
            raise bad("a collision target far off the table")
        out.new_annotations.append(AnnotationRecord(age_ms / 1000, numbers, angle, target))


def _notes(r: Reader) -> str:
    _version, size = _NOTES.unpack(r.take(_NOTES.size))
    if size > MAX_NOTES_BYTES:
        raise bad(f"notes of {size} bytes (at most {MAX_NOTES_BYTES})")
    packed = r.take(int.from_bytes(r.take(2), "little"))
    return wire_text(inflate(packed, size, "notes text"), "notes")
