"""Raw players for the load tool and the bandwidth tests: many per process, one thread (no pygame).

A `RawPlayer` says HELLO, then counts what the server sends (snapshots, their
bytes, the server's frame rate) and, when asked to, decodes snapshots to see
its own cursor come back. It never draws and keeps no more than a few numbers
per snapshot, so one process can stand in for dozens of students without
becoming the bottleneck it is trying to measure.

`play(spec, pipe)` is the body of one load-tool worker process: it connects
its share of players, has each drag a puck round in circles, sends INPUT at
the given rate and reports what it measured, including its own CPU use and how
late its loop ran, so the tool can say when it was itself the bottleneck.
"""

from __future__ import annotations

import math
import selectors
import socket
import time
from dataclasses import dataclass, field

from airtable.model.scene import Scene
from airtable.net import protocol as proto
from airtable.net.codec import SnapshotDecoder

CIRCLE_RADIUS_M = 0.5
CIRCLE_RAD_PER_S = 2.0
QUANTUM_M = 1 / 4000  # cursors are matched at the resolution format 2 sends
MAX_SENT_REMEMBERED = 4096


class LoadError(Exception):
    """A player could not join; str(error) is a sentence."""


def _key(cursor_m) -> tuple[int, int]:
    return (round(cursor_m[0] / QUANTUM_M), round(cursor_m[1] / QUANTUM_M))


@dataclass
class RawPlayer:
    """One simulated student on a non-blocking socket."""

    host: str
    port: int
    name: str
    password: str | None = None
    decode: bool = True
    sock: socket.socket | None = None
    welcome: proto.Welcome | None = None
    snapshot_times: list[float] = field(default_factory=list)
    snapshot_sizes: list[int] = field(default_factory=list)  # bytes of each SNAPSHOT frame, envelope included
    other_bytes: int = 0
    fps: list[tuple[float, float]] = field(default_factory=list)  # (receive time, server fps)
    sent: dict[tuple[int, int], float] = field(default_factory=dict)  # cursor -> first send time
    latencies_s: list[float] = field(default_factory=list)
    scene: Scene | None = None
    closed: bool = False
    error: str | None = None

    def connect(self, timeout_s: float = 5.0) -> None:
        """Connect and wait for WELCOME (blocking, bounded); then the socket is non-blocking."""
        try:
            sock = socket.create_connection((self.host, self.port), timeout=timeout_s)
        except OSError as e:
            raise LoadError(f"cannot connect to {self.host}:{self.port} ({e})") from None
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self._reader = proto.FrameReader(proto.MAX_SERVER_FRAME, proto.FRAME_NAMES, "the server")
        self._snapshots = SnapshotDecoder()
        deadline = time.monotonic() + timeout_s
        try:
            sock.sendall(proto.encode_hello(self.name, self.password))
            while self.welcome is None:
                sock.settimeout(max(0.01, deadline - time.monotonic()))
                data = sock.recv(65536)
                if not data:
                    raise LoadError("the server hung up before saying WELCOME")
                self._handle(self._reader.feed(data), time.monotonic())
        except (OSError, proto.ProtocolError) as e:
            sock.close()
            raise LoadError(f"{self.name} could not join: {e}") from None
        except LoadError:
            sock.close()
            raise
        sock.setblocking(False)
        self.sock = sock

    def _handle(self, frames: list[tuple[int, bytes]], now: float) -> None:
        for kind, payload in frames:
            if kind == proto.SNAPSHOT:
                self.snapshot_times.append(now)
                self.snapshot_sizes.append(5 + len(payload))
                if self.decode:
                    self._look(self._snapshots.feed_tick(payload).scene, now)
                continue
            self.other_bytes += 5 + len(payload)
            if kind == proto.LAYOUT:
                if self.decode:
                    self._snapshots.feed_layout(payload)
            elif kind == proto.WELCOME:
                self.welcome = proto.parse_welcome(payload)
            elif kind == proto.ERROR:
                raise LoadError(proto.parse_error(payload))
            elif kind == proto.BYE:
                self.closed = True

    def _look(self, scene: Scene, now: float) -> None:
        self.scene = scene
        self.fps.append((now, scene.fps))
        me = self.welcome.label if self.welcome else None
        for cursor in scene.cursors:
            if cursor.name == me:
                sent = self.sent.pop(_key(cursor.cursor_m), None)
                if sent is not None:
                    self.latencies_s.append(now - sent)
                    # The table shows the newest input only: those sent before this one never will be.
                    # Left in, a place the cursor's path passed again a lap later matched its first
                    # visit, and every run measured the lap (6.3 s) as its p99 (a user test).
                    self.sent = {k: t for k, t in self.sent.items() if t > sent}
                break

    def on_readable(self, now: float) -> None:
        """Read what arrived (non-blocking)."""
        try:
            data = self.sock.recv(1 << 20)
        except (BlockingIOError, InterruptedError):
            return
        except OSError as e:
            self.closed, self.error = True, f"{self.name}: connection lost ({e})"
            return
        if not data:
            self.closed = True
            return
        try:
            self._handle(self._reader.feed(data), now)
        except (proto.ProtocolError, LoadError) as e:
            self.closed, self.error = True, f"{self.name}: {e}"

    def send_input(self, cursor_m: tuple[float, float], button: int, now: float) -> bool:
        """One INPUT; False when the socket would block (the server reads slowly)."""
        if self.sock is None or self.closed:
            return False
        try:
            self.sock.send(proto.encode_input(cursor_m, button))
        except (BlockingIOError, InterruptedError):
            return False
        except OSError:
            self.closed = True
            return False
        if len(self.sent) < MAX_SENT_REMEMBERED:
            self.sent.setdefault(_key(cursor_m), now)
        return True

    def close(self) -> None:
        if self.sock is not None:
            try:
                self.sock.setblocking(True)
                self.sock.settimeout(0.5)
                self.sock.sendall(proto.encode_bye())
            except OSError:
                pass
            self.sock.close()
            self.sock = None


def pump(players: list[RawPlayer], until_s: float, sel: selectors.BaseSelector | None = None) -> None:
    """Read from every player until the monotonic time `until_s`."""
    own = sel is None
    if own:
        sel = selectors.DefaultSelector()
        for p in players:
            if p.sock is not None:
                sel.register(p.sock, selectors.EVENT_READ, p)
    try:
        while (now := time.monotonic()) < until_s:
            for key, _ in sel.select(until_s - now):
                key.data.on_readable(time.monotonic())
    finally:
        if own:
            sel.close()


# ---------------------------------------------------------------- one worker process


@dataclass(frozen=True)
class WorkerSpec:
    host: str
    port: int
    first: int  # number of this worker's first player
    count: int
    password: str | None = None
    input_hz: float = 60.0
    timeout_s: float = 5.0
    decode: bool = True
    baseline_s: float = 0.0  # > 0: the first player watches this long alone before the others join


@dataclass
class WorkerReport:
    """What one worker measured; plain numbers, so it crosses a process pipe."""

    connected: int = 0
    errors: list[str] = field(default_factory=list)
    baseline_fps: list[float] = field(default_factory=list)
    snapshot_times: list[list[float]] = field(default_factory=list)  # per player, during the run
    snapshot_bytes: int = 0  # during the run
    other_bytes: int = 0  # LAYOUT and the rest, whole connection
    fps: list[tuple[float, float]] = field(default_factory=list)
    latencies_s: list[float] = field(default_factory=list)
    cpu_share: float = 0.0  # of one core, during the run
    lag_p95_s: float = 0.0  # how late the input loop ran
    lag_max_s: float = 0.0


def _connect(spec: WorkerSpec, numbers: range, report: WorkerReport) -> list[RawPlayer]:
    players = []
    for i in numbers:
        p = RawPlayer(spec.host, spec.port, f"load{i + 1}", spec.password, spec.decode)
        try:
            p.connect(spec.timeout_s)
        except LoadError as e:
            report.errors.append(str(e))
            if "full" in str(e):
                break
            continue
        players.append(p)
    return players


def _grab(players: list[RawPlayer], timeout_s: float) -> dict[int, tuple[float, float]]:
    """Wait (bounded) for each player's first scene; each grabs the puck nearest its slot."""
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline and any(p.scene is None and not p.closed for p in players):
        pump(players, min(deadline, time.monotonic() + 0.05))
    centres = {}
    for k, p in enumerate(players):
        scene = p.scene
        if scene is not None and len(scene.pos_m):
            x, y = scene.pos_m[(int(p.name[4:]) - 1) % len(scene.pos_m)]
        elif scene is not None:
            x, y = scene.width_m / 2, scene.height_m / 2
        else:
            x, y = 5.0, 4.0
        centres[k] = (float(x), float(y))
        p.send_input(centres[k], 1, time.monotonic())
    return centres


def _drive(players: list[RawPlayer], centres, spec: WorkerSpec, start_s: float, end_s: float) -> list[float]:
    """Circle every cursor at `input_hz` until `end_s` while reading; returns the loop's lateness."""
    period = 1.0 / spec.input_hz
    lags = []
    sel = selectors.DefaultSelector()
    for p in players:
        sel.register(p.sock, selectors.EVENT_READ, p)
    try:
        pump(players, start_s, sel)
        next_t = start_s
        while (now := time.monotonic()) < end_s:
            if now >= next_t:
                lags.append(now - next_t)
                for k, p in enumerate(players):
                    angle = CIRCLE_RAD_PER_S * (now - start_s) + int(p.name[4:])
                    cx, cy = centres[k]
                    p.send_input(
                        (cx + CIRCLE_RADIUS_M * math.cos(angle), cy + CIRCLE_RADIUS_M * math.sin(angle)), 1, now
                    )
                next_t = max(next_t + period, now - period)  # fell far behind: do not burst
            pump(players, min(next_t, end_s), sel)
    finally:
        sel.close()
    return lags


def play(spec: WorkerSpec, pipe) -> None:
    """A load-tool worker process: join, wait for the start time, play, report."""
    report = WorkerReport()
    numbers = range(spec.first, spec.first + spec.count)
    players: list[RawPlayer] = []
    try:
        if spec.baseline_s > 0:
            players = _connect(spec, numbers[:1], report)
            if players:
                pump(players, time.monotonic() + spec.baseline_s)
            report.baseline_fps = [f for p in players for _, f in p.fps]
            numbers = numbers[1:]
        pipe.send(("joined-first", None))
        if not pipe.poll(60.0):
            return
        pipe.recv()
        players += _connect(spec, numbers, report)
        centres = _grab(players, spec.timeout_s)
        report.connected = len(players)
        pipe.send(("ready", report.connected))
        if not pipe.poll(60.0):
            return
        _, start_s, end_s = pipe.recv()
        cpu0 = time.process_time()
        lags = _drive(players, centres, spec, start_s, end_s)
        report.cpu_share = (time.process_time() - cpu0) / max(1e-9, end_s - start_s)
        _summarise(report, players, lags, start_s, end_s)
    finally:
        for p in players:
            p.close()
        pipe.send(("done", report))


def _summarise(report: WorkerReport, players: list[RawPlayer], lags: list[float], start_s: float, end_s: float) -> None:
    for p in players:
        if p.error:
            report.errors.append(p.error)
        inside = [(t, b) for t, b in zip(p.snapshot_times, p.snapshot_sizes, strict=True) if start_s <= t < end_s]
        report.snapshot_times.append([t for t, _ in inside])
        report.snapshot_bytes += sum(b for _, b in inside)
        report.other_bytes += p.other_bytes
        report.fps += [(t, f) for t, f in p.fps if start_s <= t < end_s]
        report.latencies_s += p.latencies_s
    if lags:
        ordered = sorted(lags)
        report.lag_p95_s = ordered[int(0.95 * (len(ordered) - 1))]
        report.lag_max_s = ordered[-1]
