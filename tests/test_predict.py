"""Predict, then reveal: the round's maths against hand-worked numbers, PREDICT and ROUND on
real sockets with three scripted students, strict refusal of bad guesses, and the local mouse."""

from __future__ import annotations

import json
import math
import time
from pathlib import Path

import numpy as np
import pygame
import pytest
from conftest import FRAME_S, WAIT_S, frames_until, press, teacher_and_student, wait_until
from test_server import RawClient, frame

from airtable.app.app import App
from airtable.app.demo_loader import BUILTIN_DIR, DemoShelf
from airtable.app.environment import DEFAULT_SIZE_PX, Environment
from airtable.app.predict import FROZEN_NOTICE, StudentGuesses, angle_deg, puck_summary, summarize
from airtable.app.window import GameWindow
from airtable.net import protocol as proto
from airtable.net.player import NetPlayer, PlayerState
from airtable.net.predictions import (
    MAX_PREDICT_SPEED_MPS,
    Arrow,
    RoundInfo,
    encode_predict,
    encode_round,
    parse_predict,
    parse_round,
)
from airtable.net.server import GameServer
from airtable.student.window import PlayerApp

# Puck 1 at rest at (5, 4); puck 0 comes at it head-on at 1 m/s. Equal masses, restitution 1:
# afterwards puck 0 stops and puck 1 leaves at (1, 0) m/s.
HEAD_ON = (
    "KEY = '5'\nTITLE = 'Head-on'\nNOTES = ''\n\n"
    "def build(table, variation=0):\n"
    "    table.add_puck((3.0, 4.0), 0.25, vel_mps=(1.0, 0.0))\n"
    "    table.add_puck((5.0, 4.0), 0.25)\n"
)
# Three guesses for puck 1: 0, 10 and 30 degrees off (1, 0), at speeds 1.0, 1.1 and 1.5 m/s.
GUESSES = [(1.0, 0.0), (1.1, 10.0), (1.5, 30.0)]
# By hand: angles 0, 10, 30 -> median 10, one within 5 deg; speeds 1.0 and 1.1 within 20 % of 1.0, 1.5 not.
EXPECTED = "puck 2: median 10 deg off; 1 of 3 within 5 deg; speeds within 20 %: 2 of 3"


def polar(speed: float, deg: float) -> tuple[float, float]:
    return (speed * math.cos(math.radians(deg)), speed * math.sin(math.radians(deg)))


# ---------------------------------------------------------------- maths


def test_angles_and_the_summary_match_the_numbers_worked_by_hand():
    assert angle_deg((1, 0), (0, 2)) == pytest.approx(90.0)
    assert angle_deg((1, 1), (-1, -1)) == pytest.approx(180.0)
    guesses = [polar(s, d) for s, d in GUESSES]
    assert puck_summary(1, (1.0, 0.0), guesses) == EXPECTED
    # Only pucks someone predicted get a line; a puck that stops is judged by speed alone.
    arrows = [Arrow(1, g, (1, 2, 3)) for g in guesses] + [Arrow(0, (0.01, 0.0), (1, 2, 3))]
    assert summarize([(0.0, 0.0), (1.0, 0.0)], arrows) == [
        "puck 1: comes to rest; 1 of 1 predicted under 0.05 m/s",
        EXPECTED,
    ]


def test_round_messages_survive_the_wire_and_stay_bounded():
    info = RoundInfo(
        4, "revealed", 2, 3, 3, tuple(Arrow(1, (0.5, 0.25), (255, 0, 0), "C1 Ann") for _ in range(10_000)),
        ((0.0, 0.0), (1.0, 0.0)), ("x" * 500,) * 100, ((3.0, 4.0), (5.0, 4.0)),
    )  # fmt: skip
    data = encode_round(info)
    assert len(data) < 300_000  # 4000 arrows at most, 32 summary lines of 120 characters
    (frame_type, payload), *_ = proto.FrameReader(proto.MAX_SERVER_FRAME, sender="the server").feed(data)
    got = parse_round(payload)
    assert frame_type == proto.ROUND == 9
    assert len(got.arrows) == 4000 and got.arrows[0] == Arrow(1, (0.5, 0.25), (255, 0, 0), "C1 Ann")
    assert len(got.summary) == 32 and len(got.summary[0]) == 120
    assert got.truth == ((0.0, 0.0), (1.0, 0.0)) and got.from_m == ((3.0, 4.0), (5.0, 4.0))
    bad = json.loads(payload)
    bad["truth"] = [[1e300, 0]]
    with pytest.raises(proto.ProtocolError, match="too fast"):
        parse_round(json.dumps(bad).encode())


BAD_PREDICTS = {
    "not JSON": (b"{round: 1}", "not valid JSON"),
    "a missing field": (b'{"round": 1, "puck": 0}', 'missing the field "vel_mps"'),
    "an unknown field": (b'{"round": 1, "puck": 0, "vel_mps": [1, 0], "mass": 9}', "unknown field"),
    "a text puck": (b'{"round": 1, "puck": "0", "vel_mps": [1, 0]}', "PREDICT puck must be a whole number"),
    "a fractional round": (b'{"round": 1.5, "puck": 0, "vel_mps": [1, 0]}', "PREDICT round must be a whole number"),
    "NaN": (b'{"round": 1, "puck": 0, "vel_mps": [NaN, 0]}', "not a finite number"),
    "1e400": (b'{"round": 1, "puck": 0, "vel_mps": [1e400, 0]}', "must be a finite number"),
    "a single number": (b'{"round": 1, "puck": 0, "vel_mps": 3}', "pair [vx, vy]"),
    "too fast": (b'{"round": 1, "puck": 0, "vel_mps": [100, 1]}', "faster than 100 m/s"),
    "a negative puck": (b'{"round": 1, "puck": -1, "vel_mps": [1, 0]}', "puck -1 is not on the table"),
    "a puck not there": (b'{"round": 1, "puck": 2, "vel_mps": [1, 0]}', "puck 2 is not on the table"),
    "a round never opened": (b'{"round": 7, "puck": 0, "vel_mps": [1, 0]}', "round 7 was never opened"),
}


@pytest.fixture
def server():
    with GameServer(host="127.0.0.1", port=0) as s:
        yield s


@pytest.mark.parametrize("case", BAD_PREDICTS, ids=list(BAD_PREDICTS))
def test_a_bad_predict_is_refused_with_an_error_naming_the_problem(server, case):
    payload, hint = BAD_PREDICTS[case]
    server.predictions.open(1, 2)
    bad = RawClient(server.port)
    try:
        bad.hello("Bea")
        bad.send(frame(proto.PREDICT, payload))
        sentence = bad.expect_error()
    finally:
        bad.close()
    assert hint in sentence, sentence
    assert server.predictions.count() == 0


def test_a_stale_predict_is_ignored_and_a_good_one_kept_latest_first(server):
    server.predictions.open(1, 2)
    server.predictions.open(2, 2)  # round 1 is over: a guess for it crossed the reveal
    student = RawClient(server.port)
    try:
        student.hello("Cy")
        student.send(encode_predict(1, 0, (1.0, 0.0)))
        student.send(encode_predict(2, 1, (0.5, 0.0)))
        student.send(encode_predict(2, 1, (0.0, 0.75)))  # changed before the reveal: latest wins
        student.send(encode_predict(2, 0, (-0.25, 0.0)))
        wait_until(lambda: len(server.predictions.arrows()) == 2, what="two guesses kept")
        assert [(a.puck, a.vel_mps) for a in server.predictions.arrows()] == [(0, (-0.25, 0.0)), (1, (0.0, 0.75))]
        assert server.predictions.count() == 1 and server.player_count == 1  # still at the table
    finally:
        student.close()
    assert len(encode_predict(2, 1, (-MAX_PREDICT_SPEED_MPS, 1e-300))) < 120  # far under the 1 KiB cap
    with pytest.raises(proto.ProtocolError):
        parse_predict(b'{"round": 1, "puck": 0, "vel_mps": [0, 0], "round": 2}', 2)


# ---------------------------------------------------------------- a whole round


def head_on_app(tmp_path: Path, server=None) -> App:
    (tmp_path / "head_on.py").write_text(HEAD_ON)
    app = App(DemoShelf([BUILTIN_DIR, tmp_path]), demo_key="5", headless=True, server=server)
    pygame.event.clear()
    return app


def next_round(student: RawClient, until, app=None) -> RoundInfo:
    """The next ROUND this student reads for which `until(info)` holds.

    With `app`, its frames run while the student waits: the app publishes a round's news
    in the frame after the news arrives (the projector's count is read live)."""
    deadline = time.monotonic() + WAIT_S
    while True:
        try:
            got = student.next_frame(timeout_s=0.02 if app is not None else WAIT_S)
        except TimeoutError:
            if app is None or time.monotonic() > deadline:
                raise
            app.frame(FRAME_S)
            continue
        assert got is not None, "connection closed while waiting for a ROUND"
        if got[0] == proto.ROUND and until(info := parse_round(got[1])):
            return info


def test_three_students_predict_over_real_sockets_then_the_reveal_sums_them_up(server, tmp_path):
    app = head_on_app(tmp_path, server)
    students = [RawClient(server.port) for _ in range(3)]
    try:
        for name, s in zip(("Ann", "Ben", "Cat"), students):
            s.hello(name)
        frames_until(app, lambda: app.student_count() == 3, "three students at the table")
        press(app, pygame.K_F6)
        assert app.predict.round.state == "open" and app.paused
        for s in students:
            info = next_round(s, lambda i: i.state == "open")
            assert (info.pucks, info.players, info.arrows) == (2, 3, ())
            assert info.from_m == tuple(map(tuple, app.table.pos_m.round(5)))  # where the pucks froze
        for s, (speed, deg) in zip(students, GUESSES):
            s.send(encode_predict(info.round_id, 1, polar(speed, deg)))
        frames_until(app, lambda: "PREDICT: 3 of 3 predicted" in app.status_line(), "3 of 3 on the projector")
        assert next_round(students[0], lambda i: i.predicted == 3, app).arrows == ()  # a count, no arrows yet
        t0 = app.table.time_s
        frames_until(app, lambda: app.table.time_s == t0, "the table stays frozen while the round is open")

        press(app, pygame.K_F6)  # reveal: the table plays until the collision is over
        assert not app.paused and len(app.predict.round.arrows) == 3
        frames_until(app, lambda: app.predict.round.settled, "the collision to be over", max_frames=600)
        assert app.paused and app.table.collision_count >= 1
        assert app.predict.round.truth[1] == pytest.approx((1.0, 0.0), abs=1e-6)
        assert app.predict.round.summary == (EXPECTED,)
        for s in students:
            info = next_round(s, lambda i: i.state == "revealed" and bool(i.truth))
            assert info.summary == (EXPECTED,) and len(info.arrows) == 3
            assert {a.color for a in info.arrows} == {(255, 52, 179), (210, 180, 140), (0, 255, 255)}
            assert {a.label for a in info.arrows} == {""}  # names only when the teacher shows them
        press(app, pygame.K_F6, mod=pygame.KMOD_SHIFT)
        info = next_round(students[1], lambda i: bool(i.arrows and i.arrows[0].label))
        assert sorted(a.label for a in info.arrows) == ["C1 Ann", "C2 Ben", "C3 Cat"]

        press(app, pygame.K_F6)  # closes the round; the table ran when it opened, so it runs on
        assert next_round(students[2], lambda i: i.state == "closed").arrows == ()
        assert not app.predict.round.active and not app.paused
    finally:
        for s in students:
            s.close()


def open_round_for(app: App, net: NetPlayer) -> None:
    """Join `net` to the app's table, then open a round (F6) and wait until the student has the ROUND."""
    net.connect()
    frames_until(app, lambda: app.student_count() == 1 and net.latest() is not None, "the student to join")
    press(app, pygame.K_F6)
    wait_until(lambda: net.round is not None and net.round.state == "open", what="the ROUND at the student")


def test_a_player_window_drags_an_arrow_and_sends_predict(server, tmp_path):
    app = head_on_app(tmp_path, server)
    net = NetPlayer("127.0.0.1", server.port, name="Dee")
    try:
        open_round_for(app, net)
        guesses = StudentGuesses()
        scene = net.latest()
        assert not guesses.press(net.round, (8.0, 1.0), scene.radius_m)  # not on a puck: the cursor as usual
        assert guesses.press(net.round, (5.1, 4.0), scene.radius_m)  # on puck 1
        assert guesses.drag(net.round, (5.0, 6.0)) == (1, pytest.approx((0.0, 2.0)))
        assert net.send_predict(1, guesses.guesses[1])
        frames_until(app, lambda: "1 of 1 predicted" in app.status_line(), "the student's guess counted")
        assert [a.vel_mps for a in server.predictions.arrows()] == [pytest.approx((0.0, 2.0))]
        assert net.state == PlayerState.CONNECTED
    finally:
        net.close()


def test_a_student_window_turns_a_mouse_drag_on_a_puck_into_predict(server, tmp_path):
    app = head_on_app(tmp_path, server)
    net = NetPlayer("127.0.0.1", server.port, name="Eve")
    try:
        open_round_for(app, net)
        window = PlayerApp(net, headless=True)
        # The student's view as it opens: the table fitted above the window's status bar.
        env = GameWindow(Environment(DEFAULT_SIZE_PX, width_m=app.table.width_m), headless=True).env
        puck = tuple(float(v) for v in env.to_screen(np.array(net.round.from_m[1])))
        tip = tuple(float(v) for v in env.to_screen(np.array(net.round.from_m[1]) + np.array([0.0, 1.5])))
        pygame.event.clear()
        post_mouse(pygame.MOUSEBUTTONDOWN, puck)
        post_mouse(pygame.MOUSEMOTION, tip)
        post_mouse(pygame.MOUSEBUTTONUP, tip)
        seen: list = []  # what the server holds, read before the window closes (a leaver's guesses go)
        window.run(seconds=WAIT_S, until=lambda: seen.extend(server.predictions.arrows()) or seen)
        (arrow,) = seen
        assert (arrow.puck, arrow.label) == (1, "C1 Eve")
        assert arrow.vel_mps == pytest.approx((0.0, 1.5), abs=2 * app.table.width_m / DEFAULT_SIZE_PX[0])
        assert window.button == 0  # the drag never pressed the cursor's button
    finally:
        net.close()


def post_mouse(kind: int, pos, button: int = 1) -> None:
    if kind == pygame.MOUSEMOTION:
        pygame.event.post(pygame.event.Event(kind, pos=pos, rel=(0, 0), buttons=(1, 0, 0)))
    else:
        pygame.event.post(pygame.event.Event(kind, pos=pos, button=button))


def test_the_local_mouse_predicts_on_the_teachers_window(tmp_path):
    app = head_on_app(tmp_path)
    press(app, pygame.K_F6)
    assert "PREDICT: 0 of 0 predicted" in app.status_line()
    puck = tuple(float(v) for v in app.env.to_screen(app.table.pos_m[1]))
    tip = tuple(float(v) for v in app.env.to_screen(app.table.pos_m[1] + np.array(polar(1.1, 10.0))))
    post_mouse(pygame.MOUSEBUTTONDOWN, puck)
    post_mouse(pygame.MOUSEMOTION, tip)
    post_mouse(pygame.MOUSEBUTTONUP, tip)
    app.frame(FRAME_S)
    assert app.local.held is None  # the drag drew an arrow; it grabbed nothing
    assert app.predict.round.local[1] == pytest.approx(
        polar(1.1, 10.0), abs=2 * app.table.width_m / app.window.surface.get_width()
    )
    assert "PREDICT: 1 of 1 predicted" in app.status_line()
    press(app, pygame.K_F6)
    frames_until(app, lambda: app.predict.round.settled, "the collision to be over", max_frames=600)
    (line,) = app.predict.round.summary
    assert line == "puck 2: median 10 deg off; 0 of 1 within 5 deg; speeds within 20 %: 1 of 1"


def test_nobody_s_string_touches_the_pucks_while_the_reveal_plays(server, tmp_path):
    app = head_on_app(tmp_path, server)
    student = RawClient(server.port)
    try:
        student.hello("Flo")
        frames_until(app, lambda: app.student_count() == 1, "the student to join")
        press(app, pygame.K_F6)
        press(app, pygame.K_F6)  # reveal at once
        x, y = app.table.pos_m[1]
        student.send(proto.encode_input((x, y), 1))  # grab puck 2 ...
        student.send(proto.encode_input((x, y + 3.0), 1))  # ... and pull it up hard
        frames_until(app, lambda: app.predict.round.settled, "the collision to be over", max_frames=600)
        assert app.predict.round.truth[1] == pytest.approx((1.0, 0.0), abs=1e-6)  # as if nobody were there
    finally:
        student.close()


def test_a_student_who_joins_mid_round_is_told_at_once(server, tmp_path):
    app = head_on_app(tmp_path, server)
    press(app, pygame.K_F6)
    late = RawClient(server.port)
    try:
        late.hello("Gus")
        info = next_round(late, lambda i: True)  # the first ROUND, without waiting for a count change
        assert (info.round_id, info.state, info.pucks) == (1, "open", 2)
        late.send(encode_predict(info.round_id, 0, (0.0, 0.0)))
        frames_until(app, lambda: "1 of 1 predicted" in app.status_line(), "the late guess counted")
    finally:
        late.close()


def test_the_anonymous_projector_hides_the_names_on_the_arrows(server, tmp_path):
    app = head_on_app(tmp_path, server)
    student = RawClient(server.port)
    try:
        student.hello("Hal")
        frames_until(app, lambda: app.student_count() == 1, "the student to join")
        press(app, pygame.K_F6)
        student.send(encode_predict(1, 1, (1.0, 0.0)))
        frames_until(app, lambda: "1 of 1 predicted" in app.status_line(), "the guess counted")
        press(app, pygame.K_F6)
        press(app, pygame.K_F6, mod=pygame.KMOD_SHIFT)  # names on
        assert [a.label for a in next_round(student, lambda i: bool(i.arrows and i.arrows[0].label)).arrows] == [
            "C1 Hal"
        ]
        press(app, pygame.K_F5)  # the anonymous projector: no names anywhere
        assert [a.label for a in next_round(student, lambda i: bool(i.arrows) and not i.arrows[0].label).arrows] == [""]
    finally:
        student.close()


# ---------------------------------------------------------------- Space during a round


def test_space_cannot_resume_the_table_while_students_predict(tmp_path):
    app = head_on_app(tmp_path)
    press(app, pygame.K_F6)
    t0 = app.table.time_s
    press(app, pygame.K_SPACE, frames=10)
    assert app.paused and app.table.time_s == t0 and app.predict.round.state == "open"
    assert app.message == FROZEN_NOTICE  # one line saying why, and what does reveal
    assert app.rewind.timeline_shown() is None  # paused, but the history's keys are off: no timeline bar
    press(app, pygame.K_PERIOD)  # nor does a single step or the history move it
    press(app, pygame.K_COMMA, mod=pygame.KMOD_SHIFT)
    assert app.table.time_s == t0 and app.rewind.history.at is None
    press(app, pygame.K_F6)  # the round key reveals, and the table plays
    assert not app.paused and app.predict.round.state == "revealed"


def test_a_round_opened_over_the_lecture_notes_closes_them(tmp_path):
    """A user test: with the notes open, F6 left the table (the pucks to predict from) and the PREDICT lines
    under them, on the teacher's window and the students'."""
    app = head_on_app(tmp_path)
    press(app, pygame.K_l)
    assert app.panels.panel() == "notes"
    press(app, pygame.K_F6)
    assert app.predict.round.state == "open" and app.panels.panel() is None and not app.panels.show_notes
    assert app.message == "prediction round open: F6 again reveals (the notes closed: L shows them)"


def test_space_pauses_a_playing_reveal_and_after_the_freeze_closes_the_round(tmp_path):
    app = head_on_app(tmp_path)
    press(app, pygame.K_F6)
    assert app.message.startswith("prediction round open")
    app.predict.round.local[1] = (1.0, 0.0)
    press(app, pygame.K_F6)
    # (a user test: "prediction round open" stayed in the header over the bar's REVEALED)
    assert app.message == "revealed (F6 again closes the round)"
    press(app, pygame.K_SPACE)  # the teacher stops the reveal to point at something
    t0 = app.table.time_s
    for _ in range(5):
        app.frame(FRAME_S)
    assert app.paused and app.table.time_s == t0 and app.predict.round.state == "revealed"
    press(app, pygame.K_SPACE)  # and lets it play on
    assert not app.paused
    frames_until(app, lambda: app.predict.round.settled, "the collision to be over", max_frames=600)
    assert app.paused and app.predict.round.summary  # frozen on the truth
    press(app, pygame.K_SPACE)  # the class has seen it: Space goes on with the lesson
    assert app.predict.round.state == "closed" and not app.paused
    assert "round closed" in app.message
    t1 = app.table.time_s
    for _ in range(5):
        app.frame(FRAME_S)
    assert app.table.time_s > t1
    press(app, pygame.K_SPACE)
    assert app.paused  # Space is pause / resume again


# ---------------------------------------------------------------- the table after the round


def shows_paused(app) -> bool:
    """Whether the table is paused, checked against what the status line and the header's message say."""
    said_paused = "PAUSED" in app.status_parts() and "paused" in app.message
    said_running = "PAUSED" not in app.status_parts() and "runs on" in app.message
    assert said_paused != said_running, (app.status_line(), app.message)
    t0 = app.table.time_s
    for _ in range(3):
        app.frame(FRAME_S)
    assert (app.table.time_s == t0) is app.paused is said_paused
    return app.paused


@pytest.mark.parametrize("paused_before", [False, True])
def test_a_round_closed_with_f6_leaves_the_table_running_or_paused_as_it_was(tmp_path, paused_before):
    """A user test: F6, F6, F6 over a running table left it paused; a teacher expects it as it was before."""
    app = head_on_app(tmp_path)
    if paused_before:
        press(app, pygame.K_SPACE)
    assert app.paused is paused_before
    press(app, pygame.K_F6)
    app.predict.round.local[1] = (1.0, 0.0)
    press(app, pygame.K_F6)
    frames_until(app, lambda: app.predict.round.settled, "the collision to be over", max_frames=600)
    press(app, pygame.K_F6)
    assert app.predict.round.state == "closed" and app.message.startswith("prediction round closed")
    assert shows_paused(app) is paused_before


@pytest.mark.parametrize("paused_before", [False, True])
def test_a_round_ended_with_esc_or_a_new_demo_leaves_the_table_as_it_was(tmp_path, paused_before):
    app = head_on_app(tmp_path)
    if paused_before:
        press(app, pygame.K_SPACE)
    press(app, pygame.K_F6)
    press(app, pygame.K_ESCAPE)
    press(app, pygame.K_ESCAPE)  # the second Esc ends the round (the first asks)
    assert app.predict.round.state == "closed" and app.message.startswith("prediction round closed (Esc)")
    assert shows_paused(app) is paused_before
    press(app, pygame.K_F6)
    press(app, pygame.K_3)  # another demo ends the round too
    assert app.predict.round.state == "closed" and app.demo_key == "3" and app.paused is paused_before


# ---------------------------------------------------------------- the summary fits the window


LONG_SUMMARY = (
    "puck 12: median 12 deg off; 9 of 28 within 5 deg; speeds within 20 %: 17 of 28",
    "puck 13: comes to rest; 3 of 28 predicted under 0.05 m/s",
)


def _check_fits(placed, width: int, summary) -> None:
    """Every line drawn lies within the window's width, and every word of `summary` is drawn, in order."""
    assert placed
    for text, rect in placed:
        assert rect.left >= 0 and rect.right <= width, (text, rect, width)
    words = " ".join(" ".join(t for t, _ in placed).split())
    for line in summary:  # wrapped, never cut
        assert " ".join(line.split()) in words, line


@pytest.mark.parametrize("size", [(480, 360), (640, 480), (1280, 720)])
def test_the_summary_wraps_to_the_teachers_window(tmp_path, size):
    (tmp_path / "head_on.py").write_text(HEAD_ON)
    app = App(DemoShelf([BUILTIN_DIR, tmp_path]), demo_key="5", headless=True, window_size_px=size)
    pygame.event.clear()
    press(app, pygame.K_F6)
    app.predict.round.local[1] = polar(1.1, 10.0)
    press(app, pygame.K_F6)
    app.paused = True
    app.predict.round.settle(app.table)  # frozen on the truth at once: the wrapping, not the collision, is tested
    app.predict.round.summary = (*app.predict.round.summary, *LONG_SUMMARY)
    app.draw()
    assert app.window.surface.get_size() == size
    _check_fits(app.predict.paint(), size[0], app.predict.round.summary)


@pytest.mark.parametrize("size", [(480, 360), (640, 480), (1280, 720)])
def test_the_summary_wraps_to_a_students_window(size):
    from airtable.app.aids_paint import AidsPainter
    from airtable.app.window import GameWindow

    info = RoundInfo(
        3, "revealed", 2, 28, 28, (Arrow(1, (1.0, 0.1), (255, 0, 0)),), ((0.0, 0.0), (1.0, 0.0)),
        ("puck 2: median 10 deg off; 1 of 3 within 5 deg; speeds within 20 %: 2 of 3", *LONG_SUMMARY),
        ((3.0, 4.0), (5.0, 4.0)),
    )  # fmt: skip

    class Net:
        round = info

    student = PlayerApp(Net(), headless=True)
    student.window = GameWindow(Environment(size, width_m=10.0), headless=True, size_px=size)
    student.painter = AidsPainter(student.window)
    placed = student._draw_round((0, 255, 0))
    _check_fits(placed, size[0], info.summary)
    if size[0] < 600:  # a narrow window breaks a summary line between its parts, not inside one
        assert any(t.strip().startswith("speeds within 20 %") for t, _ in placed)
    Net.round = RoundInfo(4, "open", 2, 17, 28, from_m=info.from_m)
    _check_fits(student._draw_round((0, 255, 0)), size[0], ("17 of 28 predicted",))


def test_the_students_status_line_has_no_teacher_keys(demos):
    from conftest import teacher_and_student

    with teacher_and_student(demos, "8") as (teacher, net):
        frames_until(teacher, lambda: teacher.student_count() == 1, "the student to join")
        press(teacher, pygame.K_F6)
        assert "F6 reveals" in teacher.status_line()
        scene = frames_until(
            teacher, lambda: (s := net.latest()) is not None and "PREDICT" in s.status and s, "the round's status"
        )
        assert "F6" not in scene.status and "PREDICT: 0 of 1 predicted" in scene.status


@pytest.mark.parametrize("size", [(640, 480), (1280, 720), (1920, 1080)], ids=lambda s: f"{s[0]}x{s[1]}")
def test_the_students_predict_lines_are_on_an_opaque_box_clear_of_the_walls(server, tmp_path, size):
    # User test: on a student's window the PREDICT lines lay over the top-left wall with no box under them.
    app = head_on_app(tmp_path, server)
    net = NetPlayer("127.0.0.1", server.port, name="Gus")
    try:
        open_round_for(app, net)
        player = PlayerApp(net, headless=True)
        player.run(seconds=WAIT_S, until=lambda: player.frames >= 2)
        win = player.window
        win.resize(size)
        win.label_boxes.clear()
        win.draw(net.latest())
        placed = player._draw_round((200, 200, 200))
        assert placed and placed[0][0].startswith("PREDICT")
        block = win.label_boxes[-1]  # the lines' panel
        assert all(block.contains(rect) for _, rect in placed)
        assert block.collidelist(win.wall_rects()) < 0, (block, win.wall_rects())
        assert pygame.Rect((0, 0), size).contains(block)
        # Opaque: between the lines the panel's ground is black, whatever lies beneath.
        assert win.surface.get_at((block.right - 2, block.bottom - 2))[:3] == (0, 0, 0)
    finally:
        net.close()


@pytest.mark.parametrize("size", [(480, 360), (640, 480)], ids=lambda s: f"{s[0]}x{s[1]}")
@pytest.mark.parametrize("demo", ["2", "4", "8"])
@pytest.mark.parametrize("aids", ["", "c", "ct", "cd"])
def test_a_small_students_window_shows_the_predict_instruction_over_a_crowded_table(demos, demo, size, aids):
    """A user test: a student's 640x480 window showed no PREDICT lines."""
    with teacher_and_student(demos, demo) as (teacher, net):
        frames_until(teacher, lambda: teacher.student_count() == 1 and net.latest() is not None, "the join")
        for key in aids:
            press(teacher, pygame.key.key_code(key))
        press(teacher, pygame.K_F6)

        def arrived() -> bool:
            values = net.aids.values_rows(None) is not None
            return net.round.state == "open" and net.aids.shows("c") == ("c" in aids) and values == ("t" in aids)

        frames_until(teacher, lambda: net.round is not None and arrived(), "the round and the aids at the student")
        player = PlayerApp(net, headless=True)
        player.run(seconds=WAIT_S, until=lambda: player.frames >= 2)  # (the connection then closes)
        win = player.window
        win.resize(size)
        player._frame()
        placed = player._draw_round((200, 200, 200))
        assert placed and placed[0][0].startswith("PREDICT"), placed
        seen = pygame.Rect(0, 0, size[0], win.status_top_px)
        assert all(seen.contains(rect) for _, rect in placed), (placed, seen)


def test_esc_while_students_guess_asks_before_it_throws_the_guesses_away(tmp_path):
    """A user test: one Esc during a prediction round ended it, every student's guess gone."""
    app = head_on_app(tmp_path)
    press(app, pygame.K_F6)
    assert app.predict.round.state == "open"
    press(app, pygame.K_ESCAPE)
    assert app.predict.round.active and "Esc again ends the prediction round" in app.message
    press(app, pygame.K_ESCAPE)
    assert not app.predict.round.active and app.running


@pytest.mark.parametrize("gravity", [False, True])
def test_a_reveal_over_a_still_table_settles_at_once_and_a_drop_from_rest_still_plays(demos, gravity):
    """A user test: demo 2 at rest, F6 F6: "playing until the collision is over" for 8 s, none coming."""
    app = App(demos, demo_key="2", headless=True)
    app.table.gravity_on = gravity  # with gravity, the pucks at rest in the air fall: something comes
    press(app, pygame.K_F6)
    press(app, pygame.K_F6)
    frames_until(app, lambda: app.predict.round.settled, "the reveal to settle", max_frames=int(9.0 / FRAME_S))
    assert (app.table.time_s < 0.1) is (not gravity)  # at once when still; played out when they fall


@pytest.mark.parametrize("demo", ["7", "9"])
def test_a_reveal_opened_before_the_demos_throw_plays_the_throw(demos, demo):
    """A user test: 9 F6 ... F6 froze again at t = 0.18 s with no collision ("puck 14: comes to rest"): the
    table was still because the demo's throw (a timed event at 1 s) had not come yet."""
    app = App(demos, demo_key=demo, headless=True)
    press(app, pygame.K_F6)
    assert app.table.time_s < 1.0 and app.table.timed.next_s() == pytest.approx(1.0)
    press(app, pygame.K_F6)
    frames_until(app, lambda: app.predict.round.settled, "the reveal to settle", max_frames=int(10.0 / FRAME_S))
    assert app.table.time_s > 1.0 and app.table.collision_count > 0
