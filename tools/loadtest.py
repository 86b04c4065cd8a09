"""Load test: can this computer hold a class? (no pygame)

    python -m tools.loadtest HOST[:PORT] --clients 30 --seconds 10

Connects N simulated players to a running table, spread over worker
processes (about 50 players each, `--processes` to choose), so the tool is
not the bottleneck it measures. Each one grabs a puck with the medium cursor
string and drags it round in circles, sending INPUT 60 times a second like a
real player with a moving mouse. The run prints:

- snapshots per second received by each player (the server's --snapshot-hz
  when all is well);
- the mean bytes per SNAPSHOT frame and the total Mbit/s to all players;
- the server's frame rate, read from its snapshots: first with one player
  watching, then with all N playing;
- cursor echo latency: from sending an INPUT to seeing that cursor position
  in a SNAPSHOT, median (p50) and 99th percentile (p99);
- the tool's own load: each worker's CPU (share of one core) and how late its
  loop ran. When either is too high the verdict says the tool itself was the
  bottleneck, so slow numbers are not blamed on the server.

Start the table first, e.g. `python -m airtable --headless --demo 4` on the
teacher's laptop, and run this from another machine on the same network (or
on the laptop itself with HOST 127.0.0.1, which also counts this tool's own
CPU use against the laptop).

    python -m tools.loadtest --serve [--port 8888] [--fps 60]

runs a bare headless table (a grid of pucks, no window) with a GameServer, to
measure the network layer on its own; the tests use the same `TableLoop`.
"""

from __future__ import annotations

import argparse
import math
import multiprocessing
import os
import statistics
import sys
import threading
import time
from collections.abc import Sequence
from dataclasses import dataclass, field

from airtable.app.loop import FixedStep, FpsCounter, FrameLoop
from airtable.model.client import Client, cursor_pulls
from airtable.model.scene import Scene
from airtable.net import protocol as proto
from airtable.net.server import GameServer
from airtable.physics.table import AirTable
from tools.rawplayer import WorkerReport, WorkerSpec, play

MAX_CLIENTS = 200
MAX_PROCESSES = 16
PLAYERS_PER_PROCESS = 50
MAX_SECONDS = 600.0
BASELINE_S = 1.0  # frame rate measured with one quiet player before the others join
WORKER_START_S = 20.0  # a spawned worker imports numpy and airtable first
TOOL_CPU_LIMIT = 0.85  # a worker busier than this (share of one core) may be what limits the numbers
# A worker whose loop runs later than this (95th percentile) sends its inputs late and reads late.
TOOL_LATE_PERIODS = 3
TOOL_LATE_S = 0.05


@dataclass
class LoadResult:
    """What a load test measured (rates per second, latencies in seconds, bytes)."""

    address: str
    clients: int
    connected: int
    seconds: float
    snapshot_rates: list[float]
    baseline_fps: float
    loaded_fps: list[float]
    latencies_s: list[float]
    errors: list[str]
    processes: int = 1
    snapshot_bytes: int = 0
    snapshots: int = 0
    other_bytes: int = 0
    tool_cpu: list[float] = field(default_factory=list)  # per worker process, share of one core
    tool_lag_s: list[float] = field(default_factory=list)  # per worker, 95th percentile lateness of its loop
    input_period_s: float = 1 / 60

    @property
    def p50_ms(self) -> float:
        return _percentile(self.latencies_s, 50) * 1e3

    @property
    def p99_ms(self) -> float:
        return _percentile(self.latencies_s, 99) * 1e3

    @property
    def mean_snapshot_bytes(self) -> float:
        return self.snapshot_bytes / self.snapshots if self.snapshots else 0.0

    @property
    def mbit_per_s(self) -> float:
        """Snapshot bytes received by all players together, in Mbit/s."""
        return 8 * self.snapshot_bytes / self.seconds / 1e6 if self.seconds > 0 else 0.0

    def tool_bottleneck(self) -> str | None:
        """Why this tool's own numbers cannot be trusted, or None."""
        busy = [c for c in self.tool_cpu if c > TOOL_CPU_LIMIT]
        late = [lag for lag in self.tool_lag_s if lag > max(TOOL_LATE_PERIODS * self.input_period_s, TOOL_LATE_S)]
        if not busy and not late:
            return None
        why = []
        if busy:
            why.append(f"a worker used {100 * max(busy):.0f} % of a core")
        if late:
            why.append(f"a worker's loop ran {1e3 * max(late):.0f} ms late (p95)")
        return (
            f"the load tool itself was the bottleneck ({', '.join(why)}): use more --processes, "
            "or run it on another machine"
        )

    def report(self) -> str:
        lines = [
            f"load test: {self.connected} of {self.clients} players in {self.processes} processes "
            f"connected to {self.address} for {self.seconds:g} s"
        ]
        lines += [f"  ! {e}" for e in self.errors[:5]]
        if self.snapshot_rates:
            r = self.snapshot_rates
            lines.append(
                f"  snapshots/s per player: min {min(r):.1f}, median {statistics.median(r):.1f}, max {max(r):.1f}"
            )
        if self.snapshots:
            lines.append(
                f"  bytes: {self.mean_snapshot_bytes:.0f} B per snapshot on average, "
                f"{self.mbit_per_s:.2f} Mbit/s to all players together"
            )
        lines += self._fps_lines()
        if self.latencies_s:
            lines.append(
                f"  cursor echo latency: p50 {self.p50_ms:.1f} ms, p99 {self.p99_ms:.1f} ms "
                f"({len(self.latencies_s)} samples)"
            )
        if self.tool_cpu:
            lines.append(
                f"  the tool: busiest worker {100 * max(self.tool_cpu):.0f} % of a core, loop lateness p95 "
                f"{1e3 * max(self.tool_lag_s, default=0):.1f} ms"
            )
        lines.append(f"verdict: {self.verdict()}")
        return "\n".join(lines)

    def _fps_lines(self) -> list[str]:
        if not self.loaded_fps:
            return []
        fps = statistics.median(self.loaded_fps)
        share = f" ({100 * fps / self.baseline_fps:.0f} %)" if self.baseline_fps > 0 else ""
        return [
            f"  server frame rate: {self.baseline_fps:.1f} fps with 1 player, {fps:.1f} fps with "
            f"{self.connected}{share} (lowest {min(self.loaded_fps):.1f})"
        ]

    def verdict(self) -> str:
        problems = []
        tool = self.tool_bottleneck()
        if tool:
            problems.append(tool)
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
    """A headless game loop in a thread: the app's fixed-step loop (loop.py) without a window.

    Each frame, under `lock`: `server.apply_inputs(clients, table)` once, as many
    fixed physics steps as the frame's time allows, then `server.publish(...)`
    with the measured frame rate. Hold `lock` to look at or step the table from
    another thread.
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
        self.dt_s = dt_s
        self.title = title
        self.fps = 0.0
        self.frames = 0
        self.lock = threading.RLock()
        self._stepper = FixedStep(dt_s)
        self._fps = FpsCounter()
        self._loop = FrameLoop(fps=fps)
        self._thread: threading.Thread | None = None

    def frame(self, frame_dt_s: float) -> None:
        """One frame of `frame_dt_s` seconds."""
        with self.lock:
            self.server.apply_inputs(self.clients, self.table)
            pulls = cursor_pulls(self.clients)  # inputs change between frames, not between steps
            for _ in range(self._stepper.steps(frame_dt_s)):
                self.table.step(self.dt_s, pulls)
            self.fps = self._fps.tick(time.monotonic())
            t = self.table
            status = f"{len(t.pos_m)} pucks   {len(self.server.player_names())} players   t = {t.time_s:.2f} s"
            self.server.publish(Scene.from_table(t, self.clients, title=self.title, status=status, fps=self.fps))
            self.frames += 1

    def start(self) -> TableLoop:
        self._thread = threading.Thread(
            target=self._loop.run, args=(self.frame,), name="airtable-table-loop", daemon=True
        )
        self._thread.start()
        return self

    def stop(self) -> None:
        self._loop.stop.set()
        if self._thread is not None:
            self._thread.join(timeout=5.0)
            self._thread = None


def table_for(demo: str | None = None, gas: int | None = None) -> tuple[AirTable, float, str]:
    """(table, physics step, title) to serve: a built-in demo by key, a gas of `gas`
    pucks (the benchmark's: 30 % cover, 1 m/s), or the plain grid."""
    if gas is not None:
        from airtable.demos.demo_0p_gas import DT_S, gas_scene

        return gas_scene(gas), DT_S, f"gas of {gas} pucks"
    if demo is not None:
        from airtable.app.demo_loader import BUILTIN_DIR, discover

        demos, _ = discover([BUILTIN_DIR])
        if demo not in demos:
            raise ValueError(f"there is no demo {demo!r}; the demos are {', '.join(demos)}")
        table = AirTable()
        demos[demo].build(table, 0)
        return table, demos[demo].dt_s, demos[demo].label()
    return grid_table(), 1 / 240, "headless table"


def serve(
    host: str, port: int, fps: float, seconds: float | None, password: str | None, max_clients: int, table=None
) -> int:
    """`--serve`: a headless table (`table_for`'s triple, default the grid) for load
    tests; prints its frame rate every 5 s."""
    table, dt_s, title = table or table_for()
    server = GameServer(host=host, port=port, password=password, max_clients=max_clients)
    try:
        server.start()
    except OSError as e:
        print(f"loadtest: {e}", file=sys.stderr)
        return 1
    for line in server.join_lines():
        print(line, flush=True)
    loop = TableLoop(server, table, fps=fps, dt_s=dt_s, title=title).start()
    end = math.inf if seconds is None else time.monotonic() + seconds
    try:
        while (left := end - time.monotonic()) > 0:
            time.sleep(min(5.0, left))
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


def default_processes(clients: int) -> int:
    """Worker processes for `clients` players: about 50 each, at most one per core."""
    return max(1, min(os.cpu_count() or 1, math.ceil(clients / PLAYERS_PER_PROCESS)))


def _check_args(clients: int, seconds: float, input_hz: float, processes: int) -> None:
    if not 1 <= clients <= MAX_CLIENTS:
        raise ValueError(f"--clients must be 1-{MAX_CLIENTS}")
    if not (math.isfinite(seconds) and 0 < seconds <= MAX_SECONDS):
        raise ValueError(f"--seconds must be above 0 and at most {MAX_SECONDS:g}")
    if not (math.isfinite(input_hz) and 1 <= input_hz <= 240):
        raise ValueError("--input-hz must be 1-240")
    if not 1 <= processes <= min(clients, MAX_PROCESSES):
        raise ValueError(f"--processes must be 1-{min(clients, MAX_PROCESSES)}")


def _start_workers(specs: list[WorkerSpec]) -> list[tuple]:
    ctx = multiprocessing.get_context("spawn")  # no fork: the caller may run server threads
    workers = []
    for spec in specs:
        parent, child = ctx.Pipe()
        proc = ctx.Process(target=play, args=(spec, child), name=f"airtable-load-{spec.first}", daemon=True)
        proc.start()
        workers.append((proc, parent))
    return workers


def _expect(pipe, what: str, timeout_s: float):
    """The next message from a worker, or None after `timeout_s` or when it has died."""
    try:
        if not pipe.poll(timeout_s):
            return None
        message = pipe.recv()
    except (EOFError, OSError):
        return None
    return message if message[0] == what else None


def _tell(workers: list[tuple], message: tuple) -> None:
    """Send `message` to every worker still listening (a dead one just misses it)."""
    for _, pipe in workers:
        try:
            pipe.send(message)
        except OSError:
            pass


def _run_workers(workers: list[tuple], seconds: float, timeout_s: float, baseline_s: float) -> list[WorkerReport]:
    """Step the workers through: first player (baseline), the rest join, play, report."""
    for _, pipe in workers:
        _expect(pipe, "joined-first", WORKER_START_S + timeout_s + baseline_s)
    _tell(workers, ("connect",))
    for _, pipe in workers:
        _expect(pipe, "ready", WORKER_START_S + 4 * timeout_s)
    start = time.monotonic() + 0.2  # CLOCK_MONOTONIC is shared by the processes of one machine
    _tell(workers, ("start", start, start + seconds))
    reports = []
    for _, pipe in workers:
        message = _expect(pipe, "done", seconds + 2 * timeout_s + 5)
        reports.append(message[1] if message else WorkerReport(errors=["a load worker did not report"]))
    return reports


def _merge(address: str, clients: int, seconds: float, reports: list[WorkerReport], period_s: float) -> LoadResult:
    base = [f for r in reports for f in r.baseline_fps]
    result = LoadResult(
        address,
        clients,
        sum(r.connected for r in reports),
        seconds,
        [len(times) / seconds for r in reports for times in r.snapshot_times],
        statistics.median(base[len(base) // 2 :]) if base else 0.0,
        [f for r in reports for _, f in r.fps],
        [t for r in reports for t in r.latencies_s],
        [e for r in reports for e in r.errors],
        processes=len(reports),
        snapshot_bytes=sum(r.snapshot_bytes for r in reports),
        snapshots=sum(len(t) for r in reports for t in r.snapshot_times),
        other_bytes=sum(r.other_bytes for r in reports),
        tool_cpu=[r.cpu_share for r in reports],
        tool_lag_s=[r.lag_p95_s for r in reports],
        input_period_s=period_s,
    )
    return result


def run_load(
    host: str,
    port: int = proto.DEFAULT_PORT,
    clients: int = 30,
    seconds: float = 10.0,
    password: str | None = None,
    input_hz: float = 60.0,
    timeout_s: float = 5.0,
    processes: int | None = None,
    baseline_s: float = BASELINE_S,
) -> LoadResult:
    """Connect `clients` simulated players from `processes` worker processes for
    `seconds` and measure (see the module docstring); the first player watches
    `baseline_s` alone before the others join."""
    processes = default_processes(clients) if processes is None else processes
    _check_args(clients, seconds, input_hz, processes)
    shares = [clients // processes + (1 if k < clients % processes else 0) for k in range(processes)]
    specs, first = [], 0
    for k, count in enumerate(shares):
        specs.append(
            WorkerSpec(host, port, first, count, password, input_hz, timeout_s, True, baseline_s if k == 0 else 0.0)
        )
        first += count
    workers = _start_workers(specs)
    try:
        reports = _run_workers(workers, seconds, timeout_s, baseline_s)
    finally:
        for proc, pipe in workers:
            proc.join(timeout=5.0)
            if proc.is_alive():
                proc.terminate()
                proc.join(timeout=2.0)
            pipe.close()
    return _merge(f"{host}:{port}", clients, seconds, reports, 1.0 / input_hz)


def main(argv: Sequence[str] | None = None) -> int:
    parser = argparse.ArgumentParser(
        prog="python -m tools.loadtest",
        description="Connect simulated players to a running air table and measure whether it holds a class.",
    )
    parser.add_argument(
        "server", metavar="HOST[:PORT]", nargs="?", help="the table's address, as in its 'join with:' line"
    )
    parser.add_argument("--clients", type=int, default=30, help=f"simulated players (1-{MAX_CLIENTS}, default 30)")
    parser.add_argument("--seconds", type=float, help="how long they play (default 10; --serve: forever)")
    parser.add_argument("--password", help="the table's password, if it has one")
    parser.add_argument("--input-hz", type=float, default=60.0, help="INPUT messages a second per player (default 60)")
    parser.add_argument(
        "--processes",
        type=int,
        help="worker processes the players are spread over (default: 1 per 50, up to the cores)",
    )
    serving = parser.add_argument_group("serving a bare table instead (--serve)")
    serving.add_argument("--serve", action="store_true", help="run a headless table with a server, no window")
    serving.add_argument("--host", default="0.0.0.0", help="address to listen on (default 0.0.0.0)")
    serving.add_argument("--port", type=int, default=proto.DEFAULT_PORT, help="port (default 8888)")
    serving.add_argument("--fps", type=float, default=60.0, help="frames a second (default 60)")
    serving.add_argument("--max-clients", type=int, default=MAX_CLIENTS, help=f"default {MAX_CLIENTS}")
    serving.add_argument("--demo", help="serve this built-in demo (e.g. 4) instead of a grid")
    serving.add_argument("--gas", type=int, help="serve a gas of this many pucks instead of a grid")
    args = parser.parse_args(argv)
    if args.serve:
        if not (math.isfinite(args.fps) and 1 <= args.fps <= 1000):
            parser.error("--fps must be 1-1000")
        try:
            table = table_for(args.demo, args.gas)
        except ValueError as e:
            parser.error(str(e))
        return serve(args.host, args.port, args.fps, args.seconds, args.password, args.max_clients, table)
    if args.server is None:
        parser.error("give the table's address HOST[:PORT], or --serve to run one")
    try:
        host, port = proto.parse_host_port(args.server)
        seconds = 10.0 if args.seconds is None else args.seconds
        result = run_load(host, port, args.clients, seconds, args.password, args.input_hz, processes=args.processes)
    except ValueError as e:
        print(f"loadtest: {e}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        return 1
    print(result.report())
    return 0 if result.connected else 1


if __name__ == "__main__":
    sys.exit(main())
