"""The student's connection to a teacher's table (no pygame): `NetPlayer`.

It connects and says HELLO, keeps the newest Scene from the server's snapshots
in a reader thread, sends INPUT, and reconnects with backoff when the server
goes away. Problems are short sentences. The window that draws it all is
airtable/student/window.py.
"""

from __future__ import annotations

import contextlib
import enum
import math
import socket
import sys
import threading
import time
from collections.abc import Callable, Iterable, Sequence

import numpy as np

from airtable.model.scene import Scene
from airtable.model.student_aids import StudentAids
from airtable.net import protocol as proto
from airtable.net.aids_wire import AidsDecoder
from airtable.net.identity import seat_proof, token_seat
from airtable.net.outbox import Outbox
from airtable.net.pacing import link_is_slow
from airtable.net.playout import SnapshotFeed
from airtable.net.predictions import RoundInfo, clamp_speed, encode_predict, parse_round
from airtable.net.seat_memory import SeatMemory
from airtable.net.udp_inputs import UdpInputs

CONNECT_TIMEOUT_S = 5.0
SILENCE_S = 10.0  # no snapshot for this long: the server is gone (snapshots come 30 times a second)
STALE_S = 2.0  # no snapshot for this long: the window says so (the table it shows is frozen)
MAX_INPUT_HZ = 60.0
HEARTBEAT_S = 1.0
RESEND_S = 0.05  # an input whose datagram is not yet acknowledged goes again after this
FIRST_BACKOFF_S = 0.25
FIRST_FULL_BACKOFF_S = 1.0  # the table is full: ask again after this, then less and less often
MAX_BACKOFF_S = 4.0
MAX_PATIENCE_S = 30.0  # the longest a handshake is waited for, on a link found slow
RECONNECTING = "reconnecting to the teacher's table..."
# After the server's BYE: the teacher quit or restarted the app, not the network (a user test: the same
# "reconnecting" as a Wi-Fi drop).
TABLE_CLOSED = "the teacher closed the table: waiting for it to open again..."


class PlayerError(Exception):
    """A problem the player cannot get past; str(error) is one sentence for the user, and `about`
    the HELLO field the server refused ("name"): the user's own input, not the network."""

    def __init__(self, message: str, about: str | None = None) -> None:
        super().__init__(message)
        self.about = about


class _ConnectError(Exception):
    """One connection attempt failed; `retry` says whether trying again can help,
    `full` that the server asked us to wait for a place."""

    def __init__(
        self, message: str, retry: bool, full: bool = False, slow: bool = False, about: str | None = None
    ) -> None:
        super().__init__(message)
        self.retry = retry
        self.full = full
        self.slow = slow  # the link is slow: try again, waiting longer
        self.about = about  # the HELLO field the server refused ("name"), if it said


class _ConnectionEndedError(Exception):
    """The connection ended; `fatal` is a sentence, or None to reconnect."""

    def __init__(self, fatal: str | None = None) -> None:
        super().__init__(fatal)
        self.fatal = fatal


class PlayerState(enum.Enum):
    CONNECTING = "connecting"
    CONNECTED = "connected"
    RETRYING = "retrying"  # the server went away: reconnecting with backoff
    WAITING = "waiting"  # the server asked us to try again (full, busy, HELLO lost): asking with backoff
    FAILED = "failed"
    CLOSED = "closed"


class InputThrottle:
    """When to send INPUT: when it changed, at most max_hz times a second, and
    at least every heartbeat_s so the server knows the player is still there.

    An input sent by UDP may be lost; while the cursor moves the next one makes up for it,
    but the last one before the hand stops has no next. So an unchanged input whose datagram
    the server has not acknowledged is due again every resend_s (`unacked`), until one is."""

    def __init__(self, max_hz: float = MAX_INPUT_HZ, heartbeat_s: float = HEARTBEAT_S, resend_s: float = RESEND_S):
        self.min_gap_s = 1.0 / max_hz
        self.heartbeat_s = heartbeat_s
        self.resend_s = resend_s
        self.reset()

    def reset(self) -> None:
        """Forget what was sent (after a reconnect the next input goes out at once)."""
        self.last: proto.InputRecord | None = None
        self.last_t = -math.inf

    def due(self, record: proto.InputRecord, now: float, unacked: bool = False) -> bool:
        gap = now - self.last_t
        if gap >= self.heartbeat_s or (unacked and gap >= self.resend_s):
            return True
        # A 1 ms allowance, so a 60 fps loop is not held to 30 sends a second by jitter.
        return record != self.last and gap >= self.min_gap_s - 0.001

    def sent(self, record: proto.InputRecord, now: float) -> None:
        self.last, self.last_t = record, now


def empty_scene(width_m: float, height_m: float) -> Scene:
    return Scene(width_m, height_m, np.zeros((0, 2)), np.zeros(0), np.zeros((0, 3), np.uint8))


def _shut(sock: socket.socket) -> None:
    """Shut both directions, which wakes a thread blocked in recv(); a socket already gone is fine."""
    with contextlib.suppress(OSError):
        sock.shutdown(socket.SHUT_RDWR)


class NetPlayer:
    """The network side of a player: handshake, newest snapshot, input, reconnect.

    `connect()` makes the first connection (raising PlayerError with a sentence
    when it fails for good: a wrong password, another version) and starts a reader
    thread. When the first try fails in a way trying again can mend (refused, no
    answer, the table full) it returns None and the thread keeps asking, with
    backoff (state RETRYING, or WAITING when the server asked to wait).
    From then on `state` (a PlayerState) is CONNECTED, RETRYING (the server went
    away; it reconnects with backoff), WAITING or FAILED (`error` says why);
    `close()` ends it. `on_snapshot(scene, t)` is called from the reader thread
    for each snapshot, if given.
    """

    CONNECTING = PlayerState.CONNECTING
    CONNECTED = PlayerState.CONNECTED
    RETRYING = PlayerState.RETRYING
    WAITING = PlayerState.WAITING
    FAILED = PlayerState.FAILED
    CLOSED = PlayerState.CLOSED

    def __init__(
        self,
        host: str,
        port: int = proto.DEFAULT_PORT,
        name: str | None = None,
        password: str | None = None,
        timeout_s: float = CONNECT_TIMEOUT_S,
        on_snapshot: Callable[[Scene, float], None] | None = None,
        protocol_version: int = proto.PROTOCOL_VERSION,
        max_backoff_s: float = MAX_BACKOFF_S,
        first_backoff_s: float = FIRST_BACKOFF_S,
        full_backoff_s: float = FIRST_FULL_BACKOFF_S,
        seat_memory: SeatMemory | None = None,
    ) -> None:
        self.host = host
        self.port = int(port)
        self.name = None if name is None else proto.check_name(name)
        self.password = password
        self.timeout_s = float(timeout_s)
        self.patience_s = self.timeout_s  # how long a handshake is waited for: longer once the link is found slow
        self.on_snapshot = on_snapshot
        self.protocol_version = protocol_version  # other than 1 only to test the server's answer
        self.max_backoff_s = max_backoff_s
        self.first_backoff_s = first_backoff_s  # the first wait after the server went away
        self.full_backoff_s = full_backoff_s  # the least wait before asking a full table again
        self.state = PlayerState.CONNECTING
        self.heard_s = time.monotonic()  # when the server was last heard from (monotonic s)
        self.lost_s: float | None = None  # when the connection was lost, while reconnecting
        self.error: str | None = None
        self.error_about: str | None = None  # with `error`: the HELLO field the server refused ("name")
        self.waiting_because: str | None = None  # the server's sentence while WAITING
        self._said_bye = False  # the server said BYE on the connection that just ended
        self.next_try: float = 0.0  # time.monotonic() of the next attempt while RETRYING or WAITING
        self.welcome: proto.Welcome | None = None
        # The tokens kept on this computer (seat_memory.py): a client started again asks for its seat back.
        self._seat_memory = seat_memory
        self._remembered = None if seat_memory is None else seat_memory.recall(self.address, self.name)
        self.reconnects = 0
        self.snapshots = 0
        self._scene: Scene | None = None
        self._feed = SnapshotFeed()
        self.aids = StudentAids()  # the teacher's aids as the AIDS frames tell them, and our own toggles
        self._aids = AidsDecoder()
        self._sock: socket.socket | None = None
        self._send_lock = threading.Lock()
        self._outbox = Outbox()  # what the socket has not taken yet (never waited for)
        self._udp: UdpInputs | None = None  # inputs as datagrams, where the server takes them (datagrams.py)
        self._tcp_input_at = -math.inf  # when an INPUT last went by TCP
        self._closed = threading.Event()
        self._thread: threading.Thread | None = None
        self._throttle = InputThrottle()
        self.round: RoundInfo | None = None  # the newest prediction round the server announced
        self.problems = 0  # things from the server left out (see skipped)
        self._said: set[str] = set()

    @property
    def address(self) -> str:
        host = f"[{self.host}]" if ":" in self.host else self.host
        return f"{host}:{self.port}"

    @property
    def status_text(self) -> str:
        """The connection state as the HUD shows it."""
        if self.state == PlayerState.CONNECTED:
            silent = self._silent_s(time.monotonic())
            if silent is not None:  # (a user test: "connected" under a banner saying nothing came for 9 s)
                return f"connected to {self.address}, nothing heard for {silent:.0f} s"
            return f"connected to {self.address}"
        if self.state == PlayerState.FAILED:
            return self.error or "failed"
        if self.state in (PlayerState.RETRYING, PlayerState.WAITING):
            return self.banner_text or ""
        return f"{self.state.value} {self.address}"

    def _silent_s(self, now: float) -> float | None:
        """How long a connected table has sent nothing (s), once that is STALE_S or more; else None."""
        silent = now - self.heard_s
        return silent if self.state == PlayerState.CONNECTED and silent >= STALE_S else None

    @property
    def banner_text(self) -> str | None:
        """A line across the window while the player cannot play, else None."""
        now = time.monotonic()
        wait = max(0, math.ceil(self.next_try - now))
        if self.state == PlayerState.RETRYING:
            since = f" ({now - self.lost_s:.0f} s)" if self.lost_s is not None and now - self.lost_s >= 1.0 else ""
            return (self.waiting_because or RECONNECTING) + since
        silent = self._silent_s(now)
        if silent is not None:  # a frozen table, said so
            return f"nothing from the teacher's table for {silent:.0f} s: the network? waiting..."
        if self.state == PlayerState.WAITING:  # the server's reason, up to its advice
            reason = (self.waiting_because or "the table cannot take you yet").split(";")[0]
            reason = "the table is full" if reason.startswith("server full") else reason
            return f"{reason}: asking again in {wait} s (Esc to leave)"
        if self.state == PlayerState.FAILED:
            return self.error
        return None

    # ---------------------------------------------------------------- connecting

    def connect(self) -> proto.Welcome | None:
        """Connect, say HELLO and wait for WELCOME; then keep reading in a thread.

        Returns None when the table is full: the thread then waits for a place."""
        try:
            opened = self._open()
        except _ConnectError as e:
            if not e.retry:
                self.state, self.error, self.error_about = PlayerState.FAILED, str(e), e.about
                raise PlayerError(str(e), e.about) from None
            # Refused, unanswered, hung up: the window opens, says why and asks again (a user test: a
            # student who started before the teacher's table got no window, only a line and exit 1).
            self._not_joined_yet(e, self.first_backoff_s)
            opened = None
        if opened is not None:
            self._adopt(opened[0], opened[1])
        self._thread = threading.Thread(target=self._run, args=(opened,), name="airtable-player", daemon=True)
        self._thread.start()
        return self.welcome

    def _open(self) -> tuple[socket.socket, proto.Welcome, proto.FrameReader, list]:
        try:
            infos = socket.getaddrinfo(self.host, self.port, 0, socket.SOCK_STREAM)
        except (socket.gaierror, UnicodeError):
            raise _ConnectError(
                f"host {self.host!r} not found: check the spelling, or use the address from the teacher's "
                "'join with:' line",
                retry=True,
            ) from None
        failure: _ConnectError | None = None
        for family, kind, protocol, _, addr in infos:
            sock = socket.socket(family, kind, protocol)
            sock.settimeout(self.timeout_s)
            try:
                sock.connect(addr)
            except OSError as e:
                failure = self._connect_failure(e)
            else:
                try:
                    return (sock, *self._handshake(sock))
                except BaseException:
                    sock.close()
                    raise
            sock.close()
        assert failure is not None
        raise failure

    def _connect_failure(self, e: OSError) -> _ConnectError:
        where = self.address
        if isinstance(e, ConnectionRefusedError):
            sentence = (
                f"connection refused by {where}: is the server running? is port {self.port} open in its firewall?"
            )
        elif isinstance(e, TimeoutError):
            sentence = (
                f"no answer from {where} within {self.timeout_s:g} s: is the address right? "
                f"is port {self.port} open in the server's firewall?"
            )
        else:
            sentence = f"cannot reach {where} ({e.strerror or e}): is this computer on the teacher's network?"
        return _ConnectError(sentence, retry=True)

    def _handshake(self, sock: socket.socket) -> tuple[proto.Welcome, proto.FrameReader, list]:
        where = self.address
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        reader = proto.FrameReader(proto.MAX_SERVER_FRAME, sender="the server")
        deadline = time.monotonic() + self.patience_s
        try:
            # After a first WELCOME, its token asks for the same seat (number, name, colour) again:
            # HELLO names the seat, and the token is proven in answer to a CHALLENGE, never sent.
            token = self.welcome.token if self.welcome is not None else self._remembered
            seat = token_seat(token)
            sock.sendall(proto.encode_hello(self.name, self.password, self.protocol_version, seat=seat))
            while True:
                sock.settimeout(max(0.01, deadline - time.monotonic()))
                data = sock.recv(65536)
                if not data:
                    raise _ConnectError(f"the server at {where} hung up before saying WELCOME", retry=True)
                frames = self._answer_challenge(sock, reader.feed(data), token)
                if frames:
                    welcome, rest = self._first_frame(frames)
                    return welcome, reader, rest
        except proto.ProtocolError as e:
            raise _ConnectError(
                f"{where} does not answer like an airtable server ({e}); check the address and port", retry=False
            ) from None
        except TimeoutError:
            # Silence is tried again, waiting longer, whatever the kernel says of the link: a relay or a
            # proxy on the way acknowledges at once over a slow link, and a busy teacher's laptop is slow
            # too (a user test through a 300 ms relay read "is it an airtable server?" and the client quit).
            why = "the network is slow" if link_is_slow(sock) is not False else "a slow network? the right address?"
            raise _ConnectError(
                f"the teacher's table at {where} has not answered within {self.patience_s:g} s ({why}); trying again",
                retry=True,
                slow=True,
            ) from None
        except OSError as e:
            raise _ConnectError(f"the connection to {where} broke during the handshake ({e})", retry=True) from None

    def _answer_challenge(self, sock: socket.socket, frames: list, token: str | None) -> list:
        """`frames` without a leading CHALLENGE, which is answered with the token's PROOF."""
        if not frames or frames[0][0] != proto.CHALLENGE:
            return frames
        if token is None:
            raise proto.ProtocolError("a CHALLENGE came though this client asked for no seat")
        sock.sendall(proto.encode_proof(seat_proof(token, proto.parse_challenge(frames[0][1]))))
        return frames[1:]

    def _first_frame(self, frames: list) -> tuple[proto.Welcome, list]:
        frame_type, payload = frames[0]
        if frame_type == proto.ERROR:
            sentence, retry, about = proto.parse_error_message(payload)
            raise _ConnectError(sentence, retry=retry, full=retry, about=about)
        if frame_type != proto.WELCOME:
            raise proto.ProtocolError(f"the first message was {proto.FRAME_NAMES[frame_type]}, not WELCOME")
        # Frames that came with the WELCOME go to the reader thread.
        return proto.parse_welcome(payload), frames[1:]

    def _adopt(self, sock: socket.socket, welcome: proto.Welcome) -> None:
        sock.settimeout(0.25)  # the reader wakes this often to check for silence and close()
        with self._send_lock:
            self._sock = sock
            self.welcome = welcome
            self._outbox = Outbox()  # what waited for the old connection is stale
            self._udp = _udp_for(sock, welcome, self._udp)
            self._feed = SnapshotFeed()  # a new connection starts from a keyframe
            self._aids = AidsDecoder()
            self._throttle.reset()
            self.round = None  # a round under way comes again after the WELCOME
            self.state = PlayerState.CONNECTED
            self.waiting_because = None
            self.heard_s, self.lost_s = time.monotonic(), None
        if self._seat_memory is not None and welcome.token:  # (a file: outside the lock)
            self._seat_memory.keep(self.address, self.name, welcome.token)

    def _slow_link(self, sentence: str) -> None:
        """A handshake timed out on a slow link: wait longer next time, and say so."""
        self.patience_s = min(MAX_PATIENCE_S, 2 * self.patience_s)
        self.waiting_because = sentence
        self.state = PlayerState.RETRYING

    def _wait_for_place(self, sentence: str, backoff_s: float) -> None:
        self.waiting_because = sentence
        self.next_try = time.monotonic() + backoff_s
        self.state = PlayerState.WAITING

    # ---------------------------------------------------------------- reader thread

    def _run(self, opened: tuple | None) -> None:
        while not self._closed.is_set():
            if opened is None:
                opened = self._reconnect()
                if opened is None:
                    return
                self.reconnects += self.welcome is not None
                self._adopt(opened[0], opened[1])
            sock, _, reader, frames = opened
            fatal = self._read(sock, reader, frames)
            with self._send_lock:
                self._sock = None
            sock.close()
            if self._closed.is_set():
                return
            if fatal is not None:
                self.state, self.error = PlayerState.FAILED, fatal
                return
            self.state, self.waiting_because = PlayerState.RETRYING, TABLE_CLOSED if self._said_bye else None
            self._said_bye = False
            self.lost_s = self.heard_s  # (the table has been frozen since)
            opened = None

    def _read(self, sock: socket.socket, reader: proto.FrameReader, frames: list) -> str | None:
        """Read until the connection ends; return a fatal sentence, or None to reconnect."""
        last_rx = time.monotonic()
        try:
            while not self._closed.is_set():
                now = time.monotonic()
                if frames:
                    last_rx = self.heard_s = now
                    self._take(frames, now)
                elif now - last_rx > max(SILENCE_S, self.timeout_s):
                    return None
                self._flush(sock)  # what the socket could not take when it was sent
                frames = self._receive(sock, reader)
        except _ConnectionEndedError as end:
            return end.fatal
        return None

    def _receive(self, sock: socket.socket, reader: proto.FrameReader) -> list:
        try:
            data = sock.recv(65536)
        except TimeoutError:
            return []
        except OSError:
            raise _ConnectionEndedError() from None
        if not data:
            raise _ConnectionEndedError()
        try:
            return reader.feed(data)
        except proto.ProtocolError as e:  # the stream lost its frames: start afresh on a new connection
            self.skipped(f"{self.address} sent a frame this client cannot read ({e}); connecting again")
            raise _ConnectionEndedError() from None

    def skipped(self, sentence: str) -> None:
        """Something from the server this client could not use, and left out: said once, on stderr.

        Data from the server never ends the session; only its ERROR can (see _take)."""
        self.problems += 1
        if sentence not in self._said:
            self._said.add(sentence)
            print(f"airtable-client: {sentence}", file=sys.stderr, flush=True)

    def _take(self, frames: list, now: float) -> None:
        for frame_type, payload in frames:
            if frame_type in (proto.SNAPSHOT, proto.LAYOUT):
                self._take_snapshot(frame_type, payload, now)
            elif frame_type == proto.AIDS:
                self._take_aids(payload, now)
            elif frame_type == proto.ROUND:
                try:
                    self.round = parse_round(payload)
                except proto.ProtocolError as e:
                    self.skipped(f"left out a prediction round this client cannot use ({e})")
            elif frame_type == proto.ERROR:
                sentence, retry, _ = proto.parse_error_message(payload)
                raise _ConnectionEndedError(None if retry else sentence)
            elif frame_type == proto.BYE:
                self._said_bye = True
                raise _ConnectionEndedError()
            else:  # a newer server's message: not for this client
                self.skipped(f"left out {proto.FRAME_NAMES[frame_type]} messages, which this client does not use")

    def _take_snapshot(self, frame_type: int, payload: bytes, now: float) -> None:
        """A LAYOUT or SNAPSHOT. One that cannot be decoded breaks the chain of deltas after it:
        the client says so and connects again, keeping its seat, for a fresh keyframe."""
        decoder = self._feed.decoder
        try:
            scene = self._feed.feed(frame_type, payload, now)
        except proto.ProtocolError as e:
            self.skipped(f"left out a snapshot this client cannot use ({e}); connecting again")
            raise _ConnectionEndedError() from None
        if decoder.problem is not None:
            self.skipped(f"the snapshot has {decoder.problem}")
            decoder.problem = None
        if scene is None:
            return  # a LAYOUT: what the next snapshots need
        self._scene = scene  # one reference swap: readers see the old or the new scene
        self.aids.snapshot(scene)
        self.snapshots += 1
        if self.on_snapshot is not None:
            self.on_snapshot(scene, now)

    def _take_aids(self, payload: bytes, now: float) -> None:
        """An AIDS frame: the teacher's aids at the tick just decoded (left out if unusable)."""
        last = self._feed.decoder.last
        try:
            if last is None:
                raise proto.ProtocolError("aids before any snapshot")
            frame = self._aids.feed(payload, last.seq, last.layout.sizes[0], last.time_us / 1e6)
        except proto.ProtocolError as e:
            self.skipped(f"left out the teacher's aids for a moment ({e})")
            return
        self.aids.take(frame, now)

    def _reconnect(self) -> tuple | None:
        """Try again with backoff until connected (the tuple of _open), failed or closed (None)."""
        backoff = self.first_backoff_s if self.state != PlayerState.WAITING else self.full_backoff_s
        self.next_try = time.monotonic() + backoff
        while not self._closed.wait(max(0.0, self.next_try - time.monotonic())):
            try:
                return self._open()
            except _ConnectError as e:
                if not e.retry:
                    self.state, self.error, self.error_about = PlayerState.FAILED, str(e), e.about
                    return None
                backoff = min(backoff * 2, self.max_backoff_s)
                self._not_joined_yet(e, backoff)
        return None

    def _not_joined_yet(self, e: _ConnectError, backoff_s: float) -> None:
        """An attempt failed in a way trying again can mend: wait, and say why where the window shows it."""
        if e.full:
            self._wait_for_place(str(e), max(backoff_s, self.full_backoff_s))
            return
        if e.slow:
            self._slow_link(str(e))
        elif self.welcome is None:  # never at the table: say why (once there, "reconnecting" says it)
            self.waiting_because, self.state = f"{e} (trying again)", PlayerState.RETRYING
        self.next_try = time.monotonic() + backoff_s

    # ---------------------------------------------------------------- the game side

    def latest(self) -> Scene | None:
        """The newest scene received (None before the first snapshot)."""
        return self._scene

    def smooth(self, now_s: float | None = None) -> Scene | None:
        """The scene to draw at `now_s` (default: now): interpolated between snapshots a
        small adaptive delay ago, so motion stays even when snapshots arrive unevenly."""
        return self._feed.scene(time.monotonic() if now_s is None else now_s)

    def send_input(self, cursor_m: Sequence[float], button: int = 0, keys: Iterable[str] = ()) -> bool:
        """Send one INPUT now (no throttle); False when not connected. Never raises."""
        return self._send(self._record(cursor_m, button, keys), time.monotonic())

    def update_input(
        self, cursor_m: Sequence[float], button: int = 0, keys: Iterable[str] = (), now: float | None = None
    ) -> bool:
        """Call every frame: sends INPUT when it changed (at most 60 a second) and
        at least once a second. Returns True when something was sent."""
        now = time.monotonic() if now is None else now
        record = self._record(cursor_m, button, keys)
        udp = self._udp  # an unacknowledged datagram matters only for a cursor at rest (InputThrottle)
        unacked = record == self._throttle.last and udp is not None and udp.confirmed(now) and not udp.delivered
        if not self._throttle.due(record, now, unacked):
            return False
        return self._send(record, now)

    def send_predict(self, puck: int, vel_mps: Sequence[float]) -> bool:
        """Send this player's guess for `puck` in the open round; False when there is none or not connected."""
        info = self.round
        if info is None or info.state != "open":
            return False
        return self._send_frame(encode_predict(info.round_id, puck, clamp_speed(vel_mps)))

    def _record(self, cursor_m: Sequence[float], button: int, keys: Iterable[str]) -> proto.InputRecord:
        welcome = self.welcome
        size = (welcome.width_m, welcome.height_m) if welcome else proto.DEFAULT_TABLE_SIZE_M
        return proto.make_input(cursor_m, button, keys, size)  # only what the server accepts

    def _send(self, record: proto.InputRecord, now: float) -> bool:
        frame = proto.encode_input(record.cursor_m, record.button, record.keys)
        udp = self._udp
        if udp is not None and self.state == PlayerState.CONNECTED:
            udp.send(frame[5:])  # the INPUT's JSON, without the frame's envelope
            if udp.confirmed(now) and now - self._tcp_input_at < HEARTBEAT_S:
                self._throttle.sent(record, now)
                return True  # UDP gets through: TCP carries only a heartbeat a second

        def sent() -> None:
            self._throttle.sent(record, now)
            self._tcp_input_at = now

        return self._send_frame(frame, on_sent=sent, replaceable=True)

    def _send_frame(self, frame: bytes, on_sent: Callable[[], None] | None = None, replaceable: bool = False) -> bool:
        """Send one frame while connected, never waiting (see outbox.py; a `replaceable` INPUT
        replaces an older one still waiting); on_sent runs under the send lock. False if not connected."""
        with self._send_lock:
            sock = self._sock
            if sock is None or self.state != PlayerState.CONNECTED:
                return False
            self._outbox.put(frame, replaceable)
            if on_sent is not None:
                on_sent()
        return self._flush(sock)

    def _flush(self, sock: socket.socket) -> bool:
        """Send what waits in the outbox; False when the connection broke (the reader then reconnects)."""
        with self._send_lock:
            if sock is not self._sock:
                return False
            try:
                self._outbox.flush(sock)
            except OSError:
                _shut(sock)  # the reader thread notices too and starts reconnecting; wake it now
                return False
        return True

    def close(self, bye: bool = True) -> None:
        """Say BYE (when connected), close the socket and stop the reader thread."""
        self._closed.set()
        with self._send_lock:
            sock = self._sock
            if sock is not None:
                if bye and self.state == PlayerState.CONNECTED:
                    self._outbox.put(proto.encode_bye())
                    with contextlib.suppress(OSError):
                        self._outbox.flush(sock)
                _shut(sock)
        if self._thread is not None and self._thread is not threading.current_thread():
            self._thread.join(timeout=5.0)
        if self._udp is not None:
            self._udp.close()
        if self.state != PlayerState.FAILED:
            self.state = PlayerState.CLOSED


def _udp_for(sock: socket.socket, welcome: proto.Welcome, old: UdpInputs | None) -> UdpInputs | None:
    """This session's input datagrams, when the server offers them (closing the last session's)."""
    if old is not None:
        old.close()
    if not welcome.udp_key:
        return None
    try:
        return UdpInputs(sock.getpeername(), welcome.udp_key, int(welcome.client[1:]))
    except OSError:
        return None  # no UDP here: every input goes by TCP
