"""Bytes per snapshot in format 2, measured on real scenes (no pygame, no sockets).

    python -m bench.snapshots

builds each scene from the real demos and the benchmark's gas, runs the
physics, feeds every snapshot tick (30 a second from a 60 fps loop) through a
`SnapshotEncoder` to one student who receives them all, and reports the mean
SNAPSHOT frame (envelope included) against the targets, the first keyframe,
the LAYOUT frame, and what the other residual coding (zigzag varints) would
have cost, so the choice of byte planes stays a measured one.
"""

from __future__ import annotations

import math
import statistics
import sys
import time
import zlib
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

from airtable.app.demo_loader import BUILTIN_DIR, load_demo_file
from airtable.model.client import Client
from airtable.model.scene import Scene
from airtable.net.codec import SnapshotEncoder, Viewer, predict
from airtable.physics.table import AirTable

FRAME_S = 1 / 60
FRAMES_PER_TICK = 2  # 30 snapshots a second from a 60 fps loop
TARGETS_B = {"demo 4, 30 students moving": 600, "1000-puck gas": 3000, "table at rest": 120, "10000-puck burst": 30000}


def step_table(table: AirTable, clients: Sequence[Client], dt_s: float) -> None:
    """One physics step with the clients' cursor strings, on either table API."""
    try:
        from airtable.model.client import cursor_pulls  # the table takes forces
    except ImportError:
        table.clients[:] = list(clients)
        table.step(dt_s)
    else:
        table.step(dt_s, pulls=cursor_pulls(clients))


def demo_table(key_file: str, variation: int = 0) -> AirTable:
    table = AirTable()
    load_demo_file(BUILTIN_DIR / key_file).build(table, variation)
    return table


def status_line(table: AirTable) -> str:
    """A status line like the teacher's app shows (it changes every tick)."""
    return "   ".join(
        [
            "gravity on" if table.gravity_on else "gravity off",
            f"correction: {table.puck_correction}",
            f"restitution: pucks {table.cr_puck:g}, walls {table.cr_wall:g}",
            f"{len(table.pos_m)} pucks",
            f"{table.collision_count} collisions",
            f"t = {table.time_s:.2f} s",
            "F1: help",
        ]
    )


@dataclass
class Run:
    """A scene to measure: its table, its students, how it moves them."""

    name: str
    table: AirTable
    clients: list[Client]
    dt_s: float = 1 / 240
    move: Callable[[float], None] | None = None  # called with the time before each frame


def students_on_demo4(count: int = 30) -> Run:
    """Demo 4 with `count` students, each dragging a puck round a 0.5 m circle at 2 rad/s."""
    table = demo_table("demo_4_grid_9x6.py")
    clients = [Client(name="local", active=False)]
    centres = []
    for i in range(count):
        c = Client(name=f"C{i + 1}", color=(40 + 7 * i, 200, 90))
        centre = table.pos_m[i % len(table.pos_m)].copy()
        c.set_input(table, centre, 1)
        clients.append(c)
        centres.append(centre)

    def move(t: float) -> None:
        for i, c in enumerate(clients[1:]):
            angle = 2.0 * t + i
            cursor = centres[i] + 0.5 * np.array([math.cos(angle), math.sin(angle)])
            c.set_input(table, cursor, 1)

    return Run("demo 4, 30 students moving", table, clients, move=move)


def gas(n: int = 1000) -> Run:
    from airtable.demos.demo_0p_gas import DT_S, gas_scene

    return Run(f"{n}-puck gas", gas_scene(n), [Client(name="local", active=False)], dt_s=DT_S)


def at_rest() -> Run:
    return Run("table at rest", demo_table("demo_4_grid_9x6.py"), [Client(name="local", active=False)])


def burst(n: int = 10000) -> Run:
    module = load_demo_file(BUILTIN_DIR / "demo_0_burst.py")
    table = AirTable()
    module.build(table, list(load_counts(module)).index(n))
    return Run(f"{n}-puck burst", table, [Client(name="local", active=False)])


def load_counts(module) -> Sequence[int]:
    return [int(v.split("=")[1]) for v in module.variations]


def scenes(run: Run, ticks: int):
    """Yield `ticks` Scenes of the run, one per snapshot tick."""
    t = 0.0
    steps = max(1, round(FRAME_S / run.dt_s))
    for _ in range(ticks):
        for _ in range(FRAMES_PER_TICK):
            if run.move is not None:
                run.move(t)
            for _ in range(steps):
                step_table(run.table, run.clients, run.dt_s)
            t += FRAME_S
        yield Scene.from_table(
            run.table, run.clients, title="Demo", status=status_line(run.table), fps=59.5 + 0.5 * math.sin(t)
        )


def varint_size(residuals: np.ndarray) -> tuple[int, int]:
    """(raw, deflated) bytes of the residuals as zigzag LEB128 varints."""
    z = ((residuals << 1) ^ (residuals >> 63)).astype(np.uint64)
    groups = []
    more = np.ones(len(z), dtype=bool)
    while more.any():
        byte = (z & np.uint64(0x7F)).astype(np.uint8)
        z = z >> np.uint64(7)
        nxt = z > 0
        groups.append(np.where(nxt, byte | 0x80, byte)[more])
        more = more & nxt
    data = b"".join(g.tobytes() for g in groups) if groups else b""
    packer = zlib.compressobj(1, zlib.DEFLATED, -15)
    return len(data), len(packer.compress(data) + packer.flush())


@dataclass
class Measured:
    name: str
    mean_b: float
    keyframe_b: int
    layout_b: int
    varint_b: float
    encode_ms: float


def measure(run: Run, ticks: int = 90) -> Measured:
    """Feed `ticks` ticks of `run` to one student who gets them all."""
    enc = SnapshotEncoder()
    viewer = Viewer()
    sizes, varints, times = [], [], []
    keyframe_b = layout_b = 0
    for i, scene in enumerate(scenes(run, ticks)):
        b1, b2 = viewer.last, viewer.prev
        t0 = time.perf_counter()
        tick = enc.add(scene)
        data = enc.frames_for(viewer)
        times.append(time.perf_counter() - t0)
        if i == 0:
            keyframe_b = len(data) - len(enc._layout_frame)
            layout_b = len(enc._layout_frame)
            continue
        sizes.append(len(data))
        residuals = tick.values - predict(tick.time_us, tick.moving, b1, b2)
        varints.append(varint_size(residuals)[1] + len(data) - _block_size(data))
    return Measured(
        run.name,
        statistics.fmean(sizes),
        keyframe_b,
        layout_b,
        statistics.fmean(varints),
        1e3 * statistics.median(times),
    )


def _block_size(frame: bytes) -> int:
    """Bytes of the residual block in a SNAPSHOT frame (what the two codings differ in)."""
    from airtable.net.codec import _TEXT_DELTA, _TICK, _VIEW, HAS_STATUS, HAS_VIEW

    payload = frame[5:]
    flags = payload[5]
    offset = _TICK.size + (_VIEW.size if flags & HAS_VIEW else 0)
    if flags & HAS_STATUS:
        offset += _TEXT_DELTA.size + int.from_bytes(payload[offset + 4 : offset + 6], "little")
    return len(payload) - offset


def snapshot_sizes(quick: bool = False) -> list[Measured]:
    """The four scenes of the targets, measured."""
    ticks = 30 if quick else 90
    runs = [students_on_demo4, lambda: gas(1000), at_rest, lambda: burst(10000)]
    return [measure(make(), ticks) for make in runs]


def report(results: Sequence[Measured]) -> str:
    lines = [
        "snapshot format 2: mean SNAPSHOT frame per tick (envelope included), 30 ticks/s, one student",
        f"{'scene':<28} {'mean B':>8} {'target':>7} {'varint B':>9} {'keyframe B':>11} {'layout B':>9}"
        f" {'encode ms':>9}",
    ]
    for m in results:
        target = TARGETS_B.get(m.name)
        mark = "" if target is None else ("ok" if m.mean_b <= target else "OVER")
        lines.append(
            f"{m.name:<28} {m.mean_b:8.0f} {target or 0:7d} {m.varint_b:9.0f} {m.keyframe_b:11d} "
            f"{m.layout_b:9d} {m.encode_ms:9.2f}  {mark}"
        )
    return "\n".join(lines)


def main(argv: Sequence[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else list(argv)
    results = snapshot_sizes(quick="--quick" in args)
    print(report(results))
    return 0 if all(m.mean_b <= TARGETS_B.get(m.name, math.inf) for m in results) else 1


if __name__ == "__main__":
    sys.exit(main())
