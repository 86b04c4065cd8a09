"""airtable-client: NetPlayer against a real server, reconnects, one-line errors, the headless window."""

from __future__ import annotations

import socket
import threading
import time

import numpy as np
import pygame
import pytest
from conftest import wait_until
from test_server import RawClient

from airtable.app.scene import CursorView
from airtable.app.window import background_for
from airtable.net import protocol as proto
from airtable.net.loadtest import TableLoop, grid_table
from airtable.net.player import InputThrottle, NetPlayer, PlayerApp, PlayerError, main, own_cursor_live
from airtable.net.server import GameServer


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
    options.setdefault("max_backoff_s", 0.3)
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


def test_own_cursor_is_drawn_at_the_live_mouse_position_with_its_string():
    welcome = proto.Welcome("C2", (210, 180, 140), 10.0, 8.7556)
    other = CursorView("C1", (255, 52, 179), (1.0, 1.0), 1, 0)
    mine = CursorView("C2", (210, 180, 140), (2.0, 2.0), 1, 3)
    cursors, extra = own_cursor_live((mine, other), welcome.client, np.array([2.5, 2.25]), 1, focused=True)
    assert cursors == (other, CursorView("C2", (210, 180, 140), (2.5, 2.25), 1, 3)) and not extra
    assert own_cursor_live((other,), welcome.client, (2.5, 2.25), 0, focused=True) == ((other,), True)
    assert own_cursor_live((mine, other), welcome.client, (2.5, 2.25), 0, focused=False) == ((other, mine), False)


# ---------------------------------------------------------------- NetPlayer


def test_player_joins_sees_the_table_and_drags_a_puck(cleanup):
    server, loop = start_table(cleanup)
    net = player(cleanup, server.port, name="Ann")
    welcome = net.connect()
    assert welcome.client == "C1 Ann" and net.state == net.CONNECTED
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
    server, _ = start_table(cleanup)
    net = player(cleanup, server.port)
    net.connect()
    assert net.update_input((1e300, -1e300), 7, ["ok", "x" * 40])
    # The server took it: the cursor shows up in the snapshots, where the clamp put it.
    x0, y0, x1, y1 = proto.cursor_limits(10.0, 8.7556)
    mine = wait_until(lambda: net.latest() and net.latest().cursors, what="our cursor in a snapshot")
    assert mine[0].cursor_m == (x1, y0) and mine[0].button == 0
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
    assert net.status_text == "server gone, retrying..."
    first_try = net.next_try
    wait_until(lambda: net.next_try > first_try, what="a refused attempt while the server is away")
    assert net.state == net.RETRYING
    server2, _ = start_table(cleanup, port=port)
    wait_until(lambda: net.state == net.CONNECTED, what="the reconnect")
    seen = net.snapshots
    wait_until(lambda: net.snapshots > seen, what="snapshots from the new server")
    assert net.reconnects == 1 and server2.player_names() == ["C1"]


def test_a_player_cut_off_by_a_restart_waits_when_the_table_is_now_full(cleanup):
    server, loop = start_table(cleanup)
    port = server.port
    net = player(cleanup, port, max_backoff_s=0.5)
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


def test_host_not_found(capsys):
    line = one_line_error(capsys, ["no-such-host.invalid"])
    assert "not found" in line and "join with" in line


def test_connection_refused(capsys):
    port = free_port()
    line = one_line_error(capsys, [f"127.0.0.1:{port}"])
    assert "is the server running?" in line and f"is port {port} open in its firewall?" in line


def test_a_full_table_is_waited_for_on_screen_and_joined_when_a_place_frees(capsys, cleanup):
    server, _ = start_table(cleanup, max_clients=1)
    first = RawClient(server.port)
    cleanup(first.close)
    first.hello()
    assert main([f"127.0.0.1:{server.port}", "--headless", "--seconds", "0.3"]) == 0
    out = capsys.readouterr().out
    assert "server full" in out and "waiting for a place" in out
    net = player(cleanup, server.port, max_backoff_s=0.5)
    assert net.connect() is None and net.state == net.WAITING
    assert net.banner_text.startswith("the table is full: asking again in")
    first.send(proto.encode_bye())
    wait_until(lambda: net.state == net.CONNECTED, what="a place at the table")
    assert net.welcome.client == "C1" and net.reconnects == 0


def test_wrong_and_missing_password(capsys, cleanup):
    server, _ = start_table(cleanup, password="sesame")
    assert "wrong password" in one_line_error(capsys, [f"127.0.0.1:{server.port}", "--password", "nope"])
    assert "needs a password" in one_line_error(capsys, [f"127.0.0.1:{server.port}"])


def test_protocol_version_mismatch_both_ways(capsys, cleanup):
    server, _ = start_table(cleanup)
    net = player(cleanup, server.port, protocol_version=2)
    with pytest.raises(PlayerError) as err:
        net.connect()
    assert "protocol 2" in str(err.value) and "same airtable version" in str(err.value)
    fake = FakeServer(proto.encode_json(proto.WELCOME, {"protocol": 2, "client": "C1"}))
    cleanup(fake.close)
    line = one_line_error(capsys, [f"127.0.0.1:{fake.port}"])
    assert "server speaks airtable protocol 2" in line


def test_something_else_on_the_port(capsys, cleanup):
    fake = FakeServer(b"HTTP/1.1 400 Bad Request\r\n\r\n")
    cleanup(fake.close)
    line = one_line_error(capsys, [f"127.0.0.1:{fake.port}"])
    assert "does not answer like an airtable server" in line


@pytest.mark.parametrize(
    "argv", [["127.0.0.1", "--name", "x" * 30], ["127.0.0.1:99999"], ["127.0.0.1", "--seconds", "-1"]]
)
def test_bad_arguments(capsys, argv):
    one_line_error(capsys, argv)


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


def test_escape_sends_bye_and_quits(cleanup):
    server, _ = start_table(cleanup)
    net = player(cleanup, server.port)
    net.connect()
    cleanup(pygame.quit)
    app = PlayerApp(net, headless=True)

    def press_escape():
        wait_until(lambda: app.frames > 2, what="the window")
        pygame.event.post(pygame.event.Event(pygame.KEYDOWN, key=pygame.K_ESCAPE, mod=0, unicode="\x1b", scancode=41))

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
