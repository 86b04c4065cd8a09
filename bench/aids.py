"""What the teacher's aids cost on the wire: mean SNAPSHOT and AIDS bytes per tick for one student.

Runs the real App headless (its collision log, chart and arrow scales),
60 frames a second of simulated time, and hands every other frame's Scene
(30 ticks a second, as the server does) to a SnapshotEncoder, for one
student who gets every tick. `python -m bench.aids` prints:

- demo 4 with 30 students dragging pucks round circles, aids off and with
  a, v and c on;
- Shift+1 (the correction comparison) with a, v and c on;
- a table at rest, aids off and on.
"""

from __future__ import annotations

import math
import statistics
import sys
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from airtable.model.client import Client
from airtable.net.codec import SnapshotEncoder, Viewer
from airtable.net.protocol import AIDS, SNAPSHOT

FRAME_DT_S = 1 / 60


@dataclass(frozen=True)
class AidsCost:
    name: str
    snapshot_b: float  # mean SNAPSHOT frame, envelope included
    aids_b: float  # mean AIDS frame per tick (0 with every aid off)
    ticks: int

    @property
    def total_b(self) -> float:
        return self.snapshot_b + self.aids_b


def frame_sizes(data: bytes) -> dict[int, int]:
    """Bytes by frame type in a run of frames (envelope included)."""
    out: dict[int, int] = {}
    k = 0
    while k < len(data):
        size = int.from_bytes(data[k : k + 4], "big")
        out[data[k + 4]] = out.get(data[k + 4], 0) + 4 + size
        k += 4 + size
    return out


def make_app(demo_key: str, aids_on: str = "", students: int = 0):
    """A headless App on `demo_key`, with the aids of `aids_on` ("avc") on and `students` dragging pucks."""
    from airtable.app.app import App
    from airtable.app.demo_loader import BUILTIN_DIR, discover

    found, _ = discover([BUILTIN_DIR])
    app = App(found, demo_key=demo_key, headless=True)
    app.aids.show_annotations = "a" in aids_on
    app.aids.vectors = 1 if "v" in aids_on else 0
    app.aids.show_chart = "c" in aids_on
    app.aids.trails = "e" in aids_on
    centres = []
    for i in range(students):
        c = Client(name=f"C{i + 1}", color=(40 + 7 * i, 200, 90))
        centre = app.table.pos_m[i % len(app.table.pos_m)].copy()
        c.set_input(app.table, centre, 1)
        app.clients.append(c)
        centres.append(centre)
    return app, centres


def measure(name: str, demo_key: str, aids_on: str, students: int = 0, ticks: int = 90, rest: bool = False) -> AidsCost:
    app, centres = make_app(demo_key, aids_on, students)
    if rest:
        app.table.vel_mps[:] = 0.0
    enc, viewer = SnapshotEncoder(), Viewer()
    snap, extra = [], []
    for frame in range(2 * ticks + 2):
        t = frame * FRAME_DT_S
        for i, c in enumerate(app.clients[1:]):
            angle = 2.0 * t + i
            c.set_input(app.table, centres[i] + 0.5 * np.array([math.cos(angle), math.sin(angle)]), 1)
        app.frame(FRAME_DT_S)
        if frame % 2:
            continue
        scene = app.scene()
        scene.aids = app.shared_aids()
        enc.add(scene)
        sizes = frame_sizes(enc.frames_for(viewer))
        if frame:  # the first tick is a keyframe with the layout
            snap.append(sizes.get(SNAPSHOT, 0))
            extra.append(sizes.get(AIDS, 0))
    return AidsCost(name, statistics.fmean(snap), statistics.fmean(extra), len(snap))


def all_costs(ticks: int = 90) -> list[AidsCost]:
    return [
        measure("demo 4, 30 students, aids off", "4", "", 30, ticks),
        measure("demo 4, 30 students, a v c on", "4", "avc", 30, ticks),
        measure("Shift+1, aids off", "1p", "", 0, ticks),
        measure("Shift+1, a v c on", "1p", "avc", 0, ticks),
        measure("demo 4 at rest, aids off", "4", "", 0, ticks, rest=True),
        measure("demo 4 at rest, a v c on", "4", "avc", 0, ticks, rest=True),
    ]


def report(costs: Sequence[AidsCost]) -> str:
    lines = ["mean bytes per tick for one student (30 ticks/s, envelopes included)"]
    lines.append(f"  {'scene':34} {'SNAPSHOT':>9} {'AIDS':>7} {'total':>7}")
    for c in costs:
        lines.append(f"  {c.name:34} {c.snapshot_b:9.1f} {c.aids_b:7.1f} {c.total_b:7.1f}")
    return "\n".join(lines)


def main(argv: Sequence[str] | None = None) -> int:
    print(report(all_costs()))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
