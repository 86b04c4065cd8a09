"""Nothing the teacher does with the view ends a student's session (issue 22, item 1).

A real teacher's App with a real server; students join over real sockets, once
through the client's network code in this process and once as a real
`airtable-client --headless` process. The teacher zooms far out, pans far away
and zooms far in with real pygame events: the students stay connected and see
the view the teacher shows.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pygame
from conftest import FRAME_S, frames_until, post_key, press, teacher_and_student, wait_until

from airtable.app.window import WALL_COLOR
from airtable.net.player import PlayerState
from airtable.student.window import PlayerApp

ROOT = Path(__file__).resolve().parent.parent
STARTUP_S = 60.0  # the bound on a client process's start (a bound, not a delay)


def wheel(teacher, clicks: int) -> None:
    """`clicks` wheel clicks (negative: out) over the window's centre, one frame each."""
    w, h = teacher.env.size_px
    pygame.event.post(pygame.event.Event(pygame.MOUSEMOTION, pos=(w / 2, h / 2), rel=(0, 0), buttons=(0, 0, 0)))
    for _ in range(abs(clicks)):
        pygame.event.post(pygame.event.Event(pygame.MOUSEWHEEL, x=0, y=1 if clicks > 0 else -1, flipped=False))
        teacher.frame(FRAME_S)


def ctrl_drag(teacher, drags: int, by_px: tuple[int, int]) -> None:
    """Ctrl + mouse drags, as a teacher pans the view: each moves by `by_px`."""
    w, h = teacher.env.size_px
    post_key(pygame.K_LCTRL)
    for _ in range(drags):
        start = (w / 2, h / 2)
        pygame.event.post(pygame.event.Event(pygame.MOUSEBUTTONDOWN, pos=start, button=1))
        end = (start[0] + by_px[0], start[1] + by_px[1])
        pygame.event.post(pygame.event.Event(pygame.MOUSEMOTION, pos=end, rel=by_px, buttons=(1, 0, 0)))
        pygame.event.post(pygame.event.Event(pygame.MOUSEBUTTONUP, pos=end, button=1))
        teacher.frame(FRAME_S)
    post_key(pygame.K_LCTRL, down=False)
    teacher.frame(FRAME_S)


def student_sees(teacher, net) -> bool:
    """The student is connected and its newest scene carries the teacher's view now."""
    scene = net.latest()
    return (
        net.state == PlayerState.CONNECTED
        and scene is not None
        and np.isclose(scene.zoom, teacher.env.zoom)
        and np.allclose(scene.origin_m, teacher.env.origin_m)
    )


def wall_pixels(student) -> int:
    """How many pixels of the student's next frame have the walls' colour."""
    student._frame()
    pixels = pygame.surfarray.pixels3d(student.window.surface)
    try:
        return int(np.all(pixels == WALL_COLOR, axis=-1).sum())
    finally:
        del pixels


def student_draws(student, condition) -> None:
    """Draw the student's frames until the count of wall pixels meets `condition` (the window
    shows the newest view after its short playout delay)."""
    wait_until(lambda: condition(wall_pixels(student)), what="the student's window to show the view")


def test_zooming_and_panning_far_keeps_the_student_connected(demos):
    with teacher_and_student(demos, "1") as (teacher, net):
        student = PlayerApp(net, headless=True)
        student._open_window()
        frames_until(teacher, lambda: teacher.student_count() == 1, "the student to join")
        wheel(teacher, -40)  # far out: the table is a small box
        frames_until(teacher, lambda: student_sees(teacher, net), "the zoomed-out view to reach the student")
        student_draws(student, lambda walls: walls > 0)
        ctrl_drag(teacher, 12, (600, 400))  # far away from the table
        assert np.hypot(*teacher.env.origin_m) > 1000, teacher.env.origin_m
        frames_until(teacher, lambda: student_sees(teacher, net), "the panned view to reach the student")
        student_draws(student, lambda walls: walls == 0)  # nothing of the table there, as on the projector
        assert "q brings it back" in teacher.hud_lines()[-1]
        assert student._view_hint(net.latest())  # and each window says so
        wheel(teacher, 200)  # as far in as the zoom goes
        frames_until(teacher, lambda: student_sees(teacher, net), "the zoomed-in view to reach the student")
        wall_pixels(student)
        press(teacher, pygame.K_q)  # the whole table again
        frames_until(teacher, lambda: student_sees(teacher, net), "the reset view to reach the student")
        student_draws(student, lambda walls: walls > 1000)
        assert net.error is None and net.reconnects == 0 and net.problems == 0
        assert student.draw_error is None
        assert teacher.student_count() == 1


def bo_plays(teacher) -> bool:
    return any(name.endswith(" Bo") for name in teacher.server.player_names())


def test_a_real_client_outlives_any_view(demos, tmp_path):
    shot = tmp_path / "student.png"
    with teacher_and_student(demos, "1") as (teacher, _):
        env = {**os.environ, "SDL_VIDEODRIVER": "dummy", "PYTHONPATH": str(ROOT)}
        client = subprocess.Popen(
            [sys.executable, "-m", "airtable.client_cli", f"127.0.0.1:{teacher.server.port}", "--headless"]
            + ["--name", "Bo", "--screenshot", str(shot)],
            env=env,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
        )
        try:
            # A new Python process with pygame and numpy takes seconds to start on a busy machine.
            deadline = time.monotonic() + STARTUP_S
            while not bo_plays(teacher) and client.poll() is None and time.monotonic() < deadline:
                teacher.frame(FRAME_S)
                time.sleep(FRAME_S)
            assert client.poll() is None and bo_plays(teacher), client.communicate()
            wheel(teacher, -40)
            ctrl_drag(teacher, 12, (-700, 300))
            wheel(teacher, 200)
            # A second of frames at the real pace: a client that gave up would have gone by now.
            for _ in range(60):
                teacher.frame(FRAME_S)
                time.sleep(FRAME_S)
            assert client.poll() is None, client.communicate()
            assert bo_plays(teacher)  # (Ann, who sends nothing, may be dropped meanwhile as any silent client)
        finally:
            if client.poll() is None:
                client.send_signal(signal.SIGINT)  # as Ctrl+C: the client saves its screenshot and leaves
            out, err = client.communicate(timeout=20)
        assert client.returncode == 0, err.decode()
        assert b"Traceback" not in err, err.decode()
        assert b"left out" not in err, err.decode()
