"""Rewind in the app, driven by real key events: back and forth through the history, and running on from the past."""

from __future__ import annotations

import socket

import numpy as np
import pygame
import pytest
from conftest import FRAME_S, press, wait_until

from airtable.app.app import App
from airtable.app.panel_view import ACCENT
from airtable.net import protocol as proto
from airtable.net.codec import UNITS_PER_M, SnapshotDecoder
from airtable.net.server import GameServer
from airtable.physics.state import same_bits

SHIFT = pygame.KMOD_LSHIFT


@pytest.fixture
def app(demos):
    a = App(demos, demo_key="7", headless=True)  # Newton's cradle: the cue is thrown at 1 s
    pygame.event.clear()
    yield a
    pygame.event.clear()


def run_frames(app: App, n: int) -> list[tuple[np.ndarray, np.ndarray]]:
    out = []
    for _ in range(n):
        app.frame(FRAME_S)
        out.append((app.table.pos_m.copy(), app.table.vel_mps.copy()))
    return out


@pytest.mark.parametrize("cr", [1.0, 0.6, 0.0])
def test_rewind_then_run_on_replays_bit_for_bit(app, cr):
    app.table.cr_puck = app.table.cr_wall = cr
    run_frames(app, 60)  # to just before the throw
    future = run_frames(app, 60)  # the throw and the collisions
    end_t = app.table.time_s
    press(app, pygame.K_SPACE)
    assert app.paused
    press(app, pygame.K_COMMA, mod=SHIFT)  # a second back
    assert app.table.time_s == pytest.approx(end_t - 1.0)
    assert "rewound 1.00 s" in app.status_line()
    press(app, pygame.K_SPACE)  # run on from there: the same throw, the same collisions
    assert app.rewind.history.timeline().newest_s == pytest.approx(end_t - 1.0 + FRAME_S)
    again = run_frames(app, 59)
    for (p1, v1), (p2, v2) in zip(future[1:], again, strict=True):
        assert same_bits(p1, p2) and same_bits(v1, v2)
    assert app.table.time_s == end_t and app.table.collision_count > 0


def test_comma_and_period_step_through_the_history_while_paused(app):
    frames = run_frames(app, 90)
    press(app, pygame.K_SPACE)
    newest = len(app.rewind.history)
    for k in range(1, 11):
        press(app, pygame.K_COMMA)
        assert app.rewind.history.in_past and same_bits(app.table.pos_m, frames[-1 - k][0])
    assert len(app.rewind.history) == newest  # looking back keeps every moment
    for k in range(9, -1, -1):
        press(app, pygame.K_PERIOD)
        assert same_bits(app.table.pos_m, frames[-1 - k][0]) and same_bits(app.table.vel_mps, frames[-1 - k][1])
    assert not app.rewind.history.in_past
    t = app.table.time_s
    press(app, pygame.K_PERIOD)  # at the newest moment: one new step, as before
    assert app.table.time_s == pytest.approx(t + app.dt_s)
    assert len(app.rewind.history) == newest + 1 and not app.rewind.history.in_past
    press(app, pygame.K_PERIOD, mod=SHIFT)  # nothing newer to jump to: it says so
    assert "newest moment" in app.message


def test_comma_while_running_pauses_there(app):
    run_frames(app, 30)
    press(app, pygame.K_COMMA)
    assert app.paused and app.rewind.history.in_past


def test_running_on_drops_the_future_from_the_history_the_recording_and_the_chart(app):
    run_frames(app, 120)
    press(app, pygame.K_SPACE)
    kept = len(app.rewind.history)
    for _ in range(20):
        press(app, pygame.K_COMMA)
    t = app.table.time_s
    assert app.lessons.recorder.newest_s > t  # still there while only looking
    press(app, pygame.K_SPACE, frames=0)
    app.frame(FRAME_S)  # the frame that runs on
    assert len(app.rewind.history) == kept - 20 + 1 and not app.rewind.history.in_past
    assert "20 later frames dropped" in app.message
    rec = app.lessons.recorder
    rec.flush()
    with open(rec.energy_path, encoding="utf-8") as f:
        times = [float(line.split(",")[0]) for line in f.readlines()[1:]]
    assert times[-1] == round(app.table.time_s, 6) and np.all(np.diff(times) > 0)  # one story, no step twice
    assert len(times) == round(app.table.time_s / app.dt_s) + 1
    chart_t = app.aids.chart.series(100.0)["time_s"]
    assert chart_t[-1] == app.table.time_s and np.all(np.diff(chart_t) > 0)


def test_the_timeline_bar_shows_while_paused(app):
    run_frames(app, 60)
    bar = app.rewind.painter.bar_rect()
    surface = app.window.surface

    def accent_pixels() -> int:
        area = pygame.surfarray.array3d(surface)[bar.left : bar.right, bar.top - bar.height : bar.bottom + bar.height]
        return int(np.count_nonzero(np.all(area == ACCENT, axis=2)))

    assert accent_pixels() == 0  # running: no bar
    press(app, pygame.K_SPACE)
    at_newest = accent_pixels()
    assert at_newest > 0
    press(app, pygame.K_COMMA, mod=SHIFT)
    columns = np.flatnonzero(
        np.any(np.all(pygame.surfarray.array3d(surface)[:, bar.centery] == ACCENT, axis=1)[None, :], axis=0)
    )
    assert len(columns) and columns.mean() < bar.right - 0.2 * bar.width  # the mark moved back along the bar


def test_the_oldest_moment_says_so(app):
    run_frames(app, 5)
    press(app, pygame.K_SPACE)
    for _ in range(10):
        press(app, pygame.K_COMMA)
    assert app.table.time_s == 0.0 and "oldest moment" in app.message


def test_students_see_the_moment_on_view(demos):
    with GameServer(host="127.0.0.1", port=0) as server:
        app = App(demos, demo_key="7", headless=True, server=server)
        student = socket.create_connection(("127.0.0.1", server.port), timeout=5.0)
        reader = proto.FrameReader(proto.MAX_SERVER_FRAME, sender="the server")
        student.settimeout(0.05)
        try:
            student.sendall(proto.encode_hello("Ann"))
            wait_until(lambda: (app.frame(FRAME_S), app.student_count() == 1)[1], what="the student to join")
            run_frames(app, 90)
            press(app, pygame.K_SPACE)
            press(app, pygame.K_COMMA, mod=SHIFT)
            shown = app.table.pos_m.copy()
            seen = {}
            decoder = SnapshotDecoder()

            def snapshot_of_the_past() -> bool:
                app.frame(FRAME_S)
                try:
                    data = student.recv(1 << 20)
                except TimeoutError:
                    return False
                for kind, payload in reader.feed(data):
                    if kind == proto.LAYOUT:
                        decoder.feed_layout(payload)
                    elif kind == proto.SNAPSHOT:
                        seen["scene"] = decoder.feed_tick(payload).scene
                scene = seen.get("scene")
                return scene is not None and abs(scene.time_s - app.table.time_s) < 1e-6

            wait_until(snapshot_of_the_past, what="a snapshot of the rewound table")
            # Snapshots carry positions in whole quarter-millimetres.
            assert np.abs(seen["scene"].pos_m - shown).max() <= 0.5 / UNITS_PER_M
            assert "rewound 1.00 s" in seen["scene"].status
        finally:
            student.close()


def test_a_demo_started_while_paused_starts_paused_at_its_beginning_and_space_runs_it(app):
    # docs/teacher.md: the teacher can talk the class through the set-up first.
    run_frames(app, 30)
    press(app, pygame.K_SPACE)
    press(app, pygame.K_2)
    assert app.paused and app.table.time_s == 0.0
    run_frames(app, 5)
    assert app.table.time_s == 0.0
    press(app, pygame.K_SPACE)
    run_frames(app, 5)
    assert not app.paused and app.table.time_s > 0.0
