"""Playout buffer: even steps from jittered arrivals, adaptive delay, snapping on restarts."""

from __future__ import annotations

import random
import socket
import threading

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from airtable.model.scene import CursorView, Scene
from airtable.net import playout
from airtable.net import protocol as proto
from airtable.net.codec import LAYOUT, SnapshotEncoder, Viewer
from airtable.net.playout import PlayoutBuffer, SnapshotFeed

SPEED_MPS = 1.0
HZ = 30
FPS = 60
CLIENT_CLOCK_S = 100.0  # the player's clock has another zero than the server's
LATENCY_S = 0.05


def puck_scene(server_s: float, x0: float = 1.0, n: int = 1) -> Scene:
    pos = np.column_stack([x0 + SPEED_MPS * server_s + np.zeros(n), np.full(n, 2.0)])
    cursor = CursorView("C1", (255, 0, 0), (x0 + SPEED_MPS * server_s, 3.0))
    return Scene(10.0, 8.7556, pos, np.full(n, 0.1), np.zeros((n, 3), np.uint8), cursors=(cursor,), time_s=server_s)


def arrivals(jitter_s: float, count: int, seed: int) -> list[tuple[float, float]]:
    """(arrival on the player's clock, server time) of snapshots sent at 30 Hz; in order, as TCP delivers."""
    rng = random.Random(seed)
    out, last = [], 0.0
    for k in range(count):
        server_s = k / HZ
        last = max(last, CLIENT_CLOCK_S + server_s + LATENCY_S + rng.uniform(-jitter_s, jitter_s))
        out.append((last, server_s))
    return out


def play(schedule, frames: int, scene_for=puck_scene, buffer: PlayoutBuffer | None = None) -> list[Scene | None]:
    """Draw `frames` frames at 60 fps, pushing each snapshot once its arrival time has come."""
    buffer = buffer or PlayoutBuffer()
    drawn, i = [], 0
    for j in range(frames):
        now = CLIENT_CLOCK_S + 0.3 + j / FPS
        while i < len(schedule) and schedule[i][0] <= now:
            arrival, server_s = schedule[i]
            buffer.push(server_s, scene_for(server_s), 0, arrival)
            i += 1
        drawn.append(buffer.sample(now))
    return drawn


def frame_steps_mm(drawn: list[Scene], skip: int = 120) -> np.ndarray:
    x = np.array([s.pos_m[0, 0] for s in drawn])
    return 1e3 * np.diff(x)[skip:]


def test_nothing_to_draw_before_the_first_snapshot():
    assert PlayoutBuffer().sample(1.0) is None


def test_a_puck_at_constant_velocity_moves_evenly_despite_20_ms_of_jitter():
    expected_mm = 1e3 * SPEED_MPS / FPS  # 16.7 mm a frame
    for seed in range(3):
        steps = frame_steps_mm(play(arrivals(0.02, 320, seed), 600))
        assert abs(steps.mean() - expected_mm) < 0.05
        assert steps.std() < 0.1  # measured 0.02-0.03 mm
        assert np.abs(steps - expected_mm).max() < 0.5  # measured at most 0.13 mm


def test_drawing_each_snapshot_as_it_arrives_would_jerk():
    # The baseline the buffer fixes: the newest arrived snapshot at each frame.
    schedule = arrivals(0.02, 320, 0)
    x, i = [], 0
    for j in range(600):
        now = CLIENT_CLOCK_S + 0.3 + j / FPS
        while i < len(schedule) and schedule[i][0] <= now:
            i += 1
        x.append(1.0 + SPEED_MPS * schedule[i - 1][1])
    steps = 1e3 * np.diff(x)[120:]
    assert steps.std() > 10.0 and steps.min() == 0.0


def test_the_delay_is_one_and_a_half_intervals_plus_the_jitter():
    calm, jittery = PlayoutBuffer(), PlayoutBuffer()
    play(arrivals(0.0, 100, 0), 180, buffer=calm)
    play(arrivals(0.02, 100, 0), 180, buffer=jittery)
    assert abs(calm.delay_s - 0.050) < 0.002
    assert calm.jitter_s < 0.001
    assert 0.025 < jittery.jitter_s < 0.040  # 90th percentile of 0-40 ms
    assert abs(jittery.delay_s - (0.050 + jittery.jitter_s)) < 0.002


def test_other_cursors_glide_too():
    drawn = play(arrivals(0.02, 200, 1), 300)
    x = np.array([s.cursors[0].cursor_m[0] for s in drawn])
    steps = 1e3 * np.diff(x)[120:]
    assert steps.std() < 0.1


def test_a_restart_snaps_instead_of_smearing():
    buffer = PlayoutBuffer()
    schedule = arrivals(0.0, 60, 0)
    play(schedule[:30], 80, buffer=buffer)
    # The teacher restarts: epoch 1, the puck back at x = 1 with the clock running on.
    arrival, server_s = schedule[30]
    buffer.push(server_s, puck_scene(0.0), 1, arrival)
    first = buffer.sample(arrival + 0.001)
    assert first.pos_m[0, 0] == 1.0
    assert buffer.snaps == 1


def test_a_new_puck_count_snaps_too():
    buffer = PlayoutBuffer()
    schedule = arrivals(0.0, 60, 0)
    play(schedule[:30], 80, buffer=buffer)
    arrival, server_s = schedule[30]
    buffer.push(server_s, puck_scene(server_s, x0=5.0, n=3), 0, arrival)
    assert np.array_equal(buffer.sample(arrival + 0.001).pos_m[:, 0], np.full(3, 5.0 + server_s))


def _serve(listener: socket.socket, count: int) -> None:
    """A scripted server: sends `count` format-2 ticks of the moving puck, clocked at 30 Hz."""
    conn, _ = listener.accept()
    with conn:
        enc, viewer = SnapshotEncoder(), Viewer()
        for k in range(count):
            enc.add(puck_scene(k / HZ), clock_s=k / HZ)
            conn.sendall(enc.frames_for(viewer))
        conn.sendall(proto.encode_bye())


def _receive_all(address) -> list[list[tuple[int, bytes]]]:
    """Every frame until BYE, grouped: each SNAPSHOT with the LAYOUT frames before it."""
    groups, group = [], []
    with socket.create_connection(address, timeout=10) as sock:
        reader = proto.FrameReader(proto.MAX_SERVER_FRAME, {proto.SNAPSHOT, LAYOUT, proto.BYE}, "the server")
        while True:
            data = sock.recv(65536)
            assert data, "the scripted server hung up early"
            for kind, payload in reader.feed(data):
                if kind == proto.BYE:
                    return groups
                group.append((kind, payload))
                if kind == proto.SNAPSHOT:
                    groups.append(group)
                    group = []


def test_jittered_snapshots_through_a_real_socket_play_evenly():
    """Format 2 over TCP on 127.0.0.1 into a SnapshotFeed; arrival times are scripted
    (jittered by +-20 ms), so the result does not depend on this machine's timing."""
    count = 200
    with socket.create_server(("127.0.0.1", 0)) as listener:
        listener.settimeout(10)
        server = threading.Thread(target=_serve, args=(listener, count), daemon=True)
        server.start()
        groups = _receive_all(listener.getsockname())
        server.join(timeout=10)
    assert len(groups) == count
    schedule = arrivals(0.02, count, 7)
    feed, drawn, i = SnapshotFeed(), [], 0
    for j in range(360):
        now = CLIENT_CLOCK_S + 0.3 + j / FPS
        while i < count and schedule[i][0] <= now:
            for kind, payload in groups[i]:
                feed.feed(kind, payload, schedule[i][0])
            i += 1
        drawn.append(feed.scene(now))
    steps = frame_steps_mm(drawn)
    assert abs(steps.mean() - 1e3 * SPEED_MPS / FPS) < 0.1
    assert steps.std() < 0.2  # quantised to 0.25 mm on the wire, still even
    assert feed.newest.pos_m[0, 0] == pytest.approx(1.0 + (i - 1) / HZ, abs=1e-3)  # the last one fed


@given(st.lists(st.floats(-10, 10), min_size=1, max_size=80), st.floats(0, 1))
def test_quantile_is_numpys_default(values, q):
    assert playout.quantile(sorted(values), q) == pytest.approx(np.percentile(values, 100 * q), abs=1e-12)
