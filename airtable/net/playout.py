"""Playout buffer: smooth motion on the student's screen from jittery snapshots (no pygame).

Snapshots leave the server about 30 times a second but arrive unevenly (Wi-Fi
adds tens of milliseconds of jitter). Drawing each one as it arrives shows
that as jerks. Instead the player draws the table as it was a short *playout
delay* ago, interpolating between the two snapshots around that moment:

    buffer.push(server_s, scene, epoch, arrival_s)   # each decoded snapshot
    scene = buffer.sample(now_s)                     # each drawn frame

`server_s` is the server's clock when it published the snapshot, `arrival_s`
and `now_s` the player's own clock. The offset between the two clocks is the
smallest (arrival - server) seen lately: the least delayed snapshot. The
jitter is how much later than that the snapshots typically come (the 90th
percentile), and the delay is 1.5 snapshot intervals plus that jitter, so the
next snapshot is almost always there before it is needed. The render clock
follows its target at +-10 % speed rather than jumping, so changes in the
delay never show as a jerk.

A new epoch (the teacher restarted or changed the demo) or a different
number of pucks snaps to the new snapshot at once instead of smearing the old
table into the new one.
"""

from __future__ import annotations

import dataclasses
import threading
from collections import deque
from dataclasses import dataclass

from airtable.model.scene import Scene
from airtable.net.codec import LAYOUT, SnapshotDecoder

WINDOW_S = 2.0  # arrivals remembered for the offset, jitter and interval
MAX_ARRIVALS = 240
MAX_SNAPSHOTS = 64
DEFAULT_INTERVAL_S = 1 / 30
MIN_DELAY_S = 0.02
MAX_DELAY_S = 0.5
SLEW = 0.1  # the render clock runs at most 10 % fast or slow while it catches up
SLEW_TIME_S = 0.5  # ... closing an error of e seconds at about e / SLEW_TIME_S per second
SNAP_S = 0.25  # further off than this, it jumps


@dataclass(frozen=True)
class _Snap:
    server_s: float
    scene: Scene
    epoch: int


class PlayoutBuffer:
    """Interpolates buffered snapshots at the player's frame times (see the module docstring)."""

    def __init__(self) -> None:
        self._snaps: deque[_Snap] = deque(maxlen=MAX_SNAPSHOTS)
        self._arrivals: deque[tuple[float, float]] = deque(maxlen=MAX_ARRIVALS)  # (arrival_s, server_s)
        self._render_s: float | None = None  # server time being drawn
        self._last_now: float | None = None
        self.delay_s = 1.5 * DEFAULT_INTERVAL_S
        self.jitter_s = 0.0
        self.interval_s = DEFAULT_INTERVAL_S
        self.snaps = 0  # times the picture jumped (restarts, long stalls), for tests and the HUD

    def push(self, server_s: float, scene: Scene, epoch: int, arrival_s: float) -> None:
        """Add a decoded snapshot (in the order they arrive)."""
        newest = self._snaps[-1] if self._snaps else None
        if newest is not None and (epoch != newest.epoch or len(scene.pos_m) != len(newest.scene.pos_m)):
            self._snap_to(server_s)
        elif newest is not None and server_s <= newest.server_s:
            return  # a stale or repeated clock: nothing to interpolate towards
        self._snaps.append(_Snap(server_s, scene, epoch))
        arrivals = self._arrivals
        arrivals.append((arrival_s, server_s))
        while arrivals and arrivals[0][0] < arrival_s - WINDOW_S:
            arrivals.popleft()
        self._measure()

    def _snap_to(self, server_s: float) -> None:
        self._snaps.clear()
        self._arrivals.clear()
        self._render_s = None
        self.snaps += 1

    def _measure(self) -> None:
        # Plain lists: a few dozen numbers per snapshot, where numpy's percentile cost more than
        # decoding the snapshot (30 students' windows each do this 30 times a second).
        arrivals = self._arrivals
        if len(arrivals) < 2:
            return
        offsets = sorted(arrival - server for arrival, server in arrivals)
        self.jitter_s = quantile(offsets, 0.9) - offsets[0]
        servers = [server for _, server in arrivals]
        self.interval_s = quantile(sorted(b - a for a, b in zip(servers, servers[1:])), 0.5)
        self.delay_s = min(max(1.5 * self.interval_s + self.jitter_s, MIN_DELAY_S), MAX_DELAY_S)

    def target_s(self, now_s: float) -> float | None:
        """The server time that should be on screen at `now_s`."""
        if not self._arrivals:
            return None
        offset = min(arrival - server for arrival, server in self._arrivals)
        return now_s - offset - self.delay_s

    def sample(self, now_s: float) -> Scene | None:
        """The scene to draw at the player's time `now_s` (None before the first snapshot)."""
        if not self._snaps:
            return None
        target = self.target_s(now_s)
        render = self._render_s
        dt = 0.0 if self._last_now is None else max(0.0, now_s - self._last_now)
        self._last_now = now_s
        if render is None or target is None or abs(target - render) > SNAP_S:
            if render is not None:
                self.snaps += 1
            render = target if target is not None else self._snaps[-1].server_s
        else:
            error = target - (render + dt)
            speed = 1.0 + min(max(error / SLEW_TIME_S, -SLEW), SLEW)
            render += dt * speed
        self._render_s = render
        self._drop_old(render)
        return self._at(render)

    def _drop_old(self, render_s: float) -> None:
        snaps = self._snaps
        while len(snaps) >= 2 and snaps[1].server_s <= render_s:
            snaps.popleft()

    def _at(self, render_s: float) -> Scene:
        snaps = self._snaps
        first = snaps[0]
        if render_s <= first.server_s or len(snaps) == 1:
            return first.scene  # too early, or starved: hold the nearest
        second = snaps[1]
        alpha = (render_s - first.server_s) / (second.server_s - first.server_s)
        return interpolate(first.scene, second.scene, min(alpha, 1.0))


def quantile(ordered: list[float], q: float) -> float:
    """The q-quantile of sorted values, interpolated between neighbours (numpy's default rule)."""
    at = q * (len(ordered) - 1)
    low = int(at)
    high = min(low + 1, len(ordered) - 1)
    return ordered[low] + (at - low) * (ordered[high] - ordered[low])


def interpolate(a: Scene, b: Scene, alpha: float) -> Scene:
    """`b` with puck and cursor positions `alpha` of the way from `a` to `b`."""
    pos = a.pos_m + alpha * (b.pos_m - a.pos_m) if a.pos_m.shape == b.pos_m.shape else b.pos_m
    before = {c.name: c.cursor_m for c in a.cursors}
    cursors = []
    for c in b.cursors:
        old = before.get(c.name)
        if old is not None:
            x = old[0] + alpha * (c.cursor_m[0] - old[0])
            y = old[1] + alpha * (c.cursor_m[1] - old[1])
            c = dataclasses.replace(c, cursor_m=(x, y))
        cursors.append(c)
    return dataclasses.replace(b, pos_m=pos, cursors=tuple(cursors))


class SnapshotFeed:
    """The player's side of snapshot format 2: frames in (network thread), smooth Scenes
    out (drawing thread). `feed` raises ProtocolError for a bad frame."""

    def __init__(self) -> None:
        self.decoder = SnapshotDecoder()
        self.buffer = PlayoutBuffer()
        self.newest: Scene | None = None  # as received, for code that wants no delay
        self._lock = threading.Lock()

    def feed(self, frame_type: int, payload: bytes, arrival_s: float) -> Scene | None:
        """Take a LAYOUT or SNAPSHOT payload; returns the decoded Scene of a SNAPSHOT."""
        if frame_type == LAYOUT:
            self.decoder.feed_layout(payload)
            return None
        decoded = self.decoder.feed_tick(payload)
        with self._lock:
            self.buffer.push(decoded.server_s, decoded.scene, decoded.epoch, arrival_s)
            self.newest = decoded.scene
        return decoded.scene

    def scene(self, now_s: float) -> Scene | None:
        """What to draw at the player's clock `now_s` (None before the first snapshot)."""
        with self._lock:
            return self.buffer.sample(now_s)
