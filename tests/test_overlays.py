"""Esc and quitting (issue 22, item 2): what is over the table is one stack.

Esc closes what the teacher opened last (a panel in the middle before a side
overlay such as the chart); with nothing open it asks, and a second Esc
quits. Closing the window asks the same way while leaving would drop students
or lose recording. Driven with real pygame events on a real headless App.
"""

from __future__ import annotations

import socket

import pygame
import pytest
from conftest import FRAME_S, escape_again, press, wait_until
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from airtable.app.app import App
from airtable.app.overlays import PANELS, Overlays
from airtable.net import protocol as proto
from airtable.net.server import GameServer

# The key that opens each overlay and the name it has on the stack.
OPENERS = {
    pygame.K_F1: "help",
    pygame.K_l: "notes",
    pygame.K_c: "chart",
    pygame.K_t: "values",
    pygame.K_d: "momenta",
    pygame.K_F2: "roster",
}


def expected_top(opened: list[str]) -> str | None:
    """What a person sees on top: the newest panel in the middle, else the newest side overlay."""
    panels = [n for n in opened if n in PANELS]
    return panels[-1] if panels else (opened[-1] if opened else None)


@given(st.lists(st.tuples(st.sampled_from(sorted(PANELS | {"chart", "values", "momenta"})), st.booleans())))
def test_the_stack_matches_a_list_kept_by_hand(moves):
    stack, opened = Overlays(), []
    for name, show in moves:
        stack.set(name, show)
        if not show and name in opened:
            opened.remove(name)
        elif show and name not in opened:
            opened.append(name)
        assert list(stack) == opened and stack.top() == expected_top(opened)


@pytest.fixture(scope="module")
def server():
    """A real server, so the roster (F2) opens; no student joins it."""
    with GameServer(host="127.0.0.1", port=0) as running:
        yield running


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(order=st.permutations(list(OPENERS)), count=st.integers(1, len(OPENERS)), menu_last=st.booleans())
def test_esc_closes_the_top_overlay_in_any_order_and_then_asks(demos, server, order, count, menu_last):
    app = App(demos, demo_key="3", headless=True, server=server)
    pygame.event.clear()
    keys = list(order[:count])
    for key in keys:
        press(app, key)
    opened = [OPENERS[k] for k in keys]
    if menu_last:  # the menu takes the keys typed while it is open: it comes last
        press(app, pygame.K_TAB)
        opened.append("menu")
    assert list(app.overlays) == opened
    while opened:
        top = expected_top(opened)
        assert app.overlays.top() == top
        press(app, pygame.K_ESCAPE)
        opened.remove(top)
        assert app.running and list(app.overlays) == opened
    assert not app.aids.show_chart and not app.lessons.show_values and not app.room.show_roster
    press(app, pygame.K_ESCAPE)
    assert app.running and app.panels.panel() == "quit"
    escape_again(app)
    assert not app.running


def test_f1_f1_esc_with_the_chart_open_closes_help_then_the_chart_and_quits_nothing(demos):
    """The habit from the issue: one page of help at 1920x1080, so F1, F1 closes it; Esc then
    closes the chart, not the lesson."""
    app = App(demos, demo_key="5", headless=True, window_size_px=(1920, 1080))
    pygame.event.clear()
    for key in (pygame.K_c, pygame.K_F1, pygame.K_F1, pygame.K_ESCAPE):
        press(app, key)
    assert app.running and not app.panels.show_help and not app.aids.show_chart
    press(app, pygame.K_t)
    press(app, pygame.K_ESCAPE)
    assert app.running and not app.lessons.show_values


def test_the_quit_question_lapses_and_any_other_key_stays(demos):
    app = App(demos, demo_key="1", headless=True)
    pygame.event.clear()
    press(app, pygame.K_ESCAPE)
    assert app.panels.panel() == "quit"
    press(app, pygame.K_LSHIFT)  # a modifier alone answers nothing
    assert app.panels.panel() == "quit"
    press(app, pygame.K_SPACE)  # another key: stay, and the key does nothing else
    assert app.running and app.panels.panel() is None and not app.paused
    press(app, pygame.K_ESCAPE)
    app.run(seconds=5.0, frame_dt_s=FRAME_S)  # the question lapses: a late Esc asks again
    assert app.running and app.panels.panel() is None
    press(app, pygame.K_ESCAPE)
    assert app.panels.panel() == "quit"


def close_window(app) -> None:
    pygame.event.post(pygame.event.Event(pygame.QUIT))
    app.frame(FRAME_S)


def test_closing_the_window_quits_at_once_when_nothing_would_be_lost(demos):
    app = App(demos, demo_key="1", headless=True)
    pygame.event.clear()
    close_window(app)
    assert not app.running


def test_closing_the_window_asks_while_recording_is_not_exported(demos, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)  # x exports into ./recordings
    app = App(demos, demo_key="1", headless=True)
    pygame.event.clear()
    for _ in range(180):  # three seconds of the demo, recorded
        app.frame(FRAME_S)
    close_window(app)
    assert app.running and app.panels.panel() == "quit"
    assert any("recording not exported" in line for line in app.quit_would_lose())
    press(app, pygame.K_SPACE)  # stay
    press(app, pygame.K_x)  # export: nothing would be lost now
    assert list((tmp_path / "recordings").glob("*.csv"))
    close_window(app)
    assert not app.running


@pytest.mark.parametrize("how", ["esc", "close"])
def test_quitting_with_a_student_connected_asks_and_says_so(demos, how):
    with GameServer(host="127.0.0.1", port=0) as server:
        app = App(demos, headless=True, server=server)
        student = socket.create_connection(("127.0.0.1", server.port), timeout=5.0)
        try:
            student.sendall(proto.encode_hello("Ann"))

            def joined() -> bool:
                app.frame(FRAME_S)
                return app.student_count() == 1

            wait_until(joined, what="the student to join")
            shown: list[tuple] = []
            draw_question = app.window.draw_question
            app.window.draw_question = lambda title, rows: (shown.append((title, rows)), draw_question(title, rows))
            press(app, pygame.K_ESCAPE) if how == "esc" else close_window(app)
            app.frame(FRAME_S)
            assert app.running and app.panels.panel() == "quit"
            assert shown[-1][0] == "Quit?" and "1 student will be dropped." in shown[-1][1]
            escape_again(app) if how == "esc" else close_window(app)
            assert not app.running
        finally:
            student.close()


@pytest.mark.parametrize("sig", ["SIGTERM", "SIGINT"])
def test_a_signal_ends_the_app_at_once_without_asking(sig, tmp_path):
    """SDL turns SIGTERM and Ctrl+C into the window's QUIT; they must not wait for an answer
    nobody will give (a logout, a script), while the close button still asks."""
    import os
    import signal
    import subprocess
    import sys
    from pathlib import Path

    root = Path(__file__).resolve().parent.parent
    env = {**os.environ, "SDL_VIDEODRIVER": "dummy", "PYTHONPATH": str(root)}
    argv = [sys.executable, "-m", "airtable", "--headless", "--no-server", "--stats", "--demo", "3"]
    app = subprocess.Popen(argv, env=env, cwd=tmp_path, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert "running without a window" in app.stdout.readline()  # the loop is about to run
        app.send_signal(getattr(signal, sig))
        out, err = app.communicate(timeout=20)
    finally:
        if app.poll() is None:
            app.kill()
    assert app.returncode == 0, err
    assert "frames" in out and "Traceback" not in err  # the --stats line: it ended the usual way


def test_mashing_esc_clears_the_screen_and_asks_but_never_quits(demos):
    """The user test: six overlays open, Esc pressed 12 times quickly (one a frame): the sixth
    closes the last, the seventh asks, and the rest of the burst answers nothing."""
    app = App(demos, demo_key="6", headless=True, window_size_px=(1920, 1080))
    pygame.event.clear()
    for key in (pygame.K_c, pygame.K_t, pygame.K_d, pygame.K_l, pygame.K_TAB):
        press(app, key)
    assert len(list(app.overlays)) >= 4
    for _ in range(12):
        press(app, pygame.K_ESCAPE)
    assert app.running and app.panels.panel() == "quit" and list(app.overlays) == ["quit"]
    escape_again(app)  # after a pause, Esc answers
    assert not app.running


def test_esc_pressed_at_a_steady_half_second_beat_never_quits(demos):
    """A user test: five overlays open, Esc pressed six times half a second apart: the fifth asked, the
    sixth quit the lesson (one of the five closed something the teacher did not see go). Closing things
    one by one at any beat up to a second's never answers the question it ends on."""
    app = App(demos, demo_key="1", headless=True, window_size_px=(1280, 720))
    pygame.event.clear()
    for key in (pygame.K_c, pygame.K_d, pygame.K_t, pygame.K_l, pygame.K_F1):
        press(app, key)
    for beat_s in (0.5, 0.9):
        for _ in range(10):
            press(app, pygame.K_ESCAPE)
            for _ in range(round(beat_s / FRAME_S)):
                app.frame(FRAME_S)
            assert app.running
        assert app.panels.panel() == "quit"
    escape_again(app)  # a person who read the question answers it
    assert not app.running


def test_esc_ends_a_prediction_round_before_it_asks_to_quit(demos):
    """A round is under way over the table (F6): Esc ends it, as it closes an overlay (asking first while the
    students guess: Esc again); the next Esc asks to quit."""
    app = App(demos, demo_key="3", headless=True)
    pygame.event.clear()
    press(app, pygame.K_F6)
    assert app.predict.round.state == "open" and app.paused
    press(app, pygame.K_ESCAPE)
    assert app.predict.round.state == "open" and "Esc again ends the prediction round" in app.message
    press(app, pygame.K_ESCAPE)
    assert app.running and app.predict.round.state == "closed" and app.panels.panel() is None
    assert not app.paused  # running, as when the round opened
    press(app, pygame.K_ESCAPE)
    assert app.running and app.panels.panel() == "quit"


def test_the_quit_question_says_how_long_it_waits_for_the_second_esc(demos):
    """A user test: the question vanished after a few seconds, unexplained, while it was being read."""
    from airtable.app.panels import QUIT_CONFIRM_S

    app = App(demos, demo_key="1", headless=True)
    asked = []
    draw_question = app.window.draw_question
    app.window.draw_question = lambda title, lines: asked.append(lines[-1]) or draw_question(title, lines)
    press(app, pygame.K_ESCAPE)
    assert app.panels.panel() == "quit" and f"again within {QUIT_CONFIRM_S:.0f} s to quit" in asked[-1]
    for _ in range(round(2.5 / FRAME_S)):
        app.frame(FRAME_S)
    assert f"again within {QUIT_CONFIRM_S - 2:.0f} s to quit" in asked[-1]
    for _ in range(round(2.0 / FRAME_S)):
        app.frame(FRAME_S)
    assert app.panels.panel() is None and app.running  # it said so: closed, the lesson goes on
