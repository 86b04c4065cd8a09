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
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass, field

from airtable.net import protocol as proto
from airtable.net.player import NetPlayer, PlayerError
from airtable.scene import Scene

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
        me = self.net.welcome.client if self.net.welcome else None
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
    parser.add_argument("server", metavar="HOST[:PORT]", help="the table's address, as in its 'join with:' line")
    parser.add_argument("--clients", type=int, default=30, help=f"simulated players (1-{MAX_CLIENTS}, default 30)")
    parser.add_argument("--seconds", type=float, default=10.0, help="how long they play (default 10)")
    parser.add_argument("--password", help="the table's password, if it has one")
    parser.add_argument("--input-hz", type=float, default=60.0, help="INPUT messages a second per player (default 60)")
    args = parser.parse_args(argv)
    try:
        host, port = proto.parse_host_port(args.server)
        result = run_load(host, port, args.clients, args.seconds, args.password, args.input_hz)
    except ValueError as e:
        print(f"loadtest: {e}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        return 1
    print(result.report())
    return 0 if result.connected else 1


if __name__ == "__main__":
    sys.exit(main())
