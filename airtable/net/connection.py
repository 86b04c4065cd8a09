"""One client connection on the server: its reading, rate limit and sending.

Owned by the server's network thread. A `Connection` reads frames (at most a
message and byte budget a second, see `RateLimit`), and sends in this order:
control frames (WELCOME, ERROR, BYE) first, then the newest snapshot tick,
coded for this player (codec.py) only when it can go: while fewer bytes are
unacknowledged than one round trip of snapshots needs (pacing.py), so a slow reader misses snapshots instead of
piling them up, and on a tight link every player's rate drops evenly. After an ERROR
it shuts its side and waits for the client to hang up (`closing`).
"""

from __future__ import annotations

import enum
import math
import selectors
import socket
import time
from collections import deque

from airtable.net import pacing
from airtable.net import protocol as proto
from airtable.net.codec import SnapshotEncoder, Viewer

RATE_PER_S = 240.0  # sustained messages a second per client (a player sends <= 61)
RATE_BURST = 480.0
BYTES_PER_S = 24 * 1024  # sustained bytes a second (a player sends about 6 KB/s)
BYTES_BURST = 48 * 1024
RECV_BYTES = 16384
LINGER_S = 2.0  # after an ERROR: time to let it reach the client before closing
RATE_WINDOW_S = 2.0  # snapshot rates are measured over this many seconds
RTT_READ_S = 0.02  # pacing reads the kernel's round trip at most this often
UDP_FRESH_S = 1.5  # a player whose input datagram came this recently sends its cursor by UDP


class State(enum.Enum):
    HELLO = "saying hello"
    PLAYING = "playing"
    CLOSING = "closing"


class RateLimit:
    """Two token buckets: messages a second and bytes a second."""

    def __init__(self, now: float) -> None:
        self.messages = RATE_BURST
        self.bytes = float(BYTES_BURST)
        self.t = now

    def spend(self, now: float, messages: int, nbytes: int) -> str | None:
        """Take what was received from the budget; a sentence when it overflows."""
        dt = max(0.0, now - self.t)
        self.t = now
        self.messages = min(RATE_BURST, self.messages + dt * RATE_PER_S) - messages
        self.bytes = min(float(BYTES_BURST), self.bytes + dt * BYTES_PER_S) - nbytes
        if self.messages < 0:
            return (
                f"more than {RATE_PER_S:g} messages a second were received; a client sends at most 60 inputs a second"
            )
        if self.bytes < 0:
            return f"more than {BYTES_PER_S // 1024} KiB a second were received; a client sends about 6 KiB a second"
        return None


class Connection:
    """One client socket, owned by the network thread."""

    def __init__(
        self, cid: int, sock: socket.socket, addr: tuple, now: float, selector: selectors.BaseSelector
    ) -> None:
        self.cid = cid
        self.sock = sock
        self.host = str(addr[0])
        self.peer = f"{addr[0]}:{addr[1]}"
        self.selector = selector
        self.reader = proto.FrameReader(proto.MAX_CLIENT_FRAME, proto.CLIENT_FRAMES, sender="a client")
        self.rate = RateLimit(now)
        self.state = State.HELLO
        self.number = 0  # player number n of "Cn", 0 before WELCOME
        self.name = ""
        self.opened = now
        self.last_rx = now
        self.deadline = now  # set by the server: when the HELLO or the closing must be done
        self.last_input: proto.InputRecord | None = None
        self.challenge: tuple[proto.Hello, str] | None = None  # a HELLO asking for a seat, and our nonce
        self.proven_seat: int | None = None  # the seat the client's PROOF proved (identity.py)
        self.last_change = now  # when the input last changed (for "idle" in the roster)
        self.snapshot_times: deque[float] = deque()  # when each snapshot went out whole
        self.lag_s = 0.0  # smoothed time a snapshot waited here before it was sent
        self._out_cur: memoryview | None = None  # the frame being sent
        self._out_ctrl: deque[bytes] = deque()  # WELCOME / ERROR / BYE, before any snapshot
        self.viewer = Viewer()  # the snapshot ticks this player holds
        self._encoder: SnapshotEncoder | None = None
        self._tick_due = False  # a newer tick than the player holds is waiting to be coded and sent
        self._last_snap_bytes = 0
        self._mean_snap_bytes = 0.0  # smoothed snapshot size, for pacing
        self._rtt: tuple[float, float] | None = None  # the kernel's round trip (smoothed, lowest), read at _rtt_at
        self._rtt_at = -math.inf
        self.held_back = False  # the tick waits for the previous one to be acknowledged
        self._snap_offered = now
        self._last_offer = now
        self.period_s = 1 / 30  # smoothed time between snapshot ticks (pacing needs the rate it aims for)
        self._sending_snap = False
        self.udp_key: str | None = None  # this session's input datagrams' key (datagrams.py), once welcomed
        self.udp_sequence = 0  # the newest input datagram applied
        self.udp_at = -math.inf  # when it came
        self.keep_seat = True  # a drop holds the seat for a return (seats.py); not after BYE or a removal
        self._drained_at = now  # when the client last took bytes we sent (see unread_s)
        self._queued_seen = 0
        self._shut = False  # our side is shut down after an ERROR
        self._events = selectors.EVENT_READ
        self.closed = False
        selector.register(sock, self._events, self)

    @property
    def who(self) -> str:
        return f"{self.name} ({self.peer})" if self.name else self.peer

    @property
    def stalled(self) -> bool:
        """A frame is part-sent: the client's socket is full."""
        return self._out_cur is not None

    def has_output(self) -> bool:
        return self._out_cur is not None or bool(self._out_ctrl) or self._tick_due

    # ------------------------------------------------------------ receiving

    def receive(self, now: float) -> list[tuple[int, bytes]] | None:
        """Frames now complete ([] when none), or None when the peer has gone.

        Raises ProtocolError for bad bytes or a client over its rate limit."""
        try:
            data = self.sock.recv(RECV_BYTES)
        except (BlockingIOError, InterruptedError):
            return []
        except OSError:  # reset by the peer
            return None
        if not data:
            return None
        if self.state == State.CLOSING:
            return []  # reading only so that closing does not reset the connection
        frames = self.reader.feed(data)
        too_much = self.rate.spend(now, len(frames), len(data))
        if too_much:
            raise proto.ProtocolError(too_much)
        if frames:
            self.last_rx = now
        return frames

    def inputs_by_udp(self, now: float) -> bool:
        """Whether this player's cursor comes by UDP now (a datagram came lately): TCP INPUTs are
        then only a heartbeat, since one held up behind a lost packet is older than the datagrams."""
        return now - self.udp_at < UDP_FRESH_S

    def note_input(self, record: proto.InputRecord, now: float) -> None:
        if record != self.last_input:
            self.last_change = now
        self.last_input = record

    # ------------------------------------------------------------ sending

    def send_control(self, frame: bytes) -> None:
        self._out_ctrl.append(frame)
        self.flush()

    def offer_tick(self, encoder: SnapshotEncoder, now: float) -> None:
        """A new snapshot tick is out: it replaces one that never started going out,
        and is coded against what this player holds when its turn comes."""
        if encoder.newest is None or self.state != State.PLAYING:
            return
        gap, self._last_offer = now - self._last_offer, now
        if 0 < gap < 1.0:  # a pause (nobody played, the app was busy) says nothing about the rate
            self.period_s += 0.1 * (gap - self.period_s)
        if not self._tick_due:
            self._snap_offered = now
        self._encoder, self._tick_due = encoder, True
        self.flush()

    def fail(self, sentence: str, now: float, retry: bool = False, about: str | None = None) -> None:
        """Send ERROR `sentence` (`about`: the HELLO field refused); close once it is out (the server
        closes it after LINGER_S)."""
        self.state = State.CLOSING
        self._tick_due = False
        self._out_ctrl.append(proto.encode_error(sentence, retry=retry, about=about))
        self.deadline = now + LINGER_S
        self.flush()

    def flush(self) -> None:
        """Send what the socket takes now; wait for EVENT_WRITE for the rest."""
        while not self._shut and not self.closed and self._next_frame():
            try:
                sent = self.sock.send(self._out_cur)
            except (BlockingIOError, InterruptedError):
                break
            except OSError:
                self.close()
                return
            if sent < len(self._out_cur):
                self._out_cur = self._out_cur[sent:]
            else:
                self._frame_done()
        if self.closed:
            return
        if self.state == State.CLOSING and not self._shut and not self.has_output():
            self._shut_down()
        events = selectors.EVENT_READ
        # A held-back tick waits for acknowledgements, not for room: the server looks again.
        if (self._out_cur is not None or self._out_ctrl) and not self._shut:
            events |= selectors.EVENT_WRITE
        if events != self._events and not self.closed:
            self._events = events
            self.selector.modify(self.sock, events, self)

    def _next_frame(self) -> bool:
        """Start the next frame unless one is part-sent; False when there is nothing to send.

        Control frames first; frames are never interleaved, because the next one
        starts only when the current one is fully sent."""
        if self._out_cur is not None:
            return True
        if self._out_ctrl:
            self._out_cur, self._sending_snap = memoryview(self._out_ctrl.popleft()), False
        elif self._tick_due:
            return self._start_tick()
        else:
            return False
        return True

    def _start_tick(self) -> bool:
        size = max(self._last_snap_bytes, round(self._mean_snap_bytes))
        now = time.monotonic()
        if now - self._rtt_at > RTT_READ_S:  # a held-back tick is looked at every 2 ms: read the round trip less often
            self._rtt, self._rtt_at = pacing.round_trip_s(self.sock), now
        self.held_back = not pacing.may_send(self.sock, size, self.period_s, self._rtt)
        if self.held_back:
            return False
        self._tick_due = False
        data = self._encoder.frames_for(self.viewer)
        if not data:
            return False
        self._last_snap_bytes = len(data)
        self._mean_snap_bytes += 0.1 * (len(data) - self._mean_snap_bytes)
        self._out_cur, self._sending_snap = memoryview(data), True
        return True

    def _frame_done(self) -> None:
        self._out_cur = None
        if self._sending_snap:
            now = time.monotonic()
            self.lag_s += 0.2 * ((now - self._snap_offered) - self.lag_s)
            times = self.snapshot_times
            times.append(now)
            while now - times[0] > RATE_WINDOW_S:
                times.popleft()

    def unread_s(self, now: float) -> float:
        """Seconds since the client last took any of the bytes sent to it (0 while nothing waits).

        A closed lid or a frozen client stops acknowledging; so does one that never reads, once
        its receive buffer is full. Where the kernel cannot tell, a frame stuck half-sent counts."""
        queued = pacing.queued_bytes(self.sock)
        if queued is None:
            queued = len(self._out_cur) if self._out_cur is not None else 0
        if queued == 0 or queued < self._queued_seen:
            self._drained_at = now
        self._queued_seen = queued
        return now - self._drained_at

    def snapshot_rate(self, now: float) -> float:
        """Snapshots a second that went out whole, over the last RATE_WINDOW_S."""
        window = min(RATE_WINDOW_S, now - self.opened)
        recent = sum(1 for t in self.snapshot_times if now - t <= RATE_WINDOW_S)
        return recent / window if window > 0 else 0.0

    def _shut_down(self) -> None:
        # The ERROR is out: shut our side and read until the client hangs up,
        # so that unread client bytes do not turn the close into a reset
        # that could discard the ERROR before the client reads it.
        self._shut = True
        try:
            self.sock.shutdown(socket.SHUT_WR)
        except OSError:
            self.close()

    def say_bye(self) -> None:
        """Best effort, when the server stops: BYE unless a frame is half sent."""
        if self.state == State.PLAYING and self._out_cur is None and not self.closed:
            try:
                self.sock.send(proto.encode_bye())
            except OSError:
                pass

    def close(self) -> None:
        if self.closed:
            return
        self.closed = True
        try:
            self.selector.unregister(self.sock)
        except (KeyError, ValueError):
            pass
        self.sock.close()
