"""GameServer over real sockets on 127.0.0.1: handshake, dragging, bad clients, full, slow clients."""

from __future__ import annotations

import json
import socket
import struct
import threading
import time
from collections.abc import Callable

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from airtable import AirTable, Client
from airtable.app.client import LOCAL_COLOR, cursor_pulls
from airtable.app.scene import Scene
from airtable.colors import rgb
from airtable.net import protocol as proto
from airtable.net.loadtest import TableLoop, grid_table, run_load
from airtable.net.server import COURSE_COLORS, GameServer, client_color, lan_addresses

WAIT_S = 5.0


def wait_until(condition: Callable[[], object], timeout_s: float = WAIT_S, what: str = "condition") -> object:
    """Poll `condition` until it is truthy; fail after a generous timeout."""
    deadline = time.monotonic() + timeout_s
    while True:
        value = condition()
        if value:
            return value
        if time.monotonic() > deadline:
            pytest.fail(f"timed out after {timeout_s} s waiting for {what}")
        time.sleep(0.005)


def frame(frame_type: int, payload: bytes) -> bytes:
    return struct.pack(">IB", len(payload) + 1, frame_type) + payload


class RawClient:
    """A bare protocol client for tests: send bytes, read frames with deadlines."""

    def __init__(self, port: int) -> None:
        self.sock = socket.create_connection(("127.0.0.1", port), timeout=WAIT_S)
        self.sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self.reader = proto.FrameReader(proto.MAX_SERVER_FRAME, sender="the server")
        self.pending: list[tuple[int, bytes]] = []
        self.welcome: proto.Welcome | None = None

    def send(self, data: bytes) -> bool:
        try:
            self.sock.sendall(data)
            return True
        except OSError:  # the server may already have dropped us
            return False

    def next_frame(self, timeout_s: float = WAIT_S) -> tuple[int, bytes] | None:
        """The next frame, or None when the server closed the connection."""
        deadline = time.monotonic() + timeout_s
        while not self.pending:
            remaining = deadline - time.monotonic()
            if remaining <= 0:
                raise TimeoutError("no frame from the server")
            self.sock.settimeout(remaining)
            try:
                data = self.sock.recv(65536)
            except ConnectionResetError:
                return None
            if not data:
                return None
            self.pending += self.reader.feed(data)
        return self.pending.pop(0)

    def next_of(self, frame_type: int) -> bytes:
        while True:
            got = self.next_frame()
            assert got is not None, f"connection closed while waiting for {proto.FRAME_NAMES[frame_type]}"
            if got[0] == frame_type:
                return got[1]

    def hello(self, name: str | None = None, password: str | None = None) -> proto.Welcome:
        self.send(proto.encode_hello(name, password))
        t, payload = self.next_frame()
        assert t == proto.WELCOME, proto.parse_error(payload) if t == proto.ERROR else t
        self.welcome = proto.parse_welcome(payload)
        return self.welcome

    def expect_error(self) -> str:
        """The ERROR sentence; the server must then close the connection."""
        while True:
            got = self.next_frame()
            assert got is not None, "closed without an ERROR"
            if got[0] == proto.ERROR:
                sentence = proto.parse_error(got[1])
                break
            assert got[0] in (proto.WELCOME, proto.SNAPSHOT), got
        assert self.next_frame() is None, "the connection stayed open after ERROR"
        return sentence

    def close(self) -> None:
        self.sock.close()


class Honest:
    """A well-behaved player, connected the whole time: holds puck 0 and circles it."""

    def __init__(self, port: int, centre_m: tuple[float, float]) -> None:
        self.client = RawClient(port)
        self.name = self.client.hello("honest").client
        self.centre_m = centre_m
        self.snapshots = 0
        self.scene: Scene | None = None
        self._stop = threading.Event()
        self.client.send(proto.encode_input(centre_m, 1))
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _run(self) -> None:
        t0 = time.monotonic()
        next_input = t0
        while not self._stop.is_set():
            now = time.monotonic()
            if now >= next_input:  # 20 inputs a second, well within the server's timeout
                a = 3 * (now - t0)
                cursor = (self.centre_m[0] + 0.2 * np.cos(a), self.centre_m[1] + 0.2 * np.sin(a))
                self.client.send(proto.encode_input(cursor, 1))
                next_input = now + 0.05
            try:
                got = self.client.next_frame(timeout_s=0.05)
            except (TimeoutError, OSError):
                continue
            if got is None:
                return
            if got[0] == proto.SNAPSHOT:
                self.scene = proto.decode_snapshot(got[1])
                self.snapshots += 1

    def me(self, scene: Scene):
        return next((c for c in scene.cursors if c.name == self.name), None)

    def assert_alive(self) -> None:
        """Still receiving snapshots, still holding its puck, and the puck still moves."""
        count = self.snapshots
        wait_until(lambda: self.snapshots >= count + 3, what="the honest client's snapshots")
        first = self.scene.pos_m[0].copy()
        wait_until(lambda: not np.array_equal(self.scene.pos_m[0], first), what="the honest puck to move")
        me = self.me(self.scene)
        assert me is not None and me.held == 0 and me.button == 1

    def close(self) -> None:
        self._stop.set()
        self._thread.join(timeout=WAIT_S)
        self.client.close()


@pytest.fixture
def clients():
    """Make RawClients that are closed after the test."""
    made: list[RawClient] = []

    def make(port: int) -> RawClient:
        c = RawClient(port)
        made.append(c)
        return c

    yield make
    for c in made:
        c.close()


@pytest.fixture
def make_server(request):
    """Start GameServers on free ports; each is stopped after the test."""

    def make(**options) -> GameServer:
        options.setdefault("host", "127.0.0.1")
        options.setdefault("port", 0)
        server = GameServer(**options)
        server.start()
        request.addfinalizer(server.stop)
        return server

    return make


@pytest.fixture
def make_loop(request):
    """Run a TableLoop (a headless game loop in a thread) until the test ends."""

    def make(server: GameServer, table: AirTable | None = None, fps: float = 120.0) -> TableLoop:
        loop = TableLoop(server, table, fps=fps)
        loop.start()
        request.addfinalizer(loop.stop)
        return loop

    return make


class Arena:
    def __init__(self, server: GameServer, loop: TableLoop, honest: Honest) -> None:
        self.server, self.loop, self.honest = server, loop, honest


@pytest.fixture(scope="module")
def arena(request):
    """One server with a running table and an honest player, shared by the bad-client tests."""
    server = GameServer(host="127.0.0.1", port=0, timeout_s=3.0)
    server.start()
    request.addfinalizer(server.stop)
    loop = TableLoop(server, grid_table(), fps=120).start()
    request.addfinalizer(loop.stop)
    honest = Honest(server.port, tuple(loop.table.pos_m[0]))
    request.addfinalizer(honest.close)
    wait_until(lambda: honest.scene is not None and honest.me(honest.scene), what="the honest cursor")
    return Arena(server, loop, honest)


def one_puck_table() -> AirTable:
    table = AirTable()
    table.add_puck((5.0, 4.0), radius_m=0.5)
    return table


# ---------------------------------------------------------------- handshake


def test_hello_gets_welcome_then_a_snapshot(make_server, make_loop, clients):
    server = make_server()
    loop = make_loop(server, grid_table())
    c = clients(server.port)
    c.send(proto.encode_hello("Ann"))
    t, payload = c.next_frame()
    assert t == proto.WELCOME
    message = json.loads(payload)
    assert message == {
        "protocol": 1,
        "client": "C1 Ann",
        "color": list(rgb("maroon1")),
        "table": {"width_m": loop.table.width_m, "height_m": loop.table.height_m},
    }
    scene = proto.decode_snapshot(c.next_of(proto.SNAPSHOT))
    assert len(scene.pos_m) == 30 and scene.title == "headless table"
    assert server.player_names() == ["C1 Ann"]


def test_names_count_up_and_colours_follow_the_course(make_server, clients):
    server = make_server()
    welcomes = [clients(server.port).hello() for _ in range(3)]
    assert [w.client for w in welcomes] == ["C1", "C2", "C3"]
    assert [w.color for w in welcomes] == [rgb(c) for c in COURSE_COLORS[:3]]


def test_client_colours_are_the_course_ten_then_distinct():
    colours = [client_color(n) for n in range(1, 61)]
    assert colours[:10] == [rgb(c) for c in COURSE_COLORS]
    assert len(set(colours)) == 60
    assert LOCAL_COLOR not in colours
    for r, g, b in colours[10:]:
        assert not (g > 200 and r < 120 and b < 120), "generated colours keep away from the local user's green"


# ---------------------------------------------------------------- input drives the table


def test_input_drags_the_puck_and_disconnect_lets_go(make_server, make_loop, clients):
    server = make_server()
    table = one_puck_table()
    loop = make_loop(server, table)
    c = clients(server.port)
    name = c.hello().client
    c.send(proto.encode_input((5.1, 4.0), 1))

    def holder() -> Client | None:
        with loop.lock:
            return next((cl for cl in loop.clients if cl.name == name and cl.held is not None), None)

    client = wait_until(holder, what="the player to grab the puck")
    c.send(proto.encode_input((8.0, 4.0), 1))
    wait_until(lambda: table.pos_m[0, 0] > 6.0, what="the puck to follow the cursor")
    c.close()  # no BYE: the connection just goes away
    wait_until(lambda: client not in loop.clients and client.held is None, what="the puck to be let go")
    assert [cl.name for cl in loop.clients] == ["local"]


def test_two_players_on_one_puck_add_their_forces(make_server, clients):
    server = make_server()
    table = one_puck_table()
    people = [Client()]  # the game loop's list; index 0 is the local user
    a, b = clients(server.port), clients(server.port)
    a.hello(), b.hello()
    for c in (a, b):
        c.send(proto.encode_input((5.1, 4.0), 1))

    def both(cursor_x: float) -> bool:
        server.apply_inputs(people, table)  # this test is the game loop
        players = people[1:]
        return len(players) == 2 and all(p.held is not None and p.cursor_m[0] == cursor_x for p in players)

    wait_until(lambda: both(5.1), what="both players to grab the puck")
    for c in (a, b):
        c.send(proto.encode_input((6.0, 4.0), 1))
    wait_until(lambda: both(6.0), what="both cursors at x = 6")

    def pulled_by_local_clients(n: int) -> float:
        """The same pull made by n Clients on a table without any network."""
        ref = one_puck_table()
        pullers = []
        for _ in range(n):
            c = Client()
            c.set_input(ref, (5.1, 4.0), 1)
            c.set_input(ref, (6.0, 4.0), 1)
            pullers.append(c)
        ref.step(1 / 240, cursor_pulls(pullers))
        return ref.vel_mps[0, 0]

    table.step(1 / 240, cursor_pulls(people))
    assert table.vel_mps[0, 0] == pulled_by_local_clients(2)
    assert table.vel_mps[0, 0] > 1.5 * pulled_by_local_clients(1) > 0
    assert table.vel_mps[0, 1] == pytest.approx(0.0, abs=1e-12)


def test_a_grab_and_a_move_within_one_frame_still_grab(make_server, clients):
    server = make_server()
    table = one_puck_table()
    people = [Client()]
    c = clients(server.port)
    c.hello()
    # Press over the puck and move away at once: both arrive before the next frame.
    c.send(proto.encode_input((5.1, 4.0), 1) + proto.encode_input((6.0, 4.0), 1) + proto.encode_input((7.0, 4.0), 1))

    def moved() -> bool:
        server.apply_inputs(people, table)  # this test is the game loop
        return len(people) == 2 and people[1].cursor_m[0] == 7.0

    wait_until(moved, what="the last input")
    assert people[1].held is table.pucks[0]


def test_bye_frees_the_name_and_removes_the_client(make_server, clients):
    server = make_server()
    table = one_puck_table()
    people = [Client()]
    c = clients(server.port)
    c.hello()
    wait_until(lambda: (server.apply_inputs(people, table), len(people) == 2)[1], what="the join")
    c.send(proto.encode_bye())
    wait_until(lambda: (server.apply_inputs(people, table), len(people) == 1)[1], what="the leave")
    assert server.player_names() == []


# ---------------------------------------------------------------- bad clients


def _after_hello(*frames: bytes) -> list[bytes]:
    return [proto.encode_hello(), *frames]


def _input(cursor="[1, 2]", button="1", keys="[]") -> bytes:
    return frame(proto.INPUT, f'{{"cursor_m": {cursor}, "button": {button}, "keys": {keys}}}'.encode())


BAD_CLIENTS = {
    "garbage bytes": ([b"\xde\xad\xbe\xef" * 8], ["limit", "airtable-client"]),
    "a web browser": ([b"GET / HTTP/1.1\r\nHost: teacher\r\n\r\n"], ["web browser", "airtable-client"]),
    "a frame over 64 KiB": ([struct.pack(">IB", 64 * 1024 + 1, 1) + b"x" * 1000], ["65536 byte limit"]),
    "an empty frame": ([b"\0\0\0\0"], ["empty"]),
    "invalid UTF-8": ([frame(proto.HELLO, b'{"protocol": 1, "name": "\xff"}')], ["UTF-8"]),
    "invalid JSON": ([frame(proto.HELLO, b'{"protocol": 1,')], ["not valid JSON", '{"protocol": 1']),
    "HELLO without protocol": ([frame(proto.HELLO, b'{"name": "Ann"}')], ["missing", "protocol"]),
    "wrong protocol version": ([proto.encode_hello(protocol=2)], ["protocol 1", "protocol 2", "same airtable"]),
    "unknown HELLO field": ([frame(proto.HELLO, b'{"protocol": 1, "admin": true}')], ["unknown field"]),
    "a 21 character name": ([proto.encode_hello("x" * 21)], ["name", "20"]),
    "a name with a bell": ([proto.encode_hello("a\x07")], ["printable"]),
    "INPUT before HELLO": ([proto.encode_input((1, 2), 1)], ["before HELLO", "HELLO"]),
    "HELLO twice": (_after_hello(proto.encode_hello()), ["twice"]),
    "unknown frame type": (_after_hello(frame(9, b"{}")), ["unknown message type 9"]),
    "a client sending SNAPSHOT": (_after_hello(frame(proto.SNAPSHOT, b"ATSN")), ["may not send SNAPSHOT"]),
    "NaN": (_after_hello(_input(cursor="[NaN, 1]")), ["NaN", "finite"]),
    "inf": (_after_hello(_input(cursor="[1, Infinity]")), ["finite"]),
    "1e308": (_after_hello(_input(cursor="[1e308, 1]")), ["too far off the table"]),
    "a string for a number": (_after_hello(_input(cursor='["1", 2]')), ["must be a number"]),
    "button 7": (_after_hello(_input(button="7")), ["button must be 0", "mouse buttons"]),
    "too many keys": (_after_hello(_input(keys=json.dumps(list("abcdefghijklmnopq")))), ["at most 16"]),
    "a long key name": (_after_hello(_input(keys='["' + "k" * 40 + '"]')), ["1 to 16"]),
    "INPUT missing a field": (_after_hello(frame(proto.INPUT, b'{"cursor_m": [1, 2]}')), ["missing"]),
    "INPUT that is a list": (_after_hello(frame(proto.INPUT, b"[1, 2, 1]")), ["JSON object"]),
    "a flood of inputs": (_after_hello(proto.encode_input((1, 2), 0) * 2000), ["messages a second"]),
}


@pytest.mark.parametrize("case", BAD_CLIENTS, ids=list(BAD_CLIENTS))
def test_bad_client_gets_an_error_and_is_dropped_while_others_play_on(arena, clients, case):
    sends, hints = BAD_CLIENTS[case]
    bad = clients(arena.server.port)
    for data in sends:
        bad.send(data)
    sentence = bad.expect_error()
    for hint in hints:
        assert hint.lower() in sentence.lower(), f"{hint!r} not in {sentence!r}"
    assert len(sentence.split()) >= 6 and (";" in sentence or ":" in sentence), "a sentence with a hint"
    bad.close()
    wait_until(lambda: arena.server.connection_count == 1, what="the bad connection to be gone")
    assert arena.server.player_names() == [arena.honest.name]
    arena.honest.assert_alive()


FIELDS = st.sampled_from(["protocol", "name", "password", "cursor_m", "button", "keys"])
json_like = st.recursive(
    st.none() | st.booleans() | st.integers() | st.floats() | st.text(max_size=8),
    lambda inner: st.lists(inner, max_size=3) | st.dictionaries(FIELDS, inner, max_size=4),
    max_leaves=10,
)
fuzz_chunks = st.lists(
    st.one_of(
        st.binary(max_size=40),
        st.builds(frame, st.integers(0, 255), st.binary(max_size=40)),
        st.builds(lambda t, v: frame(t, json.dumps(v).encode()), st.sampled_from([1, 4, 6]), json_like),
        st.just(proto.encode_hello()),
        st.builds(
            proto.encode_input,
            st.tuples(st.floats(-5, 15), st.floats(-5, 15)),
            st.integers(0, 3),
            st.lists(st.text(min_size=1, max_size=3), max_size=3),
        ),
    ),
    max_size=6,
)


def test_fuzz_random_frames_and_bytes_never_hurt_the_honest_client(arena):
    @given(fuzz_chunks)
    @settings(max_examples=80, deadline=None, suppress_health_check=list(HealthCheck))
    def throw(chunks):
        c = RawClient(arena.server.port)
        try:
            for data in chunks:
                if not c.send(data):
                    break
        finally:
            c.close()
        wait_until(lambda: arena.server.connection_count == 1, what="the fuzz connection to be gone")

    throw()
    assert arena.server.player_names() == [arena.honest.name]
    arena.honest.assert_alive()


def test_half_a_frame_then_silence_is_dropped_after_the_timeout(make_server, clients):
    server = make_server(timeout_s=0.3)
    c = clients(server.port)
    c.send(proto.encode_hello()[:7])
    sentence = c.expect_error()
    assert "0.3 s" in sentence and "join again" in sentence
    c.close()
    wait_until(lambda: server.connection_count == 0, what="the silent connection to be gone")


def test_password(make_server, clients):
    server = make_server(password="sesame")
    c = clients(server.port)
    c.send(proto.encode_hello("Ann"))
    assert "needs a password" in c.expect_error()
    c = clients(server.port)
    c.send(proto.encode_hello("Ann", "open sesame"))
    sentence = c.expect_error()
    assert "wrong password" in sentence and "--password" in sentence and "sesame" not in sentence
    assert clients(server.port).hello("Ann", "sesame").client == "C1 Ann"


def test_server_full_then_a_freed_name_is_reused(make_server, clients):
    server = make_server(max_clients=30)
    players = [clients(server.port) for _ in range(30)]
    assert [p.hello().client for p in players] == [f"C{n}" for n in range(1, 31)]
    late = clients(server.port)
    late.send(proto.encode_hello())
    sentence = late.expect_error()
    assert "server full" in sentence and "--max-clients" in sentence
    players[6].send(proto.encode_bye())
    wait_until(lambda: len(server.player_names()) == 29, what="C7 to leave")
    assert clients(server.port).hello().client == "C7"


# ---------------------------------------------------------------- slow clients and rates


def test_a_stalled_client_only_misses_snapshots(make_server, make_loop, clients):
    server = make_server(snapshot_hz=60)
    table = grid_table(60, 40)  # 2400 pucks: 65 KB snapshots fill a stalled socket fast
    loop = make_loop(server, table, fps=60)
    stalled = RawClient.__new__(RawClient)
    sock = socket.socket()
    sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
    sock.connect(("127.0.0.1", server.port))
    stalled.sock, stalled.reader, stalled.pending = sock, proto.FrameReader(proto.MAX_SERVER_FRAME), []
    try:
        stalled.hello()  # ...and then never reads again
        reader = clients(server.port)
        reader.hello()
        frames0 = loop.frames
        start = time.monotonic()
        received = 0
        while time.monotonic() - start < 1.0:
            if reader.next_frame()[0] == proto.SNAPSHOT:
                received += 1
        elapsed = time.monotonic() - start
        assert received >= 10, "the reading client still gets snapshots"
        assert loop.frames - frames0 >= 0.5 * 60 * elapsed, "the game loop never waited for the stalled client"
        assert server.connection_count == 2
        # The stalled socket really is full: the server holds a part-sent snapshot for it.
        assert any(conn.out_cur is not None for conn in server._conns.values())
    finally:
        sock.close()


def test_snapshots_are_capped_at_snapshot_hz(make_server, make_loop, clients):
    server = make_server(snapshot_hz=20)
    make_loop(server, one_puck_table(), fps=120)
    c = clients(server.port)
    c.hello()
    c.next_of(proto.SNAPSHOT)
    start = time.monotonic()
    count = 0
    while time.monotonic() - start < 1.0:
        if c.next_frame()[0] == proto.SNAPSHOT:
            count += 1
    assert count <= 20 * (time.monotonic() - start) * 1.2 + 2


# ---------------------------------------------------------------- addresses and ports


def test_join_lines():
    assert GameServer(host="192.168.1.23").join_lines() == ["join with: airtable-client 192.168.1.23"]
    assert GameServer(host="10.0.0.5", port=9000).join_lines() == ["join with: airtable-client 10.0.0.5:9000"]
    lines = GameServer(host="0.0.0.0").join_lines()
    assert lines and all(line.startswith("join with: airtable-client ") for line in lines)
    assert all(not a.startswith("127.") for a in lan_addresses()) or lan_addresses() == ["127.0.0.1"]


def test_port_zero_picks_a_free_port_and_a_busy_port_says_so(make_server):
    server = make_server()
    assert server.port > 0
    assert server.join_lines() == [f"join with: airtable-client 127.0.0.1:{server.port}"]
    with pytest.raises(OSError) as err:
        GameServer(host="127.0.0.1", port=server.port).start()
    assert "already in use" in str(err.value) and "--port" in str(err.value)


def test_stop_says_bye_and_closes(make_server, make_loop, clients):
    server = make_server()
    c = clients(server.port)
    c.hello()
    server.stop()
    frames = []
    while (got := c.next_frame()) is not None:
        frames.append(got[0])
    assert frames[-1:] == [proto.BYE]


def test_load_tool_measures_a_small_run(make_server, make_loop):
    server = make_server()
    make_loop(server, grid_table(), fps=60)
    result = run_load("127.0.0.1", server.port, clients=3, seconds=1.0)
    assert result.connected == 3 and len(result.snapshot_rates) == 3
    assert result.latencies_s and all(0 <= t < WAIT_S for t in result.latencies_s)
    assert result.baseline_fps > 0 and result.loaded_fps
    report = result.report()
    assert "p50" in report and "p99" in report and "snapshots/s" in report and "verdict" in report
    wait_until(lambda: server.connection_count == 0, what="the load players to leave")
