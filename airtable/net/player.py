"""airtable-client: join a teacher's air table over the LAN.

    airtable-client HOST[:PORT] [--name NAME] [--password PW]
                    [--headless] [--seconds S] [--screenshot FILE.png]

Two parts:
- `NetPlayer` (no pygame): connects and says HELLO, keeps the newest Scene
  from the server's snapshots in a reader thread, sends INPUT, and reconnects
  with backoff when the server goes away. Problems are short sentences.
- `PlayerApp`: the pygame window. It draws the snapshots with the same
  `GameWindow` as the teacher's window and draws its own cursor locally, so
  the student's arrow follows the mouse without network delay.
"""

from __future__ import annotations

import argparse
import contextlib
import dataclasses
import enum
import math
import os
import socket
import sys
import threading
import time
from collections.abc import Callable, Iterable, Sequence

import numpy as np

from airtable.app.aids_share import LOCAL_KEYS, StudentAids
from airtable.app.predict import StudentGuesses
from airtable.app.predict_view import paint_round
from airtable.app.room import student_banner
from airtable.app.scene import CursorView, Scene
from airtable.net import protocol as proto
from airtable.net.aids_wire import NOTES, AidsDecoder
from airtable.net.outbox import Outbox
from airtable.net.pacing import link_is_slow
from airtable.net.playout import SnapshotFeed
from airtable.net.predictions import RoundInfo, clamp_speed, encode_predict, parse_round
from airtable.net.udp_inputs import UdpInputs

CONNECT_TIMEOUT_S = 5.0
SILENCE_S = 10.0  # no snapshot for this long: the server is gone (snapshots come 30 times a second)
MAX_INPUT_HZ = 60.0
HEARTBEAT_S = 1.0
FIRST_BACKOFF_S = 0.25
FIRST_FULL_BACKOFF_S = 1.0  # the table is full: ask again after this, then less and less often
MAX_BACKOFF_S = 4.0
MAX_PATIENCE_S = 30.0  # the longest a handshake is waited for, on a link found slow
RECONNECTING = "reconnecting to the teacher's table..."
# Once nothing has moved on the table (pucks, cursors) and this window had no input for
# IDLE_AFTER_S, it draws IDLE_FPS frames a second instead of its full rate, waking at once on
# input: a still table leaves a student's laptop quiet, and motion shows within 1 / IDLE_FPS.
IDLE_FPS = 20.0
IDLE_AFTER_S = 1.0
# Drawing budgets for one frame (see fit_drawing_budget).
MAX_PUCK_AREA_SCREENS = 40.0
MAX_PUCK_LOOKS = 1024
MAX_SPRING_SPAN_PX = 20_000_000


class PlayerError(Exception):
    """A problem the player cannot get past; str(error) is one sentence for the user."""


class _ConnectError(Exception):
    """One connection attempt failed; `retry` says whether trying again can help,
    `full` that the server asked us to wait for a place."""

    def __init__(self, message: str, retry: bool, full: bool = False, slow: bool = False) -> None:
        super().__init__(message)
        self.retry = retry
        self.full = full
        self.slow = slow  # the link is slow: try again, waiting longer


class _ConnectionEndedError(Exception):
    """The connection ended; `fatal` is a sentence, or None to reconnect."""

    def __init__(self, fatal: str | None = None) -> None:
        super().__init__(fatal)
        self.fatal = fatal


class PlayerState(enum.Enum):
    CONNECTING = "connecting"
    CONNECTED = "connected"
    RETRYING = "retrying"  # the server went away: reconnecting with backoff
    WAITING = "waiting"  # the table is full or busy: asking again with backoff
    FAILED = "failed"
    CLOSED = "closed"


class InputThrottle:
    """When to send INPUT: when it changed, at most max_hz times a second, and
    at least every heartbeat_s so the server knows the player is still there."""

    def __init__(self, max_hz: float = MAX_INPUT_HZ, heartbeat_s: float = HEARTBEAT_S) -> None:
        self.min_gap_s = 1.0 / max_hz
        self.heartbeat_s = heartbeat_s
        self.reset()

    def reset(self) -> None:
        """Forget what was sent (after a reconnect the next input goes out at once)."""
        self.last: proto.InputRecord | None = None
        self.last_t = -math.inf

    def due(self, record: proto.InputRecord, now: float) -> bool:
        gap = now - self.last_t
        if gap >= self.heartbeat_s:
            return True
        # A 1 ms allowance, so a 60 fps loop is not held to 30 sends a second by jitter.
        return record != self.last and gap >= self.min_gap_s - 0.001

    def sent(self, record: proto.InputRecord, now: float) -> None:
        self.last, self.last_t = record, now


def _empty_scene(width_m: float, height_m: float) -> Scene:
    return Scene(width_m, height_m, np.zeros((0, 2)), np.zeros(0), np.zeros((0, 3), np.uint8))


def _shut(sock: socket.socket) -> None:
    """Shut both directions, which wakes a thread blocked in recv(); a socket already gone is fine."""
    with contextlib.suppress(OSError):
        sock.shutdown(socket.SHUT_RDWR)


class NetPlayer:
    """The network side of a player: handshake, newest snapshot, input, reconnect.

    `connect()` makes the first connection (raising PlayerError with a sentence
    when it fails for good) and starts a reader thread. When the table is full
    it returns None and the thread keeps asking, with backoff (state WAITING).
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
        self.error: str | None = None
        self.waiting_because: str | None = None  # the server's sentence while WAITING
        self.next_try: float = 0.0  # time.monotonic() of the next attempt while RETRYING or WAITING
        self.welcome: proto.Welcome | None = None
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

    @property
    def address(self) -> str:
        host = f"[{self.host}]" if ":" in self.host else self.host
        return f"{host}:{self.port}"

    @property
    def status_text(self) -> str:
        """The connection state as the HUD shows it."""
        if self.state == PlayerState.CONNECTED:
            return f"connected to {self.address}"
        if self.state == PlayerState.FAILED:
            return self.error or "failed"
        if self.state in (PlayerState.RETRYING, PlayerState.WAITING):
            return self.banner_text or ""
        return f"{self.state.value} {self.address}"

    @property
    def banner_text(self) -> str | None:
        """A line across the window while the player cannot play, else None."""
        wait = max(0, math.ceil(self.next_try - time.monotonic()))
        if self.state == PlayerState.RETRYING:
            return self.waiting_because or RECONNECTING
        if self.state == PlayerState.WAITING:
            return f"the table is full: asking again in {wait} s (Esc quits)"
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
            if not (e.full or e.slow):
                self.state, self.error = PlayerState.FAILED, str(e)
                raise PlayerError(str(e)) from None
            if e.full:
                self._wait_for_place(str(e), self.full_backoff_s)
            else:
                self._slow_link(str(e))
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
            # After a first WELCOME, its token asks for the same seat (number, name, colour) again.
            token = self.welcome.token if self.welcome is not None else None
            sock.sendall(proto.encode_hello(self.name, self.password, self.protocol_version, token))
            while True:
                sock.settimeout(max(0.01, deadline - time.monotonic()))
                data = sock.recv(65536)
                if not data:
                    raise _ConnectError(f"the server at {where} hung up before saying WELCOME", retry=True)
                frames = reader.feed(data)
                if frames:
                    welcome, rest = self._first_frame(frames)
                    return welcome, reader, rest
        except proto.ProtocolError as e:
            raise _ConnectError(
                f"{where} does not answer like an airtable server ({e}); check the address and port", retry=False
            ) from None
        except TimeoutError:
            if link_is_slow(sock) is not False:  # a long round trip, or our HELLO not yet acknowledged
                raise _ConnectError(
                    f"the network to {where} is slow: no answer within {self.patience_s:g} s; trying again",
                    retry=True,
                    slow=True,
                ) from None
            raise _ConnectError(
                f"{where} accepted the connection but did not answer within {self.patience_s:g} s; "
                "is it an airtable server?",
                retry=True,
            ) from None
        except OSError as e:
            raise _ConnectError(f"the connection to {where} broke during the handshake ({e})", retry=True) from None

    def _first_frame(self, frames: list) -> tuple[proto.Welcome, list]:
        frame_type, payload = frames[0]
        if frame_type == proto.ERROR:
            sentence, retry = proto.parse_error_message(payload)
            raise _ConnectError(sentence, retry=retry, full=retry)
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
            self.state, self.waiting_because = PlayerState.RETRYING, None
            opened = None

    def _read(self, sock: socket.socket, reader: proto.FrameReader, frames: list) -> str | None:
        """Read until the connection ends; return a fatal sentence, or None to reconnect."""
        last_rx = time.monotonic()
        try:
            while not self._closed.is_set():
                now = time.monotonic()
                if frames:
                    last_rx = now
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
        except proto.ProtocolError as e:
            raise _ConnectionEndedError(f"{self.address} sent something that is not airtable protocol ({e})") from None

    def _take(self, frames: list, now: float) -> None:
        for frame_type, payload in frames:
            if frame_type in (proto.SNAPSHOT, proto.LAYOUT):
                try:
                    scene = self._feed.feed(frame_type, payload, now)
                except proto.ProtocolError as e:
                    raise _ConnectionEndedError(str(e)) from None
                if scene is None:
                    continue  # a LAYOUT: what the next snapshots need
                self._scene = scene  # one reference swap: readers see the old or the new scene
                self.aids.snapshot(scene)
                self.snapshots += 1
                if self.on_snapshot is not None:
                    self.on_snapshot(scene, now)
            elif frame_type == proto.AIDS:
                self._take_aids(payload, now)
            elif frame_type == proto.ROUND:
                try:
                    self.round = parse_round(payload)
                except proto.ProtocolError as e:
                    raise _ConnectionEndedError(str(e)) from None
            elif frame_type == proto.ERROR:
                sentence, retry = proto.parse_error_message(payload)
                raise _ConnectionEndedError(None if retry else sentence)
            elif frame_type == proto.BYE:
                raise _ConnectionEndedError()
            else:
                raise _ConnectionEndedError(
                    f"{self.address} sent an unexpected {proto.FRAME_NAMES[frame_type]} message"
                )

    def _take_aids(self, payload: bytes, now: float) -> None:
        """An AIDS frame: the teacher's aids at the tick just decoded."""
        last = self._feed.decoder.last
        if last is None:
            raise _ConnectionEndedError(f"{self.address} sent aids before any snapshot")
        try:
            frame = self._aids.feed(payload, last.seq, last.layout.sizes[0], last.time_us / 1e6)
        except proto.ProtocolError as e:
            raise _ConnectionEndedError(str(e)) from None
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
                    self.state, self.error = PlayerState.FAILED, str(e)
                    return None
                backoff = min(backoff * 2, self.max_backoff_s)
                if e.full:
                    self._wait_for_place(str(e), max(backoff, self.full_backoff_s))
                else:
                    if e.slow:
                        self._slow_link(str(e))
                    self.next_try = time.monotonic() + backoff
        return None

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
        if not self._throttle.due(record, now):
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


# -------------------------------------------------------------------- the window


def _wait_for_input(seconds: float) -> None:
    """Sleep up to `seconds`, waking early when an event (input, the window) comes in; the
    event stays in the queue for the next frame."""
    import pygame

    event = pygame.event.wait(max(1, int(seconds * 1000)))
    if event.type != pygame.NOEVENT:
        pygame.event.post(event)


class PlayerApp:
    """The pygame window of a player: the server's table from snapshots, our cursor drawn locally."""

    def __init__(self, net: NetPlayer, headless: bool = False, fps: float = 60.0) -> None:
        self.net = net
        self.headless = headless
        self.fps = fps
        self.window = None  # the GameWindow, once run() has opened it
        self.env = None
        self.frames = 0
        self.states_seen: set[PlayerState] = set()  # connection states shown, for tests
        self.draw_error: str | None = None  # the first drawing error, reported once
        self.button = 0
        self.keys: set[str] = set()
        self.show_help = False  # F1: the keys of this window
        self.painter = None  # the AidsPainter, once the window is open
        self.lessons_painter = None  # the LessonsPainter (momenta, values) and
        self.timeline_painter = None  # the TimelinePainter, likewise
        self._drawn_from: tuple = ()  # the restarts and view the trails were drawn in
        self._welcome: proto.Welcome | None = None
        self.predicting = StudentGuesses()  # our arrows in a prediction round
        self._motion: tuple = ()  # what moves, as the last frame showed it (see note_motion)
        self._moved_s = -math.inf  # when it last changed

    def run(
        self, seconds: float | None = None, screenshot: str | None = None, until: Callable[[], bool] | None = None
    ) -> int:
        """The UI loop; returns the process exit status (1 when the connection failed for good).

        Ends after `seconds`, or after the frame in which `until()` is true, or
        when the user quits. Closes the connection when it ends, but leaves
        pygame running (main() quits it)."""
        import pygame

        self._open_window()
        clock = pygame.time.Clock()
        start = time.monotonic()
        status = 0
        try:
            while self._handle_events(pygame.event.get()):
                if self.net.state == PlayerState.FAILED and not status:
                    print(f"airtable-client: {self.net.error}", file=sys.stderr)
                    status = 1
                if status and self.headless:
                    break  # a window keeps showing the sentence until the student closes it
                self._frame()
                if seconds is not None and time.monotonic() - start >= seconds:
                    break
                if until is not None and until():
                    break
                if self.still(time.monotonic()) and not self.headless:
                    _wait_for_input(1.0 / IDLE_FPS)
                else:
                    clock.tick(self.fps)
        except KeyboardInterrupt:
            pass
        finally:
            if screenshot:
                self.window.save_screenshot(screenshot)
            self.net.close(bye=True)
        return status

    def note_motion(self, scene: Scene, cursor_m: np.ndarray, now_s: float) -> None:
        """Remember what moves in this frame: the pucks, every cursor, our own input."""
        motion = (scene.pos_m.tobytes(), scene.cursors, tuple(cursor_m.tolist()), self.button, frozenset(self.keys))
        if motion != self._motion:
            self._motion, self._moved_s = motion, now_s

    def still(self, now_s: float) -> bool:
        """Nothing has moved, and no input came, for IDLE_AFTER_S: the window may draw less often."""
        return now_s - self._moved_s >= IDLE_AFTER_S

    def _open_window(self) -> None:
        import pygame

        from airtable.app.window import GameWindow, LessonsPainter, TimelinePainter

        self._welcome = self.net.welcome
        from airtable.app.aids_paint import AidsPainter

        self.window = GameWindow(self._new_env(), caption=self._caption(), headless=self.headless)
        self.painter = AidsPainter(self.window)
        self.lessons_painter = LessonsPainter(self.window)
        self.timeline_painter = TimelinePainter(self.window)
        if not self.headless:
            pygame.mouse.set_visible(False)  # our arrow, drawn each frame, is the pointer

    def _table_size(self) -> tuple[float, float]:
        w = self._welcome
        return (w.width_m, w.height_m) if w is not None else proto.DEFAULT_TABLE_SIZE_M

    def _new_env(self):
        from airtable.app.environment import DEFAULT_SIZE_PX, Environment

        self.env = Environment(DEFAULT_SIZE_PX, width_m=self._table_size()[0])
        return self.env

    def _caption(self) -> str:
        return f"Air Table - {self._welcome.label}" if self._welcome else "Air Table - waiting for a place"

    def _handle_events(self, events) -> bool:
        """Mouse buttons and keys; False when the user quits (window closed or Esc)."""
        import pygame

        for event in events:
            if event.type == pygame.KEYDOWN and event.key == pygame.K_ESCAPE and self.show_help:
                self.show_help = False
                continue
            if event.type == pygame.QUIT or (event.type == pygame.KEYDOWN and event.key == pygame.K_ESCAPE):
                return False
            if event.type == pygame.KEYDOWN and self._local_key(pygame.key.name(event.key)):
                continue  # this window's own toggles: the server never hears of them
            if self._predict_event(event):
                continue
            if event.type == pygame.KEYDOWN:
                self.keys.add(pygame.key.name(event.key))
            elif event.type == pygame.KEYUP:
                self.keys.discard(pygame.key.name(event.key))
            elif event.type == pygame.MOUSEBUTTONDOWN and event.button in (1, 2, 3):
                self.button = event.button
            elif event.type == pygame.MOUSEBUTTONUP and event.button == self.button:
                held = pygame.mouse.get_pressed(3)
                self.button = next((b for b in (1, 2, 3) if held[b - 1]), 0)
        return True

    def _local_key(self, name: str) -> bool:
        """F1 and the aids a student turns on or off for their own window; True if `name` was one."""
        if name == "f1":
            self.show_help = not self.show_help
        elif name in LOCAL_KEYS:
            self.net.aids.toggle(name)
            if name == "e":
                self.window.clear_trails()
        else:
            return False
        return True

    def _follow_restarts(self, scene: Scene) -> None:
        """A demo (re)start or another view: trails and arrow scales start afresh, as on the teacher's window."""
        drawn_from = (self.net.aids.restarts, scene.zoom, scene.origin_m)
        if drawn_from != self._drawn_from:
            if self._drawn_from and drawn_from[0] != self._drawn_from[0]:
                self.painter.new_demo()
            self._drawn_from = drawn_from
            self.window.clear_trails()

    def _predict_event(self, event) -> bool:
        """While a round is open, button 1 on a puck drags our arrow; letting go sends PREDICT."""
        import pygame

        if self.env is None or event.type not in (pygame.MOUSEBUTTONDOWN, pygame.MOUSEMOTION, pygame.MOUSEBUTTONUP):
            return False
        info, guesses = self.net.round, self.predicting
        point = self.env.to_world(np.asarray(event.pos, dtype=float))
        if event.type == pygame.MOUSEBUTTONDOWN:
            scene = self.net.latest()
            radius = scene.radius_m if scene is not None else ()
            return event.button == 1 and guesses.press(info, point, radius)
        guessed = guesses.drag(info, point)
        if guessed is not None and event.type == pygame.MOUSEBUTTONUP:
            guesses.dragging = None
            self.net.send_predict(*guessed)
        return guessed is not None

    def _follow_welcome(self) -> None:
        """After a (re)connect: the new name in the caption, the new table size in the view."""
        welcome = self.net.welcome
        if welcome is None or welcome is self._welcome:
            return
        old_width = self._table_size()[0]
        self._welcome = welcome
        self.window.set_caption(self._caption())
        if welcome.width_m != old_width:  # the teacher restarted with another table
            self.window.set_env(self._new_env())

    def _frame(self) -> None:
        import pygame

        from airtable.app.environment import MAX_ZOOM, MIN_ZOOM

        net, env = self.net, self.env
        self._follow_welcome()
        scene = net.smooth() or _empty_scene(*self._table_size())
        # The teacher's view: the student sees what the projector shows.
        env.zoom = min(max(scene.zoom, MIN_ZOOM), MAX_ZOOM)
        env.origin_m = np.array(scene.origin_m, dtype=float)
        cursor_m = env.to_world(np.array(pygame.mouse.get_pos(), dtype=float))
        net.update_input(cursor_m, self.button, self.keys)
        self.note_motion(scene, cursor_m, time.monotonic())
        self.states_seen.add(net.state)
        self.frames += 1
        try:
            self._draw(fit_drawing_budget(scene, env), cursor_m, bool(pygame.mouse.get_focused()))
        except Exception as exc:  # a scene this window cannot draw must not end the student's session
            if self.draw_error is None:
                self.draw_error = f"{type(exc).__name__}: {exc}"
                print(f"airtable-client: could not draw a frame ({self.draw_error}); carrying on", file=sys.stderr)

    def _draw(self, scene: Scene, cursor_m: np.ndarray, focused: bool) -> None:
        from airtable.app.aids_student_view import STUDENT_KEYS, draw_student_aids, draw_student_lessons

        net, win, welcome = self.net, self.window, self._welcome
        me = welcome.label if welcome else ""
        color = welcome.color if welcome else (200, 200, 200)
        cursors, extra = own_cursor_live(scene.cursors, me, cursor_m, self.button, focused)
        self._follow_restarts(scene)
        win.draw(
            dataclasses.replace(scene, cursors=cursors),
            trails=net.aids.shows("e"),
            hud=(f"You are {me}" if me else "Not at the table yet", net.status_text),
            banner=net.banner_text or student_banner(scene, me),
            hud_color=color,
        )
        draw_student_lessons(self.lessons_painter, self.timeline_painter, scene, net.aids, cursor_m)
        draw_student_aids(self.painter, scene, net.aids, time.monotonic(), cursor_m)
        if extra and me:  # not in the snapshots yet: the arrow alone
            win.draw_cursor(me, color, cursor_m)
        self._draw_round(color)
        if self.show_help:
            win.draw_panel("Keys", list(STUDENT_KEYS))
        elif net.aids.teacher & NOTES and net.aids.notes is not None:
            win.draw_panel(scene.title, [net.aids.notes], large=True)
        win.present()

    def _draw_round(self, color) -> list:
        """The prediction round, if one is under way; returns the lines of text written and where."""
        info = self.net.round
        self.predicting.follow(info)
        if info is None or info.state == "closed":
            return []
        count = f"{info.predicted} of {info.players} predicted"
        # The aids' painter: its labels and these lines avoid each other.
        return paint_round(self.painter, info, self.predicting.guesses, color, count)


def fit_drawing_budget(scene: Scene, env) -> Scene:
    """The scene cut down, if needed, so that one frame stays cheap to draw.

    A server could send thousands of pucks or springs each as big as the
    window, or every puck in its own colour; drawing them would take minutes a
    frame. Honest scenes are far inside these budgets and come back unchanged:
    - pucks in view cover the window at most MAX_PUCK_AREA_SCREENS times over,
      and none is drawn wider than the window's diagonal;
    - at most MAX_PUCK_LOOKS distinct colours (beyond that, colours are rounded);
    - springs span at most MAX_SPRING_SPAN_PX pixels in all (the longest go
      first), and so do cursor strings.
    """
    changes: dict = {}
    if len(scene.radius_m):
        changes.update(_fit_pucks(scene, env))
    if len(scene.spring_pairs):
        changes.update(_fit_springs(scene, env))
    if scene.cursors:
        changes.update(_fit_cursor_strings(scene, env))
    return dataclasses.replace(scene, **changes) if changes else scene


def _fit_pucks(scene: Scene, env) -> dict:
    w, h = env.size_px
    px_per_m = float(env.length_to_px(1.0))
    r_px = scene.radius_m * px_per_m
    centers = env.to_screen(scene.pos_m)
    visible = (
        (centers[:, 0] + r_px >= 0)
        & (centers[:, 0] - r_px <= w)
        & (centers[:, 1] + r_px >= 0)
        & (centers[:, 1] - r_px <= h)
    )
    changes: dict = {}
    colors = scene.color_rgb
    if len(np.unique(colors[visible], axis=0)) > MAX_PUCK_LOOKS:
        changes["color_rgb"] = (colors & 0xE0) | 0x10  # 512 colours at most
    area_px = float(np.minimum(np.pi * r_px[visible] ** 2, w * h).sum())
    budget_px = MAX_PUCK_AREA_SCREENS * w * h
    largest_m = math.hypot(w, h) / px_per_m
    if area_px > budget_px or float(scene.radius_m.max()) > largest_m:
        shrink = math.sqrt(budget_px / area_px) if area_px > budget_px else 1.0
        changes["radius_m"] = np.minimum(scene.radius_m, largest_m) * shrink
    return changes


def _fit_springs(scene: Scene, env) -> dict:
    d = scene.pos_m[scene.spring_pairs[:, 0]] - scene.pos_m[scene.spring_pairs[:, 1]]
    # Drawing a spring costs about its length in pixels, even where it is off screen.
    span_px = (np.abs(d[:, 0]) + np.abs(d[:, 1])) * float(env.length_to_px(1.0))
    if float(span_px.sum()) <= MAX_SPRING_SPAN_PX:
        return {}
    order = np.argsort(span_px, kind="stable")
    keep = np.sort(order[np.cumsum(span_px[order]) <= MAX_SPRING_SPAN_PX])
    return {
        "spring_pairs": scene.spring_pairs[keep],
        "spring_length_m": scene.spring_length_m[keep],
        "spring_width_m": scene.spring_width_m[keep],
        "spring_color_rgb": scene.spring_color_rgb[keep],
    }


def _fit_cursor_strings(scene: Scene, env) -> dict:
    held = [i for i, c in enumerate(scene.cursors) if 0 <= c.held < len(scene.pos_m)]
    if not held:
        return {}
    ends = np.array([scene.cursors[i].cursor_m for i in held]) - scene.pos_m[[scene.cursors[i].held for i in held]]
    span_px = (np.abs(ends[:, 0]) + np.abs(ends[:, 1])) * float(env.length_to_px(1.0))
    if float(span_px.sum()) <= MAX_SPRING_SPAN_PX:
        return {}
    order = np.argsort(span_px, kind="stable")
    dropped = {held[i] for i in order[np.cumsum(span_px[order]) > MAX_SPRING_SPAN_PX]}
    cursors = tuple(dataclasses.replace(c, held=-1) if i in dropped else c for i, c in enumerate(scene.cursors))
    return {"cursors": cursors}


def own_cursor_live(
    cursors: Sequence[CursorView], me: str, cursor_m: Sequence[float], button: int, focused: bool
) -> tuple[tuple[CursorView, ...], bool]:
    """The snapshot's cursors with ours moved to where the mouse is now.

    Our cursor in a snapshot is a round trip old; drawing it at the live mouse
    position (and last, on top) makes the arrow and its string follow the hand
    without delay. Returns the cursors and whether ours still needs drawing
    on its own (it is not in the snapshots yet).
    """
    others = tuple(c for c in cursors if c.name != me)
    mine = next((c for c in cursors if c.name == me), None)
    if not focused:  # the mouse is in another window: show what the server has
        return others + ((mine,) if mine else ()), False
    if mine is None:
        return others, True
    live = dataclasses.replace(mine, cursor_m=(float(cursor_m[0]), float(cursor_m[1])), button=button)
    return others + (live,), False


def _parse_args(argv: Sequence[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(
        prog="airtable-client",
        description="Join a teacher's air table: your mouse pulls pucks on the shared table "
        "(buttons 1, 2, 3 are the medium, soft and stiff cursor strings; Esc quits).",
    )
    parser.add_argument("server", metavar="HOST[:PORT]", help="the address from the teacher's 'join with:' line")
    parser.add_argument("--name", help=f"a name shown next to your cursor (up to {proto.MAX_NAME_CHARS} characters)")
    parser.add_argument("--password", help="the table's password, if the teacher set one")
    parser.add_argument("--headless", action="store_true", help="run without a window (for tests)")
    parser.add_argument("--seconds", type=float, help="quit after this many seconds")
    parser.add_argument("--screenshot", metavar="FILE.png", help="save the last frame here when quitting")
    return parser.parse_args(argv)


def main(argv: Sequence[str] | None = None) -> int:
    """The airtable-client command; returns the exit status."""
    args = _parse_args(argv)
    try:
        host, port = proto.parse_host_port(args.server)
        name = None if args.name is None else proto.check_name(args.name)
        if args.seconds is not None and not (math.isfinite(args.seconds) and args.seconds >= 0):
            raise ValueError("--seconds must be zero or a positive number")
    except (ValueError, proto.ProtocolError) as e:
        print(f"airtable-client: {e}", file=sys.stderr)
        return 1
    net = NetPlayer(host, port, name=name, password=args.password)
    try:
        welcome = net.connect()
    except PlayerError as e:
        print(f"airtable-client: {e}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        return 1
    if welcome is None:
        print(f"airtable-client: {net.waiting_because}; waiting for a place (Esc quits)")
    else:
        print(f"airtable-client: connected to {net.address}; you are {welcome.label}")
    if args.headless:
        os.environ.setdefault("SDL_VIDEODRIVER", "dummy")  # no screen: pygame's events still need a driver
    else:
        from airtable.app.window import prefer_plain_framebuffer

        prefer_plain_framebuffer()  # software OpenGL behind the window costs 11-35 ms a flip at 1920x1080
    try:
        return PlayerApp(net, headless=args.headless).run(seconds=args.seconds, screenshot=args.screenshot)
    finally:
        import pygame

        pygame.quit()


if __name__ == "__main__":
    sys.exit(main())
