"""Load test: can this computer hold a class? (no pygame)

    python -m airtable.net.loadtest HOST[:PORT] --clients 30 --seconds 10

Connects N simulated players to a running table. Each one grabs a puck with
the medium cursor string and drags it round in circles, sending INPUT 60 times
a second like a real player with a moving mouse. The run prints:

- snapshots per second received by each player (the server's --snapshot-hz
  when all is well);
- the server's frame rate, read from its snapshots: first with one player
  watching, then with all N playing;
- cursor echo latency: from sending an INPUT to seeing that cursor position
  in a SNAPSHOT, median (p50) and 99th percentile (p99).

Start the table first, e.g. `python -m airtable --headless --demo 4` on the
teacher's laptop, and run this from another machine on the same network (or
on the laptop itself with HOST 127.0.0.1, which also counts this tool's own
CPU use against the laptop).

    python -m airtable.net.loadtest --serve [--port 8888] [--fps 60]

runs a bare headless table (a grid of pucks, no window) with a GameServer, to
measure the network layer on its own; the tests use the same `TableLoop`.
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import threading
import time
from collections import deque
from collections.abc import Sequence
from dataclasses import dataclass, field

from airtable.app.client import Client, cursor_pulls
from airtable.app.scene import Scene
from airtable.net import protocol as proto
from airtable.net.player import NetPlayer, PlayerError
from airtable.net.server import GameServer
from airtable.physics.table import AirTable

MAX_CLIENTS = 200
MAX_SECONDS = 600.0
BASELINE_S = 1.0  # frame rate measured with one quiet player before the others join
CIRCLE_RADIUS_M = 0.5
CIRCLE_RAD_PER_S = 2.0


@dataclass
class _Sim:
    """One simulated player and what it saw."""

    index: int
    net: NetPlayer
    centre_m: tuple[float, float] = (5.0, 4.0)
    sent: dict[tuple[float, float], float] = field(default_factory=dict)  # cursor -> send time
    seen: list[tuple[float, tuple[float, float]]] = field(default_factory=list)  # (receive time, own cursor)
    snapshot_times: list[float] = field(default_factory=list)
    fps: list[tuple[float, float]] = field(default_factory=list)  # (receive time, server fps)

    def on_snapshot(self, scene: Scene, t: float) -> None:
        # Reader thread: only appends (list.append is atomic), the numbers are worked out afterwards.
        self.snapshot_times.append(t)
        self.fps.append((t, scene.fps))
        me = self.net.welcome.label if self.net.welcome else None
        for cursor in scene.cursors:
            if cursor.name == me:
                self.seen.append((t, cursor.cursor_m))
                break


@dataclass
class LoadResult:
    """What a load test measured (rates per second, latencies in seconds)."""

    address: str
    clients: int
    connected: int
    seconds: float
    snapshot_rates: list[float]
    baseline_fps: float
    loaded_fps: list[float]
    latencies_s: list[float]
    errors: list[str]

    @property
    def p50_ms(self) -> float:
        return _percentile(self.latencies_s, 50) * 1e3

    @property
    def p99_ms(self) -> float:
        return _percentile(self.latencies_s, 99) * 1e3

    def report(self) -> str:
        lines = [
            f"load test: {self.connected} of {self.clients} players connected to {self.address} for {self.seconds:g} s"
        ]
        lines += [f"  ! {e}" for e in self.errors[:5]]
        if self.snapshot_rates:
            r = self.snapshot_rates
            lines.append(
                f"  snapshots/s per player: min {min(r):.1f}, median {statistics.median(r):.1f}, max {max(r):.1f}"
            )
        if self.loaded_fps:
            fps = statistics.median(self.loaded_fps)
            share = f" ({100 * fps / self.baseline_fps:.0f} %)" if self.baseline_fps > 0 else ""
            lines.append(
                f"  server frame rate: {self.baseline_fps:.1f} fps with 1 player, {fps:.1f} fps with "
                f"{self.connected}{share} (lowest {min(self.loaded_fps):.1f})"
            )
        if self.latencies_s:
            lines.append(
                f"  cursor echo latency: p50 {self.p50_ms:.1f} ms, p99 {self.p99_ms:.1f} ms "
                f"({len(self.latencies_s)} samples)"
            )
        lines.append(f"verdict: {self.verdict()}")
        return "\n".join(lines)

    def verdict(self) -> str:
        problems = []
        if self.connected < self.clients:
            problems.append(f"only {self.connected} of {self.clients} players could join")
        if self.snapshot_rates and min(self.snapshot_rates) < 0.9 * statistics.median(self.snapshot_rates):
            problems.append("some players miss snapshots (slow network or server)")
        if self.loaded_fps and self.baseline_fps > 0:
            if statistics.median(self.loaded_fps) < 0.9 * self.baseline_fps:
                problems.append("the server's frame rate drops by more than 10 %")
        if self.latencies_s and self.p99_ms > 100:
            problems.append("cursors lag (p99 echo over 100 ms)")
        if not self.latencies_s:
            problems.append("no cursor echo was measured")
        if problems:
            return "struggling: " + "; ".join(problems)
        return f"OK, this server holds {self.connected} players"


def grid_table(columns: int = 6, rows: int = 5) -> AirTable:
    """A table with a grid of pucks."""
    table = AirTable()
    # Small enough that neighbours never touch, however many there are.
    radius_m = min(0.3, 0.4 * table.width_m / columns, 0.4 * table.height_m / rows)
    for i in range(columns):
        for j in range(rows):
            x = table.width_m * (i + 0.5) / columns
            y = table.height_m * (j + 0.5) / rows
            table.add_puck((x, y), radius_m=radius_m, color="orange")
    return table


class TableLoop:
    """A headless game loop in a thread: inputs, fixed physics steps, snapshots.

    Each frame, under `lock`: `server.apply_inputs(clients, table)` and `table.step(dt_s, pulls)`
    for each physics step, then `server.publish(...)` with the measured frame
    rate. Hold `lock` to look at or step the table from another thread.
    """

    def __init__(
        self,
        server: GameServer,
        table: AirTable | None = None,
        fps: float = 60.0,
        dt_s: float = 1 / 240,
        title: str = "headless table",
    ) -> None:
        self.server = server
        self.table = table if table is not None else grid_table()
        self.clients = [Client(name="local", active=False)]  # the server adds the players
        self.period_s = 1.0 / fps
        self.dt_s = dt_s
        self.steps_per_frame = max(1, round(self.period_s / dt_s))
        self.title = title
        self.fps = 0.0
        self.frames = 0
        self._frame_times: deque[float] = deque()
        self.lock = threading.RLock()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    def frame(self) -> None:
        with self.lock:
            for _ in range(self.steps_per_frame):
                self.server.apply_inputs(self.clients, self.table)
                self.table.step(self.dt_s, cursor_pulls(self.clients))
            # Frames counted over the last second: an average of 1/dt would favour short frames.
            now = time.monotonic()
            times = self._frame_times
            times.append(now)
            while now - times[0] > 1.0:
                times.popleft()
            if len(times) > 1:
                self.fps = (len(times) - 1) / (times[-1] - times[0])
            t = self.table
            status = f"{len(t.pos_m)} pucks   {len(self.server.player_names())} players   t = {t.time_s:.2f} s"
            self.server.publish(Scene.from_table(t, self.clients, title=self.title, status=status, fps=self.fps))
            self.frames += 1

    def _run(self) -> None:
        next_t = time.monotonic()
        while not self._stop.is_set():
            self.frame()
            next_t += self.period_s
            delay = next_t - time.monotonic()
            if delay > 0:
                self._stop.wait(delay)
            else:
                next_t = time.monotonic()

    def start(self) -> TableLoop:
        self._thread = threading.Thread(target=self._run, name="airtable-table-loop", daemon=True)
        self._thread.start()
        return self

    def stop(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=5.0)
            self._thread = None


def serve(host: str, port: int, fps: float, seconds: float | None, password: str | None, max_clients: int) -> int:
    """`--serve`: a bare headless table for load tests; prints its frame rate every 5 s."""
    server = GameServer(host=host, port=port, password=password, max_clients=max_clients)
    try:
        server.start()
    except OSError as e:
        print(f"loadtest: {e}", file=sys.stderr)
        return 1
    for line in server.join_lines():
        print(line, flush=True)
    loop = TableLoop(server, fps=fps).start()
    start = time.monotonic()
    try:
        while seconds is None or time.monotonic() - start < seconds:
            time.sleep(min(5.0, seconds - (time.monotonic() - start)) if seconds is not None else 5.0)
            print(f"{loop.fps:.1f} fps, {len(server.player_names())} players", flush=True)
    except KeyboardInterrupt:
        pass
    finally:
        loop.stop()
        server.stop()
    return 0


def _percentile(values: Sequence[float], q: float) -> float:
    if not values:
        return math.nan
    ordered = sorted(values)
    k = (len(ordered) - 1) * q / 100
    lo = int(math.floor(k))
    hi = min(lo + 1, len(ordered) - 1)
    return ordered[lo] + (ordered[hi] - ordered[lo]) * (k - lo)


def _wait_for_scene(sim: _Sim, timeout_s: float) -> Scene | None:
    deadline = time.monotonic() + timeout_s
    while time.monotonic() < deadline:
        scene = sim.net.latest()
        if scene is not None:
            return scene
        time.sleep(0.01)
    return None


def run_load(
    host: str,
    port: int = proto.DEFAULT_PORT,
    clients: int = 30,
    seconds: float = 10.0,
    password: str | None = None,
    input_hz: float = 60.0,
    timeout_s: float = 5.0,
) -> LoadResult:
    """Connect `clients` simulated players for `seconds` and measure (see the module docstring)."""
    if not 1 <= clients <= MAX_CLIENTS:
        raise ValueError(f"--clients must be 1-{MAX_CLIENTS}")
    if not (math.isfinite(seconds) and 0 < seconds <= MAX_SECONDS):
        raise ValueError(f"--seconds must be above 0 and at most {MAX_SECONDS:g}")
    if not (math.isfinite(input_hz) and 1 <= input_hz <= 240):
        raise ValueError("--input-hz must be 1-240")
    sims: list[_Sim] = []
    errors: list[str] = []
    address = f"{host}:{port}"

    def connect(i: int) -> _Sim | None:
        net = NetPlayer(host, port, name=f"load{i + 1}", password=password, timeout_s=timeout_s)
        sim = _Sim(i, net)
        net.on_snapshot = sim.on_snapshot
        try:
            net.connect()
        except PlayerError as e:
            errors.append(str(e))
            return None
        return sim

    try:
        # Baseline: one quiet player watches the frame rate.
        first = connect(0)
        if first is None:
            return LoadResult(address, clients, 0, seconds, [], 0.0, [], [], errors)
        sims.append(first)
        _wait_for_scene(first, timeout_s)
        time.sleep(BASELINE_S)
        base = [fps for _, fps in first.fps]
        baseline_fps = statistics.median(base[len(base) // 2 :]) if base else 0.0
        for i in range(1, clients):
            sim = connect(i)
            if sim is None:
                if errors and "server full" in errors[-1]:
                    break
                continue
            sims.append(sim)
        # Each player drags the puck nearest its slot, or circles the middle of an empty table.
        for sim in sims:
            scene = _wait_for_scene(sim, timeout_s)
            if scene is not None and len(scene.pos_m):
                x, y = scene.pos_m[sim.index % len(scene.pos_m)]
                sim.centre_m = (float(x), float(y))
            elif scene is not None:
                sim.centre_m = (scene.width_m / 2, scene.height_m / 2)
            sim.net.send_input(sim.centre_m, 1)  # button down over the puck: grab it
        start = time.monotonic()
        end = start + seconds
        period = 1.0 / input_hz
        next_t = start
        while True:
            now = time.monotonic()
            if now >= end:
                break
            for sim in sims:
                angle = CIRCLE_RAD_PER_S * (now - start) + sim.index
                cx, cy = sim.centre_m
                cursor = (cx + CIRCLE_RADIUS_M * math.cos(angle), cy + CIRCLE_RADIUS_M * math.sin(angle))
                t_sent = time.monotonic()
                if sim.net.send_input(cursor, 1):
                    sim.sent.setdefault(cursor, t_sent)
            next_t += period
            delay = next_t - time.monotonic()
            if delay > 0:
                time.sleep(delay)
            else:
                next_t = time.monotonic()  # fell behind: do not burst to catch up
        stop = time.monotonic()
        # Let snapshots in flight arrive, then stop measuring.
        time.sleep(0.2)
    finally:
        for sim in sims:
            sim.net.close(bye=True)

    rates, fps, latencies = [], [], []
    duration = stop - start
    for sim in sims:
        rates.append(sum(1 for t in sim.snapshot_times if start <= t < stop) / duration)
        fps.extend(f for t, f in sim.fps if start <= t < stop)
        echoed: set[tuple[float, float]] = set()
        for t, cursor in sim.seen:
            t_sent = sim.sent.get(cursor)
            if t_sent is not None and cursor not in echoed:
                echoed.add(cursor)
                latencies.append(t - t_sent)
    return LoadResult(address, clients, len(sims), seconds, rates, baseline_fps, fps, latencies, errors)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m airtable.net.loadtest",
        description="Connect simulated players to a running air table and measure whether it holds a class.",
    )
    parser.add_argument(
        "server", metavar="HOST[:PORT]", nargs="?", help="the table's address, as in its 'join with:' line"
    )
    parser.add_argument("--clients", type=int, default=30, help=f"simulated players (1-{MAX_CLIENTS}, default 30)")
    parser.add_argument("--seconds", type=float, help="how long they play (default 10; --serve: forever)")
    parser.add_argument("--password", help="the table's password, if it has one")
    parser.add_argument("--input-hz", type=float, default=60.0, help="INPUT messages a second per player (default 60)")
    serving = parser.add_argument_group("serving a bare table instead (--serve)")
    serving.add_argument("--serve", action="store_true", help="run a headless table with a server, no window")
    serving.add_argument("--host", default="0.0.0.0", help="address to listen on (default 0.0.0.0)")
    serving.add_argument("--port", type=int, default=proto.DEFAULT_PORT, help="port (default 8888)")
    serving.add_argument("--fps", type=float, default=60.0, help="frames a second (default 60)")
    serving.add_argument("--max-clients", type=int, default=MAX_CLIENTS, help=f"default {MAX_CLIENTS}")
    args = parser.parse_args(argv)
    if args.serve:
        if not (math.isfinite(args.fps) and 1 <= args.fps <= 1000):
            parser.error("--fps must be 1-1000")
        return serve(args.host, args.port, args.fps, args.seconds, args.password, args.max_clients)
    if args.server is None:
        parser.error("give the table's address HOST[:PORT], or --serve to run one")
    try:
        host, port = proto.parse_host_port(args.server)
        seconds = 10.0 if args.seconds is None else args.seconds
        result = run_load(host, port, args.clients, seconds, args.password, args.input_hz)
    except ValueError as e:
        print(f"loadtest: {e}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        return 1
    print(result.report())
    return 0 if result.connected else 1


if __name__ == "__main__":
    sys.exit(main())
