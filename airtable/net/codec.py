"""Snapshot format 2: each student gets only what it lacks (no pygame, no sockets).

A Scene is split in two parts:

- the *layout* (LAYOUT frame, type 7): what rarely changes (table size,
  settings, title, radii, colours, springs, cursor names and colours). It has
  a version number and is sent to a student only when that student does not
  have the current version yet;
- the *tick* (SNAPSHOT frame, type 5, format 2): what moves. Positions are
  whole numbers of quarter millimetres. A tick is either a keyframe or a
  delta coded against the two ticks that student received last: the server
  predicts each position from them (constant velocity, scaled by the
  simulation time between the ticks) and sends only the residuals, zigzag
  coded, split into byte planes and deflated (zlib level 1).

TCP delivers in order, so the server knows what each student holds: the
ticks it queued for that student. A student that was skipped (its
connection was busy) simply gets the newest tick coded against its own last
two. Encodings are cached per (tick, base ticks): students on the same bases
share one encoding, so the work per tick is O(N) per distinct base.

Decoding checks every count, index and value against the layout and the
declared sizes before using it; anything wrong raises `ProtocolError`.
The byte layout is documented in README ("snapshot format 2").
"""

from __future__ import annotations

import math
import struct
import threading
import time
import zlib
from dataclasses import dataclass, field

import numpy as np

from airtable.model.scene import CursorView, Scene
from airtable.net import aids_wire
from airtable.net.protocol import (
    LAYOUT,
    MAX_DRAWN_CURSORS,
    MAX_DRAWN_PUCKS,
    MAX_DRAWN_SPRINGS,
    MAX_DRAWN_TEXT_CHARS,
    MAX_VIEW_ORIGIN_M,
    MAX_VIEW_ZOOM,
    MIN_VIEW_ZOOM,
    SNAPSHOT,
    ProtocolError,
    encode_frame,
    printable,
    table_size_problem,
)
from airtable.net.wire import Reader, bad, deflate, pack_residuals, unpack_residuals, wire_text

FORMAT_VERSION = 2
UNITS_PER_M = 4000  # positions travel as whole quarter millimetres
MAX_Q = 1 << 30  # |position| <= 268 km in those units, so residuals fit 32 bits
MAX_TEXT_BYTES = 1024  # title, correction mode, names
MAX_STATUS_BYTES = 2048
MAX_TIME_US = 1 << 60
MAX_GAP = 255  # ticks between a delta and its base; further back gets a keyframe
MAX_PREDICT_SPAN_US = 10_000_000  # prediction only over gaps up to 10 s (keeps int64 products small)

KEYFRAME = 1
HAS_VIEW = 2
HAS_STATUS = 4
DEFLATED = 8
GRAVITY = 1

# magic, format, flags, seq, gap1, gap2, layout version, epoch, time_us, server clock ms, centi-fps, residual width
_TICK = struct.Struct("<4sBBIBBHHqIHB")
_VIEW = struct.Struct("<3d")
_TEXT_DELTA = struct.Struct("<HHH")
# magic, format, flags, version, N, S, C, width_m, height_m
_LAYOUT = struct.Struct("<4sBBHIII2d")
TICK_MAGIC = b"ATSN"
LAYOUT_MAGIC = b"ATLY"


# ---------------------------------------------------------------- layout


@dataclass(frozen=True, eq=False)
class Layout:
    """What rarely changes; `version` (0-65535, wrapping) names one set of values."""

    version: int
    width_m: float
    height_m: float
    gravity_on: bool
    puck_correction: str
    title: str
    radius_m: np.ndarray
    color_rgb: np.ndarray
    spring_pairs: np.ndarray
    spring_length_m: np.ndarray
    spring_width_m: np.ndarray
    spring_color_rgb: np.ndarray
    cursor_names: tuple[str, ...]
    cursor_colors: np.ndarray  # (C, 3) uint8

    @property
    def sizes(self) -> tuple[int, int, int]:
        return len(self.radius_m), len(self.spring_pairs), len(self.cursor_names)

    def same_as(self, other: Layout | None) -> bool:
        """Equal values (versions aside)."""
        if other is None:
            return False
        scalars = ("width_m", "height_m", "gravity_on", "puck_correction", "title", "cursor_names")
        arrays = (
            "radius_m",
            "color_rgb",
            "spring_pairs",
            "spring_length_m",
            "spring_width_m",
            "spring_color_rgb",
            "cursor_colors",
        )
        return all(getattr(self, a) == getattr(other, a) for a in scalars) and all(
            np.array_equal(getattr(self, a), getattr(other, a)) for a in arrays
        )


def _clean_text(text: str, limit: int) -> str:
    raw = printable(text).encode("utf-8")[:limit]
    return raw.decode("utf-8", "ignore")


def layout_of(scene: Scene, version: int = 0) -> Layout:
    """The layout part of `scene`."""
    cursors = scene.cursors
    return Layout(
        version=version & 0xFFFF,
        width_m=float(scene.width_m),
        height_m=float(scene.height_m),
        gravity_on=bool(scene.gravity_on),
        puck_correction=_clean_text(scene.puck_correction, MAX_TEXT_BYTES),
        title=_clean_text(scene.title, MAX_TEXT_BYTES),
        radius_m=np.asarray(scene.radius_m, dtype="<f8").reshape(-1),
        color_rgb=np.asarray(scene.color_rgb, dtype=np.uint8).reshape(-1, 3),
        spring_pairs=np.asarray(scene.spring_pairs, dtype="<u4").reshape(-1, 2),
        spring_length_m=np.asarray(scene.spring_length_m, dtype="<f8").reshape(-1),
        spring_width_m=np.asarray(scene.spring_width_m, dtype="<f8").reshape(-1),
        spring_color_rgb=np.asarray(scene.spring_color_rgb, dtype=np.uint8).reshape(-1, 3),
        cursor_names=tuple(_clean_text(c.name, MAX_TEXT_BYTES) for c in cursors),
        cursor_colors=np.array([c.color for c in cursors], dtype=np.uint8).reshape(-1, 3),
    )


def _text_bytes(text: str) -> bytes:
    raw = text.encode("utf-8")
    return len(raw).to_bytes(2, "little") + raw


def encode_layout(layout: Layout) -> bytes:
    """The LAYOUT payload: a fixed header, then one deflated body."""
    n, s, c = layout.sizes
    header = _LAYOUT.pack(
        LAYOUT_MAGIC,
        FORMAT_VERSION,
        GRAVITY if layout.gravity_on else 0,
        layout.version,
        n,
        s,
        c,
        layout.width_m,
        layout.height_m,
    )
    body = b"".join(
        [
            layout.radius_m.astype("<f8").tobytes(),
            layout.color_rgb.astype(np.uint8).tobytes(),
            layout.spring_pairs.astype("<u4").tobytes(),
            layout.spring_length_m.astype("<f8").tobytes(),
            layout.spring_width_m.astype("<f8").tobytes(),
            layout.spring_color_rgb.astype(np.uint8).tobytes(),
            layout.cursor_colors.astype(np.uint8).tobytes(),
            _text_bytes(layout.title),
            _text_bytes(layout.puck_correction),
            *(_text_bytes(name) for name in layout.cursor_names),
        ]
    )
    return header + deflate(body)


def decode_layout(payload: bytes) -> Layout:
    """Check and decode a LAYOUT payload."""
    payload = bytes(payload)
    if len(payload) < _LAYOUT.size:
        raise ProtocolError(f"the layout is only {len(payload)} bytes, less than its {_LAYOUT.size} byte header")
    magic, version, flags, layout_version, n, s, c, width_m, height_m = _LAYOUT.unpack_from(payload)
    _check_magic(magic, version, LAYOUT_MAGIC)
    if n > MAX_DRAWN_PUCKS or s > MAX_DRAWN_SPRINGS or c > MAX_DRAWN_CURSORS:
        raise bad(
            f"{n} pucks, {s} springs and {c} cursors, more than this client draws "
            f"({MAX_DRAWN_PUCKS}, {MAX_DRAWN_SPRINGS} and {MAX_DRAWN_CURSORS})"
        )
    problem = table_size_problem(width_m, height_m)
    if problem:
        raise bad(problem)
    fixed = n * 11 + s * 27 + c * 3
    body = _inflate_texts(payload[_LAYOUT.size :], fixed, c)
    r = Reader(body, "layout")
    radius = r.array("<f8", (n,))
    color = r.array("u1", (n, 3))
    pairs = r.array("<u4", (s, 2))
    spring_length = r.array("<f8", (s,))
    spring_width = r.array("<f8", (s,))
    spring_color = r.array("u1", (s, 3))
    cursor_colors = r.array("u1", (c, 3))
    title = r.text(MAX_TEXT_BYTES, "title")
    correction = r.text(MAX_TEXT_BYTES, "puck correction mode")
    names = tuple(r.text(MAX_TEXT_BYTES, "cursor name") for _ in range(c))
    r.done()
    _check_bodies(max(width_m, height_m), radius, pairs, spring_length, spring_width, n)
    return Layout(
        layout_version,
        width_m,
        height_m,
        bool(flags & GRAVITY),
        correction,
        title[:MAX_DRAWN_TEXT_CHARS],
        radius,
        color,
        pairs,
        spring_length,
        spring_width,
        spring_color,
        names,
        cursor_colors,
    )


def _check_bodies(size: float, radius, pairs, spring_length, spring_width, n: int) -> None:
    """The same bounds as the drawing code assumes: sizes against the table's size."""
    if not (np.isfinite(radius).all() and ((radius > 0) & (radius <= size)).all()):
        raise bad("a puck radius that is not between 0 and the table's size")
    if not (np.isfinite(spring_length).all() and np.isfinite(spring_width).all()):
        raise bad("a spring size that is not finite")
    if not (
        ((spring_length >= 0) & (spring_length <= 100 * size)).all()
        and ((spring_width >= 0) & (spring_width <= size)).all()
    ):
        raise bad("a spring longer or wider than the table allows")
    if len(pairs) and int(pairs.max()) >= n:
        raise bad("a spring joined to a puck that is not there")


def _inflate_texts(data: bytes, fixed: int, cursors: int) -> bytes:
    """The layout body: `fixed` bytes of arrays then 2 + C texts of bounded size."""
    limit = fixed + (2 + cursors) * (2 + MAX_TEXT_BYTES)
    unpacker = zlib.decompressobj(-15)
    try:
        out = unpacker.decompress(data, limit + 1)
    except zlib.error:
        raise bad("a damaged layout") from None
    if len(out) > limit or not unpacker.eof or unpacker.unused_data:
        raise bad("a layout of the wrong size")
    return out


def _check_magic(magic: bytes, version: int, expected: bytes) -> None:
    if magic != expected:
        raise ProtocolError(f"the snapshot does not start with {expected.decode()}; is the server an airtable server?")
    if version != FORMAT_VERSION:
        raise ProtocolError(
            f"the snapshot format is version {version} but this client reads version {FORMAT_VERSION}; "
            "install the same airtable version as the teacher's"
        )


# ---------------------------------------------------------------- ticks


@dataclass(frozen=True, eq=False)
class Tick:
    """What moves, at one tick: whole-number state plus the few per-tick scalars.

    `values` is [x of N pucks, y of N pucks, x of C cursors, y of C cursors,
    C buttons, C held rows + 1]; the first 2N + 2C (positions, in
    quarter millimetres) are predicted at constant velocity, the rest repeat.
    """

    seq: int
    layout: Layout
    epoch: int
    time_us: int
    clock_ms: int  # the server's monotonic clock, milliseconds mod 2**32
    centi_fps: int
    view: tuple[float, float, float]  # zoom, origin_x_m, origin_y_m
    status: str
    values: np.ndarray  # int64

    @property
    def moving(self) -> int:
        n, _, c = self.layout.sizes
        return 2 * n + 2 * c


def _quantise(xy: np.ndarray) -> np.ndarray:
    q = np.rint(np.nan_to_num(np.asarray(xy, dtype=float), posinf=0.0, neginf=0.0) * UNITS_PER_M)
    return np.clip(q, -MAX_Q, MAX_Q).astype(np.int64)


def tick_values(scene: Scene) -> np.ndarray:
    """The whole-number state of `scene` (see `Tick.values`)."""
    pos = np.asarray(scene.pos_m, dtype=float).reshape(-1, 2)
    cur = np.array([c.cursor_m for c in scene.cursors], dtype=float).reshape(-1, 2)
    buttons = np.array([c.button for c in scene.cursors], dtype=np.int64)
    held = np.array([c.held for c in scene.cursors], dtype=np.int64) + 1
    return np.concatenate(
        [_quantise(pos[:, 0]), _quantise(pos[:, 1]), _quantise(cur[:, 0]), _quantise(cur[:, 1]), buttons, held]
    )


def predict(tick_time_us: int, moving: int, b1: Tick | None, b2: Tick | None) -> np.ndarray:
    """What the receiver expects before the residuals: zeros for a keyframe, else
    b1 moved on at the velocity from b2 to b1 (positions only), both sides alike."""
    if b1 is None:
        raise ValueError("a keyframe has no prediction")
    guess = b1.values.copy()
    if b2 is not None and len(b2.values) == len(guess):
        span = b1.time_us - b2.time_us
        ahead = tick_time_us - b1.time_us
        if 0 < span <= MAX_PREDICT_SPAN_US and 0 <= ahead <= 4 * span:
            step = b1.values[:moving] - b2.values[:moving]
            guess[:moving] += (step * ahead + span // 2) // span
    return guess


def _text_delta(old: str, new: str) -> bytes:
    """`new` as (bytes kept from the start of `old`, kept from its end, the middle)."""
    a, b = old.encode("utf-8"), new.encode("utf-8")
    limit = min(len(a), len(b), 0xFFFF)
    p = 0
    while p < limit and a[p] == b[p]:
        p += 1
    s = 0
    while s < limit - p and a[len(a) - 1 - s] == b[len(b) - 1 - s]:
        s += 1
    middle = b[p : len(b) - s]
    return _TEXT_DELTA.pack(p, s, len(middle)) + middle


def _apply_text_delta(old: str, r: Reader) -> str:
    keep_start, keep_end, size = _TEXT_DELTA.unpack(r.take(_TEXT_DELTA.size))
    a = old.encode("utf-8")
    if keep_start + keep_end > len(a) or keep_start + keep_end + size > MAX_STATUS_BYTES:
        raise bad("a status line that does not fit the previous one")
    return wire_text(a[:keep_start] + r.take(size) + a[len(a) - keep_end :], "a status line")


def encode_tick(tick: Tick, b1: Tick | None = None, b2: Tick | None = None) -> tuple[bytes, bool]:
    """(SNAPSHOT payload in format 2, is it a keyframe?) for `tick`: a delta on b1
    (and b2), or a keyframe when there is no base or the residuals would not fit."""
    residuals = None
    if b1 is not None:
        residuals = tick.values - predict(tick.time_us, tick.moving, b1, b2)
        if len(residuals) and np.abs(residuals).max() >= 1 << 31:
            residuals = None
    key = residuals is None
    if key:
        b1 = b2 = None
        residuals = np.diff(tick.values, prepend=np.int64(0))
    flags = KEYFRAME if key else 0
    extra = []
    if key or tick.view != b1.view:
        flags |= HAS_VIEW
        extra.append(_VIEW.pack(*tick.view))
    if key or tick.status != b1.status:
        flags |= HAS_STATUS
        extra.append(_text_delta("" if key else b1.status, tick.status))
    width, block, deflated = pack_residuals(residuals)
    if deflated:
        flags |= DEFLATED
    gap1 = 0 if key else tick.seq - b1.seq
    gap2 = 0 if key or b2 is None else b1.seq - b2.seq
    header = _TICK.pack(
        TICK_MAGIC,
        FORMAT_VERSION,
        flags,
        tick.seq & 0xFFFFFFFF,
        gap1,
        gap2,
        tick.layout.version,
        tick.epoch & 0xFFFF,
        tick.time_us,
        tick.clock_ms & 0xFFFFFFFF,
        tick.centi_fps,
        width,
    )
    return b"".join([header, *extra, block]), key


# ---------------------------------------------------------------- the server side


@dataclass
class Viewer:
    """What one student holds: its layout version and the last two ticks queued to it."""

    layout_version: int | None = None
    last: Tick | None = None
    prev: Tick | None = None
    aids: aids_wire.AidsViewer = field(default_factory=lambda: aids_wire.AidsViewer())


class SnapshotEncoder:
    """Turns the game loop's Scenes into ticks and each student's bytes.

    `add(scene)` (game loop, O(N)) records a tick; `frames_for(viewer)` (network
    thread) returns what that student needs to catch up to the newest tick: a
    LAYOUT frame if its layout is old, then one SNAPSHOT frame. Both are cached,
    so students on the same base share the work. Thread-safe.
    """

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._layout: Layout | None = None
        self._newest: Tick | None = None
        self._seq = 0
        self._epoch = 0
        self._cache: dict[tuple, bytes] = {}
        self._layout_frame = b""
        self.encodings = 0  # distinct encodings made (for tests and the bench)
        self.aids = aids_wire.AidsEncoder()  # the teacher's aids: an AIDS frame after each SNAPSHOT while any is on
        self._aids_state: tuple = (None, {}, {}, None)

    @property
    def newest(self) -> Tick | None:
        return self._newest

    def add(self, scene: Scene, clock_s: float | None = None) -> Tick:
        """Record the scene as the newest tick; `clock_s` is the server's monotonic
        clock (default: now), which lets players time their playout."""
        layout = layout_of(scene)
        old = self._layout
        if old is not None and layout.same_as(old):
            layout = old
        else:
            layout = layout_of(scene, 0 if old is None else old.version + 1)
        time_us = int(round(min(max(float(scene.time_s), -1e12), 1e12) * 1e6))
        newest = self._newest
        if newest is not None and (
            layout.sizes[0] != newest.layout.sizes[0] or time_us < newest.time_us or layout.title != newest.layout.title
        ):
            self._epoch += 1  # a restart or another demo: players snap instead of smearing
        self._seq += 1
        fps = float(scene.fps) if math.isfinite(scene.fps) else 0.0
        view = shareable_view(scene.zoom, *scene.origin_m)
        tick = Tick(
            seq=self._seq,
            layout=layout,
            epoch=self._epoch,
            time_us=time_us,
            clock_ms=int(round(1e3 * (time.monotonic() if clock_s is None else clock_s))) & 0xFFFFFFFF,
            centi_fps=min(max(round(fps * 100), 0), 0xFFFF),
            view=view,
            status=_clean_text(scene.status, MAX_STATUS_BYTES),
            values=tick_values(scene),
        )
        prepared = self.aids.prepare(scene.aids, tick.seq)
        with self._lock:
            self.aids.publish(prepared)
            self._aids_state = self.aids.state()
            if layout is not old:
                self._layout_frame = encode_frame(LAYOUT, encode_layout(layout))
            self._layout = layout
            self._newest = tick
            self._cache = {}
        return tick

    def forget(self) -> None:
        """Drop the newest tick (nobody is watching): a player who joins later waits
        for the next one instead of being greeted with a picture from long ago."""
        with self._lock:
            self._newest = None
            self._cache = {}

    def frames_for(self, viewer: Viewer) -> bytes:
        """The bytes that bring `viewer` to the newest tick (b"" if it has it); updates `viewer`."""
        with self._lock:
            tick, layout_frame, cache, aids = self._newest, self._layout_frame, self._cache, self._aids_state
        if tick is None or viewer.last is tick:
            return b""
        out = b""
        if viewer.layout_version != tick.layout.version or viewer.last is None:
            out = layout_frame
        b1, b2 = viewer.last, viewer.prev
        if b1 is None or tick.values.shape != b1.values.shape or not 0 < tick.seq - b1.seq <= MAX_GAP:
            b1 = b2 = None
        elif b2 is not None and not 0 < b1.seq - b2.seq <= MAX_GAP:
            b2 = None
        key = (tick.seq, b1.seq if b1 else 0, b2.seq if b2 else 0)
        cached = cache.get(key)
        if cached is None:
            payload, keyframe = encode_tick(tick, b1, b2)
            cached = cache[key] = (encode_frame(SNAPSHOT, payload), keyframe)
            self.encodings += 1
        data, keyframe = cached
        viewer.layout_version = tick.layout.version
        viewer.prev, viewer.last = (None if keyframe else b1), tick
        return out + data + self.aids.frame_for(viewer.aids, aids)


# ---------------------------------------------------------------- the player side


@dataclass
class Decoded:
    """One decoded tick: the Scene to draw and what the playout buffer needs."""

    scene: Scene
    seq: int
    epoch: int
    time_s: float  # simulation time
    server_s: float  # the server's clock, counted from the first tick this player decoded


@dataclass
class SnapshotDecoder:
    """The player's side: feed it LAYOUT and SNAPSHOT payloads in order, get Scenes."""

    layout: Layout | None = None
    last: Tick | None = None
    prev: Tick | None = None
    _clock_s: float = 0.0
    shown_view: tuple[float, float, float] = (1.0, 0.0, 0.0)  # the newest usable view
    # A field this client could not use and left out (a sentence), until the player reads it.
    problem: str | None = None

    def feed_layout(self, payload: bytes) -> None:
        self.layout = decode_layout(payload)

    def feed_tick(self, payload: bytes) -> Decoded:
        """Decode one SNAPSHOT payload (format 2) against what came before."""
        payload = bytes(payload)
        if len(payload) < _TICK.size:
            raise ProtocolError(f"the snapshot is only {len(payload)} bytes, less than its {_TICK.size} byte header")
        magic, version, flags, seq, gap1, gap2, lv, epoch, time_us, clock_ms, centi_fps, width = _TICK.unpack_from(
            payload
        )
        _check_magic(magic, version, TICK_MAGIC)
        layout = self.layout
        if layout is None or layout.version != lv:
            raise bad(f"layout {lv}, which was never sent")
        if not -MAX_TIME_US <= time_us <= MAX_TIME_US:
            raise bad("a time out of range")
        b1, b2 = self._bases(flags, seq, gap1, gap2)
        r = Reader(payload, "snapshot")
        r.take(_TICK.size)
        view = _VIEW.unpack(r.take(_VIEW.size)) if flags & HAS_VIEW else (b1.view if b1 else None)
        if view is None:
            raise bad("a keyframe without the view")
        if usable_view(view):
            self.shown_view = view
        else:
            self.problem = (
                f"a view of zoom {view[0]:g} at ({view[1]:g}, {view[2]:g}) m; left out, the previous view kept"
            )
        if flags & HAS_STATUS:
            status = _apply_text_delta("" if flags & KEYFRAME else b1.status, r)
        elif b1 is not None:
            status = b1.status
        else:
            raise bad("a keyframe without a status line")
        n, _, c = layout.sizes
        count = 2 * n + 4 * c
        residuals = unpack_residuals(payload[r.offset :], width, count, bool(flags & DEFLATED))
        if b1 is None:
            values = np.cumsum(residuals)
        else:
            if len(b1.values) != count:
                raise bad("a delta on a tick with another number of pucks or cursors")
            values = predict(time_us, 2 * n + 2 * c, b1, b2) + residuals
        shown, problem = _shown_values(values, layout)
        if problem is not None:
            self.problem = f"{problem}; left out"
        tick = Tick(seq, layout, epoch, time_us, clock_ms, centi_fps, view, status, values)
        if self.last is not None:  # unwrap the 32-bit millisecond clock
            self._clock_s += ((clock_ms - self.last.clock_ms) & 0xFFFFFFFF) / 1e3
        self.prev, self.last = b1, tick
        return Decoded(self._scene(tick, shown), seq, epoch, time_us / 1e6, self._clock_s)

    def _bases(self, flags: int, seq: int, gap1: int, gap2: int) -> tuple[Tick | None, Tick | None]:
        if flags & KEYFRAME:
            if gap1 or gap2:
                raise bad("a keyframe with base ticks")
            return None, None
        last, prev = self.last, self.prev
        if last is None or gap1 == 0 or seq - gap1 != last.seq:
            raise bad(f"a delta on tick {seq - gap1}, which this client does not hold")
        if gap2 == 0:
            return last, None
        if prev is None or last.seq - gap2 != prev.seq:
            raise bad(f"a delta on tick {last.seq - gap2}, which this client does not hold")
        return last, prev

    def _scene(self, tick: Tick, v: np.ndarray) -> Scene:
        """The Scene of `tick`, drawn from its values `v` as cleaned for showing."""
        layout = tick.layout
        n, _, c = layout.sizes
        pos = np.column_stack([v[:n], v[n : 2 * n]]) / UNITS_PER_M
        cur = np.column_stack([v[2 * n : 2 * n + c], v[2 * n + c : 2 * n + 2 * c]]) / UNITS_PER_M
        buttons = v[2 * n + 2 * c : 2 * n + 3 * c]
        held = v[2 * n + 3 * c :] - 1
        cursors = tuple(
            CursorView(
                name=layout.cursor_names[i],
                color=tuple(int(x) for x in layout.cursor_colors[i]),
                cursor_m=(float(cur[i, 0]), float(cur[i, 1])),
                button=int(buttons[i]),
                held=int(held[i]),
            )
            for i in range(c)
        )
        return Scene(
            width_m=layout.width_m,
            height_m=layout.height_m,
            pos_m=pos,
            radius_m=layout.radius_m,
            color_rgb=layout.color_rgb,
            spring_pairs=layout.spring_pairs.astype(np.intp),
            spring_length_m=layout.spring_length_m,
            spring_width_m=layout.spring_width_m,
            spring_color_rgb=layout.spring_color_rgb,
            cursors=cursors,
            title=layout.title,
            status=tick.status[:MAX_DRAWN_TEXT_CHARS],
            gravity_on=layout.gravity_on,
            puck_correction=layout.puck_correction,
            time_s=tick.time_us / 1e6,
            fps=tick.centi_fps / 100,
            zoom=self.shown_view[0],
            origin_m=(self.shown_view[1], self.shown_view[2]),
        )


def shareable_view(zoom: float, origin_x_m: float, origin_y_m: float) -> tuple[float, float, float]:
    """The server's view as players accept it: finite, the zoom and the origin within bounds."""
    view = (float(zoom), float(origin_x_m), float(origin_y_m))
    if not all(math.isfinite(x) for x in view):
        return (1.0, 0.0, 0.0)
    limit = MAX_VIEW_ORIGIN_M
    return (
        min(max(view[0], MIN_VIEW_ZOOM), MAX_VIEW_ZOOM),
        min(max(view[1], -limit), limit),
        min(max(view[2], -limit), limit),
    )


def usable_view(view: tuple[float, float, float]) -> bool:
    """Finite numbers of bounded size: where the view points is the teacher's business."""
    zoom, ox, oy = view
    return (
        all(math.isfinite(x) for x in view)
        and MIN_VIEW_ZOOM <= zoom <= MAX_VIEW_ZOOM
        and abs(ox) <= MAX_VIEW_ORIGIN_M
        and abs(oy) <= MAX_VIEW_ORIGIN_M
    )


def _shown_values(values: np.ndarray, layout: Layout) -> tuple[np.ndarray, str | None]:
    """`values` as a player can draw them, and what had to be cleaned (None: nothing).

    Positions beyond the coder's range are pulled to its edge; a bad button reads as
    none pressed, a held puck that is not there as none held. The tick keeps the
    values as sent: they are the base of the next delta."""
    n, _, c = layout.sizes
    moving = 2 * n + 2 * c
    problems = []
    values = values.copy()
    if np.abs(values[:moving]).max(initial=0) > MAX_Q:
        np.clip(values[:moving], -MAX_Q, MAX_Q, out=values[:moving])
        problems.append("a position beyond 268 km")
    buttons, held = values[moving : moving + c], values[moving + c :]
    bad_buttons, bad_held = (buttons < 0) | (buttons > 3), (held < 0) | (held > n)
    if bad_buttons.any() or bad_held.any():
        buttons[bad_buttons], held[bad_held] = 0, 0
        problems.append("a cursor with a bad button or held puck")
    return values, (" and ".join(problems) if problems else None)
