"""airtable-client: NetPlayer against a real server, reconnects, one-line errors, the headless window."""

from __future__ import annotations

import contextlib
import math
import os
import socket
import string
import struct
import subprocess
import sys
import threading
import time

import numpy as np
import pygame
import pytest
from conftest import WAIT_S, server_frames, wait_until
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from test_server import RawClient

from airtable.app.overlays import ESC_PAUSE_S
from airtable.app.window import background_for
from airtable.model.scene import CursorView, Scene
from airtable.net import protocol as proto
from airtable.net.codec import SnapshotEncoder, Viewer, encode_layout, layout_of
from airtable.net.player import InputThrottle, NetPlayer, PlayerError, PlayerState
from airtable.net.server import GameServer
from airtable.student.command import main
from airtable.student.window import PlayerApp, own_cursor_live
from tools.loadtest import TableLoop, grid_table


@pytest.fixture
def cleanup(request):
    """Register things to stop, closed in reverse order after the test."""
    stack: list = []
    yield stack.append
    for close in reversed(stack):
        close()


def start_table(cleanup, port: int = 0, **options) -> tuple[GameServer, TableLoop]:
    server = GameServer(host="127.0.0.1", port=port, **options)
    server.start()
    cleanup(server.stop)
    loop = TableLoop(server, grid_table(), fps=60).start()
    cleanup(loop.stop)
    return server, loop


def player(cleanup, port: int, **options) -> NetPlayer:
    """A NetPlayer that asks again soon: the waits a classroom needs are seconds."""
    options.setdefault("max_backoff_s", 0.3)
    options.setdefault("first_backoff_s", 0.05)
    options.setdefault("full_backoff_s", 0.05)
    net = NetPlayer("127.0.0.1", port, **options)
    cleanup(net.close)
    return net


def free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class FakeServer:
    """Answers any HELLO with fixed bytes, to test how the player takes odd servers."""

    def __init__(self, reply: bytes) -> None:
        self.listener = socket.create_server(("127.0.0.1", 0))
        self.port = self.listener.getsockname()[1]
        self.reply = reply
        self.conns: list[socket.socket] = []
        self.thread = threading.Thread(target=self._serve, daemon=True)
        self.thread.start()

    def _serve(self) -> None:
        try:
            conn, _ = self.listener.accept()
        except OSError:
            return
        self.conns.append(conn)
        conn.recv(65536)
        conn.sendall(self.reply)

    def close(self) -> None:
        self.listener.close()
        self.thread.join(timeout=5)
        for c in self.conns:
            c.close()


def one_line_error(capsys, argv: list[str]) -> str:
    assert main(argv) == 1
    err = capsys.readouterr().err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("airtable-client: ") and "Traceback" not in err
    return lines[0]


# ---------------------------------------------------------------- input throttle


def test_input_throttle_sends_changes_at_most_60_a_second_and_a_heartbeat():
    throttle = InputThrottle(max_hz=60, heartbeat_s=1.0)
    a = proto.InputRecord((1.0, 1.0), 0)
    b = proto.InputRecord((1.1, 1.0), 0)
    assert throttle.due(a, 0.0)
    throttle.sent(a, 0.0)
    assert not throttle.due(a, 0.5), "nothing changed"
    assert not throttle.due(b, 0.005), "changed, but too soon after the last send"
    assert throttle.due(b, 1 / 60)
    assert throttle.due(a, 1.0), "heartbeat"
    throttle.reset()
    assert throttle.due(a, 0.0)


def test_a_cursor_at_rest_is_sent_again_until_its_datagram_is_acknowledged():
    throttle = InputThrottle(max_hz=60, heartbeat_s=1.0, resend_s=0.05)
    a = proto.InputRecord((1.0, 1.0), 0)
    throttle.sent(a, 0.0)  # by UDP; this datagram may be lost, and nothing newer follows
    assert not throttle.due(a, 0.04, unacked=True), "not before resend_s"
    assert throttle.due(a, 0.05, unacked=True)
    assert not throttle.due(a, 0.5, unacked=False), "acknowledged: only the heartbeat is left"


def test_own_cursor_is_drawn_at_the_live_mouse_position_with_its_string():
    welcome = proto.Welcome("C2", (210, 180, 140), 10.0, 8.7556)
    other = CursorView("C1", (255, 52, 179), (1.0, 1.0), 1, 0)
    mine = CursorView("C2", (210, 180, 140), (2.0, 2.0), 1, 3)
    color = welcome.color
    others, live = own_cursor_live((mine, other), welcome.client, color, np.array([2.5, 2.25]), 1, focused=True)
    assert others == (other,) and live == CursorView("C2", (210, 180, 140), (2.5, 2.25), 1, 3)
    alone = CursorView("C2", (210, 180, 140), (2.5, 2.25), 0)  # not in the snapshots yet: the arrow alone
    assert own_cursor_live((other,), welcome.client, color, (2.5, 2.25), 0, focused=True) == ((other,), alone)
    assert own_cursor_live((mine, other), welcome.client, color, (2.5, 2.25), 0, focused=False) == ((other,), mine)
    assert own_cursor_live((other,), "", color, (2.5, 2.25), 0, focused=True) == ((other,), None)  # no seat yet


def test_a_still_table_lets_the_window_draw_less_often_until_something_moves():
    app = PlayerApp(NetPlayer("127.0.0.1", 1), headless=True)  # never connected: only the bookkeeping
    pucks = np.array([[1.0, 1.0], [2.0, 1.0]])
    other = CursorView("C1", (255, 52, 179), (1.0, 1.0), 0, -1)

    def scene(pos, cursors=(other,)):
        return Scene(10.0, 8.7556, pos, np.full(len(pos), 0.25), np.zeros((len(pos), 3), np.uint8), cursors=cursors)

    here = np.array([5.0, 5.0])
    app.note_motion(scene(pucks), here, now_s=10.0)
    assert not app.still(10.5)
    app.note_motion(scene(pucks.copy()), here.copy(), now_s=10.9)  # the same picture: not a change
    assert app.still(11.0)  # idle IDLE_AFTER_S = 1 s after the last change
    moved = pucks.copy()
    moved[1, 0] += 1e-6  # a puck moves, however little
    app.note_motion(scene(moved), here, now_s=12.0)
    assert not app.still(12.5) and app.still(13.0)
    walked = CursorView("C1", (255, 52, 179), (1.5, 1.0), 0, -1)  # another student's cursor
    app.note_motion(scene(moved, (walked,)), here, now_s=14.0)
    assert not app.still(14.5) and app.still(15.0)
    app.note_motion(scene(moved, (walked,)), np.array([5.0, 5.1]), now_s=16.0)  # our own mouse
    assert not app.still(16.5)
    app.button = 1  # our button, with the mouse still
    app.note_motion(scene(moved, (walked,)), np.array([5.0, 5.1]), now_s=17.5)
    assert not app.still(18.0) and app.still(18.5)


# ---------------------------------------------------------------- NetPlayer


def test_player_joins_sees_the_table_and_drags_a_puck(cleanup):
    server, loop = start_table(cleanup)
    net = player(cleanup, server.port, name="Ann")
    welcome = net.connect()
    assert welcome.label == "C1 Ann" and net.state == net.CONNECTED
    scene = wait_until(net.latest, what="a snapshot")
    assert len(scene.pos_m) == 30
    start = scene.pos_m[0].copy()
    assert net.send_input(tuple(start), 1)
    net.send_input((start[0] + 1.0, start[1] + 1.0), 1)

    def dragged():
        scene = net.latest()
        me = next((c for c in scene.cursors if c.name == "C1 Ann"), None)
        return me is not None and me.held == 0 and np.linalg.norm(scene.pos_m[0] - start) > 0.3

    wait_until(dragged, what="puck 0 to follow the player's cursor")
    net.close()
    assert net.state == net.CLOSED
    wait_until(lambda: server.player_names() == [], what="the BYE")


def test_update_input_clamps_what_the_server_would_refuse(cleanup):
    server, loop = start_table(cleanup)
    net = player(cleanup, server.port)
    net.connect()
    assert net.update_input((1e300, -1e300), 7, ["ok", "x" * 40])
    # The server took it: its cursor is where the clamp put it (off the table: not drawn, so read there).
    x0, y0, x1, y1 = proto.cursor_limits(10.0, 8.7556)

    def mine():
        with loop.lock:
            return [(tuple(c.cursor_m), c.button, c.active) for c in loop.clients[1:]]

    wait_until(lambda: mine() and mine()[0][0] != (0.0, 0.0), what="our cursor at the server")
    assert mine() == [((x1, y0), 0, False)]
    assert net.state == net.CONNECTED and server.player_names() == ["C1"]


def test_player_reconnects_when_the_server_comes_back(cleanup):
    server, loop = start_table(cleanup)
    port = server.port
    net = player(cleanup, port)
    net.connect()
    wait_until(net.latest, what="a snapshot")
    loop.stop()
    server.stop()
    wait_until(lambda: net.state == net.RETRYING, what="server gone, retrying")
    # Its BYE: the teacher quit, not the network (a user test: students read "reconnecting..." as for a drop).
    assert net.status_text == "the teacher closed the table: waiting for it to open again..."
    first_try = net.next_try
    wait_until(lambda: net.next_try > first_try, what="a refused attempt while the server is away")
    assert net.state == net.RETRYING  # and still said after it
    assert net.banner_text.startswith("the teacher closed the table: waiting for it to open again")
    server2, _ = start_table(cleanup, port=port)
    wait_until(lambda: net.state == net.CONNECTED, what="the reconnect")
    seen = net.snapshots
    wait_until(lambda: net.snapshots > seen, what="snapshots from the new server")
    assert net.reconnects == 1 and server2.player_names() == ["C1"]


def test_a_player_cut_off_by_a_restart_waits_when_the_table_is_now_full(cleanup):
    server, loop = start_table(cleanup)
    port = server.port
    # The first try comes 0.25 s after the server went away: time for the squatter to sit down first.
    net = player(cleanup, port, first_backoff_s=0.25)
    net.connect()
    loop.stop()
    server.stop()
    wait_until(lambda: net.state == net.RETRYING, what="server gone")
    server2, _ = start_table(cleanup, port=port, max_clients=1)
    squatter = RawClient(port)
    cleanup(squatter.close)
    squatter.hello()
    wait_until(lambda: net.state == net.WAITING, what="the player to wait for a place, not give up")
    assert "server full" in net.waiting_because
    squatter.send(proto.encode_bye())
    wait_until(lambda: net.state == net.CONNECTED, what="the place to be taken")
    assert net.reconnects == 1 and server2.player_names() == ["C1"]


# ---------------------------------------------------------------- one-line errors


def test_a_host_not_found_is_said_and_asked_again_in_the_window(capsys):
    assert main(["no-such-host.invalid", "--headless", "--seconds", "0.1"]) == 0
    out = capsys.readouterr().out
    assert "not found" in out and "join with" in out and "trying again" in out and "Traceback" not in out


def test_a_student_who_starts_before_the_teacher_waits_in_the_window_and_joins(capsys, cleanup):
    """A user test: refused at the first try (the teacher's table not started yet), the client printed a
    line and exited 1 with no window, where the docs say it tries again. Now it waits and joins."""
    port = free_port()
    assert main([f"127.0.0.1:{port}", "--headless", "--seconds", "0.1"]) == 0
    out = capsys.readouterr().out
    assert f"connection refused by 127.0.0.1:{port}: is the server running?" in out
    assert "firewall? (trying again; Ctrl+C quits)" in out
    net = player(cleanup, port, name="Ann")
    assert net.connect() is None and net.state is PlayerState.RETRYING
    assert net.banner_text.startswith(f"connection refused by 127.0.0.1:{port}") and "trying again" in net.banner_text
    first_try = net.next_try
    wait_until(lambda: net.next_try > first_try, what="a second refused try")
    assert net.state is PlayerState.RETRYING and "connection refused" in net.banner_text
    start_table(cleanup, port=port)
    wait_until(lambda: net.state is PlayerState.CONNECTED, what="the join once the table opened")
    assert net.welcome.name.endswith("Ann") and net.reconnects == 0 and net.banner_text is None


def test_a_full_table_is_waited_for_on_screen_and_joined_when_a_place_frees(capsys, cleanup):
    server, _ = start_table(cleanup, max_clients=1)
    first = RawClient(server.port)
    cleanup(first.close)
    first.hello()
    assert main([f"127.0.0.1:{server.port}", "--headless", "--seconds", "0.1"]) == 0
    out = capsys.readouterr().out
    assert (
        "server full" in out and "tries again by itself" in out and "(Ctrl+C quits)" in out
    )  # headless: no window to press Esc in
    net = player(cleanup, server.port)
    assert net.connect() is None and net.state == net.WAITING
    assert net.banner_text.startswith("the table is full: asking again in")
    first.send(proto.encode_bye())
    wait_until(lambda: net.state == net.CONNECTED, what="a place at the table")
    assert net.welcome.client == "C1" and net.reconnects == 0


def latin_only_teacher(cleanup, port: int = 0) -> GameServer:
    """A table whose screen draws plain Latin letters only (its font lacks the "ë" this client's has)."""
    from airtable.app.glyphs import NameCheck

    return start_table(cleanup, port, name_refusal=NameCheck(frozenset(string.ascii_letters + " ")))[0]


def test_a_name_the_teachers_screen_refuses_ends_the_client_with_status_2(capsys, cleanup):
    """A user test: a name the teacher's table refused ended the client with status 1, as a broken link does;
    it is a bad --name: one line and status 2, as for any bad argument."""
    server = latin_only_teacher(cleanup)
    assert main([f"127.0.0.1:{server.port}", "--name", "Zoë", "--headless", "--seconds", "0"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    assert err.startswith("airtable-client: the name has 'ë' (U+00EB), which the teacher's screen's font cannot draw")
    assert "write 'e' for it, as in \"Zoe\"" in err


def test_a_client_started_before_the_table_that_then_refuses_its_name_ends_with_status_2(capsys, cleanup):
    """Started before the teacher's table, the client waits; the table, once open, refuses the name: status 2."""
    port = free_port()
    net = player(cleanup, port, name="Zoë")
    assert net.connect() is None and net.state == net.RETRYING  # nobody there yet
    latin_only_teacher(cleanup, port)
    cleanup(pygame.quit)
    assert PlayerApp(net, headless=True).run(seconds=WAIT_S) == 2
    assert net.state == net.FAILED and "cannot draw" in capsys.readouterr().err


def test_wrong_and_missing_password(capsys, cleanup):
    server, _ = start_table(cleanup, password="sesame")
    assert "wrong password" in one_line_error(capsys, [f"127.0.0.1:{server.port}", "--password", "nope"])
    assert "needs a password" in one_line_error(capsys, [f"127.0.0.1:{server.port}"])


def test_protocol_version_mismatch_both_ways(capsys, cleanup):
    server, _ = start_table(cleanup)
    net = player(cleanup, server.port, protocol_version=1)  # a client of the last version
    with pytest.raises(PlayerError) as err:
        net.connect()
    assert "protocol 1" in str(err.value) and "same airtable version" in str(err.value)
    fake = FakeServer(proto.encode_json(proto.WELCOME, {"protocol": 1, "client": "C1"}))  # a server of the last
    cleanup(fake.close)
    line = one_line_error(capsys, [f"127.0.0.1:{fake.port}"])
    assert "server speaks airtable protocol 1" in line and "\n" not in line.strip()


class SilentFirstRelay:
    """Between the player and a table: the first connection is accepted and left silent (a relay on a
    slow link, or a busy teacher's laptop: the kernel acknowledges, nothing answers); later ones are
    passed through both ways."""

    def __init__(self, port: int) -> None:
        self.listener = socket.create_server(("127.0.0.1", 0))
        self.port, self.target = self.listener.getsockname()[1], port
        self.socks: list[socket.socket] = []
        self.threads = [threading.Thread(target=self._serve, daemon=True)]
        self.threads[0].start()

    def _serve(self) -> None:
        for n in range(3):  # bounded: the silent one, then a passed one or two
            try:
                conn, _ = self.listener.accept()
            except OSError:
                return
            self.socks.append(conn)
            if n:
                far = socket.create_connection(("127.0.0.1", self.target))
                self.socks.append(far)
                for a, b in ((conn, far), (far, conn)):
                    t = threading.Thread(target=self._pass, args=(a, b), daemon=True)
                    self.threads.append(t)
                    t.start()

    @staticmethod
    def _pass(a: socket.socket, b: socket.socket) -> None:
        with contextlib.suppress(OSError):
            while data := a.recv(65536):  # ends when either side closes
                b.sendall(data)

    def close(self) -> None:
        self.listener.close()
        for sock in self.socks:
            with contextlib.suppress(OSError):
                sock.shutdown(socket.SHUT_RDWR)
            sock.close()
        for t in self.threads:
            t.join(timeout=5)


def test_a_handshake_that_meets_silence_is_tried_again_not_called_another_program(cleanup):
    """A user test: through a 300 ms relay with an outage at the join, the client quit with "accepted the
    connection but did not answer within 5 s; is it an airtable server?" (the relay acknowledged at once,
    so the kernel saw a quick link). Silence is never proof of another program: it is tried again."""
    server, _ = start_table(cleanup)
    relay = SilentFirstRelay(server.port)
    cleanup(relay.close)
    net = player(cleanup, relay.port, name="Ann", timeout_s=0.5)
    assert net.connect() is None  # no PlayerError: waiting to try again
    assert net.state is PlayerState.RETRYING
    assert "has not answered within 0.5 s" in net.banner_text and "trying again" in net.banner_text
    assert "airtable server" not in net.banner_text
    wait_until(lambda: net.state is PlayerState.CONNECTED, what="the second try to join", timeout_s=20)
    assert net.welcome.name.endswith("Ann")


def test_the_window_says_when_the_table_it_shows_is_frozen_and_for_how_long_it_reconnects(cleanup, monkeypatch):
    """A user test: in an outage the window still said "connected" over a frozen table for 10 s, and after
    the teacher quit "reconnecting..." for 50 s with no time: no way to tell a drop from a closed table."""
    import airtable.net.player as player_module

    monkeypatch.setattr(player_module, "STALE_S", 0.3)
    server, loop = start_table(cleanup)
    net = player(cleanup, server.port, name="Ann")
    net.connect()
    wait_until(lambda: net.state is PlayerState.CONNECTED and net.banner_text is None, what="snapshots")
    loop.stop()  # the teacher's table stops sending (its loop froze, or the link did)
    wait_until(lambda: net.banner_text and "nothing from the teacher's table for" in net.banner_text, what="stale")
    assert net.status_text.startswith(f"connected to {net.address}, nothing heard for ")  # not plain "connected"
    server.stop()  # the teacher quits: the player reconnects, and says for how long
    wait_until(lambda: net.state is PlayerState.RETRYING, what="the drop to be noticed")
    wait_until(lambda: net.banner_text.endswith(" s)"), what="the time since the table was lost")
    assert net.banner_text.startswith("the teacher closed the table") or "trying again" in net.banner_text


def test_the_terminal_says_when_the_table_closes_and_when_the_student_is_back(capsys, cleanup):
    """A user test: after a drop the terminal printed only another "connected" line."""
    server, loop = start_table(cleanup)
    port = server.port
    net = player(cleanup, port, name="Ann")
    net.connect()
    app = PlayerApp(net, headless=True)

    def teacher_restarts() -> None:
        wait_until(lambda: app.frames > 2, what="the window drawing")
        loop.stop()
        server.stop()
        wait_until(lambda: app._last_state is PlayerState.RETRYING, what="the window to see the drop")
        start_table(cleanup, port=port)

    restart = threading.Thread(target=teacher_restarts, daemon=True)
    restart.start()
    back = lambda: net.reconnects == 1 and app._welcome is net.welcome  # noqa: E731
    assert app.run(seconds=60, until=back) == 0  # 60 s: a bound on a hang
    restart.join(timeout=10)
    lines = capsys.readouterr().out.splitlines()
    assert lines == [
        f"airtable-client: the teacher closed the table at {net.address}; waiting for it to open again",
        f"airtable-client: back at the table at {net.address}; you are {net.welcome.label}",
    ]


def test_something_else_on_the_port(capsys, cleanup):
    fake = FakeServer(b"HTTP/1.1 400 Bad Request\r\n\r\n")
    cleanup(fake.close)
    line = one_line_error(capsys, [f"127.0.0.1:{fake.port}"])
    assert "does not answer like an airtable server" in line


@pytest.mark.parametrize(
    "argv", [["127.0.0.1", "--name", "x" * 30], ["127.0.0.1:99999"], ["127.0.0.1", "--seconds", "-1"]]
)
def test_bad_arguments(capsys, argv):
    assert main(argv) == 2  # a bad argument: status 2, as the ones argparse refuses
    (line,) = capsys.readouterr().err.splitlines()
    assert line.startswith("airtable-client: ") and "Traceback" not in line


# ---------------------------------------------------------------- the headless window


def test_headless_app_draws_the_table_and_says_bye(cleanup, tmp_path):
    server, loop = start_table(cleanup)
    net = player(cleanup, server.port, name="Bo")
    net.connect()
    wait_until(net.latest, what="a snapshot")
    app = PlayerApp(net, headless=True)
    cleanup(pygame.quit)
    shot = tmp_path / "player.png"
    assert app.run(seconds=10, screenshot=str(shot), until=lambda: app.frames >= 10) == 0
    assert shot.exists() and app.frames > 0
    surface, env = app.window.surface, app.window.env
    scene = net.latest()
    background = background_for(scene)
    for pos in scene.pos_m[:5]:
        x, y = (int(round(v)) for v in env.to_screen(pos))
        assert tuple(surface.get_at((x, y)))[:3] != background, "a puck is drawn where the snapshot puts it"
    assert app.window.caption == "Air Table - C1 Bo"
    wait_until(lambda: server.player_names() == [], what="the BYE at exit")


def test_headless_app_survives_a_server_restart(cleanup):
    server, loop = start_table(cleanup)
    port = server.port
    net = player(cleanup, port)
    net.connect()
    cleanup(pygame.quit)

    def restart():
        wait_until(lambda: app.frames > 5, what="the window to run")
        loop.stop()
        server.stop()
        wait_until(lambda: net.RETRYING in app.states_seen, what="the window to show the retry")
        start_table(cleanup, port=port)

    app = PlayerApp(net, headless=True)
    t = threading.Thread(target=restart)
    t.start()
    try:
        status = app.run(seconds=10, until=lambda: net.reconnects == 1 and net.state == net.CONNECTED)
    finally:
        t.join()
    assert status == 0
    assert {net.CONNECTED, net.RETRYING} <= app.states_seen
    assert net.reconnects == 1


def test_escape_asks_then_a_second_escape_sends_bye_and_quits(cleanup):
    server, _ = start_table(cleanup)
    net = player(cleanup, server.port)
    net.connect()
    cleanup(pygame.quit)
    app = PlayerApp(net, headless=True)

    def escape():
        pygame.event.post(pygame.event.Event(pygame.KEYDOWN, key=pygame.K_ESCAPE, mod=0, unicode="\x1b", scancode=41))

    def press_escape():
        wait_until(lambda: app.frames > 2, what="the window")
        escape()  # asks
        wait_until(lambda: app.leave_asked_until > time.monotonic(), what="the question")
        frames = app.frames
        wait_until(lambda: app.frames > frames + 2, what="a few frames asking")
        assert net.state == PlayerState.CONNECTED
        time.sleep(ESC_PAUSE_S)  # a person reads the question, then answers (a burst of Escs does not)
        escape()

    t = threading.Thread(target=press_escape)
    t.start()
    start = time.monotonic()
    try:
        assert app.run(seconds=10) == 0
    finally:
        t.join()
    assert time.monotonic() - start < 5
    wait_until(lambda: server.player_names() == [], what="the BYE")


def test_an_error_from_the_server_during_play_ends_with_one_line(capsys, cleanup):
    welcome = proto.encode_welcome("C1", (255, 52, 179), 10.0, 8.7556)
    fake = FakeServer(welcome + proto.encode_error("the teacher closed the table; thanks for playing"))
    cleanup(fake.close)
    net = player(cleanup, fake.port)
    net.connect()
    cleanup(pygame.quit)
    assert PlayerApp(net, headless=True).run(seconds=5) == 1
    assert capsys.readouterr().err.strip() == "airtable-client: the teacher closed the table; thanks for playing"


def test_a_removed_student_reads_why_in_the_window_until_a_key(cleanup):
    """Issue 22: the window used to vanish, the reason only in the terminal."""
    welcome = proto.encode_welcome("C1", (255, 52, 179), 10.0, 8.7556)
    fake = FakeServer(welcome + proto.encode_error("the teacher removed you from the table"))
    cleanup(fake.close)
    net = player(cleanup, fake.port)
    net.connect()
    cleanup(pygame.quit)
    app = PlayerApp(net, headless=False)  # a window (the dummy driver's): the student is there to read
    panels = []

    def ended_and_shown() -> bool:
        if app.window is not None and not panels:
            draw_panel = app.window.draw_panel
            app.window.draw_panel = lambda title, rows, **k: (
                panels.append((title, rows)),
                draw_panel(title, rows, **k),
            )
        return app.ended is not None and any(title == "The session has ended" for title, _ in panels)

    assert app.run(seconds=10, until=ended_and_shown) == 1
    assert (
        "The session has ended",
        ["the teacher removed you from the table", "Press any key to close this window."],
    ) in [(t, list(r)) for t, r in panels]
    frames = app.frames
    pygame.event.post(pygame.event.Event(pygame.KEYDOWN, key=pygame.K_a, mod=0, unicode="a", scancode=4))
    assert app.run(seconds=10) == 0 and app.frames == frames  # the key closes it at once


# ---------------------------------------------------------------- a server that lies


class ScriptedServer:
    """A malicious server on 127.0.0.1: connection i gets HELLO answered with replies[i]
    (the last one repeats), then stays open; `send` streams more frames to the newest."""

    def __init__(self, *replies: bytes) -> None:
        self.listener = socket.create_server(("127.0.0.1", 0))
        self.listener.settimeout(0.1)
        self.port = self.listener.getsockname()[1]
        self.replies = list(replies)
        self.conns: list[socket.socket] = []
        self._stop = threading.Event()
        self.thread = threading.Thread(target=self._serve, daemon=True)
        self.thread.start()

    def _serve(self) -> None:
        while not self._stop.is_set():
            try:
                conn, _ = self.listener.accept()
            except OSError:
                continue
            conn.settimeout(5.0)
            reply = self.replies[min(len(self.conns), len(self.replies) - 1)]
            self.conns.append(conn)
            try:
                conn.recv(65536)  # the HELLO
                conn.sendall(reply)
            except OSError:
                pass

    def send(self, data: bytes) -> None:
        """Send in a thread: the client may stop reading (and hang up) half way."""

        def push():
            try:
                self.conns[-1].sendall(data)
            except OSError:
                pass

        threading.Thread(target=push, daemon=True).start()

    def cut(self) -> None:
        """Hang up on the newest connection, as a restarting server would."""
        self.conns[-1].close()

    def close(self) -> None:
        self._stop.set()
        try:
            self.listener.shutdown(socket.SHUT_RDWR)  # wakes the accept() at once
        except OSError:
            pass
        self.thread.join(timeout=5)
        self.listener.close()
        for c in self.conns:
            c.close()


def welcome_frame(width_m: float = 10.0, height_m: float = 8.7556) -> bytes:
    message = {
        "protocol": proto.PROTOCOL_VERSION,
        "client": "C1",
        "color": [255, 52, 179],
        "table": {"width_m": width_m, "height_m": height_m},
    }
    return proto.encode_json(proto.WELCOME, message)


def snapshot_frame(scene: Scene, **view: float) -> bytes:
    """The LAYOUT and SNAPSHOT frames (format 2) a new player gets for `scene`, with the
    view (zoom, origin_x_m, origin_y_m) written into the keyframe's bytes as given (an
    honest server clamps it first)."""
    encoder = SnapshotEncoder()
    encoder.add(scene)
    frames = []
    for kind, payload in server_frames(encoder.frames_for(Viewer())):
        if kind == proto.SNAPSHOT and view:
            lie = (view.get("zoom", scene.zoom), view.get("origin_x_m", scene.origin_m[0]), view.get("origin_y_m", 0.0))
            payload = payload[:31] + struct.pack("<3d", *lie) + payload[55:]  # a keyframe's view follows its header
        frames.append(proto.encode_frame(kind, payload))
    return b"".join(frames)


def counts_frame(pucks: int = 0, springs: int = 0, cursors: int = 0, padding: int = 0) -> bytes:
    """A LAYOUT that claims huge counts, with `padding` zero bytes of body after its header."""
    payload = bytearray(encode_layout(layout_of(_one_puck_scene())))
    struct.pack_into("<III", payload, 8, pucks, springs, cursors)
    return proto.encode_frame(proto.LAYOUT, bytes(payload) + b"\0" * padding)


def _one_puck_scene(radius_m: float = 0.3) -> Scene:
    return Scene(10.0, 8.7556, np.array([[5.0, 4.0]]), np.array([radius_m]), np.array([[255, 165, 0]], np.uint8))


@pytest.mark.parametrize("width_m", [1e-10, 5e-324, 1e300])
def test_a_welcome_with_an_impossible_table_is_refused_in_a_sentence(cleanup, width_m):
    fake = ScriptedServer(welcome_frame(width_m))
    cleanup(fake.close)
    with pytest.raises(PlayerError) as err:
        player(cleanup, fake.port).connect()
    assert "table size" in str(err.value) and "cannot be drawn" in str(err.value)


def test_an_impossible_table_after_a_reconnect_ends_with_one_line(capsys, cleanup):
    fake = ScriptedServer(welcome_frame(), welcome_frame(1e-10))
    cleanup(fake.close)
    net = player(cleanup, fake.port)
    net.connect()
    fake.cut()
    cleanup(pygame.quit)
    assert PlayerApp(net, headless=True).run(seconds=10) == 1
    err = capsys.readouterr().err.strip()
    assert err.startswith("airtable-client: ") and "table size" in err and "\n" not in err


LIES = {
    "zoom 1e300": snapshot_frame(_one_puck_scene(), zoom=1e300),
    "origin 1e300": snapshot_frame(_one_puck_scene(), origin_x_m=1e300),
    "radius 1e5": snapshot_frame(_one_puck_scene(1e5)),
    "2.4M pucks": counts_frame(pucks=2_400_000),
    "2M springs": counts_frame(springs=2_000_000),
    "2.5M cursors": counts_frame(cursors=2_500_000),
    # Sent whole, under the frame cap: refused by the drawing budget.
    "600,000 pucks in a frame": counts_frame(pucks=600_000, padding=600_000 * 27),
}


@pytest.mark.parametrize("case", LIES, ids=list(LIES))
def test_a_lying_snapshot_is_left_out_with_one_line_and_the_session_goes_on(capsys, cleanup, case):
    """Data from the server never ends the session (issue 22): what the client cannot use is
    left out with one line; the window keeps running and the connection is tried again."""
    fake = ScriptedServer(welcome_frame())
    cleanup(fake.close)
    net = player(cleanup, fake.port)
    net.connect()
    fake.send(LIES[case])
    cleanup(pygame.quit)
    app = PlayerApp(net, headless=True)
    assert app.run(seconds=10, until=lambda: net.problems >= 1 and app.frames >= 5) == 0
    assert net.problems >= 1 and net.error is None
    err = capsys.readouterr().err.strip()
    assert err.startswith("airtable-client: ") and "\n" not in err and "Traceback" not in err
    assert "left out" in err or "cannot read" in err
    assert "snapshot" in err or "byte limit" in err


@pytest.mark.parametrize(("field", "value"), [("zoom", 1e300), ("origin_x_m", 1e300), ("origin_x_m", 5e6)])
def test_a_view_the_client_cannot_use_keeps_the_previous_one_and_shows_the_pucks(capsys, cleanup, field, value):
    fake = ScriptedServer(welcome_frame())
    cleanup(fake.close)
    net = player(cleanup, fake.port)
    net.connect()
    fake.send(snapshot_frame(_one_puck_scene(), **{field: value}))
    scene = wait_until(net.latest, what="the snapshot, shown")
    assert (scene.zoom, *scene.origin_m) == (1.0, 0.0, 0.0)
    assert len(scene.pos_m) == 1 and net.state == PlayerState.CONNECTED and net.reconnects == 0
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "previous view kept" in err


def test_a_drawing_error_is_reported_once_and_the_client_plays_on(capsys, cleanup, monkeypatch):
    from airtable.app.window import GameWindow

    server, _ = start_table(cleanup)
    net = player(cleanup, server.port)
    net.connect()
    wait_until(net.latest, what="a snapshot")
    real_draw = GameWindow.draw
    failures = iter([True, True, True])

    def flaky_draw(self, scene, **kw):
        if next(failures, False):
            raise pygame.error("Out of memory")
        real_draw(self, scene, **kw)

    monkeypatch.setattr(GameWindow, "draw", flaky_draw)
    cleanup(pygame.quit)
    app = PlayerApp(net, headless=True)
    assert app.run(seconds=10, until=lambda: app.frames >= 10) == 0
    err = capsys.readouterr().err
    assert err.count("could not draw a frame") == 1 and "Out of memory" in err


def test_a_client_on_some_other_port_gets_a_hint_for_the_student(capsys, cleanup):
    fake = FakeServer(b"SSH-2.0-OpenSSH_9.6\r\n")
    cleanup(fake.close)
    line = one_line_error(capsys, [f"127.0.0.1:{fake.port}"])
    assert "some other program" in line and "'join with:' line" in line
    assert "join with airtable-client" not in line and "web browser" not in line


@st.composite
def extreme_scenes(draw) -> Scene:
    """Valid snapshots at the edges of what a player accepts: sizes, zoom, origin, radii, counts."""
    width_m = draw(st.sampled_from([proto.MIN_TABLE_M, 1.0, 10.0, proto.MAX_TABLE_M]))
    height_m = draw(
        st.sampled_from([width_m, min(proto.MAX_TABLE_M, width_m * 99), max(proto.MIN_TABLE_M, width_m / 99)])
    )
    x0, y0, x1, y1 = proto.cursor_limits(width_m, height_m)
    size = max(width_m, height_m)
    n = draw(st.sampled_from([0, 1, 7, 2000, proto.MAX_DRAWN_PUCKS]))
    s = draw(st.sampled_from([0, 3, proto.MAX_DRAWN_SPRINGS])) if n else 0
    c = draw(st.sampled_from([0, 2, proto.MAX_DRAWN_CURSORS]))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    corners = np.array([[x0, y0], [x1, y1], [x0, y1], [x1, y0], [width_m / 2, height_m / 2]])
    pos = corners[rng.integers(0, 5, n)] if draw(st.booleans()) else rng.uniform((x0, y0), (x1, y1), (n, 2))
    radius = np.full(n, draw(st.sampled_from([1e-9, size / 1000, size])))
    names = draw(st.sampled_from(["", "C" * 48, "Zoë 李雷 דנה"]))
    cursors = tuple(
        CursorView(f"{names}{i}", (255, 0, 0), (float(rng.uniform(x0, x1)), y1), 3, int(rng.integers(-1, n)))
        for i in range(c)
    )
    return Scene(
        width_m=width_m,
        height_m=height_m,
        pos_m=pos,
        radius_m=radius,
        color_rgb=rng.integers(0, 256, (n, 3), dtype=np.uint8),
        spring_pairs=rng.integers(0, max(n, 1), (s, 2)),
        spring_length_m=np.full(s, draw(st.sampled_from([0.0, 100 * size]))),
        spring_width_m=np.full(s, draw(st.sampled_from([0.0, size]))),
        spring_color_rgb=np.zeros((s, 3), np.uint8),
        cursors=cursors,
        title="T" * draw(st.sampled_from([0, 5000])),
        status="S" * 300,
        time_s=draw(st.sampled_from([0.0, 1e300])),
        fps=draw(st.sampled_from([0.0, 1e6])),
        zoom=draw(st.sampled_from([proto.MIN_VIEW_ZOOM, 1.0, proto.MAX_VIEW_ZOOM])),
        origin_m=tuple(draw(st.sampled_from([(x0, y0), (x1, y1), (0.0, 0.0)]))),
    )


def _rss_mb() -> float:
    with open("/proc/self/status") as f:
        line = next(line for line in f if line.startswith("VmRSS:"))
    return int(line.split()[1]) / 1024


@pytest.mark.skipif(not os.path.exists("/proc/self/status"), reason="reads the memory use from /proc")
def test_extreme_but_valid_snapshots_never_crash_hang_or_bloat_the_client(cleanup):
    cleanup(pygame.quit)
    before = _rss_mb()
    peak = [before]

    @given(st.lists(extreme_scenes(), min_size=1, max_size=3))
    @settings(max_examples=12, deadline=None, suppress_health_check=list(HealthCheck))
    def stream(scenes):
        fake = ScriptedServer(welcome_frame())
        net = NetPlayer("127.0.0.1", fake.port, max_backoff_s=0.3)
        try:
            net.connect()
            encoder, viewer, frames = SnapshotEncoder(), Viewer(), []
            for sc in scenes:
                encoder.add(sc)
                frames.append(encoder.frames_for(viewer))
            fake.send(b"".join(frames))
            app = PlayerApp(net, headless=True)
            drawn = lambda: net.snapshots == len(scenes) and app.frames > 1  # noqa: E731
            assert app.run(seconds=60, until=drawn) == 0, net.error  # 60 s: a bound on a hang, not a measurement
            assert drawn(), "every snapshot arrived and was drawn"
            peak[0] = max(peak[0], _rss_mb())
        finally:
            net.close()
            fake.close()

    stream()
    assert peak[0] - before < 500, f"the client grew by {peak[0] - before:.0f} MB"


def test_the_client_command_starts_with_its_own_line_not_pygames_banner():
    env = {k: v for k, v in os.environ.items() if k != "PYGAME_HIDE_SUPPORT_PROMPT"}
    args = "['127.0.0.1:1', '--headless', '--seconds', '0']"  # nobody on port 1
    code = f"import sys; from airtable.client_cli import main; sys.exit(main({args}))"
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True, timeout=60)
    assert out.returncode == 0
    assert out.stderr == "" and out.stdout.startswith("airtable-client: connection refused by 127.0.0.1:1"), out


def test_the_last_cursor_reaches_the_table_though_its_datagram_was_lost(cleanup):
    """Real sockets on 127.0.0.1: once UDP is confirmed, a moving cursor goes by datagrams alone.
    The datagram of the position where the hand stops is dropped; it is sent again, unacknowledged,
    without waiting for the heartbeat (switched off here)."""
    server, loop = start_table(cleanup)
    net = player(cleanup, server.port, name="Ann")
    net.connect()
    x = 1.0

    def moved_by_udp() -> bool:  # moving: UDP is confirmed and the table follows the cursor
        nonlocal x
        x = round(x + 0.01, 4)
        net.update_input((x, 2.0))
        time.sleep(0.02)
        return net._udp.confirmed(time.monotonic()) and _table_cursor_x(loop) == x

    wait_until(moved_by_udp, what="inputs over UDP")
    sock, sent = net._udp.sock, []
    net._udp.sock = _DroppingSocket(sock, drop=1, sent=sent)  # the next datagram is lost
    net._throttle = InputThrottle(heartbeat_s=math.inf)  # no heartbeat (by UDP or TCP) to make up for it
    net._tcp_input_at = math.inf
    stop_x = round(x + 0.5, 4)
    net.update_input((stop_x, 2.0))

    def arrived() -> bool:
        net.update_input((stop_x, 2.0))  # the window calls this every frame, the hand at rest
        time.sleep(0.01)
        return _table_cursor_x(loop) == stop_x

    wait_until(arrived, what="the resting cursor on the table")
    assert len(sent) >= 2, "the lost datagram was sent again"


def _table_cursor_x(loop) -> float | None:
    with loop.lock:
        players = loop.clients[1:]
        return round(float(players[0].cursor_m[0]), 4) if players else None


class _DroppingSocket:
    """A UDP socket whose first `drop` datagrams are lost on the way (the rest go out)."""

    def __init__(self, sock, drop: int, sent: list) -> None:
        self._sock, self._drop, self._sent = sock, drop, sent

    def send(self, data: bytes) -> int:
        self._sent.append(data)
        if self._drop > 0:
            self._drop -= 1
            return len(data)
        return self._sock.send(data)

    def __getattr__(self, name):
        return getattr(self._sock, name)


def test_a_hello_lost_on_a_quick_link_is_tried_again_not_the_end(cleanup):
    """The server's HELLO deadline passed on a link that looks quick (the HELLO was lost, or the
    laptop stalled between connecting and saying it): the student joins on the next try."""
    server, _ = start_table(cleanup, hello_timeout_s=0.2)
    relay = _HoldFirstHello(server.port)
    cleanup(relay.close)
    net = player(cleanup, relay.port, name="Ann")
    assert net.connect() is None and net.state == net.WAITING  # told to try again, not ended
    assert "your hello did not reach the table within 0.2 s" in net.waiting_because
    assert net.banner_text.startswith(
        "your hello did not reach the table within 0.2 s of connecting (lost on the way? a slow network?): "
        "asking again in"
    )
    wait_until(lambda: net.state == net.CONNECTED, what="the second try to join")
    assert net.welcome.client == "C1"


class _HoldFirstHello:
    """A relay on 127.0.0.1 that swallows what the first connection sends (its HELLO is lost)
    and passes the server's answer back; later connections pass both ways."""

    def __init__(self, server_port: int) -> None:
        self._listener = socket.create_server(("127.0.0.1", 0))
        self.port = self._listener.getsockname()[1]
        self._server_port, self._socks, self._closed = server_port, [], threading.Event()
        threading.Thread(target=self._accept, daemon=True).start()

    def _accept(self) -> None:
        for k in range(20):  # bounded: a test makes a few connections
            try:
                client, _ = self._listener.accept()
            except OSError:
                return
            upstream = socket.create_connection(("127.0.0.1", self._server_port))
            self._socks += [client, upstream]
            threading.Thread(target=self._pipe, args=(client, upstream, k == 0), daemon=True).start()
            threading.Thread(target=self._pipe, args=(upstream, client, False), daemon=True).start()

    def _pipe(self, src: socket.socket, dst: socket.socket, lose: bool) -> None:
        for _ in range(100_000):  # bounded
            try:
                data = src.recv(65536)
                if not data:
                    break
                if not lose:
                    dst.sendall(data)
            except OSError:
                break
        with contextlib.suppress(OSError):
            dst.shutdown(socket.SHUT_WR)

    def close(self) -> None:
        for sock in (self._listener, *self._socks):
            sock.close()


def test_a_student_holding_a_puck_keeps_the_strings_end_when_the_teachers_view_changes(monkeypatch):
    """The teacher zooms or resets the view (the student's window follows it) while the student holds a puck
    and keeps the mouse still: the pointer goes with the table, so the string's end stays on its point of
    the table (left on the screen, it came to another point and yanked the puck)."""
    from airtable.app.environment import Environment
    from airtable.app.window import GameWindow

    app = PlayerApp(NetPlayer("127.0.0.1", 1), headless=True)  # never connected: only the pointer's bookkeeping
    env = Environment((1280, 720), width_m=10.0)
    app.window = GameWindow(env, headless=True, size_px=(1280, 720))
    pointer = [(400, 300)]  # the system's pointer, as a real window has it (moved by set_pos)
    monkeypatch.setattr(pygame.mouse, "get_pos", lambda: pointer[0])
    monkeypatch.setattr(pygame.mouse, "set_pos", lambda at: pointer.__setitem__(0, tuple(at)))
    app.window.headless = False  # (its pointer: the one above)
    app.button = 1
    held_at = app._pointer_on_the_table(env).copy()
    env.zoom_about((500, 350), 1.5)  # the teacher's wheel, about the teacher's own pointer (ours stays on screen)
    np.testing.assert_allclose(app._pointer_on_the_table(env), held_at, atol=0.5 / env.px_per_m)  # to the pixel
    env.reset()
    np.testing.assert_allclose(app._pointer_on_the_table(env), held_at, atol=0.5 / env.px_per_m)
    app.button = 0  # not holding: the pointer is where the mouse is, on whatever the view shows
    env.zoom_about((900, 500), 2.5)
    np.testing.assert_allclose(app._pointer_on_the_table(env), env.to_world(np.array(pointer[0], dtype=float)))


def test_a_slow_join_says_so_on_the_terminal_before_the_window_opens(cleanup):
    """A user test: through an outage at the join, nothing showed for 8 s (the window opens once the first
    handshake ends). A join that takes over a second says so at once; a quick refusal prints nothing more."""
    silent = socket.create_server(("127.0.0.1", 0))  # accepts (the kernel does), never answers
    cleanup(silent.close)
    port = silent.getsockname()[1]
    args = [f"127.0.0.1:{port}", "--headless", "--seconds", "0.2"]
    code = f"import sys; from airtable.client_cli import main; sys.exit(main({args!r}))"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    lines = out.stdout.splitlines()
    assert lines and lines[0] == f"airtable-client: joining the table at 127.0.0.1:{port}...", out
    assert "has not answered within" in out.stdout, out


def test_a_student_who_waited_for_a_place_reads_on_the_terminal_when_they_are_in(capsys, cleanup):
    """A user test: after "trying again" or "server full", the terminal never said that joining worked."""
    server, _ = start_table(cleanup, max_clients=1)
    first = RawClient(server.port)
    cleanup(first.close)
    first.hello()
    net = player(cleanup, server.port)
    assert net.connect() is None  # waiting for a place
    first.send(proto.encode_bye())
    cleanup(pygame.quit)
    assert PlayerApp(net, headless=True).run(seconds=WAIT_S, until=lambda: net.welcome is not None) == 0
    assert net.waiting_because is None  # in: nothing to wait for (the window's line says so)
    out = capsys.readouterr().out
    assert f"airtable-client: connected to 127.0.0.1:{server.port}; you are C1" in out
