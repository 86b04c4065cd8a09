"""The teacher runs the room: count, roster, remove, hands off, seats that survive a
restart, the floor and anonymous names. Real sockets on 127.0.0.1, real pygame
events to a headless App, every wait bounded."""

from __future__ import annotations

import socket
import time

import numpy as np
import pygame
import pytest
from conftest import FRAME_S, WAIT_S, frames_until, press, wait_until

from airtable.app import room, roster_view
from airtable.app.app import App
from airtable.net import protocol as proto
from airtable.net.codec import SnapshotDecoder
from airtable.net.identity import SeatTokens, load_key
from airtable.net.player import NetPlayer, PlayerState
from airtable.net.server import GameServer, client_color


class Student:
    """A bare protocol client: HELLO, INPUT, and the newest snapshot on demand."""

    def __init__(self, port: int, name: str | None = None, token: str | None = None) -> None:
        self.sock = socket.create_connection(("127.0.0.1", port), timeout=WAIT_S)
        self.reader = proto.FrameReader(proto.MAX_SERVER_FRAME, sender="the server")
        self.pending: list[tuple[int, bytes]] = []
        self.decoder = SnapshotDecoder()
        self.sock.sendall(proto.encode_hello(name, token=token))
        kind, payload = self.next_frame()
        assert kind == proto.WELCOME, proto.parse_error(payload)
        self.welcome = proto.parse_welcome(payload)

    def next_frame(self) -> tuple[int, bytes]:
        deadline = time.monotonic() + WAIT_S
        while not self.pending:
            self.sock.settimeout(max(0.01, deadline - time.monotonic()))
            data = self.sock.recv(65536)
            if not data:
                raise ConnectionError("the server closed the connection")
            self.pending += self.reader.feed(data)
        return self.pending.pop(0)

    def next_scene(self):
        """The next Scene (snapshot format 2: a LAYOUT, then SNAPSHOTs coded against it)."""
        while True:
            kind, payload = self.next_frame()
            if kind == proto.LAYOUT:
                self.decoder.feed_layout(payload)
            elif kind == proto.SNAPSHOT:
                return self.decoder.feed_tick(payload).scene

    def drag(self, cursor_m, button: int = 1) -> None:
        self.sock.sendall(proto.encode_input(cursor_m, button))

    def close(self) -> None:
        self.sock.close()


@pytest.fixture
def served(demos, request):
    """A headless App with its GameServer on a free port, and a maker of Students."""
    server = GameServer(host="127.0.0.1", port=0)
    server.start()
    request.addfinalizer(server.stop)
    app = App(demos, headless=True, server=server)
    request.addfinalizer(pygame.quit)
    students: list[Student] = []
    request.addfinalizer(lambda: [s.close() for s in students])

    def join(name: str | None = None) -> Student:
        s = Student(server.port, name)
        students.append(s)
        frames_until(app, lambda: any(c.name == s.welcome.label for c in app.clients), "the student's Client")
        return s

    return app, server, join


def two_pucks(app: App) -> None:
    app.table.clear()
    app.table.add_puck((3.0, 4.0), radius_m=0.5)
    app.table.add_puck((7.0, 4.0), radius_m=0.5)


def click(app: App, pos) -> None:
    pygame.event.post(pygame.event.Event(pygame.MOUSEBUTTONDOWN, button=1, pos=pos))
    pygame.event.post(pygame.event.Event(pygame.MOUSEBUTTONUP, button=1, pos=pos))
    app.frame(FRAME_S)


# ---------------------------------------------------------------- 1. the teacher's view


def test_the_count_is_always_shown_and_f2_lists_every_seat(served):
    app, server, join = served
    assert "0 students (F2: roster)" in app.hud_lines()
    join("Ann")
    squatter = join("Bo")
    squatter.drag((-40.0, -40.0), 0)
    assert "2 students (F2: roster)" in app.hud_lines()
    press(app, pygame.K_F2)
    assert app.panels.panel() == "roster"
    # (the rows drawn, not only the server's roster: the network thread refreshes it between frames)
    frames_until(app, lambda: len(app.room.row_boxes) == 2 and server.roster()[1].far_off, "the far-off cursor")
    assert [n for n, _ in app.room.row_boxes] == [1, 2]
    seat = server.roster()[1]
    assert roster_view.seat_flags(seat) == "cursor far off the table"
    idle = type(seat)(**{**seat.__dict__, "idle_s": 75.0})
    assert roster_view.seat_flags(idle) == "squatting? idle 75 s, cursor far off the table"
    press(app, pygame.K_DOWN)
    assert app.room.selected == 1
    click(app, app.room.row_boxes[0][1].center)  # a click picks a row, not a puck
    assert app.room.selected == 0 and app.mouse_button == 0
    press(app, pygame.K_ESCAPE)
    assert app.panels.panel() is None and app.running


def test_a_failed_network_thread_shows_in_red(served):
    app, server, _ = served
    app.frame(FRAME_S)
    red = np.array(roster_view.ALERT_COLOR)
    assert not (pygame.surfarray.pixels3d(app.window.surface) == red).all(axis=2).any()
    server.failure = "students can no longer join: the network thread failed (ValueError: x)"
    app.frame(FRAME_S)
    assert (pygame.surfarray.pixels3d(app.window.surface) == red).all(axis=2).sum() > 100


# ---------------------------------------------------------------- 2. remove


def test_delete_twice_removes_the_selected_student_who_is_told_and_stays_away(served):
    app, server, join = served
    join("Ann")
    net = NetPlayer("127.0.0.1", server.port, name="Bo")
    try:
        net.connect()
        frames_until(app, lambda: len(server.roster()) == 2, "two seats")
        press(app, pygame.K_F2)
        press(app, pygame.K_DOWN)
        press(app, pygame.K_DELETE)
        assert app.message == "press Delete again to remove C2 Bo" and server.player_count == 2
        press(app, pygame.K_DELETE)
        assert app.message == "removed C2 Bo"
        wait_until(lambda: net.state == PlayerState.FAILED, what="the removed player to stop")
        assert net.error == room.REMOVED_SENTENCE and net.reconnects == 0
        frames_until(app, lambda: server.player_names() == ["C1 Ann"], "the seat to be free")
        assert net.state == PlayerState.FAILED and net.reconnects == 0  # no reconnection by itself
    finally:
        net.close()


# ---------------------------------------------------------------- 3. hands off


def test_hands_off_lets_go_ignores_input_and_tells_every_student(served):
    app, server, join = served
    two_pucks(app)
    ann = join("Ann")
    ann.drag((3.0, 4.0), 1)
    frames_until(app, lambda: app.clients[1].held is not None, "Ann to grab the puck")
    press(app, pygame.K_F3)
    assert server.hands_off and app.clients[1].held is None
    assert room.HANDS_OFF in app.scene().status_parts
    ann.drag((3.0, 4.0), 0)
    ann.drag((3.1, 4.0), 1)  # a new press: ignored
    before = app.table.pos_m.copy()
    frames_until(app, lambda: tuple(app.clients[1].cursor_m) == (3.1, 4.0), "Ann's cursor")
    for _ in range(30):
        app.frame(FRAME_S)
    assert app.clients[1].held is None and np.array_equal(app.table.pos_m, before)

    def banner():
        scene = ann.next_scene()
        return room.student_banner(scene)

    assert wait_until(banner, what="the hands-off banner") == room.HANDS_OFF_BANNER
    press(app, pygame.K_F3)
    assert not server.hands_off and room.HANDS_OFF not in app.scene().status_parts


# ---------------------------------------------------------------- 4. identity


def test_welcome_has_the_id_the_name_and_a_token_that_only_its_holder_can_use():
    with GameServer(host="127.0.0.1", port=0) as server:
        ann = Student(server.port, "Ann")
        try:
            w = ann.welcome
            assert (w.client, w.name, w.label, w.color) == ("C1", "Ann", "C1 Ann", client_color(1))
            assert w.token and w.token.startswith("1-")
            forged = Student(server.port, "Eve", token=w.token)  # another name: not honoured
            assert forged.welcome.client == "C2"
            forged.close()
        finally:
            ann.close()
    tokens = SeatTokens(b"k" * 32)
    assert tokens.seat(tokens.make(7, "Ann"), "Ann") == 7
    assert tokens.seat(tokens.make(7, "Ann"), "Bo") is None
    assert SeatTokens(b"x" * 32).seat(tokens.make(7, "Ann"), "Ann") is None
    assert tokens.seat("7-" + "0" * 32, "Ann") is None and tokens.seat("junk", "Ann") is None


def test_a_student_gets_the_same_seat_name_and_colour_after_a_server_restart(tmp_path):
    key = load_key(tmp_path / "airtable" / "seat-key")
    assert key is not None and load_key(tmp_path / "airtable" / "seat-key") == key  # kept in the file
    first = GameServer(host="127.0.0.1", port=0, token_key=key)
    first.start()
    other = Student(first.port, "Ann")  # takes C1, so Bo is C2
    net = NetPlayer("127.0.0.1", first.port, name="Bo", max_backoff_s=0.25)
    second = None
    try:
        assert net.connect().client == "C2"
        other.close()
        first.stop()  # the teacher restarts the app: same port, same key, no memory of seats
        wait_until(lambda: net.state == PlayerState.RETRYING, what="the player to notice")
        second = GameServer(host="127.0.0.1", port=first.port, token_key=key)
        second.start()
        wait_until(lambda: net.state == PlayerState.CONNECTED, what="the reconnection")
        w = net.welcome
        assert (w.client, w.label, w.color) == ("C2", "C2 Bo", client_color(2))  # not the free C1
        assert second.player_names() == ["C2 Bo"]
    finally:
        net.close()
        other.close()
        first.stop()
        if second is not None:
            second.stop()


# ---------------------------------------------------------------- 5. the floor, anonymous names


def test_with_the_floor_given_one_students_cursor_moves_a_puck_and_anothers_does_not(served):
    app, server, join = served
    two_pucks(app)
    ann, bo = join("Ann"), join("Bo")
    frames_until(app, lambda: len(server.roster()) == 2, "two seats")
    press(app, pygame.K_F4)
    assert server.floor == 1
    assert "floor: C1 Ann" in app.scene().status_parts
    ann.drag((3.0, 4.0), 1)
    bo.drag((7.0, 4.0), 1)
    frames_until(app, lambda: app.clients[1].held is not None and app.clients[2].button == 0, "the presses")
    ann.drag((3.0, 6.0), 1)
    bo.drag((7.0, 6.0), 1)
    frames_until(app, lambda: tuple(app.clients[2].cursor_m) == (7.0, 6.0), "Bo's cursor")
    for _ in range(60):
        app.frame(FRAME_S)
    assert app.table.pos_m[0, 1] > 4.2  # Ann's string pulls her puck up
    assert np.array_equal(app.table.pos_m[1], (7.0, 4.0))  # Bo's does nothing
    press(app, pygame.K_F4)
    assert server.floor == 2 and "floor: C2 Bo" in app.scene().status_parts
    press(app, pygame.K_F4)
    assert server.floor is None and not any(p.startswith("floor") for p in app.scene().status_parts)


def test_the_anonymous_projector_hides_names_but_not_colours(served, monkeypatch):
    app, server, join = served
    ann = join("Ann")
    ann.drag((3.0, 4.0), 0)
    frames_until(app, lambda: app.clients[1].active and server.roster(), "Ann's seat")
    press(app, pygame.K_F4)
    press(app, pygame.K_F5)
    assert app.room.anonymous and "floor: C1" in app.scene().status_parts
    projected = app.room.projected(app.scene())
    assert [(c.name, c.color) for c in projected.cursors if c.name != "teacher"] == [("C1", client_color(1))]
    assert "teacher" in [c.name for c in projected.cursors]  # the teacher's own cursor ("local" meant nothing)
    assert any(c.name == "C1 Ann" for c in app.scene().cursors)  # the students' own snapshots keep names
    press(app, pygame.K_F2)
    rows: list[list[str]] = []
    row_texts = roster_view._row_texts
    monkeypatch.setattr(roster_view, "_row_texts", lambda seat, label: rows.append(row_texts(seat, label)) or rows[-1])
    app.frame(FRAME_S)
    assert rows and rows[-1][:2] == ["C1", ""], rows


def test_a_students_window_says_hands_off(served, monkeypatch):
    from airtable.app.window import GameWindow
    from airtable.student.window import PlayerApp

    app, server, _ = served
    banners: list[str] = []
    draw_banner = GameWindow.draw_banner
    monkeypatch.setattr(GameWindow, "draw_banner", lambda self, text: (banners.append(text), draw_banner(self, text)))
    net = NetPlayer("127.0.0.1", server.port, name="Ann")
    try:
        net.connect()
        press(app, pygame.K_F3)

        def seen() -> bool:
            app.frame(FRAME_S)  # the teacher's frames publish the snapshots the student draws
            return room.HANDS_OFF_BANNER in banners

        deadline = time.monotonic() + WAIT_S
        PlayerApp(net, headless=True).run(until=lambda: seen() or time.monotonic() > deadline)
        assert room.HANDS_OFF_BANNER in banners
    finally:
        net.close()


def test_when_the_student_with_the_floor_leaves_everyone_acts_again(served):
    app, server, join = served
    ann, _ = join("Ann"), join("Bo")
    frames_until(app, lambda: len(server.roster()) == 2, "two seats")
    press(app, pygame.K_F4)
    assert server.floor == 1
    ann.close()
    frames_until(app, lambda: server.floor is None, "the floor to come back")
    assert app.message == "the student with the floor left: everyone's cursor acts again"
    assert not any(p.startswith(room.FLOOR_PREFIX) for p in app.scene().status_parts)


@pytest.mark.parametrize("size", [(640, 480), (1280, 720), (3840, 2160)])
def test_the_roster_columns_hold_a_two_digit_seat_and_a_name_of_the_longest_allowed(demos, size):
    """A user test: every seat from C10 up had a blank label (its column fitted two characters), and a
    20-letter name showed as "Wolfgang Am..." with room to spare."""
    app = App(demos, headless=True, window_size_px=size)
    font, em = app.window.font, app.window.font.get_height()
    seat_room = (roster_view.COLUMNS_EM[2] - roster_view.COLUMNS_EM[1]) * em - em // 2
    name_room = (roster_view.COLUMNS_EM[3] - roster_view.COLUMNS_EM[2]) * em - em // 2
    assert font.size("C30")[0] <= seat_room
    longest = "Wolfgang Amadeus Moz"
    assert len(longest) == proto.MAX_NAME_CHARS and font.size(longest)[0] <= name_room
    lag_room = (roster_view.COLUMNS_EM[5] - roster_view.COLUMNS_EM[4]) * em - em // 2
    assert font.size("1250 ms")[0] <= lag_room


def test_a_student_who_dropped_shows_as_away_while_the_seat_is_held(served, monkeypatch):
    """A user test: three laptops frozen 30 s: the header said "0 students", the roster "nobody has joined
    yet", though their seats were kept and they all came back. Away students are counted and listed."""
    app, server, join = served
    ann = join("Ann")
    join("Bo")
    ann.close()  # no goodbye: the lid closed
    frames_until(app, lambda: server.away(), "Ann's drop to be noticed")
    assert [name for name, _ in server.away()] == ["C1 Ann"]
    assert "1 student, 1 away (F2: roster)" in app.room.hud_lines()
    drawn: list[list] = []
    draw = roster_view.draw_roster
    monkeypatch.setattr(room, "draw_roster", lambda *a, **k: drawn.append(k["away"]) or draw(*a, **k))
    press(app, pygame.K_F2)
    app.frame(FRAME_S)
    assert drawn and [name for name, _ in drawn[-1]] == ["C1 Ann"]


@pytest.mark.parametrize("width", [120, 250, 400, 636, 900, 2000])
def test_the_rosters_keys_wrap_between_keys_never_cut_where_a_key_fits(width):
    """A user test: in a 636 px window the roster's key lines ended "F2 or Es..." and "F5: hide n..."."""
    pygame.font.init()
    font = pygame.font.Font(None, 24)
    lines = roster_view.hint_lines(font, width)
    keys = [key for hint in roster_view.HINTS for key in hint.split(roster_view.HINT_GAP)]
    assert all(font.size(line)[0] <= width for line in lines)
    if all(font.size(key)[0] <= width for key in keys):  # each key whole, each once, in order
        assert [key for line in lines for key in line.split(roster_view.HINT_GAP)] == keys
    if all(font.size(hint)[0] <= width for hint in roster_view.HINTS):
        assert lines == list(roster_view.HINTS)  # room enough: as written
