"""GameServer: lets students join the teacher's table over the LAN.

One network thread runs a `selectors` loop over every socket. It turns bytes
into validated, immutable `InputRecord`s and keeps only the newest one per
player (plus any button change since the last frame, so a quick click is not
lost); it never touches the table (STYLE.md item 12). The game loop calls

    server.apply_inputs(clients, table)   # before each step: joins, newest inputs, leaves
    server.publish(scene)        # every frame: at most snapshot_hz snapshots a second

and neither call ever waits on a socket. A snapshot is encoded once and the
same bytes go to every player; a player whose connection is slow keeps only
the newest snapshot waiting, so it misses frames instead of slowing anyone.

A client that breaks the protocol gets an ERROR with a sentence it can act on
and is dropped; nobody else notices.
"""

from __future__ import annotations

import colorsys
import errno
import hmac
import logging
import math
import selectors
import socket
import threading
import time
from collections import deque

from airtable.app.client import Client
from airtable.app.scene import Scene
from airtable.colors import rgb
from airtable.net import protocol as proto

log = logging.getLogger("airtable.net")

# The course's client colours, for C1..C10; later players get generated hues.
COURSE_COLORS = (
    "maroon1",
    "tan",
    "cyan",
    "palegreen3",
    "pink",
    "gold",
    "coral",
    "palevioletred2",
    "peachpuff",
    "rosybrown3",
)

DEFAULT_TABLE_SIZE_M = (10.0, 8.7556)  # until the game loop tells us the real size
LINGER_S = 2.0  # after an ERROR: time to let it reach the client before closing
RATE_PER_S = 240.0  # sustained messages a second per client (a player sends <= 61)
RATE_BURST = 480.0
EXTRA_CONNECTIONS = 32  # connections still saying HELLO, beyond max_clients
RECV_BYTES = 65536
MAX_QUEUED_INPUTS = 6  # records kept per player between two frames (see _queue_input)


def client_color(number: int) -> tuple[int, int, int]:
    """The colour of player C<number>: the course's ten, then well-spread hues.

    Hues step by the golden angle, so any number of them stay far apart; hues
    near green are skipped because green is the local user's colour.
    """
    if number < 1:
        raise ValueError("player numbers start at 1")
    if number <= len(COURSE_COLORS):
        return rgb(COURSE_COLORS[number - 1])
    wanted = number - len(COURSE_COLORS)
    j = 0
    while True:
        j += 1
        hue = (j * 0.6180339887498949) % 1.0
        if abs(hue - 1 / 3) < 0.07:
            continue
        wanted -= 1
        if wanted == 0:
            # Vary brightness a little with each lap round the colour wheel.
            value = 1.0 - 0.15 * ((j // 12) % 3)
            r, g, b = colorsys.hsv_to_rgb(hue, 0.7, value)
            return (round(r * 255), round(g * 255), round(b * 255))


def lan_addresses() -> list[str]:
    """This machine's IPv4 LAN addresses, without any network traffic.

    Uses the host name's addresses plus the address the OS would route private
    networks from (connecting a UDP socket sends no packet). Falls back to
    127.0.0.1 when the machine has no network.
    """
    found: list[str] = []
    try:
        for info in socket.getaddrinfo(socket.gethostname(), None, socket.AF_INET, socket.SOCK_STREAM):
            found.append(str(info[4][0]))
    except OSError:
        pass
    for probe in ("10.255.255.255", "172.31.255.255", "192.168.255.255"):
        try:
            with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
                s.connect((probe, 9))
                found.append(s.getsockname()[0])
        except OSError:
            continue
    usable = [a for a in dict.fromkeys(found) if not a.startswith(("127.", "0.", "169.254."))]
    return usable or ["127.0.0.1"]


class _Conn:
    """One connection, owned by the network thread."""

    HELLO, PLAYING, CLOSING = "hello", "playing", "closing"

    def __init__(self, cid: int, sock: socket.socket, peer: str, now: float) -> None:
        self.cid = cid
        self.sock = sock
        self.peer = peer
        self.reader = proto.FrameReader(proto.MAX_CLIENT_FRAME, proto.CLIENT_FRAMES, sender="a client")
        self.state = self.HELLO
        self.number = 0  # player number n of "Cn", 0 before WELCOME
        self.name = ""
        self.last_rx = now
        self.tokens = RATE_BURST
        self.tokens_t = now
        self.out_cur: memoryview | None = None  # the frame being sent
        self.out_ctrl: deque[bytes] = deque()  # WELCOME / ERROR / BYE, before any snapshot
        self.out_snap: bytes | None = None  # the newest snapshot not yet started
        self.shut = False  # our side is shut down after an ERROR
        self.deadline = math.inf
        self.events = selectors.EVENT_READ

    @property
    def who(self) -> str:
        return f"{self.name} ({self.peer})" if self.name else self.peer

    def has_output(self) -> bool:
        return self.out_cur is not None or bool(self.out_ctrl) or self.out_snap is not None


class GameServer:
    """The table's network server; see the module docstring for how the game loop uses it."""

    def __init__(
        self,
        host: str = "0.0.0.0",
        port: int = proto.DEFAULT_PORT,
        password: str | None = None,
        max_clients: int = 30,
        snapshot_hz: float = 30.0,
        timeout_s: float = 10.0,
    ) -> None:
        if not 0 <= int(port) <= 65535:
            raise ValueError(f"port must be 0-65535, not {port!r}")
        if not 1 <= int(max_clients) <= 1000:
            raise ValueError(f"max_clients must be 1-1000, not {max_clients!r}")
        if not (math.isfinite(snapshot_hz) and 0 < snapshot_hz <= 1000):
            raise ValueError(f"snapshot_hz must be a rate above 0 and at most 1000, not {snapshot_hz!r}")
        if not (math.isfinite(timeout_s) and timeout_s > 0):
            raise ValueError(f"timeout_s must be a positive number of seconds, not {timeout_s!r}")
        if password is not None and not password:
            password = None
        self.host = host
        self.port = int(port)
        self.password = password
        self.max_clients = int(max_clients)
        self.snapshot_hz = float(snapshot_hz)
        self.timeout_s = float(timeout_s)

        # Shared between the network thread and the game loop, under _lock.
        self._lock = threading.Lock()
        self._events: list[tuple] = []  # ("join", cid, name, color) / ("leave", cid)
        self._inputs: dict[int, list[proto.InputRecord]] = {}  # per connection, see _queue_input
        self._snapshot: bytes | None = None  # newest SNAPSHOT frame
        self._snapshot_seq = 0
        self._names: dict[int, str] = {}  # player number -> name, for player_names()
        self._table_size_m: tuple[float, float] = DEFAULT_TABLE_SIZE_M  # plain tuple: replaced, never mutated

        # Game loop only.
        self._clients: dict[int, Client] = {}
        self._next_publish = 0.0

        # Network thread only.
        self._conns: dict[int, _Conn] = {}
        self._numbers: dict[int, int] = {}  # player number -> cid
        self._sent_seq = 0
        self._next_cid = 1

        self._listener: socket.socket | None = None
        self._selector: selectors.BaseSelector | None = None
        self._wake_r: socket.socket | None = None
        self._wake_w: socket.socket | None = None
        self._thread: threading.Thread | None = None
        self._stopping = threading.Event()
        self._join_lines: tuple[int, list[str]] | None = None

    # ---------------------------------------------------------------- lifecycle

    def start(self) -> None:
        """Bind, listen and start the network thread (port 0 picks a free port)."""
        if self._thread is not None:
            raise RuntimeError("the server is already started")
        self._listener = self._bind()
        self._stopping.clear()
        self.port = self._listener.getsockname()[1]
        self._wake_r, self._wake_w = socket.socketpair()
        self._wake_r.setblocking(False)
        self._wake_w.setblocking(False)
        self._selector = selectors.DefaultSelector()
        self._selector.register(self._listener, selectors.EVENT_READ, "listen")
        self._selector.register(self._wake_r, selectors.EVENT_READ, "wake")
        self._thread = threading.Thread(target=self._run, name="airtable-server", daemon=True)
        self._thread.start()
        log.info("airtable server listening on %s port %d", self.host or "0.0.0.0", self.port)

    def _bind(self) -> socket.socket:
        host = self.host or "0.0.0.0"
        where = f"{host}:{self.port}"
        try:
            family, kind, proto, _, addr = socket.getaddrinfo(
                host, self.port, 0, socket.SOCK_STREAM, 0, socket.AI_PASSIVE
            )[0]
        except OSError as e:
            raise OSError(
                e.errno, f"cannot listen on {host!r}: it is not an address of this computer; try --host 0.0.0.0"
            ) from e
        sock = socket.socket(family, kind, proto)
        try:
            if hasattr(socket, "SO_EXCLUSIVEADDRUSE"):  # Windows: SO_REUSEADDR would let two servers share a port
                sock.setsockopt(socket.SOL_SOCKET, socket.SO_EXCLUSIVEADDRUSE, 1)
            else:  # POSIX: allows a quick restart while old connections linger in TIME_WAIT
                sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
            sock.bind(addr)
            sock.listen(64)
            sock.setblocking(False)
        except OSError as e:
            sock.close()
            if e.errno in (errno.EADDRINUSE, getattr(errno, "WSAEADDRINUSE", -1)):
                msg = (
                    f"port {self.port} is already in use on {host}: is another airtable server running? "
                    "Stop it or pick another port with --port"
                )
            elif e.errno in (errno.EACCES, errno.EPERM):
                msg = f"not allowed to listen on {where}; use a port above 1023 with --port"
            elif e.errno == errno.EADDRNOTAVAIL:
                msg = f"{host} is not an address of this computer; use --host 0.0.0.0 to listen on all of them"
            else:
                msg = f"cannot listen on {where}: {e.strerror or e}"
            raise OSError(e.errno, msg) from e
        return sock

    def stop(self) -> None:
        """Say BYE to every player, close every socket and join the network thread."""
        if self._thread is None:
            return
        self._stopping.set()
        self._wake()
        self._thread.join(timeout=5.0)
        if self._thread.is_alive():  # should not happen; do not leave sockets behind anyway
            log.warning("the network thread did not stop in time")
        for conn in list(self._conns.values()):
            self._close(conn)
        for sock in (self._listener, self._wake_r, self._wake_w):
            if sock is not None:
                sock.close()
        if self._selector is not None:
            self._selector.close()
        self._thread = None
        self._listener = self._wake_r = self._wake_w = None
        self._selector = None

    def __enter__(self) -> GameServer:
        self.start()
        return self

    def __exit__(self, *exc) -> None:
        self.stop()

    @property
    def running(self) -> bool:
        return self._thread is not None and not self._stopping.is_set()

    def join_lines(self) -> list[str]:
        """What students type to join, e.g. ["join with: airtable-client 192.168.1.23"].

        Worked out once per port and cached, since the app may ask every frame."""
        if self._join_lines is None or self._join_lines[0] != self.port:
            self._join_lines = (self.port, self._make_join_lines())
        return list(self._join_lines[1])

    def _make_join_lines(self) -> list[str]:
        host = self.host or "0.0.0.0"
        hosts = lan_addresses() if host in ("0.0.0.0", "::", "") else [host]
        lines = []
        for h in hosts:
            if self.port != proto.DEFAULT_PORT:
                h = f"[{h}]:{self.port}" if ":" in h else f"{h}:{self.port}"
            lines.append(f"join with: airtable-client {h}")
        return lines

    @property
    def connection_count(self) -> int:
        """Open connections, including ones still saying HELLO or being closed."""
        return len(self._conns)

    def player_names(self) -> list[str]:
        """Names of the players now welcomed, in player-number order."""
        with self._lock:
            return [self._names[n] for n in sorted(self._names)]

    # ---------------------------------------------------------------- game loop side

    def apply_inputs(self, clients: list[Client], table) -> None:
        """Main thread, before each step: add joined players' Clients to `clients`,
        apply each player's newest input (after any button change it skipped over),
        remove departed players' Clients. Never blocks on the network (the lock is
        only held to swap two containers)."""
        self._table_size_m = (float(table.width_m), float(table.height_m))
        with self._lock:
            events, self._events = self._events, []
            inputs, self._inputs = self._inputs, {}
        for event in events:
            if event[0] == "join":
                _, cid, name, color = event
                # Hidden until its first INPUT says where its cursor is.
                client = Client(name=name, color=color, active=False)
                self._clients[cid] = client
                clients.append(client)
            else:
                client = self._clients.pop(event[1], None)
                if client is not None:
                    client.release()
                    client.active = False
                    if client in clients:  # by identity: Client has eq=False
                        clients.remove(client)
        for cid, records in inputs.items():
            client = self._clients.get(cid)
            if client is not None:
                for record in records:
                    client.set_input(table, record.cursor_m, record.button, record.keys)
                client.active = True

    def publish(self, scene: Scene) -> None:
        """Main thread, every frame: at most snapshot_hz times a second, encode `scene`
        once and hand the bytes to every player's sender. Never blocks."""
        if not self.running:
            return
        now = time.monotonic()
        period = 1.0 / self.snapshot_hz
        # A little slack, so a 30 Hz rate from a 60 fps loop is every other
        # frame even when frames come a millisecond early.
        if now < self._next_publish - min(0.004, period / 4):
            return
        self._next_publish = max(self._next_publish + period, now)
        self._table_size_m = (float(scene.width_m), float(scene.height_m))
        if not self._names:
            return  # nobody to send to; encoding would be wasted work
        frame = proto.encode_frame(proto.SNAPSHOT, proto.encode_snapshot(scene))
        with self._lock:
            self._snapshot = frame
            self._snapshot_seq += 1
        self._wake()

    def _wake(self) -> None:
        try:
            if self._wake_w is not None:
                self._wake_w.send(b"\0")
        except OSError:
            pass  # already awake (the buffer is full) or shutting down

    # ---------------------------------------------------------------- network thread

    def _run(self) -> None:
        sel = self._selector
        assert sel is not None
        next_check = 0.0
        while not self._stopping.is_set():
            try:
                ready = sel.select(timeout=0.1)
            except OSError:  # selector closed under us during stop
                break
            for key, mask in ready:
                try:
                    if key.data == "listen":
                        self._accept()
                    elif key.data == "wake":
                        self._drain_wake()
                        self._distribute_snapshot()
                    else:
                        conn: _Conn = key.data
                        if mask & selectors.EVENT_READ and conn.cid in self._conns:
                            self._on_readable(conn)
                        if mask & selectors.EVENT_WRITE and conn.cid in self._conns:
                            self._flush(conn)
                except Exception:  # a bug must cost one connection, not the whole server
                    log.exception("network error")
                    if isinstance(key.data, _Conn) and key.data.cid in self._conns:
                        self._close(key.data)
            now = time.monotonic()
            if now >= next_check:
                next_check = now + 0.1
                self._check_timeouts(now)
        self._say_bye()

    def _accept(self) -> None:
        assert self._listener is not None
        for _ in range(64):  # a bounded batch, so a connection flood cannot starve the loop
            try:
                sock, addr = self._listener.accept()
            except (BlockingIOError, InterruptedError):
                return
            except OSError as e:  # e.g. out of file descriptors: try again on the next round
                log.warning("cannot accept a connection: %s", e)
                time.sleep(0.01)
                return
            peer = f"{addr[0]}:{addr[1]}"
            sock.setblocking(False)
            sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
            if len(self._conns) >= self.max_clients + EXTRA_CONNECTIONS:
                try:
                    sock.send(proto.encode_error(self._full_sentence()))
                except OSError:
                    pass
                sock.close()
                log.info("refused %s: too many connections", peer)
                continue
            conn = _Conn(self._next_cid, sock, peer, time.monotonic())
            self._next_cid += 1
            self._conns[conn.cid] = conn
            assert self._selector is not None
            self._selector.register(sock, conn.events, conn)

    def _drain_wake(self) -> None:
        assert self._wake_r is not None
        try:
            while self._wake_r.recv(4096):
                pass
        except (BlockingIOError, InterruptedError):
            pass

    def _distribute_snapshot(self) -> None:
        with self._lock:
            frame, seq = self._snapshot, self._snapshot_seq
        if frame is None or seq == self._sent_seq:
            return
        self._sent_seq = seq
        for conn in list(self._conns.values()):
            if conn.state == _Conn.PLAYING:
                conn.out_snap = frame  # replaces an older one that never started
                self._flush(conn)

    def _on_readable(self, conn: _Conn) -> None:
        try:
            data = conn.sock.recv(RECV_BYTES)
        except (BlockingIOError, InterruptedError):
            return
        except OSError:  # reset by the peer
            self._close(conn)
            return
        if not data:
            if conn.state != _Conn.CLOSING:
                log.info("%s left", conn.who)
            self._close(conn)
            return
        if conn.state == _Conn.CLOSING:
            return  # reading only so that closing does not reset the connection
        try:
            frames = conn.reader.feed(data)
            now = time.monotonic()
            for frame_type, payload in frames:
                conn.last_rx = now
                self._check_rate(conn, now)
                self._handle(conn, frame_type, payload)
                if conn.state == _Conn.CLOSING or conn.cid not in self._conns:
                    return
        except proto.ProtocolError as e:
            self._fail(conn, str(e))

    def _check_rate(self, conn: _Conn, now: float) -> None:
        conn.tokens = min(RATE_BURST, conn.tokens + (now - conn.tokens_t) * RATE_PER_S)
        conn.tokens_t = now
        conn.tokens -= 1.0
        if conn.tokens < 0:
            raise proto.ProtocolError(
                f"more than {RATE_PER_S:g} messages a second were received; a client sends at most 60 inputs a second"
            )

    def _handle(self, conn: _Conn, frame_type: int, payload: bytes) -> None:
        if frame_type == proto.BYE:
            log.info("%s said goodbye", conn.who)
            self._close(conn)
        elif frame_type == proto.HELLO:
            if conn.state != _Conn.HELLO:
                raise proto.ProtocolError("HELLO was sent twice; say HELLO once, then send INPUT")
            self._welcome(conn, proto.parse_hello(payload))
        elif frame_type == proto.INPUT:
            if conn.state != _Conn.PLAYING:
                raise proto.ProtocolError(
                    'INPUT came before HELLO; a client must first send HELLO like {"protocol": 1} and wait for WELCOME'
                )
            record = proto.parse_input(payload, self._table_size_m)
            with self._lock:
                self._queue_input(conn.cid, record)

    def _queue_input(self, cid: int, record: proto.InputRecord) -> None:
        """Keep the newest record, plus the first record after each button change.

        Motion between two frames collapses into the newest position, but a
        press (and where it happened) survives even when the press and the
        next move arrive within one frame, so a quick grab is not lost.
        """
        queue = self._inputs.get(cid)
        if queue is None:
            self._inputs[cid] = [record]
        elif len(queue) >= 2 and queue[-1].button == queue[-2].button == record.button:
            queue[-1] = record  # same run of one button: only its first and newest matter
        else:
            queue.append(record)
            if len(queue) > MAX_QUEUED_INPUTS:
                del queue[0]

    def _full_sentence(self) -> str:
        return (
            f"server full: all {self.max_clients} places are taken; try again when someone leaves, "
            "or ask the teacher to start the table with a higher --max-clients"
        )

    def _welcome(self, conn: _Conn, hello: proto.Hello) -> None:
        if self.password is not None:
            if hello.password is None:
                raise proto.ProtocolError(
                    "this table needs a password: ask the teacher for it and join with --password"
                )
            if not hmac.compare_digest(hello.password.encode("utf-8"), self.password.encode("utf-8")):
                raise proto.ProtocolError(
                    "wrong password: ask the teacher for the table's password and join again with --password"
                )
        if len(self._numbers) >= self.max_clients:
            raise proto.ProtocolError(self._full_sentence())
        number = 1
        while number in self._numbers:  # the lowest free number, so names get reused
            number += 1
        name = f"C{number}" + (f" {hello.name}" if hello.name else "")
        color = client_color(number)
        conn.number, conn.name, conn.state = number, name, _Conn.PLAYING
        self._numbers[number] = conn.cid
        width_m, height_m = self._table_size_m
        conn.out_ctrl.append(proto.encode_welcome(name, color, width_m, height_m))
        with self._lock:
            self._names[number] = name
            self._events.append(("join", conn.cid, name, color))
            conn.out_snap = self._snapshot  # the newest picture straight away, if there is one
        log.info("%s joined from %s", name, conn.peer)
        self._flush(conn)

    def _release_slot(self, conn: _Conn) -> None:
        """Forget the player behind `conn` (its Client goes at the next apply_inputs)."""
        if conn.number and self._numbers.get(conn.number) == conn.cid:
            del self._numbers[conn.number]
            with self._lock:
                self._names.pop(conn.number, None)
                self._inputs.pop(conn.cid, None)
                self._events.append(("leave", conn.cid))
                if not self._names:
                    # publish() stops encoding when nobody plays: do not greet the
                    # next player with a picture from long ago.
                    self._snapshot = None
        conn.number = 0

    def _fail(self, conn: _Conn, sentence: str) -> None:
        """Send ERROR `sentence`, then close once it is out (or after LINGER_S)."""
        log.info("dropped %s: %s", conn.who, sentence)
        self._release_slot(conn)
        conn.state = _Conn.CLOSING
        conn.out_snap = None
        conn.out_ctrl.append(proto.encode_error(sentence))
        conn.deadline = time.monotonic() + LINGER_S
        self._flush(conn)

    def _flush(self, conn: _Conn) -> None:
        """Send what the socket takes now; wait for EVENT_WRITE for the rest."""
        while not conn.shut:
            if conn.out_cur is None:
                # Control frames first; frames are never interleaved, because the
                # next one starts only when out_cur is fully sent.
                if conn.out_ctrl:
                    conn.out_cur = memoryview(conn.out_ctrl.popleft())
                elif conn.out_snap is not None:
                    conn.out_cur, conn.out_snap = memoryview(conn.out_snap), None
                else:
                    break
            try:
                sent = conn.sock.send(conn.out_cur)
            except (BlockingIOError, InterruptedError):
                break
            except OSError:
                self._close(conn)
                return
            conn.out_cur = conn.out_cur[sent:] if sent < len(conn.out_cur) else None
        if conn.state == _Conn.CLOSING and not conn.shut and not conn.has_output():
            # The ERROR is out: shut our side and read until the client hangs up,
            # so that unread client bytes do not turn the close into a reset
            # that could discard the ERROR before the client reads it.
            conn.shut = True
            try:
                conn.sock.shutdown(socket.SHUT_WR)
            except OSError:
                self._close(conn)
                return
        events = selectors.EVENT_READ
        if conn.has_output() and not conn.shut:
            events |= selectors.EVENT_WRITE
        if events != conn.events and self._selector is not None:
            conn.events = events
            self._selector.modify(conn.sock, events, conn)

    def _check_timeouts(self, now: float) -> None:
        for conn in list(self._conns.values()):
            if conn.state == _Conn.CLOSING:
                if now > conn.deadline:
                    self._close(conn)
            elif now - conn.last_rx > self.timeout_s:
                self._fail(
                    conn,
                    f"nothing complete was received for {self.timeout_s:g} s (a client sends at least one INPUT "
                    "a second), so the connection was closed; check the network and join again",
                )

    def _close(self, conn: _Conn) -> None:
        self._release_slot(conn)
        self._conns.pop(conn.cid, None)
        if self._selector is not None:
            try:
                self._selector.unregister(conn.sock)
            except (KeyError, ValueError):
                pass
        conn.sock.close()

    def _say_bye(self) -> None:
        """Best effort: tell players the server is going, so they show 'server gone'."""
        bye = proto.encode_bye()
        for conn in list(self._conns.values()):
            if conn.state == _Conn.PLAYING and conn.out_cur is None:
                try:
                    conn.sock.send(bye)
                except OSError:
                    pass
