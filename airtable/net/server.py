"""GameServer: lets students join the teacher's table over the LAN.

One network thread runs a `selectors` loop over every socket. It turns bytes
into validated, immutable event records (airtable/net/events.py) and never
touches the table or the loop's clients. The game loop calls, every frame:

    server.update_clients(clients, table)  # joins, leaves, newest inputs (even while paused)
    server.publish(scene)                  # after the physics steps: at most snapshot_hz a second

and neither call ever waits on a socket. Each snapshot tick is coded against
what each player holds (snapshot format 2, codec.py), once per distinct base
and shared; players are served in turn and paced (pacing.py), so a slow
connection misses ticks instead of slowing anyone, and on a tight link every
player's rate drops evenly.

Joining is guarded (see gate.py): handshakes have their own cap and a short
deadline, one computer may hold only a few handshakes and seats, and wrong
passwords earn a growing wait. When every handshake slot is taken, the
address holding the most gives its oldest up to a newcomer (`_make_room`),
so many addresses dribbling HELLOs cannot keep an honest student out. A
client that asks for its seat back proves its token (CHALLENGE, PROOF;
identity.py). A client that breaks the protocol gets an
ERROR with a sentence it can act on and is dropped; nobody else notices.
The teacher sees the seats with `roster()` and can `remove()` a player.
"""

from __future__ import annotations

import colorsys
import contextlib
import errno
import hmac
import logging
import math
import selectors
import socket
import struct
import threading
import time
from collections.abc import Callable

from airtable.model.client import Client
from airtable.model.scene import Scene
from airtable.model.seats import Seat
from airtable.net import datagrams, pacing
from airtable.net import protocol as proto
from airtable.net.codec import SnapshotEncoder
from airtable.net.connection import Connection, State
from airtable.net.events import EventQueue, PlayerInput, PlayerJoined, PlayerLeft
from airtable.net.gate import FIRST_PASSWORD_WAIT_S, HANDSHAKES_PER_ADDRESS, PLAYERS_PER_ADDRESS, Gate, QuietLog
from airtable.net.identity import SeatTokens, new_nonce
from airtable.net.names import distinct_name
from airtable.net.predictions import MAX_ROUND_PUCKS, PredictionBook, RoundInfo, encode_round, parse_predict
from airtable.net.seats import HOLD_S, HeldSeats
from airtable.physics.colors import rgb

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

HELLO_TIMEOUT_S = 3.0  # a connection must be welcomed this soon after it opens
SLOW_HELLO_S = 12.0  # or this soon, on a slow link (pacing.link_is_slow)
MAX_HANDSHAKES = 32  # connections still saying HELLO, beyond the players
MAX_PLAYERS = 1000
MAX_SNAPSHOT_HZ = 1000.0
SELECT_SOCKETS = 500  # select() watches at most 512 sockets on Windows (1024 fds on POSIX)
RESERVED_FDS = 32  # descriptors kept for the app itself (files, the display, the listener)
FAR_OFF_TABLES = 1.0  # a cursor this many table sizes beyond the edge is "far off" in the roster
ACCEPT_PAUSE_S = 0.5  # out of descriptors: stop accepting for this long
NOTICE_S = 60.0  # the projector shows why students were turned away for this long after the last one
# A seat's connection heard from this recently is in use: a client proving that seat's token is told so and
# asks again (a live client sends at least once a second). Older, it is stale (a laptop whose Wi-Fi dropped
# comes back before the server noticed): the newcomer takes the seat over. Taken over at once, two live
# windows of one student on one computer (a token they shared: seat_memory.py) took it from each other
# twice a second, without end (a user test).
IN_USE_S = 2.5
# What the newcomer is told meanwhile ({}: the seat's label and name, "C1 Ann"): a second window of the same
# student, or someone else of that name on the same computer (one seat memory; a user test).
IN_USE = (
    "{} is playing in another window; close one, or join with another --name if that is not you"
    " (this one asks again by itself)"
)


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


def _on_table(cursor_m, size_m: tuple[float, float]) -> bool:
    """Whether a cursor is on a table of `size_m` (its edge included)."""
    x, y = cursor_m
    return 0.0 <= x <= size_m[0] and 0.0 <= y <= size_m[1]


def lan_addresses() -> list[str]:
    """This machine's IPv4 LAN addresses, without any network traffic.

    Uses the host name's addresses plus the address the OS would route private
    networks from (connecting a UDP socket sends no packet); with no route, the
    interfaces' addresses. Falls back to 127.0.0.1 when the machine has no network.
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

    def usable(addresses: list[str]) -> list[str]:  # once each, without loopback and link-local ones
        return [a for a in dict.fromkeys(addresses) if not a.startswith(("127.", "0.", "169.254."))]

    # With no route out (a classroom network or a hotspot with no internet), each interface's address.
    return usable(found) or usable(interface_addresses()) or ["127.0.0.1"]


SIOCGIFADDR = 0x8915  # Linux's ioctl for an interface's IPv4 address


def interface_addresses() -> list[str]:
    """The IPv4 address of each network interface (Linux; elsewhere none): what lan_addresses falls
    back on when no route says which one faces the class."""
    try:
        import fcntl

        names = [name for _, name in socket.if_nameindex()]
    except (ImportError, OSError, AttributeError):
        return []
    found = []
    with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as s:
        for name in names:
            try:
                answer = fcntl.ioctl(s.fileno(), SIOCGIFADDR, struct.pack("256s", name.encode()[:15]))
            except OSError:
                continue  # no IPv4 address on this one
            found.append(socket.inet_ntoa(answer[20:24]))
    return found


def validate_server_options(
    port: int = proto.DEFAULT_PORT,
    max_clients: int = 30,
    snapshot_hz: float = 30.0,
    timeout_s: float = 10.0,
    error: Callable[[str], object] | None = None,
) -> None:
    """Raise ValueError with a one-line sentence if GameServer would refuse these.

    With `error` (e.g. an ArgumentParser's error), call it with the sentence instead,
    so a command line refuses exactly what the server would."""
    try:
        _check_options(port, max_clients, snapshot_hz, timeout_s)
    except ValueError as e:
        if error is None:
            raise
        error(str(e))


def _check_options(port: int, max_clients: int, snapshot_hz: float, timeout_s: float) -> None:
    if not 0 <= int(port) <= 65535:
        raise ValueError(f"the port must be 0-65535, not {port!r}")
    if not 1 <= int(max_clients) <= MAX_PLAYERS:
        raise ValueError(f"--max-clients must be 1-{MAX_PLAYERS}, not {max_clients!r}")
    # At least one a second: a student's window takes 10 s without a snapshot for a table gone.
    if not (math.isfinite(snapshot_hz) and 1 <= snapshot_hz <= MAX_SNAPSHOT_HZ):
        raise ValueError(f"--snapshot-hz must be 1-{MAX_SNAPSHOT_HZ:g} a second, not {snapshot_hz!r}")
    if not (math.isfinite(timeout_s) and timeout_s > 0):
        raise ValueError(f"the timeout must be a positive number of seconds, not {timeout_s!r}")


def connection_room(selector_class: type, open_file_limit: int | None) -> int | None:
    """How many client sockets this process can watch at once (None: no known limit)."""
    room = None
    if issubclass(selector_class, selectors.SelectSelector):
        room = SELECT_SOCKETS
    if open_file_limit is not None and open_file_limit > 0:
        by_fds = max(1, open_file_limit - RESERVED_FDS)
        room = by_fds if room is None else min(room, by_fds)
    return room


def _open_file_limit() -> int | None:
    try:
        import resource
    except ImportError:  # Windows: select() is the limit there
        return None
    soft, _ = resource.getrlimit(resource.RLIMIT_NOFILE)
    return None if soft == resource.RLIM_INFINITY else int(soft)


def free_port_after(host: str, port: int, tries: int = 20) -> int | None:
    """The first port after `port` that `host` can listen on now (None if none of `tries` is free):
    what the teacher can start with instead of a busy one."""
    for candidate in range(port + 1, min(port + 1 + tries, 65536)):
        try:
            with socket.create_server((host, candidate)):
                return candidate
        except OSError:
            continue
    return None


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
        hello_timeout_s: float = HELLO_TIMEOUT_S,
        max_handshakes: int = MAX_HANDSHAKES,
        handshakes_per_address: int = HANDSHAKES_PER_ADDRESS,
        players_per_address: int = PLAYERS_PER_ADDRESS,
        limit_loopback: bool = False,
        password_wait_s: float = FIRST_PASSWORD_WAIT_S,
        token_key: bytes | None = None,
        name_refusal: Callable[[str], str | None] | None = None,
        seat_hold_s: float = HOLD_S,
    ) -> None:
        validate_server_options(port, max_clients, snapshot_hz, timeout_s)
        self.host = host
        self.port = int(port)
        self.password = password or None
        self.max_clients = int(max_clients)
        self.snapshot_hz = float(snapshot_hz)
        self.timeout_s = float(timeout_s)
        self.hello_timeout_s = float(hello_timeout_s)
        self.max_handshakes = int(max_handshakes)
        self.failure: str | None = None  # set when the network thread died: a sentence for the teacher
        self.hands_off = False  # game loop: every student's string lets go, their input is ignored
        self.floor: int | None = None  # game loop: only player C<floor> acts (None: everyone); see may_act
        self._tokens = SeatTokens(token_key)  # the same key after a restart: the same seats
        # Shared between the network thread and the game loop.
        self._events = EventQueue()
        self._lock = threading.Lock()  # guards the fields below
        self._encoder = SnapshotEncoder()  # has its own lock
        self._snapshot_seq = 0
        self._names: dict[int, str] = {}  # player number -> name, for player_names()
        self._roster: tuple[Seat, ...] = ()
        self._away: tuple[tuple[str, float], ...] = ()  # held seats (the network thread writes, under _lock)
        self._commands: list[Callable[[], None]] = []  # from the game loop, run by the network thread
        self._table_size_m: tuple[float, float] = proto.DEFAULT_TABLE_SIZE_M  # plain tuple: replaced, never mutated
        self.predictions = PredictionBook()  # the predict-then-reveal round's guesses (has its own lock)
        self._round_frame: bytes | None = None  # the newest ROUND, for players who join during a round
        self._door_notice: tuple[str, float] = ("", 0.0)  # for the teacher, and until when (see join_lines)

        # Game loop only.
        self._clients: dict[int, Client] = {}
        self._seat_of: dict[int, int] = {}  # cid -> player number
        self._next_publish = 0.0

        self._gate = Gate(handshakes_per_address, players_per_address, limit_loopback, password_wait_s)
        self._name_refusal = name_refusal  # a name the teacher's screen cannot draw (app/glyphs.py), or None
        self._held = HeldSeats(seat_hold_s)  # seats of students who dropped, kept for their return (network thread)
        self._init_network_thread_state()

    def _init_network_thread_state(self) -> None:
        """What only the network thread touches, and the sockets it will open in start()."""
        self._conns: dict[int, Connection] = {}
        self._numbers: dict[int, int] = {}  # player number -> cid
        # Seat number -> the name it was last given to (HELLO's, "" for none): a token proves a seat only
        # while it is that student's (a student back after their seat went to another was told to wait for ever).
        self._owners: dict[int, str] = {}
        self._quiet = QuietLog(log)
        self._sent_seq = 0
        self._turns = pacing.RoundRobin()
        self._next_cid = 1
        self._accept_paused_until = 0.0
        self._listener: socket.socket | None = None
        self._udp: socket.socket | None = None  # input datagrams, on the listener's port (datagrams.py)
        self._selector: selectors.BaseSelector | None = None
        self._wake_r, self._wake_w = None, None  # a socketpair that wakes the network thread (made in start)
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
        self.failure = None
        self.port = self._listener.getsockname()[1]
        self._wake_r, self._wake_w = socket.socketpair()
        self._wake_r.setblocking(False)
        self._wake_w.setblocking(False)
        self._selector = selectors.DefaultSelector()
        self._selector.register(self._listener, selectors.EVENT_READ, "listen")
        self._selector.register(self._wake_r, selectors.EVENT_READ, "wake")
        self._udp = self._bind_udp()
        self._fit_to_room(connection_room(type(self._selector), _open_file_limit()))
        self._thread = threading.Thread(target=self._run, name="airtable-server", daemon=True)
        self._thread.start()
        log.info("airtable server listening on %s port %d", self.host or "0.0.0.0", self.port)

    def _fit_to_room(self, room: int | None) -> None:
        """Keep players plus handshakes below what this process can watch (one warning)."""
        if room is None or self.max_clients + self.max_handshakes <= room:
            return
        self.max_handshakes = max(1, min(self.max_handshakes, room // 10))
        wanted, self.max_clients = self.max_clients, max(1, room - self.max_handshakes)
        log.warning(
            "only %d of the %d players asked for can join: this computer can watch about %d connections "
            "(its open-file limit or select()); raise the limit with 'ulimit -n' or use a lower --max-clients",
            self.max_clients,
            wanted,
            room,
        )

    def _bind(self) -> socket.socket:
        host = self.host or "0.0.0.0"
        try:
            family, kind, protocol, _, addr = socket.getaddrinfo(
                host, self.port, 0, socket.SOCK_STREAM, 0, socket.AI_PASSIVE
            )[0]
        except OSError as e:
            raise OSError(
                e.errno, f"cannot listen on {host!r}: it is not an address of this computer; try --host 0.0.0.0"
            ) from e
        sock = socket.socket(family, kind, protocol)
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
            raise OSError(e.errno, self._bind_sentence(e, host)) from e
        return sock

    def _bind_sentence(self, e: OSError, host: str) -> str:
        if e.errno in (errno.EADDRINUSE, getattr(errno, "WSAEADDRINUSE", -1)):
            other = free_port_after(host, self.port)
            instead = f"start with --port {other}" if other else "pick another port with --port"
            # What to do first: a narrow window's line keeps its beginning.
            return f"{instead} (port {self.port} is already in use: another airtable?)"
        if e.errno in (errno.EACCES, errno.EPERM):
            return f"not allowed to listen on {host}:{self.port}; use a port above 1023 with --port"
        if e.errno == errno.EADDRNOTAVAIL:
            return f"{host} is not an address of this computer; use --host 0.0.0.0 to listen on all of them"
        return f"cannot listen on {host}:{self.port}: {e.strerror or e}"

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
            conn.close()
            self._settle(conn)
        for sock in (self._listener, self._wake_r, self._wake_w, self._udp):
            if sock is not None:
                sock.close()
        self._udp = None
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
        """Serving: started, not stopped, and the network thread has not failed (see `failure`)."""
        alive = self._thread is not None and self._thread.is_alive()
        return alive and not self._stopping.is_set() and self.failure is None

    def join_lines(self) -> list[str]:
        """What students type to join, e.g. ["join with: airtable-client 192.168.1.23"].

        Worked out once per port and cached, since the app may ask every frame."""
        if self._join_lines is None or self._join_lines[0] != self.port:
            self._join_lines = (self.port, self._make_join_lines())
        return list(self._join_lines[1])

    @property
    def door_notice(self) -> str | None:
        """For NOTICE_S after students were turned away per address, the line that says how to let
        them in (the projector shows it as an alert), else None."""
        with self._lock:
            notice, until = self._door_notice
        return notice if notice and time.monotonic() < until else None

    def _make_join_lines(self) -> list[str]:
        host = self.host or "0.0.0.0"
        hosts = lan_addresses() if host in ("0.0.0.0", "::", "") else [host]
        lines = []
        # The password itself never goes on the projector: the teacher says it.
        password = " --password (ask the teacher)" if self.password else ""
        for h in hosts:
            if self.port != proto.DEFAULT_PORT:
                h = f"[{h}]:{self.port}" if ":" in h else f"{h}:{self.port}"
            lines.append(f"join with: airtable-client {h}{password}")
        return lines

    # ---------------------------------------------------------------- the teacher's view

    @property
    def connection_count(self) -> int:
        """Open connections, including ones still saying HELLO or being closed."""
        return len(self._conns)

    @property
    def player_count(self) -> int:
        """Players now welcomed."""
        with self._lock:
            return len(self._names)

    @property
    def pending_events(self) -> int:
        """Event records waiting for the game loop's next update_clients (bounded)."""
        return len(self._events)

    def player_names(self) -> list[str]:
        """Names of the players now welcomed, in player-number order."""
        with self._lock:
            return [self._names[n] for n in sorted(self._names)]

    def roster(self) -> list[Seat]:
        """Every seat in player-number order (refreshed ten times a second)."""
        with self._lock:
            return list(self._roster)

    def away(self) -> list[tuple[str, float]]:
        """The students who dropped and whose seats are held for them: ("C3 Ann", seconds away), by seat."""
        with self._lock:
            return list(self._away)

    def remove(self, number: int, reason: str = "") -> bool:
        """Remove player C<number>, who gets an ERROR saying so; False if no such player."""
        with self._lock:
            if number not in self._names:
                return False
        sentence = "the teacher removed you from the table" + (f": {reason}" if reason else "")
        self._command(lambda: self._remove(number, sentence))
        return True

    def send_round(self, info: RoundInfo) -> None:
        """Game loop: tell every player (and each who joins later) where the prediction round is."""
        frame = encode_round(info)
        with self._lock:
            self._round_frame = frame if info.state != "closed" else None
        self._command(lambda: self._send_to_players(frame))

    def _send_to_players(self, frame: bytes) -> None:
        for conn in list(self._conns.values()):
            if conn.state == State.PLAYING:
                conn.send_control(frame)
                self._settle(conn)

    def _command(self, fn: Callable[[], None]) -> None:
        with self._lock:
            self._commands.append(fn)
        self._wake()

    # ---------------------------------------------------------------- game loop side

    def update_clients(self, clients: list[Client], table) -> None:
        """Game loop, every frame (paused or not): apply joins, leaves and inputs to `clients`.

        A joined player gets a Client (hidden until its first INPUT says where
        its cursor is); one that left lets go of its puck and is removed.
        `table` is where a pressed button grabs a puck. Never waits on the network."""
        self._table_size_m = (float(table.width_m), float(table.height_m))
        for event in self._events.take():
            match event:
                case PlayerJoined(cid, name, color, number):
                    client = Client(name=name, color=color, active=False)
                    self._clients[cid] = client
                    self._seat_of[cid] = number
                    clients.append(client)
                case PlayerLeft(cid):
                    self._seat_of.pop(cid, None)
                    client = self._clients.pop(cid, None)
                    if client is not None:
                        client.release()
                        client.active = False
                        if client in clients:  # by identity: Client has eq=False
                            clients.remove(client)
                case PlayerInput(cid, record):
                    client = self._clients.get(cid)
                    if client is not None:
                        button = record.button if self.may_act(self._seat_of.get(cid, 0)) else 0
                        client.set_input(table, record.cursor_m, button)  # INPUT's keys are not used
                        # A pointer off the table (outside the student's window, or never in it) is not
                        # shown: a user test saw twenty such names piled in the projector's corner.
                        client.active = bool(button) or _on_table(record.cursor_m, self._table_size_m)
        self._hold_back()

    def may_act(self, number: int) -> bool:
        """Whether player C<number>'s cursor may pull pucks now (hands off, or another has the floor)."""
        return not self.hands_off and (self.floor is None or self.floor == number)

    def _hold_back(self) -> None:
        """Players who may not act let go at once, even before their next input."""
        if not self.hands_off and self.floor is None:
            return
        for cid, client in self._clients.items():
            if client.button and not self.may_act(self._seat_of.get(cid, 0)):
                client.release()

    def apply_inputs(self, clients: list[Client], table) -> None:
        """The old name of update_clients, for game loops not yet moved over."""
        self.update_clients(clients, table)

    def publish(self, scene: Scene) -> None:
        """Game loop, after the frame's physics steps: at most snapshot_hz times a second,
        encode `scene` once and hand the bytes to every player's sender. Never blocks."""
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
        self._encoder.add(scene)
        with self._lock:
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
        """The network thread: serve until stop(); a failure is logged and shown, not silent."""
        try:
            self._serve()
        except Exception as exc:
            log.exception("the network thread failed")
            if self._listener is not None:  # new students get "refused" at once, not a hang
                self._listener.close()
            self.failure = (
                f"students can no longer join: the network thread failed ({type(exc).__name__}: {exc}); "
                "restart the app to let them in again"
            )
            for conn in list(self._conns.values()):
                conn.close()
                self._settle(conn)
            return
        self._say_bye()

    def _serve(self) -> None:
        sel = self._selector
        assert sel is not None
        next_check = 0.0
        while not self._stopping.is_set():
            held = [conn for conn in self._conns.values() if conn.held_back]
            try:
                ready = sel.select(timeout=pacing.RECHECK_S if held else 0.1)
            except OSError:  # the selector was closed under us during stop
                if self._stopping.is_set():
                    break
                raise
            for key, mask in ready:
                self._on_ready(key, mask)
            self._retry_held(held)
            now = time.monotonic()
            if now >= next_check:
                next_check = now + 0.1
                self._check_timeouts(now)
                self._refresh_roster(now)

    def _on_ready(self, key: selectors.SelectorKey, mask: int) -> None:
        if key.data == "listen":
            self._accept()
            return
        if key.data == "udp":
            self._on_datagrams()
            return
        if key.data == "wake":
            self._drain_wake()
            self._run_commands()
            self._distribute_snapshot()
            return
        conn: Connection = key.data
        try:
            if mask & selectors.EVENT_READ and not conn.closed:
                self._on_readable(conn)
            if mask & selectors.EVENT_WRITE and not conn.closed:
                conn.flush()
        except Exception:  # a bug must cost one connection, not the whole server
            log.exception("network error with %s", conn.who)
            conn.close()
        self._settle(conn)

    def _accept(self) -> None:
        assert self._listener is not None
        for _ in range(64):  # a bounded batch, so a connection flood cannot starve the loop
            try:
                sock, addr = self._listener.accept()
            except (BlockingIOError, InterruptedError):
                return
            except OSError as e:  # e.g. out of file descriptors: stop accepting for a moment
                self._quiet.note("cannot accept connections", "cannot accept a connection: %s", e)
                self._pause_accepting()
                return
            self._admit(sock, addr)

    def _pause_accepting(self) -> None:
        assert self._selector is not None and self._listener is not None
        self._selector.unregister(self._listener)
        self._accept_paused_until = time.monotonic() + ACCEPT_PAUSE_S

    def _admit(self, sock: socket.socket, addr: tuple) -> None:
        """A new connection: refuse it with a true sentence, or start its handshake."""
        sock.setblocking(False)
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        host = str(addr[0])
        refusal = self._gate.handshake_refusal(host)
        if len(self._numbers) >= self.max_clients:
            refusal = self._full_sentence()
        elif refusal is None and self._gate.handshakes_open >= self.max_handshakes and not self._make_room(host):
            refusal = self._busy_sentence()
        if refusal is not None:
            try:
                sock.send(proto.encode_error(refusal, retry=True))
            except OSError:
                pass
            sock.close()
            self._quiet.note(f"connections refused from {host}", "refused %s: %s", host, refusal)
            return
        assert self._selector is not None
        now = time.monotonic()
        conn = Connection(self._next_cid, sock, addr, now, self._selector)
        conn.deadline = now + self.hello_timeout_s
        self._next_cid += 1
        self._conns[conn.cid] = conn
        self._gate.handshake_started(host)

    def _busy_sentence(self) -> str:
        return (
            f"the table is busy: {self.max_handshakes} computers are joining at once; "
            "your client tries again by itself in a few seconds"
        )

    def _make_room(self, host: str) -> bool:
        """Every handshake slot is taken: drop one so that `host` may start, if that is fair.

        The oldest handshake of the address holding the most goes (gate.crowding); when no address
        holds more than `host` would, the oldest of all goes if it has used a third of its HELLO time
        (an honest HELLO takes a round trip, a dribbled one seconds). False: `host` must wait."""
        now = time.monotonic()
        crowded = self._gate.crowding(host)
        joining = [c for c in self._conns.values() if c.state == State.HELLO and crowded in (None, c.host)]
        oldest = min(joining, key=lambda c: c.opened, default=None)
        if oldest is None or (crowded is None and now - oldest.opened < self.hello_timeout_s / 3):
            return False
        self._fail(oldest, self._busy_sentence(), retry=True, quiet=True)
        self._settle(oldest)
        return True

    def _bind_udp(self) -> socket.socket | None:
        """A UDP socket on the listener's address and port, for input datagrams; None if it cannot be had
        (players then send every input over TCP)."""
        assert self._listener is not None and self._selector is not None
        address = self._listener.getsockname()
        sock = socket.socket(self._listener.family, socket.SOCK_DGRAM)
        try:
            sock.bind(address)
            sock.setblocking(False)
        except OSError as e:
            sock.close()
            log.warning("inputs come over TCP only: cannot listen for UDP on port %d (%s)", self.port, e)
            return None
        self._selector.register(sock, selectors.EVENT_READ, "udp")
        return sock

    def _on_datagrams(self) -> None:
        """Input datagrams: each from a welcomed player, signed with its session's key and newer than the
        last, is applied as its INPUT and acknowledged; anything else is dropped without a word."""
        assert self._udp is not None
        for _ in range(256):  # a bounded batch, so a flood cannot starve the TCP side
            try:
                data, sender = self._udp.recvfrom(datagrams.MAX_DATAGRAM + 1)
            except OSError:  # nothing more (or an ICMP error for an old ack)
                return
            d = datagrams.parse(data)
            conn = self._conns.get(self._numbers.get(d.number, -1)) if d is not None else None
            if conn is None or d.kind != datagrams.INPUT_DATAGRAM or not d.verify(conn.udp_key):
                continue
            now = time.monotonic()
            if d.sequence > conn.udp_sequence and conn.rate.spend(now, 1, len(data)) is None:
                try:
                    record = proto.parse_input(d.payload, self._table_size_m)
                except proto.ProtocolError:
                    continue
                conn.udp_sequence, conn.udp_at, conn.last_rx = d.sequence, now, now
                conn.note_input(record, now)
                self._events.input(conn.cid, record)
            with contextlib.suppress(OSError):
                self._udp.sendto(datagrams.encode_ack(conn.udp_key, d.number, d.sequence), sender)

    def _drain_wake(self) -> None:
        assert self._wake_r is not None
        try:
            while self._wake_r.recv(4096):
                pass
        except (BlockingIOError, InterruptedError):
            pass

    def _run_commands(self) -> None:
        with self._lock:
            commands, self._commands = self._commands, []
        for command in commands:
            command()

    def _distribute_snapshot(self) -> None:
        with self._lock:
            seq = self._snapshot_seq
        if seq == self._sent_seq:
            return
        self._sent_seq = seq
        now = time.monotonic()
        for conn in self._turns.order(list(self._conns.values())):
            conn.offer_tick(self._encoder, now)
            self._settle(conn)

    def _retry_held(self, held: list[Connection]) -> None:
        """Players whose tick waited for acknowledgements: send it if it may go now."""
        for conn in held:
            if not conn.closed and conn.held_back:
                conn.flush()
                self._settle(conn)

    def _on_readable(self, conn: Connection) -> None:
        now = time.monotonic()
        try:
            frames = conn.receive(now)
            if frames is None:
                if conn.state != State.CLOSING:
                    self._log_seat(conn, "leaves", "%s left", conn.who)
                conn.close()
                return
            for frame_type, payload in frames:
                self._handle(conn, frame_type, payload, now)
                if conn.state == State.CLOSING or conn.closed:
                    return
        except proto.ProtocolError as e:
            self._fail(conn, str(e))

    def _handle(self, conn: Connection, frame_type: int, payload: bytes, now: float) -> None:
        if frame_type == proto.BYE:
            self._log_seat(conn, "leaves", "%s said goodbye", conn.who)
            conn.keep_seat = False
            conn.close()
        elif frame_type == proto.HELLO:
            if conn.state != State.HELLO or conn.challenge is not None:
                raise proto.ProtocolError("HELLO was sent twice; say HELLO once, then send INPUT")
            self._hello(conn, proto.parse_hello(payload), now)
        elif frame_type == proto.PROOF:
            self._prove(conn, payload, now)
        elif frame_type == proto.INPUT:
            if conn.state != State.PLAYING:
                raise proto.ProtocolError(
                    'INPUT came before HELLO; a client must first send HELLO like {"protocol": 1} and wait for WELCOME'
                )
            record = proto.parse_input(payload, self._table_size_m)
            if not conn.inputs_by_udp(now):  # else a heartbeat: the datagrams carry newer cursors
                conn.note_input(record, now)
                self._events.input(conn.cid, record)
        elif frame_type == proto.PREDICT:
            self._predict(conn, payload)

    def _hello(self, conn: Connection, hello: proto.Hello, now: float) -> None:
        """A HELLO that asks for a seat back is challenged first; the token itself never comes (identity.py)."""
        if hello.seat is None:
            self._welcome(conn, hello, now)
            return
        conn.challenge = (hello, new_nonce())
        conn.send_control(proto.encode_challenge(conn.challenge[1]))

    def _prove(self, conn: Connection, payload: bytes, now: float) -> None:
        """The answer to our CHALLENGE: the seat is theirs if it is right; a wrong one is no seat, not an error."""
        if conn.challenge is None or conn.state != State.HELLO:
            raise proto.ProtocolError("PROOF came without a CHALLENGE; send PROOF only to answer one")
        (hello, nonce), conn.challenge = conn.challenge, None
        proof = proto.parse_proof(payload)
        assert hello.seat is not None  # only such a HELLO is challenged
        if self._tokens.proves(hello.seat, hello.name or "", nonce, proof):
            conn.proven_seat = hello.seat
        self._welcome(conn, hello, now)

    def _claimed_seat(self, conn: Connection, hello: proto.Hello, now: float) -> int | None:
        """The seat this client proved it holds: by a PROOF, or (older clients) by its token in clear; None
        if it has none, or if that seat has since been given to someone else who has it now (playing or
        held for their return): then this client is a newcomer."""
        number = conn.proven_seat
        if number is None:
            number = self._tokens.seat(hello.token, hello.name or "")
        if number is None or not (number in self._numbers or self._held.is_held(number, now)):
            return number  # (a free seat: its own again)
        return number if self._owners.get(number) == (hello.name or "") else None

    def _predict(self, conn: Connection, payload: bytes) -> None:
        """A guess in the prediction round: checked, then kept in the book (never the physics).

        One for a round that has closed (it crossed the reveal on the wire) is ignored."""
        if conn.state != State.PLAYING:
            raise proto.ProtocolError("PREDICT came before HELLO; a client must first send HELLO and wait for WELCOME")
        prediction = parse_predict(payload, MAX_ROUND_PUCKS)  # types, finite, speed; the book checks round and puck
        self.predictions.add(conn.cid, conn.name, client_color(conn.number), prediction)

    def _full_sentence(self) -> str:
        return (
            f"server full: all {self.max_clients} places are taken; your client tries again by itself, "
            "or ask the teacher to start the table with a higher --max-clients"
        )

    def _welcome(self, conn: Connection, hello: proto.Hello, now: float) -> None:
        if not self._password_ok(conn, hello, now):
            return
        if not self._take_over(conn, hello, now):
            return
        refusal = self._gate.seat_refusal(conn.host, self.password is not None, hello.name)
        if refusal is not None:  # the student's window waits and asks again: the teacher may let the class in
            self._tell_teacher(self._gate.teacher_notice())
            self._fail(conn, refusal, retry=True)
            return
        if hello.name and self._name_refusal is not None:
            refusal = self._name_refusal(hello.name)
        if refusal is not None:
            self._fail(conn, refusal, about="name")  # (the student's command: a bad --name, status 2)
            return
        number = self._seat_for(conn, hello, now)
        if number is None:
            self._fail(conn, self._full_sentence(), retry=True)
            return
        client = f"C{number}"
        shown = self._distinct(hello.name)
        name = client + (f" {shown}" if shown else "")  # the cursor's label
        color = client_color(number)
        self._gate.handshake_ended(conn.host, seated=True)
        conn.number, conn.name, conn.state = number, name, State.PLAYING
        self._numbers[number] = conn.cid
        self._owners[number] = hello.name or ""
        with self._lock:
            self._names[number] = name
        self._events.join(conn.cid, name, color, number)
        width_m, height_m = self._table_size_m
        token = self._tokens.make(number, hello.name or "")
        conn.udp_key = datagrams.new_key() if self._udp is not None else None
        conn.send_control(proto.encode_welcome(client, color, width_m, height_m, shown, token, conn.udp_key))
        conn.offer_tick(self._encoder, now)  # the newest picture straight away, if there is one
        with self._lock:
            round_frame = self._round_frame
        if round_frame is not None:  # a prediction round is under way
            conn.send_control(round_frame)
        self._log_seat(conn, "joins", "%s joined from %s", name, conn.peer)

    def _tell_teacher(self, notice: str | None) -> None:
        """A line for the log (once, then summaries) and for the projector, under the join lines, for a while."""
        if notice:
            self._quiet.note("students turned away per address", "%s", notice)
            with self._lock:
                self._door_notice = (notice, time.monotonic() + NOTICE_S)

    def _distinct(self, name: str | None) -> str | None:
        """`name` as the table shows it: "Ann 2" when an "Ann" (or an "Αnn", in look-alike letters) plays,
        or is away with a seat held for her (she gets her name back when she returns)."""
        if not name:
            return name
        playing = [self._conns[cid].name.partition(" ")[2] for cid in self._numbers.values()]
        away = [held for _, held, _ in self._held.away(time.monotonic()) if held]
        return distinct_name(name, playing + away)

    def _take_over(self, conn: Connection, hello: proto.Hello, now: float) -> bool:
        """A student back with their seat's token, while their old connection still holds it (it has
        not noticed the drop yet): the old one is closed at once, so the seat is free for the new one.
        False (the newcomer told to ask again) while the old one is still heard from (IN_USE_S)."""
        number = self._claimed_seat(conn, hello, now)
        stale = self._conns.get(self._numbers.get(number, -1)) if number is not None else None
        if stale is None:
            return True
        if now - stale.last_rx < IN_USE_S:
            self._fail(conn, IN_USE.format(stale.name), retry=True)
            return False
        self._log_seat(stale, "joins", "%s is back on a new connection; the old one is closed", stale.who)
        stale.keep_seat = False
        self._release_slot(stale)
        stale.close()
        self._settle(stale)
        return True

    def _seat_for(self, conn: Connection, hello: proto.Hello, now: float) -> int | None:
        """The seat a welcomed HELLO gets: the one its token proves, if free (given back from hold);
        else the lowest seat neither taken nor held for someone who dropped. None: the table is full."""
        if len(self._numbers) >= self.max_clients:
            return None
        number = self._claimed_seat(conn, hello, now)
        if number is not None and number <= MAX_PLAYERS and number not in self._numbers:
            self._held.give_back(number)
            return number
        return self._held.free_number(self._numbers, now)

    def _log_seat(self, conn: Connection, what: str, line: str, *args) -> None:
        """Joins and leaves (`what`), one line each, but summarised when one student churns (a laptop
        rejoining in a loop). Per student, not per address: a class behind one router, or on 127.0.0.1,
        shares an address, and only its first join was named. A flood of new names from one address
        (a script) is named up to a roomful (max_clients) a period, then counted."""
        if not conn.name:  # (a connection that never got a seat)
            self._quiet.note(f"{what} from {conn.host}", line, *args, level=logging.INFO)
            return
        budget = (f"{what} of other students from {conn.host}", self.max_clients)
        self._quiet.note(f"{what} of {conn.name} from {conn.host}", line, *args, level=logging.INFO, budget=budget)

    def _password_ok(self, conn: Connection, hello: proto.Hello, now: float) -> bool:
        if self.password is None:
            return True
        if hello.password is None:
            self._fail(conn, "this table needs a password: ask the teacher for it and join with --password", quiet=True)
            return False
        wait = self._gate.password_wait(conn.host, now)
        if wait > 0:
            self._fail(  # retry: the client asks again by itself; a right password then gets in
                conn,
                f"too many wrong passwords from your computer: waiting {math.ceil(wait)} s before the next try",
                retry=True,
                quiet=True,
            )
            return False
        if not hmac.compare_digest(hello.password.encode("utf-8"), self.password.encode("utf-8")):
            self._gate.wrong_password(conn.host, now, log)
            self._fail(
                conn,
                "wrong password: ask the teacher for the table's password and join again with --password",
                quiet=True,
            )
            return False
        self._gate.right_password(conn.host)
        return True

    def _fail(
        self, conn: Connection, sentence: str, retry: bool = False, quiet: bool = False, about: str | None = None
    ) -> None:
        """Send ERROR `sentence`, then close once it is out (or after LINGER_S); `about`: the HELLO field refused.

        Logged once per address and summarised after that (`quiet`: not at all)."""
        if not quiet:
            self._quiet.note(
                f"connections dropped from {conn.host}", "dropped %s: %s", conn.who, sentence, level=logging.INFO
            )
        self._release_slot(conn)
        conn.fail(sentence, time.monotonic(), retry=retry, about=about)

    def _remove(self, number: int, sentence: str) -> None:
        cid = self._numbers.get(number)
        conn = self._conns.get(cid) if cid is not None else None
        if conn is not None:
            conn.keep_seat = False  # removed: the seat is not kept for a return
            self._fail(conn, sentence)
            self._settle(conn)

    def _release_slot(self, conn: Connection) -> None:
        """Forget the seat or handshake behind `conn` (its Client goes at the next update_clients)."""
        if conn.state == State.HELLO:
            self._gate.handshake_ended(conn.host, seated=False)
            conn.state = State.CLOSING
        if conn.number and self._numbers.get(conn.number) == conn.cid:
            del self._numbers[conn.number]
            if conn.keep_seat:  # a drop, not a goodbye or a removal: held for their return
                self._held.hold(conn.number, time.monotonic(), conn.name.partition(" ")[2])
            self._gate.seat_freed(conn.host)
            with self._lock:
                self._names.pop(conn.number, None)
                if not self._names:
                    # publish() stops encoding when nobody plays: do not greet the
                    # next player with a picture from long ago.
                    self._encoder.forget()
            self._events.leave(conn.cid)
            self.predictions.forget(conn.cid)
        conn.number = 0

    def _settle(self, conn: Connection) -> None:
        """Bookkeeping after a connection closed itself (or was closed)."""
        if conn.closed and self._conns.get(conn.cid) is conn:
            self._release_slot(conn)
            del self._conns[conn.cid]

    def _check_timeouts(self, now: float) -> None:
        for conn in list(self._conns.values()):
            if conn.state == State.CLOSING:
                if now > conn.deadline:
                    conn.close()
            elif conn.state == State.HELLO and now > conn.deadline:
                self._hello_missing(conn, now)
            elif (dead := self._dead_sentence(conn, now)) is not None:
                self._fail(conn, dead, retry=True)
            self._settle(conn)
        if self._accept_paused_until and now >= self._accept_paused_until:
            self._accept_paused_until = 0.0
            assert self._selector is not None and self._listener is not None
            self._selector.register(self._listener, selectors.EVENT_READ, "listen")
        self._gate.forget_old_guesses(now, log)
        self._quiet.flush(now)

    def _hello_missing(self, conn: Connection, now: float) -> None:
        """The HELLO deadline passed. On a slow link (long round trip, bytes lost and sent again) the HELLO
        may still be on its way: wait up to SLOW_HELLO_S. Either way the ERROR asks the client to try
        again: a HELLO lost on a link that looks quick (only the handshake's few packets crossed it)
        is the same silence as a program that is not an airtable client, and a student's session
        must not end on it; anything else ignores the `retry`."""
        slow = pacing.link_is_slow(conn.sock)
        if slow and now - conn.opened < SLOW_HELLO_S:
            return
        if slow:
            sentence = (
                f"the network is slow: your HELLO did not arrive within {SLOW_HELLO_S:g} s; "
                "your client tries again by itself"
            )
        else:
            sentence = (
                f"your hello did not reach the table within {self.hello_timeout_s:g} s of connecting (lost on "
                "the way? a slow network?); airtable-client asks again by itself"
            )
        self._fail(conn, sentence, retry=True, quiet=True)

    def _dead_sentence(self, conn: Connection, now: float) -> str | None:
        """Why a connection counts as dead (a player's seat is then held; the ERROR carries retry), or None."""
        after = (
            "your seat is kept and your client reconnects by itself"
            if conn.state == State.PLAYING
            else "check the network and join again"
        )
        if now - conn.last_rx > self.timeout_s:
            return (
                f"nothing complete was received for {self.timeout_s:g} s (a client sends at least one INPUT "
                f"a second), so the connection was closed; {after}"
            )
        if conn.unread_s(now) > self.timeout_s:
            return f"nothing sent to you was read for {self.timeout_s:g} s, so the connection was closed; {after}"
        return None

    def _refresh_roster(self, now: float) -> None:
        width_m, height_m = self._table_size_m
        reach = FAR_OFF_TABLES * max(width_m, height_m)
        seats = []
        for number in sorted(self._numbers):
            conn = self._conns[self._numbers[number]]
            cursor = conn.last_input.cursor_m if conn.last_input else None
            far_off = cursor is not None and not (
                -reach <= cursor[0] <= width_m + reach and -reach <= cursor[1] <= height_m + reach
            )
            seats.append(
                Seat(
                    number,
                    conn.name,
                    client_color(number),
                    conn.peer,
                    conn.snapshot_rate(now),
                    conn.lag_s,
                    now - conn.last_change,
                    far_off,
                )
            )
        away = tuple((f"C{n}" + (f" {name}" if name else ""), s) for n, name, s in self._held.away(now))
        with self._lock:
            self._roster, self._away = tuple(seats), away

    def _say_bye(self) -> None:
        """Best effort: tell players the server is going, so they show 'server gone'."""
        for conn in list(self._conns.values()):
            conn.say_bye()
