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
import dataclasses
import math
import socket
import sys
import threading
import time
from collections.abc import Callable, Iterable, Sequence

import numpy as np

from airtable.app.scene import CursorView, Scene
from airtable.net import protocol as proto

CONNECT_TIMEOUT_S = 5.0
SILENCE_S = 10.0  # no snapshot for this long: the server is gone (snapshots come 30 times a second)
MAX_INPUT_HZ = 60.0
HEARTBEAT_S = 1.0
FIRST_BACKOFF_S = 0.25
MAX_BACKOFF_S = 4.0


class PlayerError(Exception):
    """A problem the player cannot get past; str(error) is one sentence for the user."""


class _ConnectError(Exception):
    """One connection attempt failed; `retry` says whether trying again can help."""

    def __init__(self, message: str, retry: bool) -> None:
        super().__init__(message)
        self.retry = retry


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


class NetPlayer:
    """The network side of a player: handshake, newest snapshot, input, reconnect.

    `connect()` makes the first connection (raising PlayerError with a sentence
    when it fails) and starts a reader thread. From then on `state` is
    CONNECTED, RETRYING (the server went away; it reconnects with backoff) or
    FAILED (`error` says why); `close()` ends it. `on_snapshot(scene, t)` is
    called from the reader thread for each snapshot, if given.
    """

    CONNECTING = "connecting"
    CONNECTED = "connected"
    RETRYING = "server gone, retrying..."
    FAILED = "failed"
    CLOSED = "closed"

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
    ) -> None:
        self.host = host
        self.port = int(port)
        self.name = None if name is None else proto.check_name(name)
        self.password = password
        self.timeout_s = float(timeout_s)
        self.on_snapshot = on_snapshot
        self.protocol_version = protocol_version  # other than 1 only to test the server's answer
        self.max_backoff_s = max_backoff_s
        self.state = self.CONNECTING
        self.error: str | None = None
        self.welcome: proto.Welcome | None = None
        self.reconnects = 0
        self.snapshots = 0
        self._scene: Scene | None = None
        self._sock: socket.socket | None = None
        self._send_lock = threading.Lock()
        self._closed = threading.Event()
        self._thread: threading.Thread | None = None
        self._throttle = InputThrottle()

    @property
    def address(self) -> str:
        host = f"[{self.host}]" if ":" in self.host else self.host
        return f"{host}:{self.port}"

    @property
    def status_text(self) -> str:
        """The connection state as the HUD shows it."""
        if self.state == self.CONNECTED:
            return f"connected to {self.address}"
        if self.state == self.FAILED:
            return self.error or "failed"
        return self.state

    # ---------------------------------------------------------------- connecting

    def connect(self) -> proto.Welcome:
        """Connect, say HELLO and wait for WELCOME; then keep reading in a thread."""
        try:
            opened = self._open()
        except _ConnectError as e:
            self.state, self.error = self.FAILED, str(e)
            raise PlayerError(str(e)) from None
        sock, welcome = opened[0], opened[1]
        self._adopt(sock, welcome)
        self._thread = threading.Thread(target=self._run, args=(opened,), name="airtable-player", daemon=True)
        self._thread.start()
        return welcome

    def _open(self) -> tuple[socket.socket, proto.Welcome, proto.FrameReader, list]:
        where = self.address
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
            except ConnectionRefusedError:
                failure = _ConnectError(
                    f"connection refused by {where}: is the server running? is port {self.port} open in its firewall?",
                    retry=True,
                )
            except TimeoutError:
                failure = _ConnectError(
                    f"no answer from {where} within {self.timeout_s:g} s: is the address right? "
                    f"is port {self.port} open in the server's firewall?",
                    retry=True,
                )
            except OSError as e:
                failure = _ConnectError(
                    f"cannot reach {where} ({e.strerror or e}): is this computer on the teacher's network?",
                    retry=True,
                )
            else:
                try:
                    return (sock, *self._handshake(sock))
                except BaseException:
                    sock.close()
                    raise
            sock.close()
        assert failure is not None
        raise failure

    def _handshake(self, sock: socket.socket) -> tuple[proto.Welcome, proto.FrameReader, list]:
        where = self.address
        sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        reader = proto.FrameReader(proto.MAX_SERVER_FRAME, sender="the server")
        deadline = time.monotonic() + self.timeout_s
        try:
            sock.sendall(proto.encode_hello(self.name, self.password, self.protocol_version))
            while True:
                sock.settimeout(max(0.01, deadline - time.monotonic()))
                data = sock.recv(65536)
                if not data:
                    raise _ConnectError(f"the server at {where} hung up before saying WELCOME", retry=True)
                frames = reader.feed(data)
                if frames:
                    frame_type, payload = frames[0]
                    if frame_type == proto.ERROR:
                        raise _ConnectError(proto.parse_error(payload), retry=False)
                    if frame_type != proto.WELCOME:
                        raise proto.ProtocolError(f"the first message was {proto.FRAME_NAMES[frame_type]}, not WELCOME")
                    # Frames that came with the WELCOME go to the reader thread.
                    return proto.parse_welcome(payload), reader, frames[1:]
        except proto.ProtocolError as e:
            raise _ConnectError(
                f"{where} does not answer like an airtable server ({e}); check the address and port", retry=False
            ) from None
        except TimeoutError:
            raise _ConnectError(
                f"{where} accepted the connection but did not answer within {self.timeout_s:g} s; "
                "is it an airtable server?",
                retry=True,
            ) from None
        except OSError as e:
            raise _ConnectError(f"the connection to {where} broke during the handshake ({e})", retry=True) from None

    def _adopt(self, sock: socket.socket, welcome: proto.Welcome) -> None:
        sock.settimeout(0.25)  # the reader wakes this often to check for silence and close()
        with self._send_lock:
            self._sock = sock
            self.welcome = welcome
            self._throttle.reset()
            self.state = self.CONNECTED

    # ---------------------------------------------------------------- reader thread

    def _run(self, opened: tuple) -> None:
        while True:
            sock, _, reader, frames = opened
            fatal = self._read(sock, reader, frames)
            with self._send_lock:
                self._sock = None
            sock.close()
            if self._closed.is_set():
                return
            if fatal is not None:
                self.state, self.error = self.FAILED, fatal
                return
            self.state = self.RETRYING
            opened = self._reconnect()
            if opened is None:
                return
            self.reconnects += 1
            self._adopt(opened[0], opened[1])

    def _read(self, sock: socket.socket, reader: proto.FrameReader, frames: list) -> str | None:
        """Read until the connection ends; return a fatal sentence, or None to reconnect."""
        last_rx = time.monotonic()
        while not self._closed.is_set():
            now = time.monotonic()
            for frame_type, payload in frames:
                last_rx = now
                if frame_type == proto.SNAPSHOT:
                    try:
                        scene = proto.decode_snapshot(payload)
                    except proto.ProtocolError as e:
                        return str(e)
                    self._scene = scene  # one reference swap: readers see the old or the new scene
                    self.snapshots += 1
                    if self.on_snapshot is not None:
                        self.on_snapshot(scene, now)
                elif frame_type == proto.ERROR:
                    return proto.parse_error(payload)
                elif frame_type == proto.BYE:
                    return None
                else:
                    return f"{self.address} sent an unexpected {proto.FRAME_NAMES[frame_type]} message"
            if now - last_rx > max(SILENCE_S, self.timeout_s):
                return None
            frames = []
            try:
                data = sock.recv(65536)
            except TimeoutError:
                continue
            except OSError:
                return None
            if not data:
                return None
            try:
                frames = reader.feed(data)
            except proto.ProtocolError as e:
                return f"{self.address} sent something that is not airtable protocol ({e})"
        return None

    def _reconnect(self) -> tuple | None:
        backoff = FIRST_BACKOFF_S
        while not self._closed.wait(backoff):
            try:
                return self._open()
            except _ConnectError as e:
                if not e.retry:
                    self.state, self.error = self.FAILED, str(e)
                    return None
            backoff = min(backoff * 2, self.max_backoff_s)
        return None

    # ---------------------------------------------------------------- the game side

    def latest(self) -> Scene | None:
        """The newest scene received (None before the first snapshot)."""
        return self._scene

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

    def _record(self, cursor_m: Sequence[float], button: int, keys: Iterable[str]) -> proto.InputRecord:
        welcome = self.welcome
        w, h = (welcome.width_m, welcome.height_m) if welcome else (10.0, 8.7556)
        # Send only what the server accepts: cursor clamped, known buttons, short key names.
        cursor = proto.clamp_cursor(cursor_m, w, h)
        button = button if button in (0, 1, 2, 3) else 0
        names = sorted(k for k in keys if 1 <= len(k) <= proto.MAX_KEY_CHARS and k.isprintable())
        return proto.InputRecord(cursor, button, frozenset(names[: proto.MAX_KEYS]))

    def _send(self, record: proto.InputRecord, now: float) -> bool:
        frame = proto.encode_input(record.cursor_m, record.button, record.keys)
        with self._send_lock:
            sock = self._sock
            if sock is None or self.state != self.CONNECTED:
                return False
            try:
                sock.sendall(frame)
            except OSError:
                # The reader thread notices too and starts reconnecting; wake it now.
                try:
                    sock.shutdown(socket.SHUT_RDWR)
                except OSError:
                    pass
                return False
            self._throttle.sent(record, now)
        return True

    def close(self, bye: bool = True) -> None:
        """Say BYE (when connected), close the socket and stop the reader thread."""
        self._closed.set()
        with self._send_lock:
            sock = self._sock
            if sock is not None:
                if bye and self.state == self.CONNECTED:
                    try:
                        sock.sendall(proto.encode_bye())
                    except OSError:
                        pass
                try:
                    sock.shutdown(socket.SHUT_RDWR)
                except OSError:
                    pass
        if self._thread is not None and self._thread is not threading.current_thread():
            self._thread.join(timeout=5.0)
        if self.state != self.FAILED:
            self.state = self.CLOSED


# -------------------------------------------------------------------- the window


class PlayerApp:
    """The pygame window of a player: the server's table from snapshots, our cursor drawn locally."""

    def __init__(self, net: NetPlayer, headless: bool = False, fps: float = 60.0) -> None:
        self.net = net
        self.headless = headless
        self.fps = fps
        self.window = None  # the GameWindow, once run() has opened it
        self.frames = 0
        self.states_seen: set[str] = set()  # connection states shown, for tests

    def run(self, seconds: float | None = None, screenshot: str | None = None) -> int:
        """The UI loop; returns the process exit status (1 when the connection failed for good).

        Closes the connection when it ends, but leaves pygame running (main() quits it)."""
        import pygame

        from airtable.app.environment import DEFAULT_SIZE_PX, Environment
        from airtable.app.window import GameWindow

        net = self.net
        welcome = net.welcome
        assert welcome is not None, "connect() first"
        env_width_m = welcome.width_m
        env = Environment(DEFAULT_SIZE_PX, width_m=env_width_m)
        win = GameWindow(env, caption=f"Air Table - {welcome.client}", headless=self.headless)
        self.window = win
        if not self.headless:
            pygame.mouse.set_visible(False)  # our arrow, drawn each frame, is the pointer
        clock = pygame.time.Clock()
        button = 0
        keys: set[str] = set()
        start = time.monotonic()
        status = 0
        try:
            while True:
                quit_now = False
                for event in pygame.event.get():
                    if event.type == pygame.QUIT:
                        quit_now = True
                    elif event.type == pygame.KEYDOWN:
                        if event.key == pygame.K_ESCAPE:
                            quit_now = True
                        else:
                            keys.add(pygame.key.name(event.key))
                    elif event.type == pygame.KEYUP:
                        keys.discard(pygame.key.name(event.key))
                    elif event.type == pygame.MOUSEBUTTONDOWN and event.button in (1, 2, 3):
                        button = event.button
                    elif event.type == pygame.MOUSEBUTTONUP and event.button == button:
                        held = pygame.mouse.get_pressed(3)
                        button = next((b for b in (1, 2, 3) if held[b - 1]), 0)
                if quit_now:
                    break
                if net.state == net.FAILED:
                    print(f"airtable-client: {net.error}", file=sys.stderr)
                    status = 1
                    break
                if net.welcome is not None and net.welcome is not welcome:  # reconnected
                    welcome = net.welcome
                    win.set_caption(f"Air Table - {welcome.client}")
                    if welcome.width_m != env_width_m:  # the teacher restarted with another table
                        env_width_m = welcome.width_m
                        env = Environment(DEFAULT_SIZE_PX, width_m=env_width_m)
                        win.env = env
                scene = net.latest()
                if scene is None:
                    scene = _empty_scene(welcome.width_m, welcome.height_m)
                # The teacher's view: the student sees what the projector shows.
                env.zoom = scene.zoom
                env.origin_m = np.array(scene.origin_m, dtype=float)
                cursor_m = env.to_world(np.array(pygame.mouse.get_pos(), dtype=float))
                net.update_input(cursor_m, button, keys)
                self.states_seen.add(net.state)
                self.frames += 1
                focused = bool(pygame.mouse.get_focused())
                cursors, extra = _own_cursor_live(scene.cursors, welcome, cursor_m, button, focused)
                win.draw(
                    dataclasses.replace(scene, cursors=cursors),
                    hud=(f"You are {welcome.client}", net.status_text),
                    banner=net.RETRYING if net.state == net.RETRYING else None,
                    hud_color=welcome.color,
                )
                if extra:  # not in the snapshots yet: the arrow alone
                    win.draw_cursor(welcome.client, welcome.color, cursor_m)
                win.present()
                if seconds is not None and time.monotonic() - start >= seconds:
                    break
                clock.tick(self.fps)
        except KeyboardInterrupt:
            pass
        finally:
            if screenshot:
                win.save_screenshot(screenshot)
            net.close(bye=True)
        return status


def _own_cursor_live(
    cursors: Sequence[CursorView], welcome: proto.Welcome, cursor_m: Sequence[float], button: int, focused: bool
) -> tuple[tuple[CursorView, ...], bool]:
    """The snapshot's cursors with ours moved to where the mouse is now.

    Our cursor in a snapshot is a round trip old; drawing it at the live mouse
    position (and last, on top) makes the arrow and its string follow the hand
    without delay. Returns the cursors and whether ours still needs drawing
    on its own (it is not in the snapshots yet).
    """
    others = tuple(c for c in cursors if c.name != welcome.client)
    mine = next((c for c in cursors if c.name == welcome.client), None)
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
    print(f"airtable-client: connected to {net.address}; you are {welcome.client}")
    if not args.headless:
        from airtable.app.window import prefer_plain_framebuffer

        prefer_plain_framebuffer()  # software OpenGL behind the window costs 11-35 ms a flip at 1920x1080
    try:
        return PlayerApp(net, headless=args.headless).run(seconds=args.seconds, screenshot=args.screenshot)
    finally:
        import pygame

        pygame.quit()


if __name__ == "__main__":
    sys.exit(main())
